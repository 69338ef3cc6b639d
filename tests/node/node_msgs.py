"""Tiny test-local message and service classes following the generated-class contract.

They let the transport tests run without the IDL code generator: the md5sums and full texts are the
real ROS 1 ones, so real rospy/roscpp peers accept them.
"""

from __future__ import annotations

import struct

_U32 = struct.Struct("<I")
_HDR = struct.Struct("<III")


def _pack_str(value: str | bytes) -> bytes:
    raw = value.encode("utf-8") if isinstance(value, str) else bytes(value)
    return _U32.pack(len(raw)) + raw


class String:
    __slots__ = ("data",)
    _type = "std_msgs/String"
    _md5sum = "992ce8a1687cec8c8bd883ec73ca41d1"
    _full_text = "string data"
    _has_header = False

    def __init__(self, data: str = "") -> None:
        self.data = data

    def serialize_to_bytes(self) -> bytes:
        return _pack_str(self.data)

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> String:
        (n,) = _U32.unpack_from(buf, 0)
        if n + 4 != len(buf):
            raise ValueError(f"std_msgs/String: length {n} does not match {len(buf) - 4} bytes")
        return cls(bytes(buf[4 : 4 + n]).decode("utf-8"))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, String) and other.data == self.data

    def __repr__(self) -> str:
        return f"String({self.data!r})"


class Int64:
    __slots__ = ("data",)
    _type = "std_msgs/Int64"
    _md5sum = "34add168574510e6e17f5d23ecc077ef"
    _full_text = "int64 data"
    _has_header = False

    def __init__(self, data: int = 0) -> None:
        self.data = data

    def serialize_to_bytes(self) -> bytes:
        return struct.pack("<q", self.data)

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> Int64:
        return cls(struct.unpack("<q", bytes(buf))[0])


class Header:
    __slots__ = ("seq", "secs", "nsecs", "frame_id")

    def __init__(self, seq: int = 0, secs: int = 0, nsecs: int = 0, frame_id: str = "") -> None:
        self.seq, self.secs, self.nsecs, self.frame_id = seq, secs, nsecs, frame_id


class Image:
    """sensor_msgs/Image with the real md5 (only what the tests need; data is bytes)."""

    __slots__ = ("header", "height", "width", "encoding", "is_bigendian", "step", "data")
    _type = "sensor_msgs/Image"
    _md5sum = "060021388200f6f0f447d0fcd9c64743"
    _full_text = (
        "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
        "uint32 step\nuint8[] data\n\n"
        "================================================================================\n"
        "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id"
    )
    _has_header = True

    def __init__(
        self, height: int = 0, width: int = 0, encoding: str = "", step: int = 0, data: bytes = b""
    ) -> None:
        self.header = Header()
        self.height, self.width, self.encoding, self.is_bigendian, self.step, self.data = (
            height,
            width,
            encoding,
            0,
            step,
            data,
        )

    def serialize_to_bytes(self) -> bytes:
        h = self.header
        return b"".join(
            (
                _HDR.pack(h.seq, h.secs, h.nsecs),
                _pack_str(h.frame_id),
                struct.pack("<II", self.height, self.width),
                _pack_str(self.encoding),
                struct.pack("<BII", self.is_bigendian, self.step, len(self.data)),
                bytes(self.data),
            )
        )

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> Image:
        mv = memoryview(buf)
        msg = cls()
        msg.header.seq, msg.header.secs, msg.header.nsecs = _HDR.unpack_from(mv, 0)
        pos = 12
        (n,) = _U32.unpack_from(mv, pos)
        msg.header.frame_id = bytes(mv[pos + 4 : pos + 4 + n]).decode()
        pos += 4 + n
        msg.height, msg.width = struct.unpack_from("<II", mv, pos)
        pos += 8
        (n,) = _U32.unpack_from(mv, pos)
        msg.encoding = bytes(mv[pos + 4 : pos + 4 + n]).decode()
        pos += 4 + n
        msg.is_bigendian, msg.step, n = struct.unpack_from("<BII", mv, pos)
        pos += 9
        msg.data = bytes(mv[pos : pos + n])
        return msg


class _AddReq:
    __slots__ = ("a", "b")
    _type = "rospy_tutorials/AddTwoIntsRequest"

    def __init__(self, a: int = 0, b: int = 0) -> None:
        self.a, self.b = a, b

    def serialize_to_bytes(self) -> bytes:
        return struct.pack("<qq", self.a, self.b)

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> _AddReq:
        return cls(*struct.unpack("<qq", bytes(buf)))


class _AddResp:
    __slots__ = ("sum",)
    _type = "rospy_tutorials/AddTwoIntsResponse"

    def __init__(self, sum: int = 0) -> None:  # noqa: A002 - the ROS field name
        self.sum = sum

    def serialize_to_bytes(self) -> bytes:
        return struct.pack("<q", self.sum)

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> _AddResp:
        return cls(*struct.unpack("<q", bytes(buf)))


class AddTwoInts:
    _type = "rospy_tutorials/AddTwoInts"
    _md5sum = "6a2e34150c00229791cc89ff309fff21"
    _request_class = _AddReq
    _response_class = _AddResp


class _Empty:
    __slots__ = ()

    def serialize_to_bytes(self) -> bytes:
        return b""


class _TriggerReq(_Empty):
    _type = "std_srvs/TriggerRequest"

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> _TriggerReq:
        return cls()


class _TriggerResp:
    __slots__ = ("success", "message")
    _type = "std_srvs/TriggerResponse"

    def __init__(self, success: bool = False, message: str = "") -> None:
        self.success, self.message = success, message

    def serialize_to_bytes(self) -> bytes:
        return struct.pack("<B", 1 if self.success else 0) + _pack_str(self.message)

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> _TriggerResp:
        (n,) = _U32.unpack_from(buf, 1)
        return cls(bool(buf[0]), bytes(buf[5 : 5 + n]).decode())


class Trigger:
    _type = "std_srvs/Trigger"
    _md5sum = "937c9679a518e3a18d831e57125ea522"
    _request_class = _TriggerReq
    _response_class = _TriggerResp
