"""md5sums and full texts as genmsg computes them; classes from message definitions."""

from __future__ import annotations

import hashlib

import pytest

from ninjemys.errors import DefinitionError
from ninjemys.idl import loader
from ninjemys.idl.fulltext import SEPARATOR, split_full_text
from ninjemys.idl.md5 import compute_md5_text

# published md5sums (ROS wiki, rosjava logs, genpy): independent of our implementation
KNOWN_MD5 = {
    "std_msgs/String": "992ce8a1687cec8c8bd883ec73ca41d1",
    "std_msgs/Header": "2176decaecbce78abc3b96ef049fabed",
    "geometry_msgs/Vector3": "4a842b65f413084dc2b10fb484ea7f17",
    "geometry_msgs/Twist": "9f195f881246fdfa2798d1d3eebca84a",
    "geometry_msgs/PoseStamped": "d3812c3cbc69362b77dc0b19b345f8f5",
    "sensor_msgs/Image": "060021388200f6f0f447d0fcd9c64743",
    "sensor_msgs/LaserScan": "90c7ef2dc6895d81024acba2ac42f369",
    "rosgraph_msgs/Log": "acffd30cd6b6de30f120938c17c593fb",
    "rosgraph_msgs/Clock": "a9c97c1d230cfc112e270351a944ee47",
    "actionlib_msgs/GoalID": "302881f31927c1df708a2dbab0e80ee8",
    "turtlesim/Pose": "863b248d5016ca62ea2e895ae5265cf9",
    "actionlib_tutorials/FibonacciAction": "f59df5767bf7634684781c92598b2406",
}
KNOWN_SRV_MD5 = {
    "turtlesim/Spawn": "0b2d2e872a8e2887d5ed626f2bf2c561",
    "rospy_tutorials/AddTwoInts": "6a2e34150c00229791cc89ff309fff21",
    "std_srvs/Trigger": "937c9679a518e3a18d831e57125ea522",
}


@pytest.mark.parametrize("type_name", sorted(KNOWN_MD5))
def test_message_md5_matches_published(type_name: str) -> None:
    assert loader.get_message_class(type_name)._md5sum == KNOWN_MD5[type_name]


@pytest.mark.parametrize("type_name", sorted(KNOWN_SRV_MD5))
def test_service_md5_matches_published(type_name: str) -> None:
    assert loader.get_service_class(type_name)._md5sum == KNOWN_SRV_MD5[type_name]


def test_md5_text_replaces_nested_types_by_their_md5() -> None:
    spec = loader.get_message_spec("geometry_msgs/PoseStamped")
    text = compute_md5_text(spec, loader.get_message_spec)
    header_md5 = KNOWN_MD5["std_msgs/Header"]
    pose_md5 = loader.get_message_class("geometry_msgs/Pose")._md5sum
    assert text == f"{header_md5} header\n{pose_md5} pose"
    assert hashlib.md5(text.encode()).hexdigest() == KNOWN_MD5["geometry_msgs/PoseStamped"]


def test_md5_text_keeps_constants_first_and_array_suffixes(fixture_path) -> None:
    spec = loader.get_message_spec("h1_test_msgs/AllTypes")
    lines = compute_md5_text(spec, loader.get_message_spec).split("\n")
    assert lines[:5] == [
        "int8 CONST_I8=-5",
        "uint32 CONST_U32=42",
        "float64 CONST_F=1.5",
        "bool CONST_B=True",
        "string CONST_S=hello # not a comment = still text",
    ]
    assert "byte[] by_v" in lines and "char[3] ch_f" in lines
    inner_md5 = loader.get_message_class("h1_test_msgs/Inner")._md5sum
    assert f"{inner_md5} inner_v" in lines  # array suffix dropped for nested types


def test_full_text_layout_depth_first_first_appearance() -> None:
    text = loader.get_message_class("geometry_msgs/PoseStamped")._full_text
    blocks = text.split(SEPARATOR + "\n")
    assert blocks[0] == "Header header\nPose pose\n\n"
    assert [b.split("\n", 1)[0] for b in blocks[1:]] == [
        "MSG: std_msgs/Header",
        "MSG: geometry_msgs/Pose",
        "MSG: geometry_msgs/Point",
        "MSG: geometry_msgs/Quaternion",
    ]
    assert not text.endswith("\n\n")


