"""A tf peer for the interop tests, runnable under Debian's ROS 1 (/usr/bin/python3) and under ninjemys
(the venv): both offer the same rospy/tf2_ros/tf API, so one script plays either side.

    tf_peer.py broadcast [--accumulate] [--bad]   # /tf chain w->a->b->c at 20 Hz, statics c->d and a->e
    tf_peer.py listen [--tf]                      # print the lookups as one JSON line, then exit
"""

import json
import math
import random
import sys

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped

LINKS = [("w", "a"), ("a", "b"), ("b", "c")]
STATIC = [("c", "d"), ("a", "e")]
PAIRS = [("w", "d"), ("d", "w"), ("e", "d"), ("b", "e"), ("w", "c"), ("c", "a")]


def values(link):
    """Fixed, frame-dependent transforms with full-precision floats (a seed per link)."""
    rnd = random.Random("-".join(link))
    q = [rnd.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(v * v for v in q))
    return [rnd.uniform(-3, 3) for _ in range(3)] + [v / n for v in q]


def message(link, stamp, vals=None):
    m = TransformStamped()
    m.header.frame_id, m.child_frame_id = link
    m.header.stamp = stamp
    v = values(link) if vals is None else vals
    t, r = m.transform.translation, m.transform.rotation
    t.x, t.y, t.z, r.x, r.y, r.z, r.w = v
    return m


def broadcast(accumulate, bad):
    rospy.init_node("tf_peer_broadcaster")
    br = tf2_ros.TransformBroadcaster()
    sb = tf2_ros.StaticTransformBroadcaster()
    if accumulate:  # ROS 1's C++ broadcaster (and ours) keep both; the Python one of Noetic forgets
        for link in STATIC:
            sb.sendTransform(message(link, rospy.Time(0)))
    else:
        sb.sendTransform([message(link, rospy.Time(0)) for link in STATIC])
    print("ready", flush=True)
    while not rospy.is_shutdown():
        now = rospy.Time.now()
        batch = [message(link, now) for link in LINKS]
        if bad:
            batch.append(message(("w", "w"), now))
            batch.append(message(("w", "n"), now, [float("nan"), 0, 0, 0, 0, 0, 1]))
            batch.append(message(("w", "q"), now, [0, 0, 0, 0, 0, 0, 2]))
        br.sendTransform(batch)
        rospy.sleep(0.05)


def listen(legacy):
    rospy.init_node("tf_peer_listener")
    out = {}
    if legacy:
        import tf

        listener = tf.TransformListener()
        for target, source in PAIRS:
            listener.waitForTransform(target, source, rospy.Time(0), rospy.Duration(20.0))
            trans, rot = listener.lookupTransform(target, source, rospy.Time(0))
            out[target + "<-" + source] = list(trans) + list(rot)
    else:
        buf = tf2_ros.Buffer()
        tf2_ros.TransformListener(buf)
        for target, source in PAIRS:
            m = buf.lookup_transform(target, source, rospy.Time(0), rospy.Duration(20.0))
            t, r = m.transform.translation, m.transform.rotation
            out[target + "<-" + source] = [t.x, t.y, t.z, r.x, r.y, r.z, r.w]
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    if sys.argv[1] == "broadcast":
        broadcast("--accumulate" in sys.argv, "--bad" in sys.argv)
    else:
        listen("--tf" in sys.argv)
