"""Security and robustness: rosauth MAC and Foxglove token, TLS, Origin checks, bad input."""

from __future__ import annotations

import datetime
import ipaddress
import json
import ssl
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import ClientConnection, connect

from ninjemys.bridge.rosbridge import rosauth_mac
from ninjemys.bridge.server import Gateway
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.testing import wait_until

String = get_message_class("std_msgs/String")
SECRET = "relatively_long_secret"


def recv_json(ws: ClientConnection, timeout: float = 5.0) -> dict:
    return json.loads(ws.recv(timeout=timeout))


def recv_until(ws: ClientConnection, pred: Callable[[dict], bool], timeout: float = 10.0) -> dict:
    deadline = time.monotonic() + timeout
    while True:
        msg = recv_json(ws, max(0.01, deadline - time.monotonic()))
        if pred(msg):
            return msg


def talker(node: Node) -> Callable[[], None]:
    pub = node.publisher("/chatter", String)
    return lambda: pub.publish(String(data="secret data"))


def auth_op(secret: str, **overrides: object) -> str:
    now = int(time.time())
    fields = {"client": "192.168.1.101", "dest": "127.0.0.1", "rand": "xyzzy", "level": "admin"}
    fields.update({k: v for k, v in overrides.items() if k in fields})
    t, end = now, now + 120
    mac = rosauth_mac(secret, fields["client"], fields["dest"], fields["rand"], t, fields["level"], end)
    return json.dumps({"op": "auth", "mac": overrides.get("mac", mac), "t": t, "end": end, **fields})


@pytest.fixture
def secret_file(tmp_path: Path) -> Path:
    path = tmp_path / "secret.txt"
    path.write_text(SECRET + "\n")
    return path


def test_rosbridge_auth(make_gateway: Callable[..., Gateway], node: Node, secret_file: Path) -> None:
    gateway = make_gateway(authenticate=True, secret_file=str(secret_file))
    publish = talker(node)
    url = f"ws://127.0.0.1:{gateway.port}/"
    subscribe = json.dumps({"op": "subscribe", "topic": "/chatter", "type": "std_msgs/String"})
    with connect(url) as intruder:
        intruder.send(subscribe)
        status = recv_json(intruder)
        assert status["op"] == "status" and "not authenticated" in status["msg"]
        for _ in range(5):
            publish()
        with pytest.raises(TimeoutError):  # it sees nothing
            recv_json(intruder, timeout=0.5)
        intruder.send(auth_op(SECRET, mac="0" * 128))
        assert "wrong MAC" in recv_json(intruder)["msg"]
        with pytest.raises(ConnectionClosed):
            intruder.recv(timeout=5)
    with connect(url) as friend:
        friend.send(auth_op(SECRET))
        friend.send(subscribe)
        wait_until(lambda: "/chatter" in gateway.taps.topics(), what="the authenticated subscription")

        def heard() -> bool:
            publish()
            try:
                return recv_json(friend, timeout=0.2)["msg"]["data"] == "secret data"
            except TimeoutError:
                return False

        wait_until(heard, what="data for the authenticated client")


def test_foxglove_token(make_gateway: Callable[..., Gateway], secret_file: Path) -> None:
    gateway = make_gateway(authenticate=True, secret_file=str(secret_file), token="fox-token")
    url = f"ws://127.0.0.1:{gateway.port}/"
    with pytest.raises(InvalidStatus) as refused:
        connect(url, subprotocols=["foxglove.websocket.v1"]).close()
    assert refused.value.response.status_code == 401
    with pytest.raises(InvalidStatus):
        connect(url + "?token=wrong", subprotocols=["foxglove.websocket.v1"]).close()
    with connect(url + "?token=fox-token", subprotocols=["foxglove.websocket.v1"]) as ws:
        assert recv_json(ws)["op"] == "serverInfo"
    headers = {"Authorization": "Bearer fox-token"}
    with connect(url, subprotocols=["foxglove.websocket.v1"], additional_headers=headers) as ws:
        assert recv_json(ws)["op"] == "serverInfo"


def _certificate(tmp_path: Path) -> tuple[Path, Path]:
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import NameOID

    key = ec.generate_private_key(ec.SECP256R1())
    name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "localhost")])
    now = datetime.datetime.now(datetime.UTC)
    cert = (
        x509.CertificateBuilder()
        .subject_name(name)
        .issuer_name(name)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=1))
        .add_extension(
            x509.SubjectAlternativeName(
                [x509.DNSName("localhost"), x509.IPAddress(ipaddress.ip_address("127.0.0.1"))]
            ),
            critical=False,
        )
        .sign(key, hashes.SHA256())
    )
    certfile, keyfile = tmp_path / "cert.pem", tmp_path / "key.pem"
    certfile.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    keyfile.write_bytes(
        key.private_bytes(
            serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
        )
    )
    return certfile, keyfile


