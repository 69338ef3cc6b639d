"""rosbag.Bag, the ROS 1 Python API: messages in and out, queries, and agreement with real rosbag."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from bagtest_util import BASE, ros1_run

import rosbag
from ninjemys.bag.writer import BagWriter
from ninjemys.rostime import Time
from ninjemys.testing import ninjemys_bin


def sample(path, compression="none"):
    from geometry_msgs.msg import PoseStamped
    from sensor_msgs.msg import Image
    from std_msgs.msg import String

    written = []
    with rosbag.Bag(str(path), "w", compression=compression) as bag:
        for i in range(30):
            t = Time(1_700_000_000, i * 10_000_000)
            s = String(data=f"text {i}")
            bag.write("/text", s, t)
            written.append(("/text", s, t))
            if i % 5 == 0:
                p = PoseStamped()
                p.header.frame_id = "map"
                p.header.stamp = t
                p.pose.position.x = i * 1.5
                p.pose.orientation.w = 1.0
                bag.write("/pose", p, t + __import__("ninjemys.rostime").rostime.Duration(0, 1))
                written.append(("/pose", p, None))
            if i == 10:
                img = Image(height=100, width=100, encoding="mono8", step=100, data=bytes(range(100)) * 100)
                bag.write("/image", img, t + __import__("ninjemys.rostime").rostime.Duration(0, 2))
                written.append(("/image", img, None))
    return written


@pytest.mark.parametrize("compression", ["none", "bz2", "lz4"])
def test_write_then_read_messages(tmp_path, compression):
    path = tmp_path / "a.bag"
    written = sample(path, compression)
    with rosbag.Bag(str(path)) as bag:
        got = list(bag.read_messages())
        assert [(m.topic, m.message) for m in got] == [(t, m) for t, m, _ in written]
        assert all(isinstance(m.timestamp, Time) for m in got)
        assert got[0].timestamp == Time(1_700_000_000, 0)
        topic, msg, t = got[0]  # unpacks like ROS 1's namedtuple
        assert topic == "/text" and msg.data == "text 0"
        assert bag.get_message_count() == len(written)
        assert bag.get_message_count("/pose") == 6
        assert bag.get_start_time() == pytest.approx(1_700_000_000.0)
        info = bag.get_type_and_topic_info()
        assert info.msg_types["geometry_msgs/PoseStamped"] == "d3812c3cbc69362b77dc0b19b345f8f5"
        assert info.topics["/text"].message_count == 30 and info.topics["/text"].frequency == pytest.approx(
            100.0
        )
        assert bag.get_compression_info().compression == compression


def test_read_filters_raw_and_headers(tmp_path):
    path = tmp_path / "a.bag"
    sample(path)
    with rosbag.Bag(str(path)) as bag:
        window = list(
            bag.read_messages(
                topics=["/text"],
                start_time=Time(1_700_000_000, 50_000_000),
                end_time=Time(1_700_000_000, 100_000_000),
            )
        )
        assert [m.message.data for m in window] == [f"text {i}" for i in range(5, 11)]
        poses = list(
            bag.read_messages(
                connection_filter=lambda topic, datatype, md5sum, msg_def, header: datatype.endswith(
                    "PoseStamped"
                )
            )
        )
        assert {m.topic for m in poses} == {"/pose"}
        raw = next(bag.read_messages(topics="/text", raw=True))
        datatype, data, md5sum, pos, pytype = raw.message
        assert (
            datatype == "std_msgs/String" and data == b"\x06\x00\x00\x00text 0" and pytype._md5sum == md5sum
        )
        with_header = next(bag.read_messages(topics="/pose", return_connection_header=True))
        assert with_header.connection_header["type"] == "geometry_msgs/PoseStamped"


def test_unknown_types_are_decoded_from_the_bags_own_definition(tmp_path):
    from ninjemys.idl.loader import message_class_from_definition

    definition = "int32 a\nstring b\nfloat64[] c\n"
    cls = message_class_from_definition("my_private_pkg/Thing", definition)
    payload = cls(a=7, b="seven", c=[1.0, 2.0]).serialize_to_bytes()
    path = tmp_path / "custom.bag"
    with BagWriter(path) as w:
        conn = w.connection(
            "/thing",
            {
                "type": b"my_private_pkg/Thing",
                "md5sum": cls._md5sum.encode(),
                "message_definition": definition.encode(),
            },
        )
        w.write(conn, BASE, payload)
    with rosbag.Bag(str(path)) as bag:
        (msg,) = [m.message for m in bag.read_messages()]
    assert (msg.a, msg.b, list(msg.c)) == (7, "seven", [1.0, 2.0])
    assert msg._type == "my_private_pkg/Thing"


def test_append_mode_and_reindex(tmp_path):
    from std_msgs.msg import String

    path = tmp_path / "a.bag"
    with rosbag.Bag(str(path), "w") as bag:
        bag.write("/x", String(data="one"), Time(1, 0))
    with rosbag.Bag(str(path), "a") as bag:
        bag.write("/x", String(data="two"), Time(2, 0))
    with rosbag.Bag(str(path)) as bag:
        assert [m.message.data for m in bag.read_messages()] == ["one", "two"]
    # drop the index as a crash would, then reindex through the API
    with open(path, "r+b") as f:
        f.seek(13)
        from ninjemys.bag.format import file_header_record

        f.write(file_header_record(0, 0, 0))
    with pytest.raises(rosbag.ROSBagUnindexedException):
        rosbag.Bag(str(path), "a")
    with rosbag.Bag(str(path), "a", allow_unindexed=True) as bag:
        list(bag.reindex())
    with rosbag.Bag(str(path)) as bag:
        assert bag.get_message_count() == 2 and not bag.warnings


def test_mode_errors(tmp_path):
    with pytest.raises(rosbag.ROSBagException):
        rosbag.Bag(str(tmp_path / "missing.bag"))
    with rosbag.Bag(str(tmp_path / "w.bag"), "w") as bag:
        with pytest.raises(rosbag.ROSBagException):
            list(bag.read_messages())
    with pytest.raises(ValueError):
        rosbag.Bag(str(tmp_path / "w.bag"), "x")


@pytest.mark.ros1
@pytest.mark.parametrize("compression", ["none", "lz4"])
def test_real_rosbag_decodes_our_messages(tmp_path, compression):
    path = tmp_path / "a.bag"
    written = sample(path, compression)
    code = """
