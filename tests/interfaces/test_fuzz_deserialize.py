"""Bad input never escapes as anything but DeserializationError, never hangs, never allocates gigabytes.

For every shipped type: every strict prefix of a valid buffer (truncation) must raise
``ninjemys.errors.DeserializationError``; a length prefix overwritten with 0xFFFFFFFF anywhere in a valid
buffer, and random byte strings, must either decode or raise exactly that error, with a bounded
memory peak (a bogus length must be checked against the bytes left, not allocated).
"""

from __future__ import annotations

import struct
import tracemalloc

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from iface_inventory import inventory
from iface_values import build_ours, tree_strategy

from ninjemys.errors import DeserializationError
from ninjemys.idl.loader import get_message_class

INV = inventory()
FUZZ_SETTINGS = settings(
    max_examples=3,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
#: far above anything a test buffer (at most a few KiB) can legitimately need
MEMORY_CEILING = 32 * 1024 * 1024
BOGUS_LENGTHS = (b"\xff\xff\xff\xff", b"\xff\xff\xff\x7f", b"\x00\x00\x00\x10")
MAX_CUTS = 48


class _MemoryPeak:
    """Peak of traced allocations inside a ``with`` block (numpy registers its buffers with tracemalloc)."""

    def __enter__(self) -> _MemoryPeak:
        tracemalloc.start()
        return self

    def __exit__(self, *exc: object) -> None:
        _, self.peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()


def _decodes_or_fails_cleanly(cls: type, data: bytes) -> None:
    """Decoding succeeds or raises DeserializationError: any other exception propagates and fails the test."""
    try:
        cls.deserialize_from(data)
    except DeserializationError:
        pass


def _positions(length: int) -> list[int]:
    if length <= MAX_CUTS:
        return list(range(length))
    step = length / MAX_CUTS
    return sorted({int(i * step) for i in range(MAX_CUTS)} | {length - 1})


@pytest.mark.timeout(90)
@pytest.mark.parametrize("type_name", INV.all_message_like)
def test_truncated_and_bogus_length_buffers(type_name: str) -> None:
    cls = get_message_class(type_name)

    @FUZZ_SETTINGS
    @given(tree_strategy(type_name))
    def check(tree: dict) -> None:
        data = build_ours(type_name, tree).serialize_to_bytes()
        for cut in _positions(len(data)):
            with pytest.raises(DeserializationError):
                cls.deserialize_from(data[:cut])
        with _MemoryPeak() as memory:
            for offset in _positions(max(len(data) - 3, 0)):
                for bogus in BOGUS_LENGTHS:
                    _decodes_or_fails_cleanly(cls, data[:offset] + bogus + data[offset + 4 :])
        assert memory.peak < MEMORY_CEILING, (
            f"{type_name}: a bogus length made decoding peak at {memory.peak}"
        )

    check()


@pytest.mark.timeout(90)
@pytest.mark.parametrize("type_name", INV.all_message_like)
def test_random_buffers(type_name: str) -> None:
    cls = get_message_class(type_name)

    @settings(FUZZ_SETTINGS, max_examples=10)
    @given(st.lists(st.binary(max_size=96), min_size=1, max_size=8))
    def check(buffers: list[bytes]) -> None:
        with _MemoryPeak() as memory:
            for data in buffers:
                _decodes_or_fails_cleanly(cls, data)
        assert memory.peak < MEMORY_CEILING

    check()


@pytest.mark.parametrize(
    ("type_name", "prefix"),
    [
        ("std_msgs/String", b""),
        ("std_msgs/UInt8MultiArray", struct.pack("<II", 0, 0)),  # layout: no dims, data_offset 0
        # header (seq, stamp, empty frame_id), height, width, empty encoding, is_bigendian, step
        (
            "sensor_msgs/Image",
            struct.pack("<IIIIIII", 0, 0, 0, 0, 480, 640, 0) + b"\x00" + struct.pack("<I", 1920),
        ),
    ],
)
def test_huge_length_prefix_is_rejected_before_allocating(type_name: str, prefix: bytes) -> None:
    """A 4 GiB length with a few bytes behind it: one clear error, no MemoryError, no 4 GiB buffer."""
    cls = get_message_class(type_name)
    with _MemoryPeak() as memory, pytest.raises(DeserializationError):
        cls.deserialize_from(prefix + b"\xff\xff\xff\xff" + b"abc")
    assert memory.peak < MEMORY_CEILING


def test_huge_message_array_count_fails_fast() -> None:
    """2^31 PointField elements announced in 8 bytes: fails on the bytes left, not after 2^31 objects."""
    cls = get_message_class("sensor_msgs/PointCloud2")
    header = struct.pack("<III", 0, 0, 0) + struct.pack("<I", 0)  # seq, stamp, empty frame_id
    data = header + struct.pack("<II", 1, 1) + struct.pack("<I", 0x7FFFFFFF) + b"\x00" * 8
    with pytest.raises(DeserializationError):
        cls.deserialize_from(data)
