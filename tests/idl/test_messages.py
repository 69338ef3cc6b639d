"""Generated classes: wire format (checked against genpy), genpy's surface, views, errors."""

from __future__ import annotations

import copy
import io
import json
import pickle
import random
import struct
import subprocess
from pathlib import Path

import pytest
from idl_fixtures import populated_all_types

from ninjemys.errors import DeserializationError, SerializationError
from ninjemys.idl.arrays import NumericArray
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.rostime import Duration, Time
from ninjemys.testing import ROS1_PYTHON, have_ros1

ORACLE = Path(__file__).with_name("genpy_dynamic_oracle.py")


def test_round_trip_of_every_field_kind(fixture_path) -> None:
    msg = populated_all_types()
    data = msg.serialize_to_bytes()
    back = type(msg).deserialize_from(data)
    assert back == msg
    assert back.serialize_to_bytes() == data
    assert back.s == "héllo" and back.t == Time(5, 6) and back.d == Duration(-1, 5)
    assert back.b is True and back.b_v == [True, False]
    assert isinstance(back.u8_f, bytes) and back.u8_f == b"abcd"
    assert back.f64_f == tuple(float(i) for i in range(36))
    assert back.inner_v[1].values == [4.0] and back.inner.p.x == 3.0
    assert len(back.empties) == 3


@pytest.mark.ros1
@pytest.mark.skipif(not have_ros1(), reason="needs Debian's ROS 1")
def test_fixture_types_agree_with_genpy(fixture_path) -> None:
    """genpy, given our full text, computes our md5, re-serializes our bytes identically, prints our str."""
    msg = populated_all_types()
    cls = type(msg)
    inner = get_message_class("h1_test_msgs/Inner")(name="z", values=[1.5])
    items = [
        {"type": cls._type, "full_text": cls._full_text, "data": msg.serialize_to_bytes().hex()},
        {"type": inner._type, "full_text": inner._full_text, "data": inner.serialize_to_bytes().hex()},
    ]
    done = subprocess.run(
        [ROS1_PYTHON, str(ORACLE)],
        input=json.dumps(items),
        capture_output=True,
        text=True,
        env={"PATH": "/usr/bin:/bin"},
        timeout=60,
        check=True,
    )
    for item, theirs, ours in zip(items, json.loads(done.stdout), (msg, inner), strict=True):
        assert theirs["md5"] == type(ours)._md5sum
        assert theirs["data"] == item["data"]
        decoded = type(ours).deserialize_from(bytes.fromhex(item["data"]))
        assert theirs["str"] == str(decoded)


def test_known_wire_bytes_of_pose_stamped() -> None:
    cls = get_message_class("geometry_msgs/PoseStamped")
    msg = cls()
    msg.header.seq, msg.header.stamp, msg.header.frame_id = 1, Time(2, 3), "map"
    msg.pose.position.x, msg.pose.orientation.w = 1.5, 1.0
    expected = struct.pack("<IIII3s7d", 1, 2, 3, 3, b"map", 1.5, 0, 0, 0, 0, 0, 1.0)
    assert msg.serialize_to_bytes() == expected
    buff = io.BytesIO()
    msg.serialize(buff)
    assert buff.getvalue() == expected
    assert cls().deserialize(expected) == msg


def test_fixed_size_runs_are_one_struct_call() -> None:
    """Header.seq+stamp+len(frame_id) and the Pose's seven float64 are one precompiled Struct each."""
    source = get_message_class("geometry_msgs/PoseStamped")._source
    deser = source[source.index("def deserialize_from") :]
    assert deser.count(".unpack_from(") == 2
    ser = source[source.index("def _ser") : source.index("def frame_parts")]
    assert ser.count(".pack(") == 2
    straight = source[source.index("def frame_parts") : source.index("def serialize_to_bytes")]
    assert straight.count(".pack(") == 2
    assert "'<IIII'" in source and "'<ddddddd'" in source


