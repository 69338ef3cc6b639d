"""tf2 MessageFilter on ninjemys' tf2 buffer: held until transformable, drops with reasons."""

from __future__ import annotations

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.message_filters import SimpleFilter
from ninjemys.message_filters.tf2 import FilterFailureReason, MessageFilter
from ninjemys.rostime import Time
from ninjemys.tf2.buffer import Buffer

PointStamped = get_message_class("geometry_msgs/PointStamped")
TransformStamped = get_message_class("geometry_msgs/TransformStamped")


def tf(parent: str, child: str, secs: float) -> object:
    t = TransformStamped()
    t.header.frame_id = parent
    t.header.stamp = Time.from_sec(secs)
    t.child_frame_id = child
    t.transform.translation.x = 1.0
    t.transform.rotation.w = 1.0
    return t


def point(frame: str, secs: float) -> object:
    p = PointStamped()
    p.header.frame_id = frame
    p.header.stamp = Time.from_sec(secs)
    return p


@pytest.fixture
def setup():
    src = SimpleFilter()
    buffer = Buffer()
    mf = MessageFilter(src, buffer, "map", queue_size=3)
    passed: list = []
    failed: list = []
    mf.registerCallback(passed.append)
    mf.registerFailureCallback(lambda m, why: failed.append((m, why)))
    return src, buffer, mf, passed, failed


def test_held_until_transform_arrives(setup) -> None:
    src, buffer, mf, passed, failed = setup
    early = point("laser", 100.5)
    src.signalMessage(early)
    assert passed == [] and mf.pending() == 1
    buffer.set_transform(tf("map", "laser", 100.0), "test")
    assert passed == [] and mf.pending() == 1  # 100.5 is still in the future of the data
    buffer.set_transform(tf("map", "laser", 101.0), "test")
    assert passed == [early] and mf.pending() == 0 and failed == []
    now = point("/laser", 100.7)  # a leading slash is ignored, as tf2
    src.signalMessage(now)
    assert passed == [early, now]


def test_drops_with_reasons(setup) -> None:
    src, buffer, mf, passed, failed = setup
    src.signalMessage(point("", 1.0))
    assert failed[-1][1] is FilterFailureReason.EmptyFrameID
    waiting = [point("camera", 200.0 + i) for i in range(4)]
    for msg in waiting:
        src.signalMessage(msg)
    assert failed[-1] == (waiting[0], FilterFailureReason.Unknown) and mf.pending() == 3
    buffer.set_transform(tf("map", "base", 300.0), "test")
    buffer.set_transform(tf("map", "base", 301.0), "test")
    src.signalMessage(point("base", 250.0))
    assert failed[-1][1] is FilterFailureReason.OutTheBack
    mf.clear()
    assert mf.pending() == 0 and passed == []


def test_tolerance_and_multiple_targets() -> None:
    src, buffer = SimpleFilter(), Buffer()
    mf = MessageFilter(src, buffer, ["map", "odom"], queue_size=10)
    mf.setTolerance(0.5)
    passed: list = []
    mf.registerCallback(passed.append)
    buffer.set_transform(tf("map", "odom", 10.0), "test")
    buffer.set_transform(tf("map", "odom", 12.0), "test")
    buffer.set_transform(tf("odom", "laser", 10.0), "test")
    buffer.set_transform(tf("odom", "laser", 11.2), "test")
    msg = point("laser", 11.0)
    src.signalMessage(msg)
    assert passed == []  # 11.5 is not covered yet
    buffer.set_transform(tf("odom", "laser", 11.6), "test")
    assert passed == [msg]
    assert mf.getTargetFramesString() == "map odom "


def test_facade_with_tf2_ros_buffer() -> None:
    import tf2_ros
    from message_filters.tf2 import MessageFilter as Facade

    src = SimpleFilter()
    buffer = tf2_ros.Buffer()
    mf = Facade(src, buffer, "map", 5)
    out: list = []
    mf.registerCallback(out.append)
    msg = point("laser", 5.0)
    src.signalMessage(msg)
    buffer.set_transform(tf("map", "laser", 4.0), "test")
    buffer.set_transform(tf("map", "laser", 6.0), "test")
    assert out == [msg]
