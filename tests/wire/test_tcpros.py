"""TCPROS framing: FrameReader under every split of the byte stream, size limits, service responses."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from ninjemys.errors import ProtocolError
from ninjemys.wire import tcpros


def _feed(reader: tcpros.FrameReader, data: bytes, chunk_sizes: list[int]) -> list[bytes]:
    out: list[bytes] = []
    pos, i = 0, 0
    while pos < len(data):
        buf = reader.buffer()
        assert len(buf) > 0
        n = min(len(buf), chunk_sizes[i % len(chunk_sizes)] or 1, len(data) - pos)
        buf[:n] = data[pos : pos + n]
        pos += n
        i += 1
        out.extend(bytes(f) for f in reader.commit(n))
    return out


@given(
    payloads=st.lists(st.binary(max_size=300), max_size=20),
    chunks=st.lists(st.integers(min_value=1, max_value=500), min_size=1, max_size=10),
)
def test_any_split_yields_the_same_frames(payloads: list[bytes], chunks: list[int]) -> None:
    data = b"".join(tcpros.frame(p) for p in payloads)
    reader = tcpros.FrameReader(size=128)
    assert _feed(reader, data, chunks) == payloads
    assert reader.pending == 0


def test_large_frame_is_received_in_place() -> None:
    big = bytes(range(256)) * 4096
    reader = tcpros.FrameReader(size=1024)
    data = tcpros.frame(b"small") + tcpros.frame(big) + tcpros.frame(b"after")
    frames = _feed(reader, data, [700, 100000])
    assert frames == [b"small", big, b"after"]


def test_pending_reports_a_partial_frame() -> None:
    reader = tcpros.FrameReader(size=64)
    data = tcpros.frame(b"hello")[:6]
    assert _feed(reader, data, [6]) == []
    assert reader.pending == 6


def test_oversized_length_prefix_is_refused_before_allocation() -> None:
    reader = tcpros.FrameReader(size=64, limit=1000)
    buf = reader.buffer()
    buf[:4] = struct.pack("<I", 1001)
    with pytest.raises(ProtocolError, match="exceeds"):
        reader.commit(4)
    with pytest.raises(ProtocolError):
        tcpros.decode_length(struct.pack("<I", 0xFFFFFFFF))


def test_service_response_encoding() -> None:
    assert tcpros.encode_service_response(True, b"\x01\x02") == b"\x01\x02\x00\x00\x00\x01\x02"
    assert tcpros.encode_service_response(False, "boom") == b"\x00\x04\x00\x00\x00boom"