def test_defaults_and_constructor_forms() -> None:
    cls = get_message_class("sensor_msgs/Image")
    msg = cls()
    assert msg.data == b"" and msg.encoding == "" and msg.header.stamp == Time(0, 0)
    assert cls(height=2).height == 2 and cls(height=2).width == 0
    twist_cls = get_message_class("geometry_msgs/Twist")
    vec = get_message_class("geometry_msgs/Vector3")
    twist = twist_cls(vec(1.0, 2.0, 3.0), None)
    assert twist.linear.y == 2.0 and twist.angular == vec()
    with pytest.raises(TypeError):
        vec(1.0, 2.0)
    with pytest.raises(TypeError):
        vec(1.0, 2.0, 3.0, x=1.0)
    with pytest.raises(AttributeError, match="nonsense"):
        vec(nonsense=1)
    assert get_message_class("sensor_msgs/CameraInfo")().K == [0.0] * 9
    assert get_message_class("rosgraph_msgs/Log").ERROR == 8


def test_genpy_surface_attributes() -> None:
    cls = get_message_class("geometry_msgs/PoseStamped")
    assert cls._type == "geometry_msgs/PoseStamped"
    assert cls.__slots__ == ("header", "pose")
    assert cls._slot_types == ("std_msgs/Header", "geometry_msgs/Pose")
    assert cls._has_header is True
    assert get_message_class("geometry_msgs/Pose")._has_header is False
    assert cls.__module__ == "geometry_msgs.msg"
    with pytest.raises(AttributeError):
        cls().extra = 1  # __slots__: no stray attributes


def test_str_is_the_rostopic_echo_yaml() -> None:
    cls = get_message_class("geometry_msgs/PoseStamped")
    msg = cls()
    msg.header.frame_id = "map"
    assert str(msg) == (
        'header: \n  seq: 0\n  stamp: \n    secs: 0\n    nsecs:         0\n  frame_id: "map"\n'
        "pose: \n  position: \n    x: 0.0\n    y: 0.0\n    z: 0.0\n"
        "  orientation: \n    x: 0.0\n    y: 0.0\n    z: 0.0\n    w: 0.0"
    )
    assert repr(msg) == str(msg)
    image = get_message_class("sensor_msgs/Image")(data=b"\x01\x02")
    assert "data: [1, 2]" in str(image)
    assert str(get_message_class("std_msgs/String")()) == "data: ''"


def test_wrong_field_type_names_field_and_types() -> None:
    cls = get_message_class("geometry_msgs/PoseStamped")
    msg = cls()
    msg.pose.position.x = "one"
    with pytest.raises(
        SerializationError, match=r"geometry_msgs/PoseStamped\.pose\.position\.x: expected float64.*got str"
    ):
        msg.serialize_to_bytes()
    header = get_message_class("std_msgs/Header")(seq=-1)
    with pytest.raises(SerializationError, match=r"std_msgs/Header\.seq: value -1 out of range for uint32"):
        header.serialize_to_bytes()
    image = get_message_class("sensor_msgs/Image")(data=[1, 2, 300])
    with pytest.raises(SerializationError, match=r"sensor_msgs/Image\.data\[2\]: value 300 out of range"):
        image.serialize_to_bytes()
    scan = get_message_class("sensor_msgs/LaserScan")(ranges=3.0)
    with pytest.raises(SerializationError, match=r"sensor_msgs/LaserScan\.ranges: expected float32\[\]"):
        scan.serialize_to_bytes()
    string = get_message_class("std_msgs/String")(data=5)
    with pytest.raises(SerializationError, match=r"std_msgs/String\.data: expected string .* got int"):
        string.serialize_to_bytes()
    stamped = get_message_class("std_msgs/Header")(stamp=5)
    with pytest.raises(SerializationError, match=r"std_msgs/Header\.stamp: expected Time, got int"):
        stamped.serialize_to_bytes()


