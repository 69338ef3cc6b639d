"""The ROS 1 module names over ninjemys.tf2: tf2_py, tf2_ros, tf2_geometry_msgs and tf's legacy API."""

from __future__ import annotations

import math
import time

import pytest

import tf
import tf2_geometry_msgs  # noqa: F401  (registers the conversions)
import tf2_py
import tf2_ros
from geometry_msgs.msg import (
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
    QuaternionStamped,
    TransformStamped,
    Vector3Stamped,
    WrenchStamped,
)
from ninjemys.rostime import Duration, Time


def ts(parent, child, secs, x=0.0, y=0.0, z=0.0, yaw=0.0):
    m = TransformStamped()
    m.header.frame_id, m.child_frame_id, m.header.stamp = parent, child, Time(secs)
    m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = x, y, z
    m.transform.rotation.z, m.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return m


@pytest.fixture
def buffer():
    b = tf2_ros.Buffer(debug=False)
    b.set_transform(ts("map", "base", 10, x=1.0, yaw=math.pi / 2), "test")
    b.set_transform(ts("map", "base", 11, x=2.0, yaw=math.pi / 2), "test")
    b.set_transform_static(ts("base", "laser", 0, x=0.5), "test")
    return b


def test_exception_hierarchy_and_names():
    for cls in (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException):
        assert issubclass(cls, tf2_ros.TransformException) and cls is getattr(tf2_py, cls.__name__)
    assert issubclass(tf2_ros.InvalidArgumentException, tf2_ros.TransformException)
    assert issubclass(tf2_ros.TimeoutException, tf2_ros.TransformException)
    assert tf.Exception is tf2_ros.TransformException and tf.LookupException is tf2_ros.LookupException


def test_buffer_lookup_messages(buffer):
    m = buffer.lookup_transform("map", "laser", Time(0))
    assert isinstance(m, TransformStamped)
    assert (m.header.frame_id, m.child_frame_id, m.header.stamp) == ("map", "laser", Time(11))
    assert m.transform.translation.x == pytest.approx(2.0) and m.transform.translation.y == pytest.approx(0.5)
    m = buffer.lookup_transform("map", "laser", Time(10, 500_000_000), Duration(0.1))
    assert m.transform.translation.x == pytest.approx(1.5)
    m = buffer.lookup_transform_full("laser", Time(10), "laser", Time(11), "map")
    assert m.transform.translation.y == pytest.approx(-1.0)  # the base moved 1 m along map x = laser -y
    assert buffer.get_latest_common_time("map", "laser") == Time(11)
    assert buffer._chain("map", Time(0), "laser", Time(0), "map") == ["laser", "base", "map"]
    assert buffer._getFrameStrings() == ["base", "map", "laser"] and buffer._frameExists("map")
    assert buffer._allFramesAsDot(Time(12)).startswith("digraph G {")
    assert str(buffer.lookup_transform_core("map", "base", Time(0)).header.stamp) == "11000000000"


def test_can_transform_timeout_and_debug_tuple(buffer):
    start = time.monotonic()
    assert buffer.can_transform("map", "nowhere", Time(0), Duration(0.2)) is False
    assert time.monotonic() - start >= 0.19
    ok, why = buffer.can_transform("map", "laser", Time(30), return_debug_tuple=True)
    assert not ok and "19.000000000s into the future" in why
    with pytest.raises(tf2_ros.ExtrapolationException):
        buffer.lookup_transform("map", "laser", Time(30), Duration(0.05))
    assert buffer.can_transform_full("laser", Time(10), "laser", Time(11), "map")


def test_lookup_with_timeout_answers_at_once_or_waits_for_the_data(buffer):
    """Available data is returned without waiting; missing data is waited for (another thread
    sends it) up to the timeout, then tf2's exception for the lookup is raised."""
    start = time.monotonic()
    assert buffer.lookup_transform("map", "laser", Time(0), Duration(5.0)).header.stamp == Time(11)
    assert time.monotonic() - start < 1.0
    import threading

    sender = threading.Timer(0.2, lambda: buffer.set_transform(ts("base", "arm", 11, x=3.0), "test"))
    sender.start()
    m = buffer.lookup_transform("map", "arm", Time(0), Duration(5.0))
    sender.join()
    assert m.transform.translation.y == pytest.approx(3.0) and time.monotonic() - start >= 0.19
    start = time.monotonic()
    with pytest.raises(tf2_ros.LookupException, match="nowhere"):
        buffer.lookup_transform("map", "nowhere", Time(0), Duration(0.2))
    assert time.monotonic() - start >= 0.19


