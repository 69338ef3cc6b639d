"""Opt-in authentication (NINJEMYS_SECRET): what is signed gets in, what is not is refused with a clear
reason, at every entry point (master XML-RPC, slave XML-RPC, TCPROS topics, services); with no secret
the wire is ROS 1's and real ROS 1 nodes work as before."""

from __future__ import annotations

import os
import socket
import struct
import subprocess
import sys
import time
import xmlrpc.client
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys import testing
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.net import auth
from ninjemys.node import Node
from ninjemys.wire import headers

String = get_message_class("std_msgs/String")
AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")


# -- the signature on its own ---------------------------------------------------------------------


def test_signatures_check_once_within_the_window_and_with_the_right_secret(monkeypatch) -> None:  # noqa: ANN001
    a, b = auth.Signer(b"s3cret"), auth.Signer(b"other")
    token = a.sign(b"payload")
    assert a.check(token, b"payload") is None
    assert a.check(token, b"payload") == "replayed signature"
    assert b.check(a.sign(b"x"), b"x") == "wrong secret"
    assert a.check(a.sign(b"x"), b"y") == "wrong secret"  # the body is covered
    assert "not signed" in (a.check(None, b"x") or "")
    assert a.check("v1 1 2 3", b"x") == "malformed signature"  # the old format
    old = a.sign(b"x")
    monkeypatch.setattr(auth.time, "time", lambda: time.monotonic() + 1e9)
    assert "clocks more than 120 s apart" in (a.check(old, b"x") or "")


def test_the_secret_comes_from_the_environment_or_a_file(tmp_path: Path) -> None:
    assert auth.load_secret({}) is None
    assert auth.load_secret({"NINJEMYS_SECRET": "abc"}) == b"abc"
    f = tmp_path / "secret"
    f.write_text("from-file\n")
    assert auth.load_secret({"NINJEMYS_SECRET_FILE": str(f)}) == b"from-file"
    with pytest.raises(auth.AuthError, match="cannot read the secret"):
        auth.load_secret({"NINJEMYS_SECRET_FILE": str(tmp_path / "missing")})
    (tmp_path / "empty").write_text("\n")
    with pytest.raises(auth.AuthError, match="empty"):
        auth.load_secret({"NINJEMYS_SECRET_FILE": str(tmp_path / "empty")})


