"""The gateway's pure parts: message <-> JSON/CBOR, png compression, rosauth's MAC, the fair outbox."""

from __future__ import annotations

import base64
import hashlib
import json
import math
import re
import struct

import cbor2
import pytest
from bridge_helpers import png_pixels

from ninjemys.bridge.convert import ConversionError, from_value, to_value
from ninjemys.bridge.outbox import Outbox
from ninjemys.bridge.rosapi import typedefs
from ninjemys.bridge.rosbridge import png_compress, rosauth_mac
from ninjemys.idl.loader import get_message_class

Image = get_message_class("sensor_msgs/Image")
CameraInfo = get_message_class("sensor_msgs/CameraInfo")
Marker = get_message_class("visualization_msgs/Marker")
LaserScan = get_message_class("sensor_msgs/LaserScan")


def test_to_json_follows_rosbridge_message_conversion() -> None:
    msg = Image(height=2, width=1, encoding="mono8", step=1, data=b"\x00\xff")
    msg.header.stamp.secs, msg.header.stamp.nsecs = 5, 6
    value = to_value(Image.deserialize_from(msg.serialize_to_bytes()))
    assert value["data"] == base64.b64encode(b"\x00\xff").decode()
    assert value["header"] == {"seq": 0, "stamp": {"secs": 5, "nsecs": 6}, "frame_id": ""}
    info = to_value(CameraInfo(K=[1.0] * 9))
    assert info["K"] == [1.0] * 9 and info["roi"]["do_rectify"] is False
    marker = to_value(Marker(lifetime=get_message_class("std_msgs/Duration")().data))
    assert marker["lifetime"] == {"secs": 0, "nsecs": 0} and marker["points"] == []
    json.dumps(info)  # plain JSON all the way down
    scan = to_value(LaserScan(range_max=math.inf, ranges=[1.0, math.nan, -math.inf]))
    assert scan["range_max"] is None and scan["ranges"] == [1.0, None, None]
    json.dumps(scan, allow_nan=False)


def test_to_cbor_uses_bytes_and_typed_arrays() -> None:
    scan = LaserScan.deserialize_from(LaserScan(ranges=[1.0, 2.5], intensities=[]).serialize_to_bytes())
    value = to_value(scan, cbor=True)
    tag = value["ranges"]
    assert isinstance(tag, cbor2.CBORTag) and tag.tag == 85  # float32 little-endian (RFC 8746)
    assert struct.unpack("<2f", tag.value) == (1.0, 2.5)
    assert to_value(Image(data=b"ab"), cbor=True)["data"] == b"ab"
    assert cbor2.loads(cbor2.dumps(value))["angle_min"] == 0.0


def test_from_json_round_trip_and_defaults() -> None:
    msg = from_value(
        Image, {"height": 3, "data": base64.b64encode(b"xyz").decode(), "header": {"stamp": {"secs": 1}}}
    )
    assert msg.height == 3 and bytes(msg.data) == b"xyz" and msg.header.stamp.secs == 1 and msg.width == 0
    assert from_value(Image, {"data": [1, 2, 3]}).data == b"\x01\x02\x03"
    again = Image.deserialize_from(msg.serialize_to_bytes())
    assert to_value(again)["data"] == base64.b64encode(b"xyz").decode()
    info = from_value(CameraInfo, {"D": [0, 1.5], "K": [0] * 9})
    assert list(info.D) == [0.0, 1.5]
    assert math.isnan(from_value(LaserScan, {"range_min": None}).range_min)


@pytest.mark.parametrize(
    ("value", "error"),
    [
        ({"height": "3"}, "sensor_msgs/Image.height: expected an integer (uint32), got string"),
        ({"height": -1}, "out of range for uint32"),
        ({"height": True}, "expected an integer"),
        ({"encoding": 5}, "Image.encoding: expected a string, got int"),
        ({"data": "***"}, "expected base64 text"),
        ({"header": []}, "expected a JSON object for type std_msgs/Header, got array"),
        ({"header": {"stamp": "now!"}}, "expected {secs, nsecs}"),
        ({"colour": 1}, "has no field 'colour'"),
    ],
)
def test_from_json_errors_name_the_field(value: dict, error: str) -> None:
    with pytest.raises(ConversionError, match=re.escape(error)):
        from_value(Image, value)
    with pytest.raises(ConversionError, match="expected 9 elements"):
        from_value(CameraInfo, {"K": [1.0]})


@pytest.mark.parametrize("text", ["", "a", '{"op": "publish", "topic": "/x", "msg": {"data": "héllo"}}' * 7])
def test_png_compression_holds_the_text_padded_with_newlines(text: str) -> None:
    pixels = png_pixels(png_compress(text))
    assert pixels.rstrip(b"\n") == text.encode().rstrip(b"\n")
    assert set(pixels[len(text.encode()) :]) <= {ord("\n")}


def test_rosauth_mac_is_sha512_of_the_concatenated_fields() -> None:
    expected = hashlib.sha512(b"secretclient1dest1rand11700000000admin1700000120").hexdigest()
    assert rosauth_mac("secret", "client1", "dest1", "rand1", 1700000000, "admin", 1700000120) == expected


def test_outbox_drops_oldest_per_lane_and_counts() -> None:
    box = Outbox(10_000, lambda: None)
    for i in range(5):
        box.put("/a", f"a{i}", 3)
    assert box.dropped["/a"] == 2
    assert [box.take() for _ in range(3)] == ["a2", "a3", "a4"]
    assert box.take() is None


def test_outbox_big_topic_pays_for_its_own_backlog_and_lanes_alternate() -> None:
    woke: list[int] = []
    box = Outbox(1000, lambda: woke.append(1))
    for i in range(10):
        box.put("/image", b"x" * 300, 100)
        box.put("/small", f"s{i}", 100)
    assert box.bytes <= 1000 + 300
    assert box.dropped["/image"] > 0 and box.dropped["/small"] == 0
    box.put_control("reply")
    first = [box.take() for _ in range(5)]
    assert first[0] == "reply"
    kinds = ["image" if isinstance(x, bytes) else "small" for x in first[1:]]
    assert kinds in (["image", "small", "image", "small"], ["small", "image", "small", "image"])
    assert len(woke) == 1  # one wake-up until the sender drains it


def test_typedefs_like_rosapi() -> None:
    defs = typedefs("visualization_msgs/Marker")
    top = defs[0]
    assert top["type"] == "visualization_msgs/Marker"
    i = top["fieldnames"].index("points")
    assert top["fieldtypes"][i] == "geometry_msgs/Point" and top["fieldarraylen"][i] == 0
    assert top["examples"][top["fieldnames"].index("ns")] == ""
    assert "ARROW" in top["constnames"] and top["constvalues"][top["constnames"].index("CUBE")] == "1"
    assert [d["type"] for d in defs].count("geometry_msgs/Point") == 1
    assert {"duration", "time", "std_msgs/Header"} <= {d["type"] for d in defs}


def test_published_md5sums() -> None:
    """The shipped rosapi and tf2_web_republisher interfaces hash as Noetic's do (published values)."""
    from ninjemys.idl.loader import get_service_class

    assert get_service_class("rosapi/Topics")._md5sum == "d966d98fc333fa1f3135af765eac1ba8"
    assert get_service_class("rosapi/MessageDetails")._md5sum == "f9c88144f6f6bd888dd99d4e0411905d"
    assert get_service_class("tf2_web_republisher/RepublishTFs")._md5sum == "ec8570dea2e6015c309eb6611d1a57d0"
