"""``roslaunch rosbridge_server rosbridge_websocket.launch`` and ``foxglove_bridge.launch`` with ROS 1's
arguments start the gateway (and rosapi) as processes that real clients reach."""

from __future__ import annotations

import json
import os
import signal
import subprocess
from collections.abc import Iterator

import pytest
from websockets.sync.client import connect

from ninjemys.testing import free_port, ninjemys_bin, wait_until

roslibpy = pytest.importorskip("roslibpy")


@pytest.fixture
def launch(master_uri: str) -> Iterator:
    procs: list[subprocess.Popen] = []

    def start(package: str, file: str, *args: str) -> subprocess.Popen:
        env = dict(os.environ, ROS_MASTER_URI=master_uri)
        proc = subprocess.Popen(
            [ninjemys_bin("roslaunch"), package, file, *args],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        procs.append(proc)
        return proc

    yield start
    for proc in procs:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)


def _connect_when_up(url: str, **kwargs: object) -> object:
    def attempt() -> object:
        try:
            return connect(url, open_timeout=2, **kwargs)
        except OSError:
            return None

    return wait_until(attempt, timeout=60, what=f"the gateway at {url}")


def test_rosbridge_websocket_launch(launch, master_uri: str) -> None:
    port = free_port()
    launch("rosbridge_server", "rosbridge_websocket.launch", f"port:={port}")
    with _connect_when_up(f"ws://127.0.0.1:{port}/") as ws:
        request = {"op": "call_service", "service": "/rosapi/nodes", "id": "n1"}

        def nodes() -> list[str] | None:
            ws.send(json.dumps(request))
            reply = json.loads(ws.recv(timeout=10))
            return reply["values"]["nodes"] if reply.get("result") else None

        names = wait_until(nodes, timeout=30, what="rosapi")
        assert {"/rosbridge_websocket", "/rosapi"} <= set(names)
        ws.send(json.dumps({"op": "subscribe", "topic": "/client_count", "type": "std_msgs/Int32"}))
        count = json.loads(ws.recv(timeout=10))
        assert count["op"] == "publish" and count["msg"]["data"] >= 1  # latched, as rosbridge's


def test_foxglove_bridge_launch(launch, master_uri: str) -> None:
    from ninjemys.idl.loader import get_message_class
    from ninjemys.node import Node

    port = free_port()
    peer = Node("launch_peer", master_uri=master_uri)
    try:
        peer.publisher("/launch_probe", get_message_class("std_msgs/String"))
        launch("foxglove_bridge", "foxglove_bridge.launch", f"port:={port}")
        with _connect_when_up(f"ws://127.0.0.1:{port}/", subprotocols=["foxglove.websocket.v1"]) as ws:
            info = json.loads(ws.recv(timeout=10))
            assert info["op"] == "serverInfo" and info["name"] == "/foxglove_bridge"
            channels = json.loads(ws.recv(timeout=10))["channels"]
            probe = next(c for c in channels if c["topic"] == "/launch_probe")
            assert probe["schemaName"] == "std_msgs/String" and probe["encoding"] == "ros1"
    finally:
        peer.shutdown("test over")