def test_tcpros_fields_are_signed_over_every_other_field(monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("NINJEMYS_SECRET", "k")
    fields = auth.sign_fields({"callerid": "/a", "topic": "/t", "md5sum": "*"})
    assert auth.check_fields(dict(fields)) is None
    forged = auth.sign_fields({"callerid": "/a", "topic": "/t", "md5sum": "*"})
    forged["topic"] = "/other"
    assert auth.check_fields(forged) == "wrong secret"
    assert auth.check_fields({"error": "the peer's refusal"}) is None  # passed on to be reported
    monkeypatch.delenv("NINJEMYS_SECRET")
    assert auth.sign_fields({"a": "1"}) == {"a": "1"}  # off: ROS 1's header, byte for byte


# -- a graph with a secret ---------------------------------------------------------------------------


@pytest.fixture
def secured(monkeypatch, tmp_path: Path) -> Iterator[str]:  # noqa: ANN001
    monkeypatch.setenv("NINJEMYS_SECRET", "correct horse battery staple")
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with testing.run_master(env=env) as uri:
        yield uri


def _unsigned(uri: str) -> xmlrpc.client.ServerProxy:
    return xmlrpc.client.ServerProxy(uri)


def test_signed_nodes_work_as_usual(secured: str) -> None:
    talker, listener = Node("talker", master_uri=secured), Node("listener", master_uri=secured)
    try:
        got: list[str] = []
        listener.subscriber("chatter", String, lambda m: got.append(m.data))
        pub = talker.publisher("chatter", String)
        deadline = time.monotonic() + 10
        while not got and time.monotonic() < deadline:
            pub.publish(String("signed"))
            time.sleep(0.05)
        assert got and got[0] == "signed"
        talker.set_param("/gain", 3)
        assert listener.get_param("/gain") == 3
        talker.service("add", AddTwoInts, lambda r: AddTwoInts._response_class(sum=r.a + r.b))
        assert listener.service_proxy("add", AddTwoInts)(2, 3).sum == 5
    finally:
        talker.shutdown()
        listener.shutdown()


def test_the_master_refuses_what_is_not_signed(secured: str) -> None:
    master = _unsigned(secured)
    for call in (
        lambda: master.registerPublisher("/intruder", "/chatter", "std_msgs/String", "http://h:1/"),
        lambda: master.registerSubscriber("/intruder", "/chatter", "std_msgs/String", "http://h:1/"),
        lambda: master.setParam("/intruder", "/gain", 99),
        lambda: master.getSystemState("/intruder"),
    ):
        code, status, _ = call()
        assert code == -1 and status.startswith("authentication failed: not signed"), status
    wrong = auth.Signer(b"a guess")
    body = xmlrpc.client.dumps(("/intruder", "/gain", 99), "setParam").encode()
    host, port = secured.split("//")[1].strip("/").split(":")
    request = (
        f"POST /RPC2 HTTP/1.1\r\nHost: {host}\r\nContent-Type: text/xml\r\nContent-Length: {len(body)}\r\n"
        f"X-Ninjemys-Auth: {wrong.sign(body)}\r\nConnection: close\r\n\r\n"
    ).encode() + body
    with socket.create_connection((host, int(port)), timeout=10) as s:
        s.sendall(request)
        answer = b""
        while chunk := s.recv(65536):
            answer += chunk
    assert b"authentication failed: wrong secret" in answer


def test_a_nodes_slave_api_refuses_what_is_not_signed(secured: str) -> None:
    node = Node("guarded", master_uri=secured)
    try:
        node.publisher("chatter", String)
        slave = _unsigned(node.uri)
        code, status, _ = slave.requestTopic("/intruder", "/chatter", [["TCPROS"]])
        assert code == -1 and "authentication failed" in status
        code, status, _ = slave.shutdown("/intruder", "rosnode kill")
        assert code == -1 and "authentication failed" in status
        assert not node.is_shutdown
    finally:
        node.shutdown()


def _raw_header(port: int, fields: dict[str, str]) -> dict[str, str]:
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(headers.encode_header(fields))
        prefix = s.recv(4, socket.MSG_WAITALL)
        (n,) = struct.unpack("<I", prefix)
        return headers.decode_header(s.recv(n, socket.MSG_WAITALL))


def test_tcpros_topics_and_services_refuse_an_unsigned_header(secured: str) -> None:
    node = Node("provider", master_uri=secured)
    try:
        node.publisher("chatter", String)
        node.service("add", AddTwoInts, lambda r: AddTwoInts._response_class(sum=r.a + r.b))
        # raw headers, as a node without the secret (or a ROS 1 node) sends them: no signature field
        topic = _raw_header(node.tcpros_port, {"callerid": "/intruder", "topic": "/chatter", "md5sum": "*",
                                               "type": "std_msgs/String"})  # fmt: skip
        assert topic["error"].startswith("authentication failed: not signed"), topic
        service = _raw_header(node.tcpros_port, {"callerid": "/intruder", "service": "/add", "md5sum": "*"})
        assert service["error"].startswith("authentication failed"), service
        # a ninjemys process without the secret is told why, in its own words
        outsider = subprocess.run(
            [sys.executable, "-c", _OUTSIDER, secured, node.uri],
            env={k: v for k, v in os.environ.items() if k != "NINJEMYS_SECRET"},
            capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        assert "authentication failed" in outsider.stdout, outsider
    finally:
        node.shutdown()


_OUTSIDER = """
import sys
from ninjemys.master.client import MasterClient
from ninjemys.errors import NinjemysError
try:
    MasterClient(sys.argv[1], "/outsider").register_publisher("/chatter", "std_msgs/String", "http://h:1/")
except NinjemysError as exc:
    print(exc)
"""


@pytest.mark.ros1
def test_a_real_ros1_tool_is_refused_with_the_reason_and_works_without_a_secret(tmp_path: Path) -> None:
    if not testing.have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    for secret in ("s", ""):
        env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path), NINJEMYS_SECRET=secret)
        with testing.run_master(env=env) as uri:
            out = subprocess.run(
                ["/usr/bin/rosparam", "set", "/x", "1"], env=testing.ros1_env(uri), capture_output=True,
                text=True, timeout=30,
            )  # fmt: skip
            if secret:
                assert out.returncode != 0 and "authentication failed" in out.stdout + out.stderr, out
            else:
                assert out.returncode == 0, out.stderr
                got = subprocess.run(["/usr/bin/rosparam", "get", "/x"], env=testing.ros1_env(uri),
                                     capture_output=True, text=True, timeout=30)  # fmt: skip
                assert got.stdout.strip() == "1"


