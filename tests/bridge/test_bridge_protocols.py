"""Protocol details with a raw WebSocket client: rosbridge compression and fragments, CBOR input,
Foxglove time under sim time, connection graph and parameter updates."""

from __future__ import annotations

import base64
import json
import struct
import subprocess
import threading
import time
from collections.abc import Callable

import cbor2
import pytest
from bridge_helpers import png_pixels
from websockets.sync.client import ClientConnection, connect

from ninjemys.bridge.server import Gateway
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.rostime import Time
from ninjemys.testing import ros1_env, wait_until

String = get_message_class("std_msgs/String")
Clock = get_message_class("rosgraph_msgs/Clock")


def first(
    ws: ClientConnection, pred: Callable[[object], bool], publish: Callable[[], None] | None = None
) -> object:
    """The first message (JSON decoded, or raw bytes) satisfying ``pred``; ``publish`` is called between reads."""
    deadline = time.monotonic() + 15
    while time.monotonic() < deadline:
        if publish is not None:
            publish()
        try:
            data = ws.recv(timeout=0.2)
        except TimeoutError:
            continue
        item = json.loads(data) if isinstance(data, str) else data
        if pred(item):
            return item
    raise AssertionError("expected message never came")


def test_rosbridge_compressions_and_fragments(gateway: Gateway, node: Node) -> None:
    pub = node.publisher("/words", String)
    text = "ninjemys " * 40
    publish = lambda: pub.publish(String(data=text))  # noqa: E731
    expected = {"op": "publish", "topic": "/words", "msg": {"data": text}}
    url = f"ws://127.0.0.1:{gateway.port}/"
    with connect(url) as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/words", "compression": "png"}))
        png = first(ws, lambda m: isinstance(m, dict) and m.get("op") == "png", publish)
        assert json.loads(png_pixels(png["data"]).rstrip(b"\n")) == expected
    with connect(url) as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/words", "compression": "cbor"}))
        frame = first(ws, lambda m: isinstance(m, bytes), publish)
        assert cbor2.loads(frame) == expected
    with connect(url) as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/words", "compression": "cbor-raw"}))
        raw = cbor2.loads(first(ws, lambda m: isinstance(m, bytes), publish))
        assert raw["op"] == "publish" and raw["msg"]["bytes"] == String(data=text).serialize_to_bytes()
        assert abs(raw["msg"]["secs"] - time.time()) < 60
    with connect(url) as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/words", "fragment_size": 100}))
        frag = first(
            ws, lambda m: isinstance(m, dict) and m.get("op") == "fragment" and m["num"] == 0, publish
        )
        parts = {0: frag["data"]}
        while len(parts) < frag["total"]:
            more = json.loads(ws.recv(timeout=5))
            if more.get("op") == "fragment" and more["id"] == frag["id"]:
                parts[more["num"]] = more["data"]
        assert json.loads("".join(parts[i] for i in range(frag["total"]))) == expected


def test_rosbridge_cbor_input_and_incoming_fragments(gateway: Gateway, node: Node) -> None:
    got: list[str] = []
    node.subscriber("/cbor_in", String, lambda m: got.append(m.data))
    with connect(f"ws://127.0.0.1:{gateway.port}/") as ws:
        ws.send(cbor2.dumps({"op": "advertise", "topic": "/cbor_in", "type": "std_msgs/String"}))
        publish = json.dumps({"op": "publish", "topic": "/cbor_in", "msg": {"data": "pieced together"}})

        def sent() -> bool:
            pieces = [publish[i : i + 16] for i in range(0, len(publish), 16)]
            for n, piece in enumerate(pieces):
                ws.send(
                    json.dumps({"op": "fragment", "id": "f1", "data": piece, "num": n, "total": len(pieces)})
                )
            return bool(got)

        wait_until(sent, what="a fragmented publish")
    assert got[0] == "pieced together"


