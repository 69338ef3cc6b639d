"""The fused receive loop (issue 25): a generated ``decode_frames`` cuts TCPROS frames out of a chunk
and decodes them in one function. It must give exactly what ``deserialize_from`` gives frame by frame,
for every shape of type, on plain and tagged (SHMROS) streams, and report a bad frame without losing
the frames around it."""

from __future__ import annotations

import random
import struct

import pytest

from ninjemys.errors import DeserializationError, ProtocolError
from ninjemys.idl.framedecode import frames_decoder
from ninjemys.idl.loader import get_message_class
from ninjemys.wire.tcpros import FrameReader, TaggedFrame

String = get_message_class("std_msgs/String")
Empty = get_message_class("std_msgs/Empty")
JointState = get_message_class("sensor_msgs/JointState")
Image = get_message_class("sensor_msgs/Image")
Imu = get_message_class("sensor_msgs/Imu")
TFMessage = get_message_class("tf2_msgs/TFMessage")
TransformStamped = get_message_class("geometry_msgs/TransformStamped")


def _samples() -> list[object]:
    js = JointState()
    js.header.seq, js.header.frame_id = 7, "base"
    js.header.stamp.secs, js.header.stamp.nsecs = 12, 345
    js.name = [f"j{i}" for i in range(20)]
    js.position = [0.1 * i for i in range(20)]
    js.velocity = []
    js.effort = [1.5] * 20
    img = Image(height=2, width=3, encoding="rgb8", step=9, data=bytes(range(18)))
    imu = Imu()
    imu.orientation.w = 1.0
    imu.orientation_covariance = [float(i) for i in range(9)]
    tf = TFMessage()
    for i in range(3):
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = "odom", f"link{i}"
        t.transform.translation.x = i + 0.5
        t.transform.rotation.w = 1.0
        tf.transforms.append(t)
    return [String("héllo"), String(""), Empty(), js, img, imu, tf]


def _frame(body: bytes, tag: bytes = b"") -> bytes:
    return struct.pack("<I", len(tag) + len(body)) + tag + body


@pytest.mark.parametrize("tagged", [False, True], ids=["plain", "tagged"])
@pytest.mark.parametrize("msg", _samples(), ids=lambda m: type(m)._type)
def test_a_chunk_of_frames_decodes_as_deserialize_from_does(msg: object, tagged: bool) -> None:
    cls = type(msg)
    body = msg.serialize_to_bytes()  # type: ignore[attr-defined]
    tag = b"\0" if tagged else b""
    partial = _frame(body, tag)[:-1] if body else b"\0\0"  # an incomplete frame at the end
    data = _frame(body, tag) * 5 + partial
    decode, min_frame = frames_decoder(cls, tagged)  # type: ignore[misc]
    assert min_frame <= len(_frame(body, tag))
    out: list[object] = []
    bad: list[object] = []
    pos = decode(data, 0, len(data), out, bad)
    assert pos == 5 * len(_frame(body, tag)), "it must stop at the incomplete frame"
    assert not bad
    expected = cls.deserialize_from(body)  # type: ignore[attr-defined]
    assert len(out) == 5
    for got in out:
        assert type(got) is cls
        assert got == expected
        assert got.serialize_to_bytes() == body  # type: ignore[attr-defined]


def test_a_bad_frame_is_reported_once_and_the_next_ones_still_decode() -> None:
    decode, _ = frames_decoder(String)  # type: ignore[misc]
    good = _frame(String("ok").serialize_to_bytes())
    lying = _frame(struct.pack("<I", 1000) + b"abc")  # its string claims more than the frame holds
    data = good + lying + good
    out: list[object] = []
    bad: list[tuple[int, Exception]] = []
    assert decode(data, 0, len(data), out, bad) == len(data)
    assert [m.data for m in out] == ["ok", "ok"]  # type: ignore[attr-defined]
    assert len(bad) == 1
    length, exc = bad[0]
    assert length == 7
    assert isinstance(exc, DeserializationError)
    assert "std_msgs/String" in str(exc)


def test_a_truncated_fixed_part_is_a_deserialization_error_too() -> None:
    decode, _ = frames_decoder(JointState)  # type: ignore[misc]
    data = _frame(b"\1\2\3") + _frame(JointState().serialize_to_bytes())
    out: list[object] = []
    bad: list[tuple[int, Exception]] = []
    decode(data, 0, len(data), out, bad)
    assert len(out) == 1
    assert len(bad) == 1
    assert bad[0][0] == 3
    assert isinstance(bad[0][1], DeserializationError)
    assert "cannot decode 3 bytes" in str(bad[0][1])


