"""The straight-line ``frame_parts``/``serialize_to_bytes`` generated for types without loops give
exactly the generic (``_ser``-driven) bytes, and bad values still get the field-naming diagnosis."""

from __future__ import annotations

import struct

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_roundtrip_property import message

from ninjemys.errors import SerializationError
from ninjemys.idl.loader import get_message_class
from ninjemys.idl.message import Message

STRAIGHT = (
    "std_msgs/String",
    "std_msgs/Int64",
    "std_msgs/Empty",
    "std_msgs/Header",
    "geometry_msgs/Twist",
    "geometry_msgs/PoseStamped",
    "sensor_msgs/Imu",
    "sensor_msgs/Image",
    "sensor_msgs/LaserScan",
    "rosgraph_msgs/Clock",
)
WITH_LOOPS = ("nav_msgs/Path", "sensor_msgs/PointCloud2", "rosgraph_msgs/Log")


def test_types_without_loops_get_their_own_serializers_and_others_keep_the_generic_ones() -> None:
    for name in STRAIGHT:
        cls = get_message_class(name)
        assert "frame_parts" in cls.__dict__ and "serialize_to_bytes" in cls.__dict__, name
    for name in WITH_LOOPS:
        cls = get_message_class(name)
        assert "frame_parts" not in cls.__dict__, name


@settings(
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(data=st.data())
def test_straight_bytes_equal_the_generic_bytes(data: st.DataObject) -> None:
    for name in STRAIGHT + WITH_LOOPS:
        msg = data.draw(message(name), label=name)
        generic = Message.serialize_to_bytes(msg)
        assert msg.serialize_to_bytes() == generic
        total, parts = msg.frame_parts()
        framed = b"".join(parts)
        assert total == len(framed) == len(generic) + 4
        assert framed == struct.pack("<I", len(generic)) + generic
        assert msg.serialize_framed() == framed
        # the publisher's one-piece frames: plain TCPROS, and SHMROS inline (length + tag byte 0)
        assert msg._wire_frame() == framed
        assert msg._wire_frame(1) == struct.pack("<IB", len(generic) + 1, 0) + generic


def test_small_types_get_the_fused_frame_and_unbounded_arrays_do_not() -> None:
    """Issue 25: a small message's frame is one pack per fixed run plus its strings, its length
    prefix packed with the first run; a type with a uint8[] or numeric array of any length keeps the
    generic frame (a big array must reach the socket or the ring without a copy)."""
    for name in ("std_msgs/String", "std_msgs/Int64", "std_msgs/Empty", "std_msgs/Header",
                 "geometry_msgs/Twist", "geometry_msgs/PoseStamped", "sensor_msgs/Imu",
                 "rosgraph_msgs/Clock"):  # fmt: skip
        cls = get_message_class(name)
        assert cls._wire_small and "_wire_frame" in cls.__dict__, name
    for name in ("sensor_msgs/Image", "sensor_msgs/LaserScan", *WITH_LOOPS):
        cls = get_message_class(name)
        assert not cls._wire_small and "_wire_frame" not in cls.__dict__, name
    source = get_message_class("std_msgs/String")._source
    fused = source[source.index("def _wire_frame") :]
    assert fused.count(".pack(") == 2  # one per branch (tagged or not): one runs
    assert "'<II'" in source and "'<IBI'" in source


def test_a_bad_value_is_still_named_by_field() -> None:
    twist = get_message_class("geometry_msgs/Twist")()
    twist.linear.x = "fast"
    with pytest.raises(SerializationError, match="linear.x"):
        twist.frame_parts()
    with pytest.raises(SerializationError, match="linear.x"):
        twist.serialize_to_bytes()
    with pytest.raises(SerializationError, match="data"):
        get_message_class("std_msgs/String")(5).frame_parts()
    with pytest.raises(SerializationError, match="linear.x"):
        twist._wire_frame(1)
    with pytest.raises(SerializationError, match="data"):
        get_message_class("std_msgs/String")(5)._wire_frame()