def test_the_master_clients_connection_is_signed_once_and_then_trusted(secured: str, monkeypatch) -> None:  # noqa: ANN001
    """With a shared secret a connection proven once is trusted for every caller; a master client
    signs its first call on each connection and again after a reconnect."""
    from ninjemys.master.client import MasterClient

    signed: list[str] = []
    real = auth.header_line

    def counting(creds: auth.Credentials | None, body: bytes, caller: str | None = None) -> str:
        line = real(creds, body, caller)
        signed.append(line)
        return line

    monkeypatch.setattr(auth, "header_line", counting)
    with MasterClient(secured, "/counted") as client:
        for _ in range(5):
            client.get_system_state()
        assert len(signed) == 1 and signed[0].startswith("X-Ninjemys-Auth: v2 ")
        client.close()
        client.get_system_state()
        client.get_system_state()
        assert len(signed) == 2
    host, port = secured.split("//")[1].strip("/").split(":")
    with socket.create_connection((host, int(port)), timeout=10) as s:  # untrusted: refused
        body = xmlrpc.client.dumps(("/counted",), "getSystemState").encode()
        s.sendall(
            f"POST /RPC2 HTTP/1.1\r\nHost: {host}\r\nContent-Length: {len(body)}\r\n\r\n".encode() + body
        )
        assert b"authentication failed: not signed" in s.recv(65536)


_ROSPY_TALKER = """
import rospy
from std_msgs.msg import String
rospy.init_node("ros1_talker")
pub = rospy.Publisher("from_ros1", String, queue_size=10)
got = []
rospy.Subscriber("from_ninjemys", String, lambda m: got.append(m.data))
rate = rospy.Rate(20)
while not rospy.is_shutdown() and not got:
    pub.publish(String("hello from rospy"))
    rate.sleep()
print(got[0] if got else "nothing")
"""


@pytest.mark.ros1
def test_a_real_rospy_node_talks_as_before_with_authentication_off(monkeypatch, tmp_path: Path) -> None:  # noqa: ANN001
    """Authentication off (no variable set): Debian's rospy node and ours exchange messages both ways
    through our master, nothing signed on either side."""
    if not testing.have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    for name in ("NINJEMYS_SECRET", "NINJEMYS_SECRET_FILE", "NINJEMYS_KEYS_FILE", "NINJEMYS_KEY"):
        monkeypatch.delenv(name, raising=False)
    assert auth.credentials() is None
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with testing.run_master(env=env) as uri:
        node = Node("ours", master_uri=uri)
        try:
            heard: list[str] = []
            node.subscriber("from_ros1", String, lambda m: heard.append(m.data))
            pub = node.publisher("from_ninjemys", String)
            proc = subprocess.Popen(
                [testing.ROS1_PYTHON, "-c", _ROSPY_TALKER], env=testing.ros1_env(uri),
                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            )  # fmt: skip
            try:
                testing.wait_until(lambda: bool(heard), timeout=60, what="rospy's message")
                testing.wait_until(
                    lambda: pub.publish(String("hello from ninjemys")) or proc.poll() is not None,
                    timeout=60, what="rospy to hear us", step=0.05,
                )  # fmt: skip
                out, err = proc.communicate(timeout=30)
            finally:
                proc.kill()
                proc.wait()
            assert heard[0] == "hello from rospy"
            assert out.strip() == "hello from ninjemys", err
        finally:
            node.shutdown()
