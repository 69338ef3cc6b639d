"""Damaged bags: truncation, bit flips, empty files, crashed recordings and reindex."""

from __future__ import annotations

import random
import shutil

import pytest
from bagtest_util import BASE, STRING_HEADER, read_with_real_rosbag, string_bytes, write_sample

from ninjemys.bag.reader import BagReader
from ninjemys.bag.reindex import reindex_in_place
from ninjemys.bag.writer import BagWriter
from ninjemys.errors import BagError


def outcome(path):
    """('error', msg) or ('ok', messages, warnings): the only two things a damaged bag may produce."""
    try:
        with BagReader(path) as r:
            msgs = [(m.connection.topic, m.time, bytes(m.data)) for m in r.read()]
            return ("ok", msgs, r.warnings)
    except BagError as exc:
        return ("error", str(exc))


def test_empty_file_is_a_clear_error(tmp_path):
    path = tmp_path / "empty.bag"
    path.write_bytes(b"")
    with pytest.raises(BagError, match="empty"):
        BagReader(path)


def test_not_a_bag_and_old_version(tmp_path):
    (tmp_path / "x.bag").write_bytes(b"hello world, not a bag at all")
    with pytest.raises(BagError, match="not a bag"):
        BagReader(tmp_path / "x.bag")
    (tmp_path / "v.bag").write_bytes(b"#ROSBAG V1.2\n" + b"\0" * 100)
    with pytest.raises(BagError, match="1.2"):
        BagReader(tmp_path / "v.bag")


@pytest.mark.parametrize("compression", ["none", "lz4", "bz2"])
def test_every_truncation_gives_a_prefix_or_an_error(tmp_path, compression):
    src = tmp_path / "src.bag"
    expected = write_sample(src, compression, count=120, chunk_threshold=800)
    data = src.read_bytes()
    cut_path = tmp_path / "cut.bag"
    recovered_any = False
    for cut in range(0, len(data), max(1, len(data) // 150)):
        cut_path.write_bytes(data[:cut])
        result = outcome(cut_path)
        if result[0] == "ok":
            msgs = result[1]
            # a truncated bag reads back a time-ordered subset of what was written, and says so
            assert set(msgs) <= set(expected)
            assert msgs == sorted(msgs, key=lambda m: m[1])
            if cut < len(data):
                assert result[2], f"no warning for a bag cut at {cut}"
            recovered_any = recovered_any or len(msgs) > 0
    assert recovered_any


@pytest.mark.parametrize("compression", ["none", "lz4"])
def test_bit_flips_never_crash(tmp_path, compression):
    src = tmp_path / "src.bag"
    write_sample(src, compression, count=80, chunk_threshold=600)
    data = src.read_bytes()
    rng = random.Random(1234)
    flipped = tmp_path / "flip.bag"
    for _ in range(150):
        buf = bytearray(data)
        pos = rng.randrange(len(buf))
        buf[pos] ^= 1 << rng.randrange(8)
        flipped.write_bytes(bytes(buf))
        assert outcome(flipped)[0] in ("ok", "error")


def test_crashed_recording_is_read_by_scan_and_recovered_by_reindex(tmp_path):
    path = tmp_path / "rec.bag"
    writer = BagWriter(path, compression="lz4", active=True, flush_interval=0.0)
    c = writer.connection("/chatter", STRING_HEADER)
    expected = []
    for i in range(500):
        data = string_bytes(f"m{i}")
        writer.write(c, BASE + i * 1000, data)
        expected.append(("/chatter", BASE + i * 1000, data))
    writer.abandon()  # the process dies: no index, file still named *.active
    active = tmp_path / "rec.bag.active"
    assert active.exists() and not path.exists()
    with BagReader(active) as r:
        assert not r.indexed and any("not indexed" in w for w in r.warnings)
        assert [(m.connection.topic, m.time, bytes(m.data)) for m in r.read()] == expected
    list(reindex_in_place(active))
    with BagReader(active) as r:
        assert r.indexed and not r.warnings
        assert [(m.connection.topic, m.time, bytes(m.data)) for m in r.read()] == expected


@pytest.mark.parametrize("compression", ["none", "lz4", "bz2"])
def test_reindex_of_a_bag_cut_mid_chunk_keeps_every_intact_message(tmp_path, compression):
    path = tmp_path / "rec.bag"
    expected = write_sample(path, compression, count=200, chunk_threshold=1500)
    with BagReader(path) as r:
        last_chunk = r.chunk_infos[-1]
        before_last = sum(c.message_count for c in r.chunk_infos[:-1])
    data = path.read_bytes()
    cut = tmp_path / "cut.bag"
    cut.write_bytes(data[: last_chunk.pos + 300])
    list(reindex_in_place(cut))
    with BagReader(cut) as r:
        assert r.indexed and not r.warnings
        got = [(m.connection.topic, m.time, bytes(m.data)) for m in r.read()]
    assert got[:before_last] == expected[:before_last]
    assert set(got) <= set(expected)
    if compression == "none":
        assert len(got) > before_last  # the intact head of the cut chunk came back too


@pytest.mark.ros1
def test_real_rosbag_reads_a_reindexed_bag(tmp_path):
    path = tmp_path / "rec.bag"
    expected = write_sample(path, "lz4", count=200, chunk_threshold=1500)
    with BagReader(path) as r:
        last = r.chunk_infos[-1].pos
        keep = sum(c.message_count for c in r.chunk_infos[:-1])
    cut = tmp_path / "cut.bag"
    shutil.copy(path, cut)
    with open(cut, "r+b") as f:
        f.truncate(last + 50)
    list(reindex_in_place(cut))
    assert read_with_real_rosbag(cut)[:keep] == expected[:keep]


def test_reindex_of_garbage_is_a_bag_error(tmp_path):
    path = tmp_path / "g.bag"
    path.write_bytes(b"#ROSBAG V2.0\n" + b"\xff" * 5000)
    with pytest.raises(BagError):
        list(reindex_in_place(path))


def test_encrypted_bag_is_named_as_such(tmp_path):
    from ninjemys.bag.format import MAGIC, U32, U64, encode_header

    header = encode_header(
        {
            "op": b"\x03",
            "index_pos": U64.pack(0),
            "conn_count": U32.pack(0),
            "chunk_count": U32.pack(0),
            "encryptor": b"rosbag/AesCbcEncryptor",
        }
    )
    pad = 4096 - 8 - len(header)
    path = tmp_path / "enc.bag"
    path.write_bytes(MAGIC + U32.pack(len(header)) + header + U32.pack(pad) + b" " * pad)
    with pytest.raises(BagError, match="encrypted with rosbag/AesCbcEncryptor"):
        BagReader(path)