import json, sys, rosbag
out = []
for topic, msg, t in rosbag.Bag(sys.argv[1]).read_messages():
    out.append([topic, str(msg), t.to_nsec()])
print(json.dumps(out))
"""
    proc = ros1_run(code, str(path))
    assert proc.returncode == 0, proc.stderr
    theirs = json.loads(proc.stdout)
    assert [(t, text) for t, text, _ in theirs] == [(t, str(m)) for t, m, _ in written]


@pytest.mark.ros1
def test_type_and_topic_info_matches_real_rosbag(tmp_path):
    path = tmp_path / "a.bag"
    sample(path)
    code = """
import json, sys, rosbag
info = rosbag.Bag(sys.argv[1]).get_type_and_topic_info()
print(json.dumps([info.msg_types, {k: list(v) for k, v in info.topics.items()}]))
"""
    proc = ros1_run(code, str(path))
    assert proc.returncode == 0, proc.stderr
    with rosbag.Bag(str(path)) as bag:
        info = bag.get_type_and_topic_info()
        ours = [info.msg_types, {k: list(v) for k, v in info.topics.items()}]
    assert json.loads(json.dumps(ours)) == json.loads(proc.stdout)


def test_filter_on_message_fields(tmp_path):
    path = tmp_path / "a.bag"
    sample(path)
    out = tmp_path / "f.bag"
    proc = subprocess.run(
        [
            ninjemys_bin("rosbag"),
            "filter",
            str(path),
            str(out),
            "topic == '/pose' and m.pose.position.x > 10",
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    with rosbag.Bag(str(out)) as bag:
        assert [m.message.pose.position.x for m in bag.read_messages()] == [15.0, 22.5, 30.0, 37.5]


def test_garbage_message_bytes_and_bad_definitions_are_format_errors(tmp_path):
    path = tmp_path / "bad.bag"
    with BagWriter(path) as w:
        c = w.connection(
            "/s",
            {
                "type": b"std_msgs/String",
                "md5sum": b"992ce8a1687cec8c8bd883ec73ca41d1",
                "message_definition": b"string data\n",
            },
        )
        w.write(c, BASE, b"\xff\xff\xff\x7f")  # a string length far past the message end
        d = w.connection(
            "/weird",
            {
                "type": b"my_pkg/Weird",
                "md5sum": b"0" * 32,
                "message_definition": b"not a ! valid definition\n",
            },
        )
        w.write(d, BASE + 1, b"")
    with rosbag.Bag(str(path)) as bag:
        with pytest.raises(rosbag.ROSBagFormatException, match="/s"):
            list(bag.read_messages(topics="/s"))
        with pytest.raises(rosbag.ROSBagException):
            list(bag.read_messages(topics="/weird"))
        assert len(list(bag.read_messages(raw=True))) == 2  # raw reading never needs the classes


@pytest.mark.ros1
def test_a_csv_export_script_reads_what_real_rosbag_gives(tmp_path):
    """The bag-to-CSV scripts of course and lab repositories walk a message through
    ``type(value).__slots__`` (a stamp's secs and nsecs included: genpy's Time and Duration list
    them; a float32[] is a tuple, written whole), stamp rows with ``t.to_time()``, and print the bag
    with ``str(bag)`` (each topic's rate, as rosbag computes it when the index is read): the same
    text from Debian's rosbag and ours."""
    from sensor_msgs.msg import LaserScan

    path = tmp_path / "a.bag"
    sample(path)
    with rosbag.Bag(str(path), "a") as bag:
        bag.write(
            "/scan", LaserScan(ranges=[1.0, 2.5, float("inf")], angle_increment=0.5), Time(1_700_000_001)
        )
    code = """
import sys, rosbag

def flat(value, prefix=""):
    if hasattr(value, "__slots__"):
        return [row for s in type(value).__slots__ for row in flat(getattr(value, s), prefix + s + ".")]
    return [(prefix[:-1], str(value))]

bag = rosbag.Bag(sys.argv[1])
for topic, msg, t in bag.read_messages(topics=["/pose", "/scan"]):
    print(topic, t.to_time(), flat(msg))
print(str(bag).split("topics:")[1])
print(rosbag.Bag(sys.argv[1], skip_index=True))
"""
    theirs = ros1_run(code, str(path))
    assert theirs.returncode == 0, theirs.stderr
    assert "header.stamp.nsecs" in theirs.stdout and " msgs @ " in theirs.stdout
    ours = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True)
    assert ours.returncode == 0, ours.stderr
    assert ours.stdout == theirs.stdout


