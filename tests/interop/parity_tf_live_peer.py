"""tf2_ros and tf in a running node, printed as JSON (run under either interpreter, ROS_MASTER_URI
set): broadcasters feeding listeners in the same node, lookups that wait for data (and what they
raise when it never comes), tf.TransformListener's waitForTransform, and the static broadcaster."""

import json
import time

import rospy
import tf
import tf2_ros
from geometry_msgs.msg import TransformStamped

rospy.init_node("parity_tf_live_peer")


def outcome(fn, *args, **kwargs):
    try:
        return ["ok", fn(*args, **kwargs)]
    except Exception as exc:
        bases = [c.__name__ for c in type(exc).__mro__ if c.__name__ not in ("NinjemysError", "object")]
        return ["raise", bases, str(exc)]


def transform(parent, child, x, stamp):
    t = TransformStamped()
    t.header.frame_id = parent
    t.header.stamp = stamp
    t.child_frame_id = child
    t.transform.translation.x = x
    t.transform.rotation.w = 1.0
    return t


out = {"live": {}}
buffer = tf2_ros.Buffer()
listener = tf2_ros.TransformListener(buffer)
old = tf.TransformListener()
static = tf2_ros.StaticTransformBroadcaster()
dynamic = tf2_ros.TransformBroadcaster()
time.sleep(1.0)  # the broadcasters' and listeners' connections

static.sendTransform(transform("world", "map", 1.0, rospy.Time.now()))
static.sendTransform([transform("map", "dock", 2.0, rospy.Time.now())])  # a second call: both stay latched
stamp = rospy.Time.now()
for _ in range(5):
    dynamic.sendTransform(transform("map", "robot", 3.0, stamp))
    time.sleep(0.05)

ok = buffer.can_transform("world", "robot", rospy.Time(0), rospy.Duration(5.0))
out["live"]["can_wait"] = ok
out["live"]["static_both"] = [
    buffer.can_transform("world", "dock", rospy.Time(0), rospy.Duration(5.0)),
    round(buffer.lookup_transform("world", "dock", rospy.Time(0)).transform.translation.x, 9),
]
tr = buffer.lookup_transform("world", "robot", rospy.Time(0), rospy.Duration(1.0))
# ROS 1's tf2_py passes stamps through a double (about 100 ns lost at today's epoch); ours keeps
# them exact: both are within a microsecond of what was sent
out["live"]["lookup"] = [
    tr.header.frame_id,
    tr.child_frame_id,
    abs((tr.header.stamp - stamp).to_sec()) < 1e-6,
    round(tr.transform.translation.x, 9),
]
out["live"]["timeout_unknown"] = outcome(
    buffer.lookup_transform, "world", "nowhere", rospy.Time(0), rospy.Duration(0.3)
)
future = outcome(
    lambda: buffer.lookup_transform("world", "robot", stamp + rospy.Duration(2.0), rospy.Duration(0.3))
)
# the times in the text are today's (they differ between runs): compare its words
out["live"]["timeout_future"] = future[:2] + [" ".join(w for w in future[2].split() if not w[:1].isdigit())]
out["live"]["can_timeout"] = buffer.can_transform("world", "nowhere", rospy.Time(0), rospy.Duration(0.3))
out["live"]["can_timeout_debug"] = list(
    buffer.can_transform("world", "nowhere", rospy.Time(0), rospy.Duration(0.3), return_debug_tuple=True)
)
old.waitForTransform("world", "robot", rospy.Time(0), rospy.Duration(5.0))
out["live"]["old_lookup"] = [round(v, 9) for v in old.lookupTransform("world", "robot", rospy.Time(0))[0]]
out["live"]["old_wait_fail"] = outcome(
    old.waitForTransform, "world", "nowhere", rospy.Time(0), rospy.Duration(0.3)
)
out["live"]["old_common"] = abs((old.getLatestCommonTime("world", "robot") - stamp).to_sec()) < 1e-6
out["live"]["old_frames"] = sorted(old.getFrameStrings())
out["live"]["old_exists"] = [old.frameExists("robot"), old.frameExists("world")]
print(json.dumps(out))
rospy.signal_shutdown("done")
