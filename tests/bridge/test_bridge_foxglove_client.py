"""Foxglove WebSocket acceptance with Foxglove's own client: ``FoxgloveClient`` from npm
``@foxglove/ws-protocol``, run by Node.js, decoding ROS 1 bytes with ``@foxglove/rosmsg-serialization``
from the schema the gateway advertised."""

from __future__ import annotations

import json
import shutil
import subprocess
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from ninjemys.bridge.server import Gateway
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.testing import wait_until

NODE = shutil.which("node") or ("/usr/bin/node" if Path("/usr/bin/node").exists() else None)
ROOT = Path(__file__).resolve().parents[2]
JS_DIR = Path(__file__).parent / "js"
NPM_DIR = ROOT / ".cache" / "npm"

pytestmark = pytest.mark.skipif(NODE is None, reason="Node.js is not installed")

PoseStamped = get_message_class("geometry_msgs/PoseStamped")
String = get_message_class("std_msgs/String")
AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")


@pytest.fixture(scope="module")
def node_modules() -> Path:
    """The npm packages (``make test`` installs them; a bare pytest run installs them here the same way)."""
    modules = NPM_DIR / "node_modules"
    if not (modules / "@foxglove" / "ws-protocol").exists():
        npm = shutil.which("npm")
        if npm is None:
            pytest.fail("npm is needed to install @foxglove/ws-protocol (make test does it)")
        NPM_DIR.mkdir(parents=True, exist_ok=True)
        for name in ("package.json", "package-lock.json"):
            shutil.copy(JS_DIR / name, NPM_DIR / name)
        subprocess.run([npm, "ci", "--no-audit", "--no-fund", "--loglevel=error"], cwd=NPM_DIR, check=True)
    return modules


def run_client(
    gateway: Gateway,
    node_modules: Path,
    subprotocol: str,
    until: set[str],
    also: Callable[[], object] = lambda: True,
    timeout: float = 30.0,
) -> dict[str, list[dict]]:
    """Run the JS client until it has printed every event in ``until`` and ``also()`` holds; returns
    the events by name."""
    env = {"NODE_PATH": str(node_modules), "PATH": "/usr/bin:/bin"}
    proc = subprocess.Popen(
        [NODE, str(JS_DIR / "foxglove_client.js"), f"ws://127.0.0.1:{gateway.port}/", subprotocol],
        stdout=subprocess.PIPE,
        stdin=subprocess.PIPE,
        env=env,
        text=True,
    )
    events: dict[str, list[dict]] = {}
    done = threading.Event()

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            item = json.loads(line)
            events.setdefault(item["event"], []).append(item)
            if until <= set(events):
                done.set()
        done.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        done.wait(timeout)
        wait_until(also, timeout=timeout, what="the ROS side's condition")
    finally:
        proc.kill()
        proc.wait(10)
    missing = until - set(events)
    assert not missing, f"the Foxglove client never saw {sorted(missing)}; it saw {json.dumps(events)[:2000]}"
    return events


@pytest.mark.parametrize("subprotocol", ["foxglove.websocket.v1", "foxglove.sdk.v1"])
def test_foxglove_client(gateway: Gateway, node: Node, node_modules: Path, subprotocol: str) -> None:
    node.set_param("/fox/speed", 0.5)
    node.set_param("/fox/name", "puzzlebot")
    node.service("/add_two_ints", AddTwoInts, lambda r: r.a + r.b)
    got: list[str] = []
    node.subscriber("/fox_in", String, lambda m: got.append(m.data))
    pub = node.publisher("/fox_out", PoseStamped)
    wait_until(
        lambda: any(c["topic"] == "/fox_out" for c in gateway.catalog.channels.values()), what="channel"
    )
    wait_until(lambda: gateway.catalog.services, what="service catalogue")
    stop = threading.Event()

    def publish() -> None:
        msg = PoseStamped()
        msg.header.frame_id = "map"
        msg.pose.position.x = 1.5
        msg.pose.orientation.w = 1.0
        while not stop.wait(0.05):
            pub.publish(msg)

    publisher = threading.Thread(target=publish, daemon=True)
    publisher.start()
    try:
        events = run_client(
            gateway,
            node_modules,
            subprotocol,
            {"open", "serverInfo", "advertise", "message", "serviceCallResponse", "parameterValues"},
            also=lambda: got,
        )
    finally:
        stop.set()
        publisher.join()
    assert events["open"][0]["protocol"] == subprotocol
    info = events["serverInfo"][0]
    assert {"clientPublish", "parameters", "parametersSubscribe", "services", "connectionGraph"} <= set(
        info["capabilities"]
    )
    assert "time" not in info["capabilities"]  # wall time: no time messages
    assert info["encodings"] == ["ros1"]
    channel = events["advertise"][0]
    assert channel["encoding"] == "ros1" and channel["schemaName"] == "geometry_msgs/PoseStamped"
    msg = events["message"][0]["msg"]
    assert msg["header"]["frame_id"] == "map" and msg["pose"]["position"]["x"] == 1.5
    assert abs(events["message"][0]["timestamp"] / 1e9 - time.time()) < 60
    assert events["serviceCallResponse"][0]["msg"] == {"sum": 42}
    assert events["serviceCallResponse"][0]["encoding"] == "ros1"
    params = {p["name"]: p["value"] for p in events["parameterValues"][0]["parameters"]}
    assert params == {"/fox/speed": 0.5, "/fox/name": "puzzlebot"}
    assert got[0] == "hello from foxglove"
