"""Connection headers: the byte-exact wiki example, round trips, and malformed input."""

from __future__ import annotations

import struct

import pytest

from ninjemys.errors import ProtocolError
from ninjemys.wire import headers

# The wiki's example (rostopic pub /chatter std_msgs/String hello): 176 bytes of header.
WIKI_FIELDS = {
    "message_definition": "string data\n\n",
    "callerid": "/rostopic_4767_1316912741557",
    "latching": "1",
    "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1",
    "topic": "/chatter",
    "type": "std_msgs/String",
}


def test_wiki_example_layout() -> None:
    data = headers.encode_header(WIKI_FIELDS)
    assert struct.unpack_from("<I", data)[0] == len(data) - 4 == 176
    assert data[4:8] == struct.pack("<I", len("message_definition=string data\n\n"))
    assert data[8:40] == b"message_definition=string data\n\n"[:32]
    assert headers.decode_header(data[4:]) == WIKI_FIELDS


def test_values_may_contain_equals_and_binary() -> None:
    fields = {"error": "a=b=c", "blob": "\udcff\x00x"}
    assert headers.decode_header(headers.encode_header(fields)[4:]) == fields


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (struct.pack("<I", 10) + b"a=b", "claims 10 bytes"),
        (struct.pack("<I", 3) + b"abc", "no name=value"),
        (struct.pack("<I", 3) + b"=bc", "no name=value"),
        (struct.pack("<I", 3) + b"a=b" + b"\x01\x00", "truncated"),
    ],
)
def test_malformed_bodies_raise_protocol_error(body: bytes, message: str) -> None:
    with pytest.raises(ProtocolError, match=message):
        headers.decode_header(body)


def test_length_prefix_is_capped() -> None:
    with pytest.raises(ProtocolError, match="exceeds"):
        headers.header_length(struct.pack("<I", headers.MAX_HEADER_LEN + 1))
    assert headers.header_length(struct.pack("<I", 176)) == 176


def test_subscriber_checks_match_ros1_texts() -> None:
    ok = {"topic": "/chatter", "md5sum": "*", "callerid": "/l", "type": "*"}
    assert headers.check_subscriber_header(ok, "/chatter", "std_msgs/String", "992c") is None
    missing = headers.check_subscriber_header({"topic": "/chatter"}, "/chatter", "std_msgs/String", "992c")
    assert missing == "Missing required element md5sum in connection header"
    wrong_type = dict(ok, md5sum="1234", type="std_msgs/Int64")
    assert "topic types do not match" in headers.check_subscriber_header(
        wrong_type, "/chatter", "std_msgs/String", "992c"
    )
    same_type = dict(ok, md5sum="1234", type="std_msgs/String")
    assert "wants topic" in headers.check_subscriber_header(same_type, "/chatter", "std_msgs/String", "992c")


def test_publisher_and_service_checks() -> None:
    assert headers.check_publisher_header({"md5sum": "abc"}, "t/T", "abc") is None
    assert "refused" in headers.check_publisher_header({"error": "nope"}, "t/T", "abc")
    assert headers.check_publisher_header({"md5sum": "x"}, "*", "*") is None
    assert (
        headers.check_service_client_header({"service": "/s", "md5sum": "*", "callerid": "/c"}, "/s", "m")
        is None
    )
    assert "md5sums do not match" in headers.check_service_client_header(
        {"service": "/s", "md5sum": "q", "callerid": "/c"}, "/s", "m"
    )


def test_field_name_with_equals_is_refused() -> None:
    with pytest.raises(ProtocolError):
        headers.encode_header({"a=b": "c"})
