"""The WebSocket gateway's authentication (rosauth's MAC, Foxglove's token) uses the graph's credentials
when no ``secret_file`` is given: the shared NINJEMYS_SECRET, or with per-node keys the key of the
gateway's node. One secret for the graph, its gateway and its Zenoh bridge."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from urllib.parse import quote

import pytest
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import ClientConnection, connect

from ninjemys.bridge.rosbridge import rosauth_mac
from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.errors import NinjemysError
from ninjemys.master.core import MasterThread
from ninjemys.testing import free_port


def _auth_op(secret: str) -> str:
    now = int(time.time())
    fields = {"client": "192.168.1.101", "dest": "127.0.0.1", "rand": "xyzzy", "level": "admin"}
    mac = rosauth_mac(
        secret, fields["client"], fields["dest"], fields["rand"], now, fields["level"], now + 120
    )
    return json.dumps({"op": "auth", "mac": mac, "t": now, "end": now + 120, **fields})


def _status(ws: ClientConnection) -> str:
    ws.send(json.dumps({"op": "status", "id": "s"}))
    return json.dumps(json.loads(ws.recv(timeout=10)))


@pytest.fixture
def gateway(
    request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> Iterator[Gateway]:
    for name in ("NINJEMYS_SECRET", "NINJEMYS_SECRET_FILE", "NINJEMYS_KEYS_FILE", "NINJEMYS_KEY"):
        monkeypatch.delenv(name, raising=False)
    mode = request.param
    if mode == "shared":
        monkeypatch.setenv("NINJEMYS_SECRET", "the-graphs-secret")
    else:  # per-node keys: the gateway's node has a key of its own
        keys = tmp_path / "keys"
        keys.write_text("/rosbridge_websocket the-graphs-secret\n* everyone-elses-key\n")
        monkeypatch.setenv("NINJEMYS_KEYS_FILE", str(keys))
    with MasterThread() as uri:
        monkeypatch.setenv("ROS_MASTER_URI", uri)
        gw = Gateway(GatewayOptions(port=free_port(), update_period=0.2, authenticate=True))
        gw.run_in_thread()
        try:
            yield gw
        finally:
            gw.shutdown()


@pytest.mark.parametrize("gateway", ["shared", "per-node"], indirect=True)
def test_the_gateway_takes_the_graphs_secret(gateway: Gateway) -> None:
    url = f"ws://127.0.0.1:{gateway.port}/"
    with connect(url) as stranger:
        assert "not authenticated" in _status(stranger)
    with connect(url) as intruder:
        intruder.send(_auth_op("a guess"))
        assert "wrong MAC" in intruder.recv(timeout=10)
        with pytest.raises(ConnectionClosed):
            intruder.recv(timeout=10)
    with connect(url) as friend:
        friend.send(_auth_op("the-graphs-secret"))
        assert "not authenticated" not in _status(friend)
    with pytest.raises(InvalidStatus) as refused:
        connect(url + "?token=a-guess", subprotocols=["foxglove.websocket.v1"]).close()
    assert refused.value.response.status_code == 401
    with connect(url + "?token=" + quote("the-graphs-secret"), subprotocols=["foxglove.websocket.v1"]) as fox:
        assert json.loads(fox.recv(timeout=10))["op"] == "serverInfo"


def test_the_gateway_refuses_to_start_authenticating_without_a_secret(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    for name in ("NINJEMYS_SECRET", "NINJEMYS_SECRET_FILE", "NINJEMYS_KEYS_FILE", "NINJEMYS_KEY"):
        monkeypatch.delenv(name, raising=False)
    with pytest.raises(NinjemysError, match="authentication is on but no secret is set"):
        GatewayOptions(authenticate=True).secret()