def test_foxglove_time_under_sim_time(make_gateway: Callable[..., Gateway], node: Node) -> None:
    node.set_param("/use_sim_time", True)
    clock = node.publisher("/clock", Clock)
    chatter = node.publisher("/sim_chatter", String)
    gateway = make_gateway()
    with connect(f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"]) as ws:
        info = json.loads(ws.recv(timeout=5))
        assert "time" in info["capabilities"]
        advertised = json.loads(ws.recv(timeout=5))  # the channels known at connection time
        cid = next(c["id"] for c in advertised["channels"] if c["topic"] == "/sim_chatter")

        def tick() -> None:
            clock.publish(Clock(clock=Time(1234, 500)))

        frame = first(ws, lambda m: isinstance(m, bytes) and m[0] == 2, tick)
        assert struct.unpack("<BQ", frame) == (2, 1234 * 10**9 + 500)
        ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 9, "channelId": cid}]}))
        data = first(
            ws, lambda m: isinstance(m, bytes) and m[0] == 1, lambda: chatter.publish(String(data="t"))
        )
        _, sub_id, stamp = struct.unpack_from("<BIQ", data)
        assert sub_id == 9 and stamp == 1234 * 10**9 + 500  # message times come from the sim clock


def test_foxglove_connection_graph_and_parameter_updates(gateway: Gateway, node: Node) -> None:
    node.set_param("/fox/gain", 1)
    node.publisher("/graph_seed", String)
    wait_until(lambda: "/graph_seed" in gateway.catalog.graph["pub"], what="the graph poll")
    with connect(f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"]) as ws:
        ws.send(json.dumps({"op": "subscribeConnectionGraph"}))
        graph = first(ws, lambda m: isinstance(m, dict) and m.get("op") == "connectionGraphUpdate")
        assert any(t["name"] == "/graph_seed" for t in graph["publishedTopics"])
        node.publisher("/fresh_topic", String)
        update = first(
            ws,
            lambda m: (
                isinstance(m, dict)
                and m.get("op") == "connectionGraphUpdate"
                and any(t["name"] == "/fresh_topic" for t in m["publishedTopics"])
            ),
        )
        assert {"name": "/fresh_topic", "publisherIds": [node.name]} in update["publishedTopics"]
        ws.send(json.dumps({"op": "subscribeParameterUpdates", "parameterNames": ["/fox/gain"]}))
        wait_until(lambda: "/fox/gain" in gateway._watched, what="the parameter subscription")
        node.set_param("/fox/gain", 2.5)
        values = first(ws, lambda m: isinstance(m, dict) and m.get("op") == "parameterValues")
        assert values["parameters"] == [{"name": "/fox/gain", "value": 2.5, "type": "float64"}]
        ws.send(
            json.dumps(
                {"op": "setParameters", "parameters": [{"name": "/fox/list", "value": [1, 2]}], "id": "s1"}
            )
        )
        reply = first(ws, lambda m: isinstance(m, dict) and m.get("id") == "s1")
        assert reply["parameters"] == [{"name": "/fox/list", "value": [1, 2]}]
        assert node.get_param("/fox/list") == [1, 2]
        blob = base64.b64encode(b"\x00\x01").decode()
        ws.send(
            json.dumps(
                {
                    "op": "setParameters",
                    "parameters": [{"name": "/fox/blob", "value": blob, "type": "byte_array"}],
                }
            )
        )
        wait_until(lambda: node.has_param("/fox/blob"), what="a byte_array parameter")


def test_foxglove_client_publishes_a_type_we_do_not_ship(gateway: Gateway, node: Node) -> None:
    got: list[bytes] = []
    node.subscriber("/custom", None, lambda m: got.append(bytes(m.data)), raw=True)
    schema = "int32 a\nstring label\n"
    payload = struct.pack("<iI", 7, 3) + b"abc"
    with connect(f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"]) as ws:
        channel = {
            "id": 4,
            "topic": "/custom",
            "encoding": "ros1",
            "schemaName": "my_robot/Thing",
            "schema": schema,
        }
        ws.send(json.dumps({"op": "advertise", "channels": [channel]}))

        def sent() -> bool:
            ws.send(struct.pack("<BI", 1, 4) + payload)
            return bool(got)

        wait_until(sent, what="the client's custom-type message")
    assert got[0] == payload
    assert ["/custom", "my_robot/Thing"] in node.master.get_topic_types()


def test_a_flood_of_ops_is_absorbed(gateway: Gateway, node: Node) -> None:
    """A client sending ops faster than they run: reading pauses (bounded backlog), nothing is lost."""
    got: list[str] = []
    node.subscriber("/flood", String, lambda m: got.append(m.data), queue_size=10000)
    with connect(f"ws://127.0.0.1:{gateway.port}/") as ws:
        ws.send(json.dumps({"op": "advertise", "topic": "/flood", "type": "std_msgs/String"}))
        wait_until(
            lambda: (
                gateway.publishers.get("/flood") and gateway.publishers.get("/flood")[0].get_num_connections()
            ),
            what="the subscriber connected",
        )
        for i in range(3000):
            ws.send(json.dumps({"op": "publish", "topic": "/flood", "msg": {"data": str(i)}}))
        wait_until(lambda: len(got) == 3000, timeout=60, what="every published message")
    assert got[-1] == "2999"


def test_throttle_rate_and_cleanup_on_disconnect(gateway: Gateway, node: Node) -> None:
    pub = node.publisher("/fast", String)
    with connect(f"ws://127.0.0.1:{gateway.port}/") as ws:
        ws.send(
            json.dumps({"op": "subscribe", "topic": "/fast", "type": "std_msgs/String", "throttle_rate": 400})
        )
        wait_until(lambda: pub.get_num_connections(), what="the gateway's subscription")
        received = 0
        end = time.monotonic() + 1.5
        while time.monotonic() < end:  # 50 Hz for 1.5 s; at most one message per 400 ms gets through
            pub.publish(String(data="x"))
            try:
                while True:
                    received += json.loads(ws.recv(timeout=0.02)).get("op") == "publish"
            except TimeoutError:
                pass
        assert 2 <= received <= 5
        ws.send(json.dumps({"op": "advertise", "topic": "/from_client", "type": "std_msgs/String"}))
        wait_until(lambda: gateway.publishers.get("/from_client"), what="the client's publisher")
    # the client left: its subscription and publisher are gone from the graph
    wait_until(
        lambda: not gateway.taps.topics() and gateway.publishers.get("/from_client") is None, what="cleanup"
    )
    wait_until(lambda: pub.get_num_connections() == 0, what="the tap's connection closed")


@pytest.mark.ros1
def test_real_ros1_publisher_to_foxglove_and_rosbridge(gateway: Gateway, master_uri: str) -> None:
    """Debian's rostopic pub -> gateway: Foxglove gets the exact TCPROS bytes, rosbridge the JSON."""
    proc = subprocess.Popen(
        ["/usr/bin/rostopic", "pub", "-r", "20", "/real_chatter", "std_msgs/String", "data: from real ROS"],
        env=ros1_env(master_uri),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        wait_until(
            lambda: any(c["topic"] == "/real_chatter" for c in gateway.catalog.channels.values()),
            timeout=30,
            what="channel",
        )
        cid = next(c["id"] for c in gateway.catalog.channels.values() if c["topic"] == "/real_chatter")
        with connect(f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"]) as fox:
            fox.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 3, "channelId": cid}]}))
            data = first(fox, lambda m: isinstance(m, bytes) and m[0] == 1)
            assert data[13:] == String(data="from real ROS").serialize_to_bytes()
        with connect(f"ws://127.0.0.1:{gateway.port}/") as ws:
            ws.send(json.dumps({"op": "subscribe", "topic": "/real_chatter"}))
            msg = first(ws, lambda m: isinstance(m, dict) and m.get("op") == "publish")
            assert msg["msg"] == {"data": "from real ROS"}
    finally:
        proc.terminate()
        proc.wait(10)


