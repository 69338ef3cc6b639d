"""Per-node keys (NINJEMYS_KEYS_FILE, NINJEMYS_KEY): a request is checked with the key of the caller it
claims to be, at every entry point (master XML-RPC, slave XML-RPC, TCPROS topic header, service header);
a key lets its holder speak only as the names it is listed for."""

from __future__ import annotations

import os
import re
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys import testing
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.net import auth
from ninjemys.node import Node
from ninjemys.wire import headers
from ninjemys.wire import xmlrpc as wire

String = get_message_class("std_msgs/String")
AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")

KEYS = """\
# node name or pattern    key
/master                   key-of-the-master
/rosout                   key-of-rosout
/talker                   key-of-the-talker
/listener                 key-of-the-listener
/robot1/*                 key-of-robot1
/robot1/arm/*             key-of-the-arm
"""


# -- the keys file and who signs with what ---------------------------------------------------------


def test_a_keys_file_maps_names_and_patterns_to_keys(tmp_path: Path) -> None:
    path = tmp_path / "keys"
    path.write_text(KEYS)
    creds = auth.load_credentials({"NINJEMYS_KEYS_FILE": str(path)})
    assert creds is not None and creds.single is None
    assert creds.secret_for("/talker") == b"key-of-the-talker"
    assert creds.secret_for("/robot1/camera") == b"key-of-robot1"
    assert creds.secret_for("/robot1/arm/driver") == b"key-of-the-arm"  # the longest pattern wins
    assert creds.secret_for("/robot2/camera") is None
    assert auth.parse_keys("/a k#1  # a comment\n") == {"/a": b"k#1"}  # a key may hold '#'

    # the talker's own key (NINJEMYS_KEY) signs whatever it claims; the master checks the claim
    mine = auth.load_credentials({"NINJEMYS_KEY": "key-of-the-talker"})
    assert mine is not None and not mine.can_check
    body = wire.dump_call("registerPublisher", ["/talker", "/chatter", "std_msgs/String", "http://h:1/"])
    assert creds.check(mine.sign(body, "/talker"), body, "/talker") is None
    impostor = wire.dump_call(
        "registerPublisher", ["/listener", "/chatter", "std_msgs/String", "http://h:1/"]
    )
    assert creds.check(mine.sign(impostor, "/listener"), impostor, "/listener") == "wrong secret"
    unknown = wire.dump_call("getSystemState", ["/robot2/x"])
    assert "no key for /robot2/x" in (
        creds.check(mine.sign(unknown, "/robot2/x"), unknown, "/robot2/x") or ""
    )
    assert "cannot check callers" in (mine.check(None, body, "/talker") or "")


def test_the_caller_is_read_from_the_call_itself() -> None:
    assert auth.xmlrpc_caller(wire.dump_call("lookupNode", ["/a/b", "/c"])) == "/a/b"
    assert (
        auth.xmlrpc_caller(b"<methodCall><params><param><value>/plain</value></param></params>") == "/plain"
    )
    assert auth.xmlrpc_caller(wire.dump_call("getPid", [])) == ""
    assert auth.xmlrpc_caller(wire.dump_call("x", [3])) == ""


@pytest.mark.parametrize(
    ("text", "error"),
    [
        ("/talker\n", "keys:1: expected '<node name> <key>'"),
        ("# a comment\n/talker two words\n", "keys:2: expected '<node name> <key>'"),
        ("talker k\n", "keys:1: 'talker' is not a global node name"),
        ("/a*b k\n", "keys:1: '/a*b' is not a global node name"),
        ("/a k\n\n/a j\n", "keys:3: /a is listed twice"),
        ("# nothing\n", "keys: no keys"),
    ],
)
def test_a_bad_keys_file_is_one_error_naming_the_line(text: str, error: str) -> None:
    with pytest.raises(auth.AuthError, match=re.escape(error)):
        auth.parse_keys(text, "keys")


def test_a_missing_keys_file_and_mixed_modes_are_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(auth.AuthError, match="NINJEMYS_KEYS_FILE=.*missing: cannot read the keys"):
        auth.load_credentials({"NINJEMYS_KEYS_FILE": str(tmp_path / "missing")})
    with pytest.raises(auth.AuthError, match="use one"):
        auth.load_credentials({"NINJEMYS_SECRET": "s", "NINJEMYS_KEY": "k"})


