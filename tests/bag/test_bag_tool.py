"""The rosbag command: info (vs real rosbag), reindex, compress/decompress, check, filter, export."""

from __future__ import annotations

import subprocess

import pytest
from bagtest_util import BASE, STRING_HEADER, read_with_real_rosbag, string_bytes, write_sample

from ninjemys.bag.reader import BagReader
from ninjemys.bag.writer import BagWriter
from ninjemys.testing import ninjemys_bin


def rosbag(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [ninjemys_bin("rosbag"), *args], capture_output=True, text=True, timeout=60, cwd=cwd
    )


def messages(path):
    with BagReader(path) as r:
        return [(m.connection.topic, m.time, bytes(m.data)) for m in r.read()]


@pytest.mark.ros1
@pytest.mark.parametrize("compression", ["none", "bz2", "lz4"])
@pytest.mark.parametrize(
    "flags", [[], ["-y"], ["--freq"], ["-y", "--freq"], ["-y", "-k", "topics"], ["-y", "-k", "duration"]]
)
def test_info_matches_real_rosbag(tmp_path, compression, flags):
    write_sample(tmp_path / "a.bag", compression)
    ours = rosbag("info", *flags, "a.bag", cwd=tmp_path)
    theirs = subprocess.run(
        ["/usr/bin/rosbag", "info", *flags, "a.bag"], capture_output=True, text=True, cwd=tmp_path
    )
    assert ours.returncode == theirs.returncode == 0, ours.stderr
    assert ours.stdout == theirs.stdout


@pytest.mark.ros1
def test_info_of_several_bags_and_empty_bag_matches(tmp_path):
    write_sample(tmp_path / "a.bag", "lz4", count=20)
    BagWriter(tmp_path / "e.bag").close()
    ours = rosbag("info", "a.bag", "e.bag", cwd=tmp_path)
    theirs = subprocess.run(
        ["/usr/bin/rosbag", "info", "a.bag", "e.bag"], capture_output=True, text=True, cwd=tmp_path
    )
    assert ours.stdout == theirs.stdout


def test_info_errors_are_one_line(tmp_path):
    (tmp_path / "bad.bag").write_bytes(b"nope")
    proc = rosbag("info", str(tmp_path / "bad.bag"))
    assert proc.returncode == 1
    assert proc.stderr.startswith("ERROR") and proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    proc = rosbag("info", str(tmp_path / "missing.bag"))
    assert proc.returncode == 1 and "Traceback" not in proc.stderr


def test_reindex_recovers_an_active_bag(tmp_path):
    writer = BagWriter(tmp_path / "rec.bag", compression="lz4", active=True, flush_interval=0.0)
    c = writer.connection("/chatter", STRING_HEADER)
    for i in range(100):
        writer.write(c, BASE + i, string_bytes(str(i)))
    writer.abandon()
    active = tmp_path / "rec.bag.active"
    proc = rosbag("reindex", str(active))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "rec.bag.orig.active").exists()  # ROS 1's backup naming (NAME.orig.EXT)
    with BagReader(active) as r:
        assert r.indexed and r.message_count == 100


@pytest.mark.parametrize("target", ["bz2", "lz4"])
def test_compress_then_decompress_keeps_messages(tmp_path, target):
    path = tmp_path / "a.bag"
    expected = write_sample(path, "none")
    flag = "--lz4" if target == "lz4" else "--bz2"
    assert rosbag("compress", flag, str(path)).returncode == 0
    with BagReader(path) as r:
        assert {h.compression for h in r.chunk_headers.values()} == {target}
        assert r.topic_connections("/other")[0].callerid == "/talker"
    assert messages(path) == expected
    assert messages(tmp_path / "a.orig.bag") == expected
    assert rosbag("decompress", "-f", str(path)).returncode == 0
    with BagReader(path) as r:
        assert {h.compression for h in r.chunk_headers.values()} == {"none"}
    assert messages(path) == expected


def test_compress_into_output_dir(tmp_path):
    path = tmp_path / "a.bag"
    expected = write_sample(path, "none", count=30)
    out = tmp_path / "out"
    out.mkdir()
    assert rosbag("compress", "--lz4", "--output-dir", str(out), str(path)).returncode == 0
    assert messages(out / "a.bag") == expected and messages(path) == expected