def test_split_full_text_recovers_every_block() -> None:
    cls = loader.get_message_class("nav_msgs/Odometry")
    blocks = split_full_text(cls._type, cls._full_text)
    assert set(blocks) >= {"nav_msgs/Odometry", "std_msgs/Header", "geometry_msgs/PoseWithCovariance"}


def test_class_from_definition_reuses_the_known_class_when_md5_matches() -> None:
    cls = loader.get_message_class("sensor_msgs/Imu")
    built = loader.message_class_from_definition("sensor_msgs/Imu", cls._full_text, cls._md5sum)
    assert built is cls


def test_class_from_definition_of_an_unknown_type_decodes_its_bytes() -> None:
    full_text = (
        "uint8 MODE_X=3\nHeader header\nfloat32[] values\nother_pkg/Part[] parts\n"
        f"{SEPARATOR}\nMSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n"
        f"{SEPARATOR}\nMSG: other_pkg/Part\nstring name\n"
    )
    cls = loader.message_class_from_definition("unknown_pkg/Thing", full_text)
    assert cls.MODE_X == 3 and cls._has_header
    part = loader.message_class_from_definition("unknown_pkg/Thing", full_text)
    assert part is cls  # cached
    msg = cls(values=[0.5], parts=[])
    msg.header.frame_id = "x"
    again = cls.deserialize_from(msg.serialize_to_bytes())
    assert again.header.frame_id == "x" and list(again.values) == [0.5]
    md5 = cls._md5sum
    assert loader.message_class_from_definition("unknown_pkg/Thing", full_text, md5) is not None


def test_class_from_definition_rejects_a_wrong_md5() -> None:
    with pytest.raises(DefinitionError, match="announced"):
        loader.message_class_from_definition("unknown_pkg/Other", "int32 x\n", "0" * 32)


def test_class_from_definition_with_missing_embedded_type_is_an_error() -> None:
    with pytest.raises(Exception, match="nowhere_pkg"):
        loader.message_class_from_definition("unknown_pkg/Broken", "nowhere_pkg/Missing m\n")


@pytest.mark.ros1
def test_action_expansion_matches_debian_move_base_msgs(tmp_path, monkeypatch) -> None:
    """Debian ships move_base_msgs built by actionlib's genaction: our expansion gives the same md5s."""
    import json
    import subprocess

    from ninjemys.idl import search
    from ninjemys.testing import ROS1_PYTHON, have_ros1

    if not have_ros1():
        pytest.skip("needs Debian's ROS 1")
    pkg = tmp_path / "move_base_msgs"
    (pkg / "action").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>move_base_msgs</name></package>")
    (pkg / "action" / "MoveBase.action").write_text(
        "geometry_msgs/PoseStamped target_pose\n---\n---\ngeometry_msgs/PoseStamped base_position\n"
    )
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    search.clear_cache()
    suffixes = ["Action", "ActionGoal", "ActionResult", "ActionFeedback", "Goal", "Result", "Feedback"]
    script = (
        "import json, move_base_msgs.msg as m\n"
        f"print(json.dumps({{s: getattr(m, 'MoveBase' + s)._md5sum for s in {suffixes!r}}}))\n"
    )
    done = subprocess.run(
        [ROS1_PYTHON, "-c", script], capture_output=True, text=True, env={"PATH": "/usr/bin"}, timeout=60
    )
    if done.returncode != 0:
        pytest.skip(f"Debian's move_base_msgs is not importable: {done.stderr[-200:]}")
    theirs = json.loads(done.stdout)
    ours = {s: loader.get_message_class(f"move_base_msgs/MoveBase{s}")._md5sum for s in suffixes}
    assert ours == theirs
    search.clear_cache()


def test_recursive_definitions_are_rejected() -> None:
    full_text = f"Node[] children\n{SEPARATOR}\nMSG: tree_pkg/Node\nNode[] children\n"
    with pytest.raises(DefinitionError, match="recursive message type: tree_pkg/Node -> tree_pkg/Node"):
        loader.message_class_from_definition("tree_pkg/Node", full_text)
