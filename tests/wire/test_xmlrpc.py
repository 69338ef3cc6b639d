"""The sans-IO XML-RPC codec: marshalling, ROS triples, 64-bit integers, and bounded HTTP parsing."""

from __future__ import annotations

import xmlrpc.client

import pytest

from ninjemys.errors import ProtocolError
from ninjemys.wire import xmlrpc as wire


def test_call_round_trips_every_xmlrpc_type() -> None:
    params = ("/caller", 7, -2.5, True, "text <&>", b"\x00\xff", [1, [2]], {"a": {"b": "c"}})
    method, decoded = wire.parse_call(wire.dump_call("setParam", params))
    assert method == "setParam"
    assert decoded == params


def test_stdlib_client_understands_our_response() -> None:
    value = [1, "ok", {"x": [1.5, "s", b"bin"]}]
    (decoded,), _ = xmlrpc.client.loads(wire.dump_response(value), use_builtin_types=True)
    assert decoded == value
    assert wire.parse_response(wire.dump_response(value)) == value


def test_integers_beyond_32_bits_go_out_as_i8_and_come_back() -> None:
    body = wire.dump_response([1, "", 2**40])
    assert b"<i8>1099511627776</i8>" in body
    assert b"<int>5</int>" in wire.dump_response(5)
    # the stdlib (what rospy and rosmaster use) parses <i8>
    (decoded,), _ = xmlrpc.client.loads(body)
    assert decoded == [1, "", 2**40]


def test_integers_beyond_64_bits_are_a_clear_error() -> None:
    with pytest.raises(ProtocolError, match="does not fit in 64 bits"):
        wire.dump_response(2**70)


def test_none_is_refused() -> None:
    with pytest.raises(ProtocolError, match="None"):
        wire.dump_call("m", (None,))


def test_fault_response_raises_fault() -> None:
    with pytest.raises(xmlrpc.client.Fault) as info:
        wire.parse_response(wire.dump_fault(3, "bad"))
    assert (info.value.faultCode, info.value.faultString) == (3, "bad")


@pytest.mark.parametrize(
    "body",
    [
        b"",
        b"\x00\x01garbage",
        b"<methodCall><methodName>x</methodName><params><param><value><int>zz",
        b"<methodCall><params/></methodCall>",
        b"<?xml version='1.0'?><methodCall><methodName>m</methodName>"
        b"<params><param><value><double>abc</double></value></param></params></methodCall>",
    ],
)
def test_malformed_calls_raise_protocol_error(body: bytes) -> None:
    with pytest.raises(ProtocolError):
        wire.parse_call(body)


def test_ros_triples() -> None:
    assert wire.ok("fine", 3) == [1, "fine", 3]
    assert wire.error("bad") == [-1, "bad", 0]
    assert wire.failure("tried", "") == [0, "tried", ""]


def test_request_parser_handles_fragments_and_pipelining() -> None:
    body = wire.dump_call("getPid", ("/a",))
    request = wire.http_request("h", 1, body)
    parser = wire.HttpRequestParser()
    got = []
    for i in range(0, len(request), 7):
        got += parser.feed(request[i : i + 7])
    assert len(got) == 1 and got[0].body == body and got[0].keep_alive
    assert len(parser.feed(request + request)) == 2
    assert not parser.pending


def test_connection_close_and_http10_keep_alive_rules() -> None:
    close = wire.HttpRequestParser().feed(wire.http_request("h", 1, b"x", keep_alive=False))[0]
    assert not close.keep_alive
    old = wire.HttpRequestParser().feed(b"POST / HTTP/1.0\r\nContent-Length: 0\r\n\r\n")[0]
    assert not old.keep_alive


@pytest.mark.parametrize(
    "data, match",
    [
        (b"POST / HTTP/1.1\r\nContent-Length: 99999999999\r\n\r\n", "exceeds"),
        (b"POST / HTTP/1.1\r\nContent-Length: -1\r\n\r\n", "Content-Length"),
        (b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n", "chunked"),
        (b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03\r\n\r\n", "start line|method|version"),
        (b"POST / HTTP/9.9\r\n\r\n", "version"),
        (b"POST / HTTP/1.1\r\nno colon here\r\n\r\n", "header line"),
    ],
)
def test_bad_requests_are_rejected(data: bytes, match: str) -> None:
    with pytest.raises(ProtocolError, match=match):
        wire.HttpRequestParser().feed(data)


def test_header_size_is_bounded_without_a_terminator() -> None:
    parser = wire.HttpRequestParser(max_header=1024)
    parser.feed(b"POST / HTTP/1.1\r\n")
    with pytest.raises(ProtocolError, match="header larger"):
        parser.feed(b"X-Junk: " + b"a" * 2000)


def test_response_parser_needs_content_length() -> None:
    with pytest.raises(ProtocolError, match="Content-Length"):
        wire.HttpResponseParser().feed(b"HTTP/1.1 200 OK\r\n\r\n")
    ok = wire.HttpResponseParser().feed(wire.http_response(b"abc"))[0]
    assert ok.start[1] == "200" and ok.body == b"abc"
