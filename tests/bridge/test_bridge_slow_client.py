"""A client that stops reading while a 30 MB/s image topic flows: the gateway's memory for it stays
within its budget (oldest images dropped and counted), and a 10 Hz small topic still reaches a second
client on time."""

from __future__ import annotations

import json
import resource
import threading
import time
from collections.abc import Callable
from typing import Any

from websockets.sync.client import connect

from ninjemys.bridge.server import Gateway
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.testing import wait_until

Image = get_message_class("sensor_msgs/Image")
String = get_message_class("std_msgs/String")
BUDGET = 4 * 1024 * 1024


def test_stalled_client_is_bounded_and_does_not_starve_others(
    make_gateway: Callable[..., Gateway], node: Node
) -> None:
    gateway = make_gateway(max_client_bytes=BUDGET)
    url = f"ws://127.0.0.1:{gateway.port}/"
    # queue_size=None: publishing waits for TCP rather than dropping, so every image reaches the gateway
    images = node.publisher("/camera/image_raw", Image, queue_size=None)
    beats = node.publisher("/heartbeat", String)
    wanted = {"/camera/image_raw", "/heartbeat"}
    wait_until(lambda: wanted <= {c["topic"] for c in gateway.catalog.channels.values()}, what="channels")
    channels = {c["topic"]: c["id"] for c in gateway.catalog.channels.values()}

    # client 1: Foxglove, subscribes to both, then never reads again (max_queue=1: its socket fills)
    with (
        connect(url, subprotocols=["foxglove.websocket.v1"], max_queue=1, close_timeout=0.5) as stalled,
        connect(url, close_timeout=0.5) as healthy,
    ):
        status, peak_queued, arrivals, sent_beats, frame_size, rss_before, sent_images = _flood(
            gateway, stalled, healthy, channels, images, beats
        )
    # the stalled client's queue stayed within its budget (plus the one message being added)
    assert peak_queued <= BUDGET + frame_size + 1024
    fox = next(c for c in status["clients"] if c["protocol"] == "foxglove.websocket.v1")
    # drops are counted per topic: all but what the budget and the socket buffers held was dropped
    assert sent_images >= 40
    assert fox["dropped"].get("/camera/image_raw", 0) >= sent_images - 30
    # ~4 s of 30 MB/s went nowhere: the process did not keep it (ru_maxrss is in KiB)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss_before < 150 * 1024
    # the healthy client got the 10 Hz topic, each beat promptly
    received = {stamp for stamp, _ in arrivals}
    assert len(received & set(sent_beats)) >= 0.9 * len(sent_beats)
    delays = sorted(arrived - stamp for stamp, arrived in arrivals)
    # generous bounds (a loaded CI machine): starvation behind the images would mean seconds
    assert delays[len(delays) // 2] < 0.5 and delays[-1] < 2.0, delays[-5:]


def _flood(gateway: Gateway, stalled: Any, healthy: Any, channels: dict, images: Any, beats: Any) -> tuple:
    """4 s of 30 MB/s images and a 10 Hz heartbeat; returns what the test checks."""
    stalled.send(
        json.dumps(
            {
                "op": "subscribe",
                "subscriptions": [
                    {"id": 1, "channelId": channels["/camera/image_raw"]},
                    {"id": 2, "channelId": channels["/heartbeat"]},
                ],
            }
        )
    )
    # client 2: rosbridge, only the small topic
    arrivals: list[tuple[float, float]] = []
    healthy.send(json.dumps({"op": "subscribe", "topic": "/heartbeat", "type": "std_msgs/String"}))
    stop = threading.Event()

    def read_healthy() -> None:
        while not stop.is_set():
            try:
                msg = json.loads(healthy.recv(timeout=0.5))
            except TimeoutError:
                continue
            except Exception:
                return
            if msg.get("op") == "publish":
                arrivals.append((float(msg["msg"]["data"]), time.monotonic()))

    reader = threading.Thread(target=read_healthy, daemon=True)
    reader.start()
    wait_until(lambda: images.get_num_connections() and beats.get_num_connections() >= 1, what="taps")
    frame = Image(height=480, width=640, encoding="rgb8", step=1920, data=bytes(640 * 480 * 3))
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    sent_beats: list[float] = []
    sent_images = 0
    peak_queued = 0
    start = time.monotonic()
    next_image = next_beat = start
    while time.monotonic() - start < 4.0:  # 33 images/s of 921,600 bytes: 30 MB/s
        now = time.monotonic()
        if now >= next_image:
            images.publish(frame)
            sent_images += 1
            next_image += 1 / 33
        if now >= next_beat:
            stamp = time.monotonic()
            beats.publish(String(data=repr(stamp)))
            sent_beats.append(stamp)
            next_beat += 0.1
        for client in gateway.status()["clients"]:
            peak_queued = max(peak_queued, client["queued_bytes"])
        time.sleep(max(0.0, min(next_image, next_beat) - time.monotonic()))
    time.sleep(1.0)
    stop.set()
    reader.join(5)
    return gateway.status(), peak_queued, arrivals, sent_beats, len(frame.data), rss_before, sent_images


def test_rosbridge_client_is_told_about_its_drops(make_gateway: Callable[..., Gateway], node: Node) -> None:
    gateway = make_gateway(max_client_bytes=1024 * 1024)
    images = node.publisher("/camera/small", Image, queue_size=100)
    frame = Image(height=100, width=1000, encoding="rgb8", step=3000, data=bytes(300_000))
    with connect(f"ws://127.0.0.1:{gateway.port}/", max_queue=1, close_timeout=0.5) as ws:
        ws.send(json.dumps({"op": "set_level", "level": "warning"}))
        ws.send(
            json.dumps(
                {"op": "subscribe", "topic": "/camera/small", "type": "sensor_msgs/Image", "queue_length": 2}
            )
        )
        wait_until(lambda: images.get_num_connections(), what="the tap")
        for _ in range(60):  # 18 MB while the client reads nothing
            images.publish(frame)
            time.sleep(0.01)
        wait_until(
            lambda: gateway.status()["clients"][0]["dropped"].get("/camera/small"), what="drops counted"
        )
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            msg = json.loads(ws.recv(timeout=10))
            if msg.get("op") == "status":
                break
        assert msg["level"] == "warning" and "dropped" in msg["msg"] and "/camera/small" in msg["msg"]


WINDOW = 256 * 1024
FRAME = Image(height=100, width=1000, encoding="rgb8", step=3000, data=bytes(300_000))


def _subscribed(gateway: Gateway, node: Node, topic: str, ws: Any) -> Any:
    """An image publisher on ``topic`` whose channel Foxglove client ``ws`` subscribed (id 1)."""
    images = node.publisher(topic, Image, queue_size=None)
    wait_until(lambda: topic in {c["topic"] for c in gateway.catalog.channels.values()}, what="channel")
    channel = next(c["id"] for c in gateway.catalog.channels.values() if c["topic"] == topic)
    ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channel}]}))
    wait_until(lambda: images.get_num_connections(), what="the tap")
    return images