@pytest.mark.ros1
def test_real_rosbag_reads_our_compressed_output(tmp_path):
    path = tmp_path / "a.bag"
    expected = write_sample(path, "none")
    assert rosbag("compress", "--lz4", str(path)).returncode == 0
    assert read_with_real_rosbag(path) == expected


def test_check_sound_and_damaged(tmp_path):
    path = tmp_path / "a.bag"
    write_sample(path, "lz4")
    proc = rosbag("check", str(path))
    assert proc.returncode == 0 and proc.stdout.strip() == "Bag file does not need any migrations."
    data = bytearray(path.read_bytes())
    with BagReader(path) as r:
        pos = r.chunk_headers[r.chunk_infos[1].pos].data_pos + 20
    data[pos] ^= 0xFF
    path.write_bytes(bytes(data))
    proc = rosbag("check", str(path))
    assert proc.returncode == 1 and "ERROR" in proc.stderr and "Traceback" not in proc.stderr


def test_filter_by_topic_and_time(tmp_path):
    path = tmp_path / "a.bag"
    expected = write_sample(path, "lz4")
    cutoff = BASE + 100 * 10_000_000
    proc = rosbag(
        "filter", str(path), str(tmp_path / "f.bag"), f"topic == '/other' and t.to_nsec() < {cutoff}"
    )
    assert proc.returncode == 0, proc.stderr
    assert messages(tmp_path / "f.bag") == [e for e in expected if e[0] == "/other" and e[1] < cutoff]


def test_filter_bad_expression_is_one_line(tmp_path):
    path = tmp_path / "a.bag"
    write_sample(path, count=10)
    proc = rosbag("filter", str(path), str(tmp_path / "f.bag"), "topic ==")
    assert proc.returncode != 0 and "Traceback" not in proc.stderr and "ERROR" in proc.stderr


def test_export_mcap_reads_back_with_mcap(tmp_path):
    from mcap.reader import make_reader

    path = tmp_path / "a.bag"
    expected = write_sample(path, "bz2")
    out = tmp_path / "a.mcap"
    proc = rosbag("export", "--mcap", str(out), str(path))
    assert proc.returncode == 0, proc.stderr
    with open(out, "rb") as f:
        reader = make_reader(f)
        got = [(ch.topic, m.log_time, m.data) for _s, ch, m in reader.iter_messages(log_time_order=True)]
        summary = reader.get_summary()
    assert got == expected
    schemas = {s.name: (s.encoding, s.data) for s in summary.schemas.values()}
    assert schemas == {"std_msgs/String": ("ros1msg", b"string data\n")}
    assert {c.message_encoding for c in summary.channels.values()} == {"ros1"}
    other = [c for c in summary.channels.values() if c.topic == "/other"][0]
    assert other.metadata["callerid"] == "/talker" and other.metadata["latching"] == "1"


def test_export_mcap_decodes_with_mcap_ros1_support(tmp_path):
    from mcap.reader import make_reader
    from mcap_ros1.decoder import DecoderFactory

    path = tmp_path / "a.bag"
    write_sample(path, "none", count=12)
    out = tmp_path / "a.mcap"
    assert rosbag("export", "-q", "--mcap", str(out), str(path)).returncode == 0
    with open(out, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        texts = [msg.data for _s, _c, _m, msg in reader.iter_decoded_messages()]
    assert texts == [f"message {i}" for i in range(12)]


@pytest.mark.ros1
def test_info_matches_with_several_connections_per_topic(tmp_path):
    with BagWriter(tmp_path / "c.bag", compression="bz2") as w:
        a = w.connection("/chatter", dict(STRING_HEADER, callerid=b"/one"))
        b = w.connection("/chatter", dict(STRING_HEADER, callerid=b"/two"))
        c = w.connection("/single", STRING_HEADER)
        for i in range(100):
            w.write((a, b, c)[i % 3], BASE + i * 37_000_000, string_bytes(str(i)))
    for flags in ([], ["-y"], ["--freq"]):
        ours = rosbag("info", *flags, "c.bag", cwd=tmp_path)
        theirs = subprocess.run(
            ["/usr/bin/rosbag", "info", *flags, "c.bag"], capture_output=True, text=True, cwd=tmp_path
        )
        assert ours.stdout == theirs.stdout
    assert "(2 connections)" in ours.stdout