# -- a graph with per-node keys ---------------------------------------------------------------------


@pytest.fixture
def keyed(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Iterator[str]:
    path = tmp_path / "keys"
    path.write_text(KEYS)
    monkeypatch.delenv("NINJEMYS_SECRET", raising=False)
    monkeypatch.delenv("NINJEMYS_KEY", raising=False)
    monkeypatch.setenv("NINJEMYS_KEYS_FILE", str(path))
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with testing.run_master(env=env) as uri:
        yield uri


def _call(uri: str, method: str, params: list[object], key: str | None) -> object:
    """One XML-RPC call signed with ``key`` (None: unsigned), on a fresh connection."""
    body = wire.dump_call(method, params)
    host, port = uri.split("//")[1].strip("/").split(":")
    extra = "" if key is None else f"{auth.HTTP_HEADER}: {auth.Signer(key.encode()).sign(body)}\r\n"
    with socket.create_connection((host, int(port)), timeout=10) as s:
        s.sendall(wire.http_request(host, int(port), body, keep_alive=False, extra_headers=extra))
        parser = wire.HttpResponseParser()
        while not (messages := parser.feed(s.recv(65536))):
            pass
    return wire.parse_response(messages[0].body)


def test_keyed_nodes_work_as_usual(keyed: str) -> None:
    talker, listener = Node("talker", master_uri=keyed), Node("listener", master_uri=keyed)
    try:
        got: list[str] = []
        listener.subscriber("chatter", String, lambda m: got.append(m.data))
        pub = talker.publisher("chatter", String)
        deadline = time.monotonic() + 10
        while not got and time.monotonic() < deadline:
            pub.publish(String("keyed"))
            time.sleep(0.05)
        assert got and got[0] == "keyed"
        talker.set_param("/gain", 3)
        assert listener.get_param("/gain") == 3
        talker.service("add", AddTwoInts, lambda r: AddTwoInts._response_class(sum=r.a + r.b))
        assert listener.service_proxy("add", AddTwoInts)(2, 3).sum == 5
    finally:
        talker.shutdown()
        listener.shutdown()


def test_the_master_checks_each_caller_with_its_own_key(keyed: str) -> None:
    args = ["/chatter", "std_msgs/String", "http://h:1/"]
    assert _call(keyed, "registerPublisher", ["/talker", *args], "key-of-the-talker")[0] == 1  # type: ignore[index]
    assert _call(keyed, "setParam", ["/robot1/cam", "/robot1/exposure", 3], "key-of-robot1")[0] == 1  # type: ignore[index]
    for params, key, why in (
        (["/listener", *args], "key-of-the-talker", "wrong secret"),  # the talker's key, the listener's name
        (["/robot1/arm/x", *args], "key-of-robot1", "wrong secret"),  # the arm has a key of its own
        (["/intruder", *args], "key-of-the-talker", "no key for /intruder"),
        (["/talker", *args], None, "not signed (this graph requires per-node keys: /talker has none"),
    ):
        code, status, _ = _call(keyed, "registerPublisher", params, key)  # type: ignore[misc]
        assert code == -1 and status.startswith(f"authentication failed: {why}"), (params, status)
    # a process holding only its own key (NINJEMYS_KEY) registers as itself, and only as itself
    env = {k: v for k, v in os.environ.items() if k != "NINJEMYS_KEYS_FILE"}
    out = subprocess.run(
        [sys.executable, "-c", _OWN_KEY, keyed], env=dict(env, NINJEMYS_KEY="key-of-the-talker"),
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert out.stdout.splitlines() == [
        "/talker: ok",
        "/listener: lookupNode: authentication failed: wrong secret",
    ]


_OWN_KEY = """
import sys
from ninjemys.master.client import MasterClient
from ninjemys.errors import MasterError
for name in ("/talker", "/listener"):
    try:
        MasterClient(sys.argv[1], name).lookup_node("/talker")
        print(name + ": ok")
    except MasterError as exc:
        print(f"{name}: {exc}")
"""


def test_a_nodes_slave_api_checks_the_callers_key(keyed: str) -> None:
    node = Node("talker", master_uri=keyed)
    try:
        node.publisher("chatter", String)
        ok = _call(node.uri, "getPid", ["/listener"], "key-of-the-listener")
        assert ok[0] == 1, ok  # type: ignore[index]
        code, status, _ = _call(node.uri, "shutdown", ["/master", "rosnode kill"], "key-of-the-listener")  # type: ignore[misc]
        assert code == -1 and status == "authentication failed: wrong secret"
        assert not node.is_shutdown
    finally:
        node.shutdown()


def _raw_header(port: int, fields: dict[str, str], key: str | None) -> dict[str, str]:
    if key is not None:
        fields[auth.TCPROS_FIELD] = auth.Signer(key.encode()).sign(auth._canonical(fields))
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(headers.encode_header(fields))
        (n,) = struct.unpack("<I", s.recv(4, socket.MSG_WAITALL))
        return headers.decode_header(s.recv(n, socket.MSG_WAITALL))


def test_tcpros_topic_and_service_headers_are_checked_by_callerid(keyed: str) -> None:
    node = Node("talker", master_uri=keyed)
    try:
        node.publisher("chatter", String)
        node.service("add", AddTwoInts, lambda r: AddTwoInts._response_class(sum=r.a + r.b))
        topic = {"topic": "/chatter", "md5sum": "*", "type": "std_msgs/String"}
        service = {"service": "/add", "md5sum": "*"}
        for fields in (topic, service):
            good = _raw_header(node.tcpros_port, {"callerid": "/listener", **fields}, "key-of-the-listener")
            assert "error" not in good and good["callerid"] == "/talker", good
            # the publisher's and the server's replies are signed with the talker's key
            assert (
                auth.Signer(b"key-of-the-talker").check(good[auth.TCPROS_FIELD], auth._canonical(good))
                is None
            )
            forged = _raw_header(node.tcpros_port, {"callerid": "/master", **fields}, "key-of-the-listener")
            assert forged["error"] == "authentication failed: wrong secret", forged
            unknown = _raw_header(node.tcpros_port, {"callerid": "/nobody", **fields}, "key-of-the-listener")
            assert unknown["error"].startswith("authentication failed: no key for /nobody"), unknown
    finally:
        node.shutdown()


class _KeepAlive:
    """One keep-alive connection to an XML-RPC server, requests signed or not, one at a time."""

    def __init__(self, uri: str) -> None:
        self.host, port = uri.split("//")[1].strip("/").split(":")
        self.port = int(port)
        self.sock = socket.create_connection((self.host, self.port), timeout=10)

    def call(self, method: str, params: list[object], key: str | None) -> list[object]:
        body = wire.dump_call(method, params)
        extra = "" if key is None else f"{auth.HTTP_HEADER}: {auth.Signer(key.encode()).sign(body)}\r\n"
        self.sock.sendall(wire.http_request(self.host, self.port, body, extra_headers=extra))
        parser = wire.HttpResponseParser()
        while not (messages := parser.feed(self.sock.recv(65536))):
            pass
        result = wire.parse_response(messages[0].body)
        assert isinstance(result, list)
        return result


def test_a_keep_alive_connection_is_trusted_for_the_caller_its_first_signed_call_proved(keyed: str) -> None:
    """The master client's connection is authenticated once (like a TCPROS connection by its header);
    the trust is the connection's and the caller's: not another connection's, not another name's."""
    conn = _KeepAlive(keyed)
    try:
        code, status, _ = conn.call("getSystemState", ["/talker"], None)
        assert code == -1 and str(status).startswith("authentication failed: not signed")
        assert (
            conn.call("getSystemState", ["/talker"], "key-of-rosout")[0] == -1
        )  # a wrong key proves nothing
        assert conn.call("getSystemState", ["/talker"], None)[0] == -1
        assert conn.call("getSystemState", ["/talker"], "key-of-the-talker")[0] == 1
        assert conn.call("getSystemState", ["/talker"], None)[0] == 1  # trusted now, for /talker
        code, status, _ = conn.call("getSystemState", ["/listener"], None)
        assert code == -1 and str(status).startswith("authentication failed: not signed")
        assert conn.call("getSystemState", ["/listener"], "key-of-the-talker")[0] == -1
        other = _KeepAlive(keyed)  # a fresh connection starts untrusted
        try:
            assert other.call("getSystemState", ["/talker"], None)[0] == -1
        finally:
            other.sock.close()
    finally:
        conn.sock.close()