def test_a_stalled_client_has_at_most_a_window_in_flight(
    make_gateway: Callable[..., Gateway], node: Node
) -> None:
    """What a client has not read stays in the gateway's outbox (where the oldest is dropped), not
    in the sockets' buffers (where it would reach the client late): past ``client_window`` bytes
    unconfirmed by its pongs the gateway sends no more."""
    gateway = make_gateway(client_window=WINDOW)
    url = f"ws://127.0.0.1:{gateway.port}/"
    with connect(url, subprotocols=["foxglove.websocket.v1"], max_queue=1, close_timeout=0.5) as stalled:
        images = _subscribed(gateway, node, "/camera/stall", stalled)
        for _ in range(40):  # 12 MB, while the client reads nothing
            images.publish(FRAME)
        wait_until(
            lambda: gateway.status()["clients"][0]["dropped"].get("/camera/stall", 0) >= 20, what="drops"
        )
        client = gateway.status()["clients"][0]
    # one batch and one frame may go out past the window before the sender stops
    assert client["unconfirmed_bytes"] <= WINDOW + 64 * 1024 + 2 * len(FRAME.data), client


def test_a_client_that_reads_gets_everything_through_the_window(
    make_gateway: Callable[..., Gateway], node: Node
) -> None:
    """The window only paces: a client that keeps reading (its library answers the pings) gets every
    message of a burst many windows long. The burst fits the client's outbox twice over: on a loaded
    machine the whole of it can reach the gateway before its sender has written a window, and past
    ``max_client_bytes`` the outbox drops the oldest (what the slow-client tests want, not this one)."""
    burst = 30  # 9 MB: about 35 windows
    gateway = make_gateway(
        client_window=WINDOW, queue_length=100, max_client_bytes=2 * burst * len(FRAME.data)
    )
    with connect(
        f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"], close_timeout=0.5
    ) as ws:
        images = _subscribed(gateway, node, "/camera/paced", ws)
        for _ in range(burst):
            images.publish(FRAME)
        got = 0
        while got < burst:
            data = ws.recv(timeout=30)
            if isinstance(data, bytes) and data[0] == 0x01:
                got += 1
        assert gateway.status()["clients"][0]["dropped"] == {}