def test_a_short_frame_of_fixed_fields_never_reads_the_next_frame() -> None:
    """deserialize_from's buffer ends with the message; the chunk does not, so the decoder must check."""
    Point = get_message_class("geometry_msgs/Point")
    decode, _ = frames_decoder(Point)  # type: ignore[misc]
    full = Point(1.0, 2.0, 3.0).serialize_to_bytes()
    data = _frame(full[:16]) + _frame(full)
    out: list[object] = []
    bad: list[tuple[int, Exception]] = []
    assert decode(data, 0, len(data), out, bad) == len(data)
    assert out == [Point(1.0, 2.0, 3.0)]
    assert len(bad) == 1 and bad[0][0] == 16
    assert "geometry_msgs/Point: cannot decode 16 bytes" in str(bad[0][1])
    with pytest.raises(DeserializationError):
        Point.deserialize_from(full[:16])  # the per-frame path refuses the same frame


def test_a_tagged_run_stops_at_a_frame_with_another_tag() -> None:
    decode, _ = frames_decoder(String, True)  # type: ignore[misc]
    inline = _frame(String("a").serialize_to_bytes(), b"\0")
    notice = _frame(b"x" * 28, b"\1")
    data = inline + inline + notice + inline
    out: list[object] = []
    assert decode(data, 0, len(data), out, []) == 2 * len(inline)
    assert len(out) == 2


def test_arrays_are_views_of_an_immutable_copy() -> None:
    decode, _ = frames_decoder(Image)  # type: ignore[misc]
    img = _samples()[4]
    data = _frame(img.serialize_to_bytes())  # type: ignore[attr-defined]
    out: list[object] = []
    decode(data, 0, len(data), out, [])
    assert bytes(out[0].data) == bytes(range(18))  # type: ignore[attr-defined]
    assert out[0].data.readonly  # type: ignore[attr-defined]


def test_the_decoder_is_made_once_per_class_and_tagging() -> None:
    assert frames_decoder(String) is frames_decoder(String)
    assert frames_decoder(String)[0] is not frames_decoder(String, True)[0]  # type: ignore[index]
    assert frames_decoder(object) is None  # not one of our generated classes: the caller's old path


def test_a_subclass_is_decoded_as_itself_unless_it_decodes_its_own_way() -> None:
    class Plain(String):  # type: ignore[misc, valid-type]
        __slots__ = ()

    class Own(String):  # type: ignore[misc, valid-type]
        __slots__ = ()

        @classmethod
        def deserialize_from(cls, buf):  # type: ignore[no-untyped-def]
            return super().deserialize_from(buf)

    decode, _ = frames_decoder(Plain)  # type: ignore[misc]
    data = _frame(String("x").serialize_to_bytes())
    out: list[object] = []
    decode(data, 0, len(data), out, [])
    assert type(out[0]) is Plain and out[0].data == "x"  # type: ignore[attr-defined]
    assert frames_decoder(Own) is None


@pytest.mark.parametrize("tagged", [False, True], ids=["plain", "tagged"])
def test_the_reader_fed_in_random_pieces_gives_every_message_in_order(tagged: bool) -> None:
    """commit_decoded against commit + deserialize_from, with a large frame received in place and, on a
    tagged stream, frames with other tags in between (left to the caller, in order)."""
    rng = random.Random(25)
    tag = b"\0" if tagged else b""
    bodies = [String("m%d" % i + "x" * rng.randrange(0, 40)).serialize_to_bytes() for i in range(300)]
    bodies[100] = String("L" * 50_000).serialize_to_bytes()  # above half the 64 KiB buffer
    stream = b""
    expected: list[object] = []
    for i, body in enumerate(bodies):
        stream += _frame(body, tag)
        expected.append(String.deserialize_from(body).data)
        if tagged and i % 37 == 0:
            stream += _frame(b"notice", b"\1")
            expected.append(("special", b"\1notice"))
    decode, _ = frames_decoder(String, tagged)  # type: ignore[misc]
    reader = FrameReader(tagged=tagged)
    got: list[object] = []
    pos = 0
    while pos < len(stream):
        buf = reader.buffer()
        n = min(len(buf), rng.choice([1, 3, 7, 100, 4096, 70_000]), len(stream) - pos)
        buf[:n] = stream[pos : pos + n]
        pos += n
        out: list[object] = []
        bad: list[object] = []
        frames = reader.commit_decoded(n, decode, out, bad)
        assert not bad
        got.extend(m.data for m in out)  # type: ignore[attr-defined]
        for f in frames:
            if isinstance(f, TaggedFrame):
                got.append(("special", bytes(f)))
            elif tagged and isinstance(f, bytearray):  # a large frame keeps its tag
                assert f[0] == 0
                got.append(String.deserialize_from(bytes(f[1:])).data)
            else:
                got.append(String.deserialize_from(f).data)
    assert reader.pending == 0
    assert got == expected


def test_the_reader_refuses_an_oversized_prefix_after_decoded_frames() -> None:
    decode, _ = frames_decoder(String)  # type: ignore[misc]
    reader = FrameReader(limit=1000)
    data = _frame(String("ok").serialize_to_bytes()) + struct.pack("<I", 5000) + b"ab"
    buf = reader.buffer()
    buf[: len(data)] = data
    out: list[object] = []
    with pytest.raises(ProtocolError, match="exceeds"):
        reader.commit_decoded(len(data), decode, out, [])
    assert [m.data for m in out] == ["ok"]  # type: ignore[attr-defined]