def test_transform_registered_types(buffer):
    p = PointStamped()
    p.header.frame_id, p.header.stamp = "laser", Time(11)
    p.point.x = 1.0
    out = buffer.transform(p, "map")
    assert out.header.frame_id == "map" and out.header.stamp == Time(11)
    assert (out.point.x, out.point.y) == pytest.approx((2.0, 1.5))
    v = Vector3Stamped()
    v.header.frame_id, v.header.stamp = "laser", Time(11)
    v.vector.x = 1.0
    assert (buffer.transform(v, "map").vector.x, buffer.transform(v, "map").vector.y) == pytest.approx(
        (0.0, 1.0)
    )
    ps = PoseStamped()
    ps.header.frame_id, ps.header.stamp = "laser", Time(11)
    ps.pose.orientation.w = 1.0
    out = buffer.transform(ps, "map")
    assert out.pose.position.y == pytest.approx(0.5)
    assert (out.pose.orientation.z, out.pose.orientation.w) == pytest.approx((math.sin(math.pi / 4),) * 2)
    w = WrenchStamped()
    w.header.frame_id, w.header.stamp = "laser", Time(11)
    w.wrench.force.x = 2.0
    assert buffer.transform(w, "map").wrench.force.y == pytest.approx(2.0)
    c = PoseWithCovarianceStamped()
    c.header.frame_id, c.header.stamp = "laser", Time(11)
    c.pose.pose.orientation.w = 1.0
    c.pose.covariance = [1.0 if i == 0 else 0.0 for i in range(36)]
    out = buffer.transform(c, "map")
    assert out.pose.covariance[7] == pytest.approx(1.0) and out.pose.covariance[0] == pytest.approx(0.0)
    assert tf2_geometry_msgs.do_transform_pose(
        ps.pose, buffer.lookup_transform("map", "laser", Time(11))
    ).position.y
    with pytest.raises(tf2_ros.TypeException):
        buffer.transform(QuaternionStamped(), "map")
    assert tf2_ros.convert(p, PointStamped) == p


def test_tf2_py_buffer_core():
    core = tf2_py.BufferCore(Duration(5))
    core.set_transform(ts("a", "b", 1, x=1.0), "me")
    assert core.lookup_transform_core("a", "b", Time(0)).transform.translation.x == 1.0
    assert core.can_transform_core("a", "c", Time(0)) == (
        False,
        "canTransform: source_frame c does not exist.",
    )
    assert core.all_frames_as_yaml().startswith("b: \n  parent: 'a'\n  broadcaster: 'me'")


def test_legacy_transformer(buffer):
    t = tf.TransformerROS()
    for m in (ts("map", "base", 10, x=1.0, yaw=math.pi / 2), ts("base", "laser", 10, x=0.5)):
        t.setTransform(m, "me")
    trans, rot = t.lookupTransform("/map", "laser", Time(0))
    assert trans == pytest.approx([1.0, 0.5, 0.0]) and rot == pytest.approx(
        [0, 0, math.sin(math.pi / 4)] + [math.cos(math.pi / 4)]
    )
    assert t.frameExists("laser") and not t.frameExists("nope")
    assert sorted(t.getFrameStrings()) == ["base", "laser"]
    assert t.getLatestCommonTime("map", "laser") == Time(10)
    assert t.canTransform("map", "laser", Time(0)) and t.getTFPrefix() == ""
    assert "Frame laser exists with parent base." in t.allFramesAsString()
    p = PointStamped()
    p.header.frame_id, p.header.stamp = "laser", Time(10)
    p.point.x = 1.0
    assert (t.transformPoint("map", p).point.x, t.transformPoint("map", p).point.y) == pytest.approx(
        (1.0, 1.5)
    )
    ps = PoseStamped()
    ps.header.frame_id, ps.header.stamp = "laser", Time(10)
    ps.pose.orientation.w = 1.0
    assert t.transformPose("map", ps).pose.position.y == pytest.approx(0.5)
    m = t.asMatrix("map", p.header)
    assert m[:3, 3] == pytest.approx([1.0, 0.5, 0.0])
    with pytest.raises(tf2_ros.TransformException, match="dedicated thread"):
        t.waitForTransform("map", "laser", Time(0), Duration(0.1))
    tr, rt = t.lookupTransformFull("laser", Time(10), "laser", Time(10), "map")
    assert tr == pytest.approx([0, 0, 0], abs=1e-12)
