"""One server for the web app and the gateway: the web tools' pages over HTTP and the gateway at /ws."""

from __future__ import annotations

import json
import urllib.request
from collections.abc import Iterator

import pytest
from websockets.sync.client import connect

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.web.app import WebApp


@pytest.fixture
def app_with_gateway(master_uri: str) -> Iterator[tuple[WebApp, Gateway]]:
    gateway = Gateway(GatewayOptions(update_period=0.2))
    gateway.start()
    app = WebApp(master_uri)
    app.add_gateway(gateway)
    app.start()
    yield app, gateway
    gateway.shutdown()
    app.stop()


def test_web_app_and_gateway_share_one_server(app_with_gateway: tuple[WebApp, Gateway]) -> None:
    app, gateway = app_with_gateway
    base = app.url.rstrip("/")
    with urllib.request.urlopen(base + "/", timeout=10) as page:
        assert b"<html" in page.read().lower()
    with urllib.request.urlopen(base + "/static/nav.js", timeout=10) as script:
        assert script.status == 200
    ws_url = base.replace("http", "ws", 1) + "/ws"
    with connect(ws_url, subprotocols=["foxglove.websocket.v1"]) as fox:
        assert json.loads(fox.recv(timeout=5))["op"] == "serverInfo"
        with urllib.request.urlopen(base + "/api/bridge/status", timeout=10) as status:
            clients = json.loads(status.read())["clients"]
        assert [c["protocol"] for c in clients] == ["foxglove.websocket.v1"]
    with connect(ws_url) as rosbridge:
        rosbridge.send(json.dumps({"op": "call_service", "service": "/nothing_here", "id": "x"}))
        assert json.loads(rosbridge.recv(timeout=10))["result"] is False