def test_tls(make_gateway: Callable[..., Gateway], node: Node, tmp_path: Path) -> None:
    pytest.importorskip("cryptography")
    certfile, keyfile = _certificate(tmp_path)
    gateway = make_gateway(certfile=str(certfile), keyfile=str(keyfile))
    assert gateway.url.startswith("wss://")
    ctx = ssl.create_default_context(cafile=str(certfile))
    got: list[str] = []
    node.subscriber("/over_tls", String, lambda m: got.append(m.data))
    with connect(f"wss://localhost:{gateway.port}/", ssl=ctx) as ws:
        ws.send(json.dumps({"op": "advertise", "topic": "/over_tls", "type": "std_msgs/String"}))

        def sent() -> bool:
            ws.send(json.dumps({"op": "publish", "topic": "/over_tls", "msg": {"data": "encrypted"}}))
            return bool(got)

        wait_until(sent, what="a publication over TLS")
    assert got[0] == "encrypted"
    with pytest.raises((ssl.SSLError, OSError)):  # a client that does not trust the certificate is refused
        connect(f"wss://localhost:{gateway.port}/", ssl=ssl.create_default_context(), open_timeout=5).close()


def test_origin_check(gateway: Gateway) -> None:
    url = f"ws://127.0.0.1:{gateway.port}/"
    with pytest.raises(InvalidStatus) as refused:
        connect(url, origin="http://evil.example").close()
    assert refused.value.response.status_code == 403
    with connect(url, origin=f"http://localhost:{gateway.port}") as ws:
        ws.send(json.dumps({"op": "set_level", "level": "info"}))


def test_bad_input_gets_status_errors_and_the_server_keeps_serving(
    make_gateway: Callable[..., Gateway], node: Node
) -> None:
    gateway = make_gateway(max_message_size=64 * 1024)
    url = f"ws://127.0.0.1:{gateway.port}/"
    publish = talker(node)
    with connect(url) as ws:
        cases = [
            ("{not json", "malformed message"),
            (json.dumps([1, 2]), "must be an object"),
            (json.dumps({"op": "dance"}), "unknown op 'dance'"),
            (json.dumps({"op": "subscribe", "topic": 5}), "field 'topic' must be str"),
            (json.dumps({"op": "subscribe"}), "missing field 'topic'"),
            (json.dumps({"op": "advertise", "topic": "/x", "type": "no_pkg/Nothing"}), "no_pkg/Nothing"),
            (json.dumps({"op": "advertise", "topic": "/typed", "type": "std_msgs/String", "id": "a1"}), None),
            (
                json.dumps({"op": "publish", "topic": "/typed", "msg": {"data": 42}, "id": "p1"}),
                "expected a string",
            ),
            (json.dumps({"op": "publish", "topic": "/typed", "msg": {"nope": 1}}), "has no field 'nope'"),
            (
                json.dumps({"op": "subscribe", "topic": "/chatter", "compression": "zip"}),
                "compression must be",
            ),
            (
                json.dumps({"op": "subscribe", "topic": "/chatter", "fragment_size": -5}),
                "must not be negative",
            ),
        ]
        for text, expected in cases:
            ws.send(text)
            if expected is not None:
                status = recv_json(ws)
                assert status["op"] == "status" and status["level"] == "error", status
                assert expected in status["msg"], (text, status)
        # the same connection still works after every error
        ws.send(json.dumps({"op": "subscribe", "topic": "/chatter", "type": "std_msgs/String"}))
        wait_until(lambda: "/chatter" in gateway.taps.topics(), what="subscription after errors")

        def heard() -> bool:
            publish()
            try:
                return recv_json(ws, timeout=0.2).get("op") == "publish"
            except TimeoutError:
                return False

        wait_until(heard, what="data after errors")
    with connect(url) as big:
        big.send("x" * (100 * 1024))  # over max_message_size: a status error, then a 1009 close
        status = recv_json(big)
        assert status["op"] == "status" and "too big" in status["msg"]
        with pytest.raises(ConnectionClosed) as closed:
            big.recv(timeout=5)
        assert closed.value.rcvd is not None and closed.value.rcvd.code == 1009
    with connect(url, subprotocols=["foxglove.websocket.v1"]) as fox:
        assert recv_json(fox)["op"] == "serverInfo"
        fox.send("{oops")
        assert recv_until(fox, lambda m: m["op"] == "status")["level"] == 2
        fox.send(json.dumps({"op": "subscribe", "subscriptions": "all"}))
        assert "subscribe" in recv_until(fox, lambda m: m["op"] == "status")["message"]
        fox.send(json.dumps({"op": "unsubscribe"}))
        assert "missing field 'subscriptionIds'" in recv_until(fox, lambda m: m["op"] == "status")["message"]
        fox.send(b"\x09garbage")
        assert "binary opcode" in recv_until(fox, lambda m: m["op"] == "status")["message"]
    with connect(url) as again:  # and new clients are served
        again.send(json.dumps({"op": "call_service", "service": "/nobody", "id": "c1"}))
        reply = recv_json(again)
        assert reply["op"] == "service_response" and reply["result"] is False and reply["id"] == "c1"