def test_uint8_arrays_accept_bytes_lists_and_buffers() -> None:
    cls = get_message_class("std_msgs/UInt8MultiArray")
    expected = cls(data=b"\x01\x02\x03").serialize_to_bytes()
    for value in ([1, 2, 3], (1, 2, 3), bytearray(b"\x01\x02\x03"), memoryview(b"\x01\x02\x03")):
        assert cls(data=value).serialize_to_bytes() == expected


def test_large_arrays_deserialize_as_views_without_copies() -> None:
    image_cls = get_message_class("sensor_msgs/Image")
    payload = bytes(range(256)) * 64
    data = image_cls(height=1, width=len(payload), encoding="mono8", data=payload).serialize_to_bytes()
    image = image_cls.deserialize_from(data)
    assert isinstance(image.data, memoryview) and image.data.obj is data  # a view into the received bytes
    assert image.data == payload and bytes(image.data) == payload and image.data[3] == 3
    assert image_cls.deserialize_from(image.serialize_to_bytes()) == image

    scan_cls = get_message_class("sensor_msgs/LaserScan")
    scan = scan_cls.deserialize_from(scan_cls(ranges=[0.5, 1.5, 2.5]).serialize_to_bytes())
    ranges = scan.ranges
    assert isinstance(ranges, NumericArray)
    assert ranges == [0.5, 1.5, 2.5] and ranges == (0.5, 1.5, 2.5) and ranges != [0.5]
    assert len(ranges) == 3 and ranges[-1] == 2.5 and list(ranges) == [0.5, 1.5, 2.5]
    assert ranges[1:] == (1.5, 2.5) and 1.5 in ranges and min(ranges) == 0.5
    assert repr(ranges) == "(0.5, 1.5, 2.5)"
    assert scan_cls.deserialize_from(scan.serialize_to_bytes()) == scan
    assert copy.deepcopy(scan).ranges == [0.5, 1.5, 2.5]
    assert pickle.loads(pickle.dumps(scan)) == scan


def test_numpy_paths() -> None:
    np = pytest.importorskip("numpy")
    scan_cls = get_message_class("sensor_msgs/LaserScan")
    scan = scan_cls(ranges=np.array([0.5, 1.5], dtype=np.float32))
    data = scan.serialize_to_bytes()
    assert data == scan_cls(ranges=[0.5, 1.5]).serialize_to_bytes()
    view = np.asarray(scan_cls.deserialize_from(data).ranges)
    assert view.dtype == np.float32 and view.tolist() == [0.5, 1.5]
    numpy_msg = scan_cls().deserialize_numpy(data, np)
    assert isinstance(numpy_msg.ranges, np.ndarray)
    buff = io.BytesIO()
    numpy_msg.serialize_numpy(buff, np)
    assert buff.getvalue() == data


def test_mutable_input_buffers_are_accepted() -> None:
    cls = get_message_class("geometry_msgs/PoseStamped")
    data = cls().serialize_to_bytes()
    assert cls.deserialize_from(bytearray(data)) == cls.deserialize_from(memoryview(data))


def test_truncated_and_oversized_buffers_raise_deserialization_error() -> None:
    cls = get_message_class("sensor_msgs/PointCloud2")
    field_cls = get_message_class("sensor_msgs/PointField")
    data = cls(fields=[field_cls("x", 0, 7, 1)], data=b"\x00" * 64).serialize_to_bytes()
    for cut in range(len(data)):
        with pytest.raises(DeserializationError):
            cls.deserialize_from(data[:cut])
    # a bogus length prefix of 4 GB must fail fast instead of allocating
    bogus = struct.pack("<III", 0, 0, 0) + struct.pack("<I", 0xFFFFFFF0)
    with pytest.raises(DeserializationError, match="frame_id"):
        cls.deserialize_from(bogus + b"\x00" * 16)
    path_cls = get_message_class("nav_msgs/Path")
    huge_count = struct.pack("<IIII", 0, 0, 0, 0) + struct.pack("<I", 0xFFFFFFFF)
    with pytest.raises(DeserializationError, match="poses"):
        path_cls.deserialize_from(huge_count)


