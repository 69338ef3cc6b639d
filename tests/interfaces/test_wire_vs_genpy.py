"""Wire bytes, property-based: for random instances of every shipped type, ours == genpy's, both ways.

For each type, hypothesis draws batches of random value trees; the genpy oracle (one long-lived
/usr/bin/python3 process) serializes each batch in one round trip. Our ``serialize_to_bytes()`` and classic
``serialize(buff)`` must give the same bytes, and our ``deserialize_from`` of genpy's bytes must give back
the drawn values; ``str(msg)`` must be genpy's YAML (what rostopic echo prints). Types Debian lacks are built in the oracle by genpy.dynamic from our full text.
"""

from __future__ import annotations

import base64
import io

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from iface_inventory import inventory
from iface_oracle import GenpyOracle
from iface_values import build_ours, tree_of_ours, tree_strategy

from ninjemys.idl.loader import get_message_class

pytestmark = pytest.mark.ros1

INV = inventory()

WIRE_SETTINGS = settings(
    max_examples=3,
    deadline=None,
    database=None,
    derandomize=False,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)


@pytest.mark.parametrize("type_name", INV.all_message_like)
def test_wire_bytes_equal_genpy(type_name: str, genpy_oracle: GenpyOracle) -> None:
    cls = get_message_class(type_name)
    genpy_oracle.define(type_name, cls._full_text)

    @WIRE_SETTINGS
    @given(st.lists(tree_strategy(type_name), min_size=2, max_size=5))
    def check(trees: list[dict]) -> None:
        expected = genpy_oracle.serialize(type_name, trees)
        expected_text = genpy_oracle.call("strify", type=type_name, values=trees)
        for tree, theirs, text in zip(trees, expected, expected_text, strict=True):
            msg = build_ours(type_name, tree)
            assert msg.serialize_to_bytes() == theirs, f"{type_name}: serialize_to_bytes differs from genpy"
            buff = io.BytesIO()
            msg.serialize(buff)
            assert buff.getvalue() == theirs, f"{type_name}: serialize(buff) differs from genpy"
            back = cls.deserialize_from(theirs)
            assert tree_of_ours(back) == tree, f"{type_name}: deserialize_from(genpy bytes) lost values"
            assert cls().deserialize(theirs) == back
            assert back == msg
            assert str(msg) == text, f"{type_name}: str() differs from genpy's (the rostopic echo YAML)"

    check()


@pytest.mark.parametrize(
    "type_name", ["sensor_msgs/Image", "sensor_msgs/PointCloud2", "sensor_msgs/LaserScan", "nav_msgs/Path"]
)
def test_genpy_reads_our_bytes_of_large_messages(type_name: str, genpy_oracle: GenpyOracle) -> None:
    """The benchmark types at realistic sizes: genpy decodes our bytes to the values we put in."""
    cls = get_message_class(type_name)
    genpy_oracle.define(type_name, cls._full_text)
    msg = cls()
    if type_name == "sensor_msgs/Image":
        msg.height, msg.width, msg.encoding, msg.step = 48, 64, "rgb8", 192
        msg.data = bytes(range(256)) * (48 * 192 // 256)
    elif type_name == "sensor_msgs/PointCloud2":
        msg.height, msg.width, msg.point_step, msg.row_step = 1, 4096, 16, 65536
        msg.data = bytes(i % 251 for i in range(65536))
    elif type_name == "sensor_msgs/LaserScan":
        msg.angle_min, msg.angle_max, msg.range_max = -1.5, 1.5, 30.0
        msg.ranges = [float(i) / 4 for i in range(720)]
    else:
        pose_cls = get_message_class("geometry_msgs/PoseStamped")
        poses = []
        for i in range(1000):
            pose = pose_cls()
            pose.pose.position.x = float(i)
            pose.pose.orientation.w = 1.0
            poses.append(pose)
        msg.poses = poses
    ours = msg.serialize_to_bytes()
    (theirs_tree,) = genpy_oracle.deserialize(type_name, [ours])
    assert theirs_tree == tree_of_ours(msg)
    assert genpy_oracle.serialize(type_name, [theirs_tree]) == [ours]


def test_default_instances_equal_genpy(genpy_oracle: GenpyOracle) -> None:
    """ROS defaults (zeros, empty strings, zero-filled fixed arrays, nested defaults), for every type at once."""
    for type_name in INV.all_message_like:
        genpy_oracle.define(type_name, get_message_class(type_name)._full_text)
    expected = genpy_oracle.call("defaults", types=list(INV.all_message_like))
    for type_name in INV.all_message_like:
        msg = get_message_class(type_name)()
        assert msg.serialize_to_bytes() == base64.b64decode(expected[type_name]["data"]), type_name
        assert str(msg) == expected[type_name]["text"], type_name


@pytest.mark.parametrize("type_name", INV.all_message_like)
def test_positional_constructor_equals_keywords(type_name: str) -> None:
    """genpy accepts every field positionally, in slot order; user code relies on it (Point(1, 2, 3))."""
    cls = get_message_class(type_name)

    @settings(WIRE_SETTINGS, max_examples=2)
    @given(tree_strategy(type_name))
    def check(tree: dict) -> None:
        by_keyword = build_ours(type_name, tree)
        by_position = cls(*[getattr(by_keyword, name) for name in cls.__slots__])
        assert by_position == by_keyword
        assert by_position.serialize_to_bytes() == by_keyword.serialize_to_bytes()

    check()