RAW_READ = """
import sys, rosbag, genpy
from std_msgs.msg import String, UInt8MultiArray
if sys.argv[2] == "write":
    with rosbag.Bag(sys.argv[1], "w", compression=sys.argv[3]) as b:
        for i in range(3):
            b.write("/chatter", String(data="hi %d" % i), genpy.Time(1, i))
            b.write("/u8", UInt8MultiArray(data=bytes([i, 255])), genpy.Time(1, i))
    sys.exit(0)
with rosbag.Bag(sys.argv[1]) as b:
    for topic, raw, t in b.read_messages(raw=True):
        dt, data, md5, pos, pytype = raw
        print(topic, len(raw), dt, type(data).__name__, data.hex(), md5, pos, pytype._type, pytype._md5sum, t)
"""


@pytest.mark.parametrize("compression", ["none", "bz2", "lz4"])
def test_a_raw_read_gives_real_rosbags_tuple(tmp_path, compression):
    """``read_messages(raw=True)``: (datatype, data bytes, md5sum, (chunk_pos, offset in the chunk),
    pytype), the position as rosbag gives it (ours gave the chunk's position alone)."""
    from ninjemys.testing import have_ros1

    if not have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    path = tmp_path / "raw.bag"
    made = ros1_run(RAW_READ, str(path), "write", compression)
    assert made.returncode == 0, made.stderr
    theirs = ros1_run(RAW_READ, str(path), "read")
    assert theirs.returncode == 0, theirs.stderr
    assert "(4117, 167)" in theirs.stdout  # the first message record, after its connection record
    ours = subprocess.run([sys.executable, "-c", RAW_READ, str(path), "read"], capture_output=True, text=True)
    assert ours.returncode == 0, ours.stderr
    assert ours.stdout == theirs.stdout
