"""tf2_ros.BufferClient against a running ``rosrun tf2_ros buffer_server``, printed as JSON (run under
either interpreter, ROS_MASTER_URI set): lookups that succeed, fail, wait for a frame broadcast later,
time out, and the advanced form."""

import json
import threading
import time

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped

rospy.init_node("parity_buffer_client_peer")


def outcome(fn, *args, **kwargs):
    try:
        return ["ok", fn(*args, **kwargs)]
    except Exception as exc:
        bases = [c.__name__ for c in type(exc).__mro__ if c.__name__ not in ("NinjemysError", "object")]
        return ["raise", bases, str(exc).split(", when looking up")[0].split(" Requested time")[0]]


def transform(parent, child, x):
    t = TransformStamped()
    t.header.frame_id = parent
    t.header.stamp = rospy.Time.now()
    t.child_frame_id = child
    t.transform.translation.x = x
    t.transform.rotation.w = 1.0
    return t


def xyz(t):
    return [t.header.frame_id, t.child_frame_id, round(t.transform.translation.x, 9)]


static = tf2_ros.StaticTransformBroadcaster()
static.sendTransform([transform("world", "base", 1.0), transform("base", "arm", 0.5)])
client = tf2_ros.BufferClient("tf2_buffer_server")
out = {"client": {"server": client.wait_for_server(rospy.Duration(10.0))}}
deadline = time.time() + 10.0
while not client.can_transform("world", "arm", rospy.Time(0)) and time.time() < deadline:
    time.sleep(0.1)
out["client"]["lookup"] = outcome(lambda: xyz(client.lookup_transform("world", "arm", rospy.Time(0))))
out["client"]["reverse"] = outcome(
    lambda: xyz(client.lookup_transform("arm", "world", rospy.Time(0), rospy.Duration(1.0)))
)
out["client"]["unknown"] = outcome(client.lookup_transform, "world", "nowhere", rospy.Time(0))
out["client"]["unknown_timeout"] = outcome(
    client.lookup_transform, "world", "nowhere", rospy.Time(0), rospy.Duration(0.5)
)
out["client"]["can"] = [
    client.can_transform("world", "arm", rospy.Time(0)),
    client.can_transform("world", "x", rospy.Time(0)),
]
out["client"]["full"] = outcome(
    lambda: xyz(
        client.lookup_transform_full(
            "arm", rospy.Time(0), "base", rospy.Time(0), "world", rospy.Duration(1.0)
        )
    )
)
late = tf2_ros.StaticTransformBroadcaster()
threading.Timer(0.5, lambda: late.sendTransform(transform("world", "late", 3.0))).start()
out["client"]["waits"] = outcome(
    lambda: xyz(client.lookup_transform("world", "late", rospy.Time(0), rospy.Duration(5.0)))
)
print(json.dumps(out))
rospy.signal_shutdown("done")
