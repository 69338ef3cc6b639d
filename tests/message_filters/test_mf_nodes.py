"""message_filters.Subscriber over real topics: the core on a Node, and the rospy facade."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

from ninjemys.idl.loader import get_message_class
from ninjemys.master.core import MasterThread
from ninjemys.message_filters import ApproximateTimeSynchronizer, Subscriber
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
print(got, subs[1].getTopic())
"""


def test_rospy_facade_subscriber(tmp_path) -> None:
    with MasterThread() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        out = subprocess.run(
            [sys.executable, "-c", FACADE], env=env, capture_output=True, text=True, timeout=60
        )
        assert out.stdout.strip() == "[5, 6, 7] /f1", out.stderr