def test_random_buffers_never_escape_as_other_errors(fixture_path) -> None:
    rng = random.Random(1234)
    types = [
        "h1_test_msgs/AllTypes",
        "sensor_msgs/PointCloud2",
        "nav_msgs/Path",
        "visualization_msgs/MarkerArray",
        "rosgraph_msgs/Log",
        "diagnostic_msgs/DiagnosticArray",
    ]
    good = populated_all_types().serialize_to_bytes()
    for type_name in types:
        cls = get_message_class(type_name)
        for _ in range(300):
            size = rng.randrange(0, 200)
            candidates = [bytes(rng.randrange(256) for _ in range(size))]
            if type_name == "h1_test_msgs/AllTypes":  # bit flips in a valid message
                flipped = bytearray(good)
                flipped[rng.randrange(len(flipped))] ^= 1 << rng.randrange(8)
                candidates.append(bytes(flipped))
            for data in candidates:
                try:
                    cls.deserialize_from(data)
                except DeserializationError:
                    pass


def test_service_classes() -> None:
    srv = get_service_class("rospy_tutorials/AddTwoInts")
    assert srv._type == "rospy_tutorials/AddTwoInts"
    request = srv._request_class(a=1, b=2)
    assert request._type == "rospy_tutorials/AddTwoIntsRequest"
    assert srv._request_class.deserialize_from(request.serialize_to_bytes()) == request
    assert srv._response_class(sum=3).sum == 3
    assert srv._request_class.__module__ == "rospy_tutorials.srv"


def test_action_generated_classes() -> None:
    goal_cls = get_message_class("actionlib_tutorials/FibonacciActionGoal")
    goal = goal_cls()
    goal.goal.order = 5
    goal.goal_id.id = "g1"
    back = goal_cls.deserialize_from(goal.serialize_to_bytes())
    assert back.goal.order == 5 and back.goal_id.id == "g1" and goal_cls._has_header


def test_strify_options_follow_genpy() -> None:
    from ninjemys.idl.message import strify_message

    cls = get_message_class("std_msgs/Header")
    msg = cls(seq=7, stamp=Time(12, 5), frame_id="f")
    text = strify_message(msg, field_filter=lambda m: ["seq", "stamp"], fixed_numeric_width=4)
    assert text == "seq:    7\nstamp: \n  secs:   12\n  nsecs:    5"
    assert strify_message(msg, time_offset=Time(10)).split("\n")[2:4] == ["  secs: 2", "  nsecs:         5"]


def test_received_messages_can_carry_the_connection_header() -> None:
    msg = get_message_class("std_msgs/String")(data="x")
    msg._connection_header = {"callerid": "/talker"}
    assert msg._connection_header["callerid"] == "/talker"
    assert msg == get_message_class("std_msgs/String")(data="x")  # not part of equality


def test_time_out_of_wire_range_names_the_field() -> None:
    header = get_message_class("std_msgs/Header")(stamp=Time(2**32, 0))
    with pytest.raises(SerializationError, match=r"std_msgs/Header\.stamp: secs=4294967296 does not fit"):
        header.serialize_to_bytes()


def test_string_rendering_fast_path_matches_pyyaml():
    """rostopic echo's quoted strings: the no-PyYAML fast path must print exactly what PyYAML does."""
    import random
    import string

    import yaml

    from ninjemys.idl.message import _yaml_string

    rng = random.Random(7)
    alphabet = string.printable[:95] + "   é\t"
    for _ in range(3000):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randint(1, 120)))
        assert _yaml_string(text) == yaml.dump(text, default_style='"').rstrip("\n"), text