def test_rosbridge_subscribes_to_a_type_only_the_publisher_knows(gateway: Gateway, node: Node) -> None:
    from ninjemys.idl.loader import message_class_from_definition

    Thing = message_class_from_definition("their_robot/Status", "int32 level\nstring[] notes\n")
    pub = node.publisher("/their_status", Thing)
    with connect(f"ws://127.0.0.1:{gateway.port}/") as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/their_status", "type": "no_such/Type"}))
        assert "no_such/Type" in json.loads(ws.recv(timeout=5))["msg"]
        ws.send(json.dumps({"op": "subscribe", "topic": "/their_status"}))
        msg = first(
            ws,
            lambda m: isinstance(m, dict) and m.get("op") == "publish",
            lambda: pub.publish(Thing(level=3, notes=["ok"])),
        )
        assert msg["msg"] == {"level": 3, "notes": ["ok"]}


def test_foxglove_channel_for_a_type_only_the_publisher_knows(gateway: Gateway, node: Node) -> None:
    """The schema of a type the gateway cannot load comes from a publisher's connection header."""
    from ninjemys.idl.loader import message_class_from_definition

    Thing = message_class_from_definition("their_robot/Pose2", "float64 x\nfloat64 y\nstring frame\n")
    pub = node.publisher("/their_pose", Thing)
    sample = Thing(x=1.5, y=-2.0, frame="map")
    stop = threading.Event()

    def publish() -> None:
        while not stop.wait(0.05):
            pub.publish(sample)

    threading.Thread(target=publish, daemon=True).start()
    try:
        channel = wait_until(
            lambda: next((c for c in gateway.catalog.channels.values() if c["topic"] == "/their_pose"), None),
            timeout=20,
            what="a channel for the unknown type",
        )
        assert channel["schemaName"] == "their_robot/Pose2" and channel["schema"] == Thing._full_text
        with connect(f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"]) as ws:
            ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 5, "channelId": channel["id"]}]}))
            data = first(ws, lambda m: isinstance(m, bytes) and m[0] == 1)
            assert data[13:] == sample.serialize_to_bytes()
    finally:
        stop.set()


