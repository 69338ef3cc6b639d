"""The bag library: round trips, index-driven reads, ordering, append, and interop with real readers."""

from __future__ import annotations

import struct

import pytest
from bagtest_util import BASE, STRING_HEADER, read_with_real_rosbag, string_bytes, write_sample

from ninjemys.bag.format import FILE_HEADER_LENGTH, MAGIC
from ninjemys.bag.reader import BagReader
from ninjemys.bag.writer import BagWriter
from ninjemys.errors import BagError

COMPRESSIONS = ["none", "bz2", "lz4"]


def read_all(path, **kw):
    with BagReader(path) as r:
        return [(m.connection.topic, m.time, bytes(m.data)) for m in r.read(**kw)]


@pytest.mark.parametrize("compression", COMPRESSIONS)
def test_round_trip_every_compression(tmp_path, compression):
    path = tmp_path / "a.bag"
    expected = write_sample(path, compression)
    with BagReader(path) as r:
        assert r.indexed and not r.warnings
        assert len(r.chunk_infos) > 3
        assert {h.compression for h in r.chunk_headers.values()} == {compression}
        assert r.message_count == len(expected)
        other = r.topic_connections("/other")[0]
        assert other.callerid == "/talker" and other.latching
    assert read_all(path) == expected


def test_file_header_is_4096_bytes_and_index_position_set(tmp_path):
    path = tmp_path / "a.bag"
    write_sample(path)
    raw = path.read_bytes()
    assert raw.startswith(MAGIC)
    (hlen,) = struct.unpack_from("<I", raw, len(MAGIC))
    (dlen,) = struct.unpack_from("<I", raw, len(MAGIC) + 4 + hlen)
    assert 8 + hlen + dlen == FILE_HEADER_LENGTH
    with BagReader(path) as r:
        assert MAGIC.__len__() + FILE_HEADER_LENGTH < r.index_pos < r.size


def test_topic_and_time_range_reads_use_only_matching_chunks(tmp_path, monkeypatch):
    path = tmp_path / "a.bag"
    expected = write_sample(path, "lz4")
    lo, hi = BASE + 100 * 10_000_000, BASE + 150 * 10_000_000
    want = [e for e in expected if e[0] == "/chatter" and lo <= e[1] <= hi]
    with BagReader(path) as r:
        loaded = []
        original = r._load_chunk
        monkeypatch.setattr(r, "_load_chunk", lambda pos: (loaded.append(pos), original(pos))[1])
        got = [(m.connection.topic, m.time, bytes(m.data)) for m in r.read("/chatter", lo, hi)]
        assert got == want
        overlapping = [c.pos for c in r.chunk_infos if c.end_time >= lo and c.start_time <= hi]
        assert sorted(loaded) == sorted(overlapping) and len(loaded) < len(r.chunk_infos)


def test_out_of_order_writes_come_back_in_time_order(tmp_path):
    path = tmp_path / "a.bag"
    stamps = [5, 1, 9, 3, 7, 2, 8, 4, 6, 0] * 3
    with BagWriter(path, chunk_threshold=60) as w:
        c = w.connection("/x", STRING_HEADER)
        for i, s in enumerate(stamps):
            w.write(c, BASE + s * 1000 + i, string_bytes(str(i)))
    got = read_all(path)
    assert [t for _, t, _ in got] == sorted(BASE + s * 1000 + i for i, s in enumerate(stamps))


def test_append_mode_keeps_old_messages(tmp_path):
    path = tmp_path / "a.bag"
    expected = write_sample(path, "bz2", count=30)
    with BagWriter(path, compression="lz4", append=True) as w:
        c = w.connection("/chatter", STRING_HEADER)
        w.write(c, BASE + 10**10, string_bytes("late"))
    got = read_all(path)
    assert got == expected + [("/chatter", BASE + 10**10, string_bytes("late"))]
    with BagReader(path) as r:
        assert len(r.topic_connections("/chatter")) == 1


def test_empty_bag_round_trip(tmp_path):
    path = tmp_path / "e.bag"
    BagWriter(path).close()
    with BagReader(path) as r:
        assert r.indexed and r.message_count == 0 and r.start_time is None
        assert list(r.read()) == []


def test_bad_compression_is_a_bag_error(tmp_path):
    with pytest.raises(BagError, match="compression"):
        BagWriter(tmp_path / "x.bag", compression="zip")


@pytest.mark.ros1
@pytest.mark.parametrize("compression", COMPRESSIONS)
def test_real_rosbag_reads_our_bags(tmp_path, compression):
    path = tmp_path / "ours.bag"
    expected = write_sample(path, compression)
    assert read_with_real_rosbag(path) == expected


@pytest.mark.parametrize("compression", COMPRESSIONS)
def test_rosbags_reads_our_bags(tmp_path, compression):
    from rosbags.rosbag1 import Reader

    path = tmp_path / "ours.bag"
    expected = write_sample(path, compression)
    with Reader(path) as reader:
        got = [(c.topic, t, bytes(d)) for c, t, d in reader.messages()]
        assert {c.msgtype for c in reader.connections} == {"std_msgs/msg/String"}
    assert got == expected


@pytest.mark.parametrize("compression", ["none", "bz2", "lz4"])
def test_we_read_rosbags_bags(tmp_path, compression):
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    path = tmp_path / "theirs.bag"
    expected = []
    writer = Writer(path)
    if compression != "none":
        writer.set_compression(getattr(Writer.CompressionFormat, compression.upper()))
    with writer:
        conn = writer.add_connection("/chatter", "std_msgs/msg/String", typestore=store)
        for i in range(20000):
            data = string_bytes(f"rosbags {i}")
            writer.write(conn, BASE + i * 1000, data)
            expected.append(("/chatter", BASE + i * 1000, data))
    assert read_all(path) == expected


@pytest.mark.ros1
@pytest.mark.parametrize("compression", COMPRESSIONS)
def test_we_read_real_rosbag_bags(tmp_path, compression):
    from bagtest_util import ros1_run

    path = tmp_path / "real.bag"
    code = """
import sys, rosbag, genpy
from std_msgs.msg import String, Int32
with rosbag.Bag(sys.argv[1], 'w', compression=sys.argv[2], chunk_threshold=2000) as b:
    for i in range(250):
        if i % 4:
            b.write('/s', String(data='real %d' % i), genpy.Time(1700000000, i * 1000))
        else:
            b.write('/i', Int32(data=i), genpy.Time(1700000000, i * 1000))
"""
    proc = ros1_run(code, str(path), compression)
    assert proc.returncode == 0, proc.stderr
    expected = read_with_real_rosbag(path)
    assert len(expected) == 250
    assert read_all(path) == expected


@pytest.mark.ros1
def test_real_rosbag_reads_full_compressible_lz4_chunks(tmp_path):
    # many 64 KiB lz4 blocks per chunk: roslz4 only follows independent blocks
    path = tmp_path / "big.bag"
    data = string_bytes("x" * 1020)
    with BagWriter(path, compression="lz4") as w:
        c = w.connection("/a", STRING_HEADER)
        for i in range(3000):
            w.write(c, BASE + i, data)
    got = read_with_real_rosbag(path)
    assert len(got) == 3000 and got[-1] == ("/a", BASE + 2999, data)
