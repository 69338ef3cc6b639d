"""Stopping the gateway (alone, or inside a web app) while clients are connected is silent: the
connections get a close frame and their tasks end before the loop closes."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

_PRELUDE = """
import json, threading, time
from websockets.sync.client import connect
from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.master.core import MasterThread
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node

def clients(url):
    fox = connect(url, subprotocols=["foxglove.websocket.v1"])
    rb = connect(url)
    rb.send(json.dumps({"op": "subscribe", "topic": "/chatter", "type": "std_msgs/String"}))
    fox.recv(timeout=5)  # serverInfo: the session runs
    return fox, rb

def closed_by_server(ws):
    # the server's close frame reaches the client (code 1001: going away)
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        try:
            ws.recv(timeout=0.5)
        except TimeoutError:
            continue
        except Exception:
            break
    assert ws.close_code == 1001, ws.close_code
"""

_STANDALONE = """
with MasterThread() as uri:
    node = Node("talker", master_uri=uri)
    pub = node.publisher("/chatter", get_message_class("std_msgs/String"))
    gateway = Gateway(GatewayOptions(port=0, update_period=0.2, node_name="gw", client_count=True))
    url = gateway.run_in_thread()
    fox, rb = clients(url)
    for _ in range(20):
        pub.publish(get_message_class("std_msgs/String")(data="x"))
        time.sleep(0.01)
    gateway.shutdown()
    closed_by_server(fox)
    closed_by_server(rb)
    node.shutdown()
print("done")
"""

_WEBAPP = """
from ninjemys.web.app import WebApp
with MasterThread() as uri:
    node = Node("talker", master_uri=uri)
    pub = node.publisher("/chatter", get_message_class("std_msgs/String"))
    gateway = Gateway(GatewayOptions(update_period=0.2, node_name="gw"), node=node)
    gateway.start()
    app = WebApp(uri)
    app.add_gateway(gateway)
    app.start()
    fox, rb = clients(app.url.replace("http", "ws", 1) + "ws")
    pub.publish(get_message_class("std_msgs/String")(data="x"))
    time.sleep(0.3)
    app.stop()  # the page is still open: the app's loop closes under it
    gateway.shutdown()
    closed_by_server(fox)
    closed_by_server(rb)
    node.shutdown()
print("done")
"""


@pytest.mark.parametrize("script", [_STANDALONE, _WEBAPP], ids=["standalone", "webapp"])
def test_shutdown_with_clients_connected_is_silent(script: str) -> None:
    code = textwrap.dedent(_PRELUDE) + textwrap.dedent(script)
    run = subprocess.run(
        [sys.executable, "-X", "dev", "-c", code], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip().endswith("done")
    for noise in ("Task was destroyed", "Event loop is closed", "was never awaited", "Traceback"):
        assert noise not in run.stderr, run.stderr