def test_foxglove_subscriptions_end_with_their_channel(gateway: Gateway, node: Node) -> None:
    """A channel unadvertised (its last publisher gone) takes the client's subscriptions on it along,
    as Foxglove's own server does: the gateway stops taking the topic for an id nobody reads."""
    pub = node.publisher("/ephemeral", String)
    channel = wait_until(
        lambda: next((c for c in gateway.catalog.channels.values() if c["topic"] == "/ephemeral"), None),
        what="a channel for /ephemeral",
    )
    with connect(f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"]) as ws:
        ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": channel["id"]}]}))
        first(ws, lambda m: isinstance(m, bytes) and m[0] == 1, lambda: pub.publish(String(data="x")))
        assert "/ephemeral" in gateway.taps.topics()
        pub.unregister()
        gone = first(ws, lambda m: isinstance(m, dict) and m.get("op") == "unadvertise")
        assert channel["id"] in gone["channelIds"]  # type: ignore[index]
        wait_until(lambda: "/ephemeral" not in gateway.taps.topics(), what="the tap on /ephemeral dropped")
        # the client's later unsubscribe of the ended subscription is harmless
        ws.send(json.dumps({"op": "unsubscribe", "subscriptionIds": [7]}))
        ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": channel["id"]}]}))
        status = first(ws, lambda m: isinstance(m, dict) and m.get("op") == "status")
        assert f"unknown channel {channel['id']}" in status["message"]  # type: ignore[index]
