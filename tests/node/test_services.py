"""Services between ninjemys nodes: calls, persistent connections, errors, probes, waiting."""

from __future__ import annotations

import socket
import threading

import pytest
from node_msgs import AddTwoInts, Trigger

from ninjemys.errors import ServiceError, TimeoutError_
from ninjemys.net.addresses import split_uri
from ninjemys.wire import headers


def test_call_with_fields_request_and_persistent(make_node) -> None:
    server, client = make_node("server"), make_node("client")
    server.service("add_two_ints", AddTwoInts, lambda r: AddTwoInts._response_class(r.a + r.b))
    client.wait_for_service("add_two_ints", timeout=5)
    once = client.service_proxy("add_two_ints", AddTwoInts)
    assert once(2, 3).sum == 5
    assert once(AddTwoInts._request_class(a=-7, b=2)).sum == -5
    persistent = client.service_proxy("add_two_ints", AddTwoInts, persistent=True)
    assert [persistent(i, i).sum for i in range(50)] == [2 * i for i in range(50)]
    assert persistent._sock is not None  # one connection kept for all calls


def test_handler_return_forms(make_node) -> None:
    server, client = make_node("server"), make_node("client")
    server.service("plain", AddTwoInts, lambda r: r.a * r.b)
    server.service("as_dict", AddTwoInts, lambda r: {"sum": 42})
    server.service("as_tuple", Trigger, lambda r: (True, "ok"))
    client.wait_for_service("as_tuple", timeout=5)
    assert client.service_proxy("plain", AddTwoInts)(6, 7).sum == 42
    assert client.service_proxy("as_dict", AddTwoInts)(0, 0).sum == 42
    resp = client.service_proxy("as_tuple", Trigger)()
    assert resp.success is True and resp.message == "ok"


def test_handler_error_is_reported_and_connection_survives(make_node) -> None:
    server, client = make_node("server"), make_node("client")

    def handler(req):
        if req.a < 0:
            raise ValueError("negative numbers are not allowed")
        return req.a + req.b

    server.service("checked", AddTwoInts, handler)
    client.wait_for_service("checked", timeout=5)
    proxy = client.service_proxy("checked", AddTwoInts, persistent=True)
    with pytest.raises(ServiceError, match="negative numbers are not allowed"):
        proxy(-1, 0)
    assert proxy(1, 1).sum == 2


def test_unknown_service_and_wait_timeout(make_node) -> None:
    client = make_node("client")
    with pytest.raises(ServiceError, match="unavailable"):
        client.service_proxy("nobody_home", AddTwoInts)(1, 2)
    with pytest.raises(TimeoutError_):
        client.wait_for_service("nobody_home", timeout=0.3)


def test_wait_for_service_returns_when_it_appears(make_node) -> None:
    server, client = make_node("server"), make_node("client")
    timer = threading.Timer(0.3, lambda: server.service("late", AddTwoInts, lambda r: r.a))
    timer.start()
    try:
        client.wait_for_service("late", timeout=5)
        assert client.service_proxy("late", AddTwoInts)(9, 0).sum == 9
    finally:
        timer.cancel()


def test_probe_gets_header_and_close(make_node) -> None:
    server = make_node("server")
    server.service("add_two_ints", AddTwoInts, lambda r: r.a + r.b)
    host, port = split_uri(server.master.lookup_service("/add_two_ints"))
    with socket.create_connection((host, port), timeout=5) as sock:
        sock.sendall(
            headers.encode_header(
                {"callerid": "/probe", "service": "/add_two_ints", "md5sum": "*", "probe": "1"}
            )
        )
        data = b""
        while chunk := sock.recv(65536):
            data += chunk
    reply = headers.decode_header(data[4:])
    assert reply["type"] == "rospy_tutorials/AddTwoInts"
    assert reply["md5sum"] == AddTwoInts._md5sum
    assert reply["request_type"] == "rospy_tutorials/AddTwoIntsRequest"


def test_wrong_md5_gets_error_header(make_node) -> None:
    server = make_node("server")
    server.service("add_two_ints", AddTwoInts, lambda r: r.a + r.b)
    host, port = split_uri(server.master.lookup_service("/add_two_ints"))
    with socket.create_connection((host, port), timeout=5) as sock:
        sock.sendall(
            headers.encode_header({"callerid": "/x", "service": "/add_two_ints", "md5sum": "0" * 32})
        )
        data = b""
        while chunk := sock.recv(65536):
            data += chunk
    assert "md5sums do not match" in headers.decode_header(data[4:])["error"]
