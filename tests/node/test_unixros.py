"""UNIXROS (the default between ninjemys nodes of one host): they stream TCPROS over a Unix-domain socket, negotiated in
requestTopic (topics) or found from a local service URI (services); the bytes are the same as over
TCP, getBusInfo names the transport, and NINJEMYS_UNIXROS=0 keeps everything on TCP."""

from __future__ import annotations

import socket
import subprocess
import sys
from pathlib import Path

import pytest
from node_msgs import String

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.testing import wait_until

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="UNIXROS needs Linux")


@pytest.fixture(autouse=True)
def unixros_on(monkeypatch) -> None:  # noqa: ANN001
    """UNIXROS is the default: these tests run without NINJEMYS_UNIXROS, whatever the caller set."""
    monkeypatch.delenv("NINJEMYS_UNIXROS", raising=False)
    monkeypatch.setenv("NINJEMYS_SHM", "0")  # SHMROS is offered before UNIXROS (tests/node/test_shm.py)


Image = get_message_class("sensor_msgs/Image")
AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")


def _transports(node, topic: str) -> list[str]:  # noqa: ANN001
    return [entry[3] for entry in node.bus_info() if entry[4] == topic]


def test_the_same_stream_is_byte_identical_over_unixros_and_tcpros(make_node, monkeypatch) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("stream", Image, queue_size=None)
    over_unix: list[bytes] = []
    make_node("unix_listener").subscriber(
        "stream", Image, lambda m: over_unix.append(bytes(m.data)), raw=True
    )
    assert wait_until(lambda: pub.get_num_connections() == 1)  # connected before the switch below
    monkeypatch.setenv("NINJEMYS_UNIXROS", "0")
    over_tcp: list[bytes] = []
    make_node("tcp_listener").subscriber("stream", Image, lambda m: over_tcp.append(bytes(m.data)), raw=True)
    assert wait_until(lambda: pub.get_num_connections() == 2)
    assert sorted(_transports(talker, "/stream")) == ["TCPROS", "UNIXROS"]
    for i, size in enumerate((0, 1, 1000, 65536, 300_000, 7)):
        img = Image(
            height=1,
            width=size,
            encoding="mono8",
            step=size,
            data=bytes((i * 7 + k) % 256 for k in range(size)),
        )
        img.header.seq = i
        pub.publish(img)
    assert wait_until(lambda: len(over_unix) == 6 and len(over_tcp) == 6, timeout=15)
    assert over_unix == over_tcp


def test_a_talker_in_another_process_is_read_over_unixros(make_node, master) -> None:  # noqa: ANN001
    listener = make_node("listener")
    got: list[str] = []
    listener.subscriber("chatter", String, lambda m: got.append(m.data))
    child = subprocess.Popen(
        [
            sys.executable,
            str(Path(__file__).parent / "talker_proc.py"),
            master.uri,
            "/talker",
            "/chatter",
            "t",
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert wait_until(lambda: len(got) >= 5, timeout=20)
        assert _transports(listener, "/chatter") == ["UNIXROS"]
        # the peer's bus info says the same, as rosnode info shows it
        import xmlrpc.client

        uri = listener.master.lookup_node("/talker")
        info = xmlrpc.client.ServerProxy(uri).getBusInfo("/x")[2]
        assert [e[3] for e in info if e[4] == "/chatter"] == ["UNIXROS"]
    finally:
        child.kill()
        child.wait()


def test_services_use_the_unix_socket_of_a_local_server(make_node, monkeypatch) -> None:  # noqa: ANN001
    server = make_node("adder")
    server.service("add_two_ints", AddTwoInts, lambda req: AddTwoInts._response_class(sum=req.a + req.b))
    client = make_node("caller")
    proxy = client.service_proxy("add_two_ints", AddTwoInts, persistent=True)
    assert proxy(3, 4).sum == 7
    assert proxy._link.sock.family == socket.AF_UNIX
    monkeypatch.setenv("NINJEMYS_UNIXROS", "0")
    tcp = client.service_proxy("add_two_ints", AddTwoInts, persistent=True)
    assert tcp(5, 6).sum == 11
    assert tcp._link.sock.family == socket.AF_INET
    # a non-persistent proxy connects per call, locally too
    monkeypatch.setenv("NINJEMYS_UNIXROS", "1")
    assert client.service_proxy("add_two_ints", AddTwoInts)(1, 1).sum == 2


def test_a_closed_node_leaves_no_unix_socket_behind(make_node) -> None:  # noqa: ANN001
    node = make_node("short_lived")
    address = node.unix_address
    assert address == f"@ninjemys-tcpros-{node.tcpros_port}"
    names = Path("/proc/net/unix").read_text()
    assert address in names
    node.shutdown("done")
    assert wait_until(lambda: address not in Path("/proc/net/unix").read_text(), timeout=5)
