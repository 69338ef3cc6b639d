"""message_filters.Subscriber over real topics: the core on a Node, and the rospy facade."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

from ninjemys.idl.loader import get_message_class
from ninjemys.master.core import MasterThread
from ninjemys.message_filters import ApproximateTimeSynchronizer, SimpleFilter, Subscriber, _pass_on
from ninjemys.node import Node
from ninjemys.rostime import Time

PointStamped = get_message_class("geometry_msgs/PointStamped")


def stamped(secs: float) -> object:
    msg = PointStamped()
    msg.header.stamp = Time.from_sec(secs)
    return msg


def test_core_subscribers_feed_a_synchronizer() -> None:
    with MasterThread() as uri:
        node = Node("mf_node", master_uri=uri)
        try:
            pubs = [node.publisher(f"/s{i}", PointStamped, queue_size=10) for i in range(2)]
            subs = [Subscriber(node, f"/s{i}", PointStamped) for i in range(2)]
            assert subs[0].getTopic() == "/s0"
            # one thread reads and calls back for all of a node's message_filters Subscribers
            assert subs[1].sub._thread is subs[0].sub._thread
            sync = ApproximateTimeSynchronizer(subs, 10, 0.05)
            got: list = []
            done = threading.Event()

            def on_pair(a, b):
                got.append((a.header.stamp.to_sec(), b.header.stamp.to_sec()))
                if len(got) == 3:
                    done.set()

            sync.registerCallback(on_pair)
            deadline = time.monotonic() + 10
            while any(s.get_num_connections() == 0 for s in subs) and time.monotonic() < deadline:
                time.sleep(0.01)
            for k in range(3):
                pubs[0].publish(stamped(10.0 + k))
                pubs[1].publish(stamped(10.01 + k))
            assert done.wait(10)
            assert [round(a) for a, _b in got] == [10, 11, 12]
            for s in subs:
                s.unregister()
        finally:
            node.shutdown("test over")


FACADE = """
import rospy, message_filters
from geometry_msgs.msg import PointStamped
rospy.init_node("mf_facade")
pubs = [rospy.Publisher("/f%d" % i, PointStamped, queue_size=10) for i in range(3)]
subs = [message_filters.Subscriber("/f%d" % i, PointStamped) for i in range(3)]
ts = message_filters.TimeSynchronizer(subs, 10)
got = []
ts.registerCallback(lambda a, b, c: got.append(a.header.stamp.secs))
while any(s.get_num_connections() == 0 for s in subs):
    rospy.sleep(0.01)
for k in range(3):
    for p in pubs:
        m = PointStamped(); m.header.stamp = rospy.Time(5 + k); p.publish(m)
deadline = rospy.get_time() + 10
while len(got) < 3 and rospy.get_time() < deadline:
    rospy.sleep(0.01)
print(got, subs[1].getTopic(), len({s.sub._impl._thread for s in subs}))
"""


def test_rospy_facade_subscriber(tmp_path) -> None:
    with MasterThread() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        out = subprocess.run(
            [sys.executable, "-c", FACADE], env=env, capture_output=True, text=True, timeout=60
        )
        assert out.stdout.strip() == "[5, 6, 7] /f1 1", out.stderr


def test_tf2_message_filter_on_a_live_graph() -> None:
    """Scans wait in the filter until the listener's /tf data covers their stamps, then come out in order."""
    from ninjemys.message_filters.tf2 import MessageFilter
    from ninjemys.tf2.buffer import Buffer
    from ninjemys.tf2.node import TransformBroadcaster, TransformListener

    TransformStamped = get_message_class("geometry_msgs/TransformStamped")
    with MasterThread() as uri:
        node = Node("mf_tf", master_uri=uri)
        try:
            buffer = Buffer()
            listener = TransformListener(node, buffer)
            assert listener.tf_static_sub._thread is listener.tf_sub._thread  # one thread reads both
            broadcaster = TransformBroadcaster(node)
            points = node.publisher("/points", PointStamped, queue_size=10)
            source = Subscriber(node, "/points", PointStamped)
            mf = MessageFilter(source, buffer, "map", queue_size=10)
            out: list = []
            done = threading.Event()

            def on_point(msg):
                out.append(msg.header.stamp.to_sec())
                if len(out) == 2:
                    done.set()

            mf.registerCallback(on_point)
            deadline = time.monotonic() + 10
            while (
                source.get_num_connections() == 0 or broadcaster.pub_tf.get_num_connections() == 0
            ) and time.monotonic() < deadline:
                time.sleep(0.01)
            for secs in (20.2, 20.7):
                msg = stamped(secs)
                msg.header.frame_id = "laser"
                points.publish(msg)
            while mf.pending() < 2 and time.monotonic() < deadline:
                time.sleep(0.01)
            assert out == [] and mf.pending() == 2
            for secs in (20.0, 21.0):
                t = TransformStamped()
                t.header.frame_id, t.child_frame_id = "map", "laser"
                t.header.stamp = Time.from_sec(secs)
                t.transform.rotation.w = 1.0
                broadcaster.sendTransform(t)
            assert done.wait(10)
            assert [round(s, 3) for s in out] == [20.2, 20.7]
            listener.unregister()
        finally:
            node.shutdown("test over")


def test_a_source_passes_each_message_to_every_filter_even_one_added_meanwhile() -> None:
    """A Subscriber's messages go straight to its one filter, or to all of them; a filter connected
    from inside that call gets the next message."""
    src = SimpleFilter()
    got: list[tuple[str, int]] = []

    def first(m: int) -> None:
        got.append(("first", m))
        if len(src.callbacks) == 1:
            src.registerCallback(lambda m: got.append(("second", m)))

    src.registerCallback(first)
    _pass_on(src, 1)
    _pass_on(src, 2)
    assert got == [("first", 1), ("first", 2), ("second", 2)]
