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
    with pytest.raises(wire.Fault) as info:
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
        (
            "POST / HTTP/1.1\r\nContent-Length: 35\u00b2\r\n\r\n".encode(),
            "Content-Length",
        ),  # found by fuzzing
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


# --- cross-checks against the stdlib codec (what rospy and rosmaster use) ---------------------------

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_xml_text = st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=20)
_scalars = (
    st.integers(min_value=-(2**31), max_value=2**31 - 1)
    | st.booleans()
    | st.floats(allow_nan=False)
    | _xml_text
    | st.binary(max_size=20)
)
_values = st.recursive(
    _scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(_xml_text, inner, max_size=4),
    max_leaves=20,
)


@settings(max_examples=150, deadline=None)
@given(st.lists(_values, max_size=4))
def test_stdlib_reads_what_we_write(params: list[object]) -> None:
    decoded, method = xmlrpc.client.loads(wire.dump_call("m", params), use_builtin_types=True)
    assert method == "m" and list(decoded) == params


@settings(max_examples=150, deadline=None)
@given(st.lists(_values, max_size=4))
def test_we_read_what_stdlib_writes(params: list[object]) -> None:
    body = xmlrpc.client.dumps(tuple(params), "m").encode()
    assert wire.parse_call(body) == ("m", tuple(params))


def test_untyped_values_nil_and_i8_from_other_peers() -> None:
    body = (
        b"<?xml version='1.0'?><methodCall><methodName>m</methodName><params>"
        b"<param><value>bare text</value></param><param><value></value></param>"
        b"<param><value><i8>-9000000000</i8></value></param><param><value><ex:nil/></value></param>"
        b"<param><value><dateTime.iso8601>20240102T03:04:05</dateTime.iso8601></value></param>"
        b"</params></methodCall>"
    )
    import datetime

    assert wire.parse_call(body) == (
        "m",
        ("bare text", "", -9000000000, None, datetime.datetime(2024, 1, 2, 3, 4, 5)),
    )


def test_foreign_value_types_are_marshalled() -> None:
    import datetime

    params = (xmlrpc.client.Binary(b"\x01"), datetime.datetime(2024, 1, 2, 3, 4, 5), (1, 2))
    decoded, _ = xmlrpc.client.loads(wire.dump_call("m", params), use_builtin_types=True)
    assert decoded == (b"\x01", datetime.datetime(2024, 1, 2, 3, 4, 5), [1, 2])
    with pytest.raises(ProtocolError, match="cannot marshal"):
        wire.dump_call("m", (object(),))
    with pytest.raises(ProtocolError, match="struct keys"):
        wire.dump_call("m", ({1: 2},))


def test_deep_nesting_is_parsed_without_recursion() -> None:
    depth = 5000
    body = (
        b"<methodCall><methodName>m</methodName><params><param>"
        + b"<value><array><data>" * depth
        + b"</data></array></value>" * depth
        + b"</param></params></methodCall>"
    )
    _, (value,) = wire.parse_call(body)
    for _ in range(depth - 1):
        value = value[0]
    assert value == []


def test_marshalled_values_are_sent_verbatim() -> None:
    cached = wire.Marshalled([["/t", ["/n"]]])
    assert wire.dump_response([1, "s", cached]) == wire.dump_response([1, "s", [["/t", ["/n"]]]])
