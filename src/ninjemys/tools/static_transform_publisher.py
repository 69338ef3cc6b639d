"""``static_transform_publisher``, both of ROS 1's:

- ``rosrun tf2_ros static_transform_publisher x y z yaw pitch roll frame_id child_frame_id`` (or
  ``x y z qx qy qz qw frame_id child_frame_id``, or ``/param_name``) latches the transform once on
  ``/tf_static`` and spins;
- ``rosrun tf static_transform_publisher ... period_in_ms`` (tf's legacy one) re-sends it on ``/tf``
  every period, stamped one period into the future.

Arguments, usage text and errors are ROS 1's. One difference: a quaternion that is not of unit length
is normalized with a warning (ROS 1 sends it as is and every tf2 listener then drops it).
"""

from __future__ import annotations

import math
import sys
from typing import Any

from ninjemys.tf2.math import quaternion_from_rpy
from ninjemys.tools.cli import entry, wait_for_master_like_roscpp
from ninjemys.tools.tf_echo import atof

TF2_USAGE = (
    "A command line utility for manually sending a transform.\n"
    "Usage: static_transform_publisher x y z qx qy qz qw frame_id child_frame_id \n"
    "OR \n"
    "Usage: static_transform_publisher x y z yaw pitch roll frame_id child_frame_id \n"
    "OR \n"
    "Usage: static_transform_publisher /param_name \n"
    "\nThis transform is the transform of the coordinate frame from frame_id into the coordinate frame \n"
    "of the child_frame_id.  \n"
)

TF_USAGE = (
    "A command line utility for manually sending a transform.\n"
    "It will periodicaly republish the given transform. \n"
    "Usage: static_transform_publisher x y z yaw pitch roll frame_id child_frame_id  period(milliseconds) \n"
    "OR \n"
    "Usage: static_transform_publisher x y z qx qy qz qw frame_id child_frame_id  period(milliseconds) \n"
    "\nThis transform is the transform of the coordinate frame from frame_id into the coordinate frame \n"
    "of the child_frame_id.  \n"
)


def parse_numbers(nums: list[str]) -> tuple[float, ...] | None:
    """The 7 floats of a 6-number (x y z yaw pitch roll) or 7-number (x y z qx qy qz qw) form."""
    v = [atof(a) for a in nums]
    if len(v) == 6:
        return (v[0], v[1], v[2], *quaternion_from_rpy(v[5], v[4], v[3]))
    if len(v) == 7:
        return tuple(v)
    return None


def _normalized(t: tuple[float, ...], log: Any) -> tuple[float, ...] | None:
    qx, qy, qz, qw = t[3:]
    n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    if not n or not math.isfinite(n):
        log(f"the quaternion ({qx:g} {qy:g} {qz:g} {qw:g}) has no direction: cannot make a rotation of it")
        return None
    if abs(n * n - 1.0) >= 10e-6:
        log(f"the quaternion ({qx:g} {qy:g} {qz:g} {qw:g}) has norm {n:g}; sending it normalized", warn=True)
        return (*t[:3], qx / n, qy / n, qz / n, qw / n)
    return t


def _from_param(rospy: Any, name: str) -> tuple[str, str, tuple[float, ...]] | None:
    rospy.loginfo(f"Looking for TF in parameter: {name}")
    if not rospy.has_param(name):
        rospy.logfatal(f"Could not read TF from parameter server: {name}")
        return None
    data = rospy.get_param(name)
    try:
        tr = data["transform"]["translation"]
        rot = data["transform"]["rotation"]
        values = tuple(float(v) for v in (tr["x"], tr["y"], tr["z"], rot["x"], rot["y"], rot["z"], rot["w"]))
        return str(data["header"]["frame_id"]), str(data["child_frame_id"]), values
    except (KeyError, TypeError, ValueError):
        rospy.logfatal(f"Could not validate XmlRpcC for TF data: {data}")
        return None


def _report(rospy: Any) -> Any:
    def log(line: str, warn: bool = False) -> None:
        (rospy.logwarn if warn else rospy.logfatal)(line)

    return log


def main(argv: list[str] | None = None) -> int:
    """tf2_ros's static_transform_publisher."""
    import rospy
    import tf2_ros
    from geometry_msgs.msg import TransformStamped

    full = ["static_transform_publisher", *(sys.argv[1:] if argv is None else argv)]
    args = rospy.myargv(full)[1:]
    if len(args) not in (1, 8, 9):
        sys.stdout.write(TF2_USAGE)
        sys.stdout.flush()
        sys.stderr.write(
            "[ERROR] static_transform_publisher exited due to not having the right number of arguments\n"
        )
        return 255
    rospy.init_node("static_transform_publisher", argv=full, anonymous=True)
    if not wait_for_master_like_roscpp(rospy.core.process_node()):
        return 0  # Ctrl-C while waiting for the master, as roscpp: a quiet exit
    if len(args) == 1:
        got = _from_param(rospy, args[0])
        if got is None:
            return 255
        parent, child, values = got
    else:
        values = parse_numbers(args[:-2])
        parent, child = args[-2], args[-1]
    if parent == child:
        rospy.logfatal(f"target_frame and source frame are the same ({parent}, {child}) this cannot work")
        return 1
    values = _normalized(values, _report(rospy))
    if values is None:
        return 1
    msg = TransformStamped()
    msg.header.stamp = rospy.Time.now()
    msg.header.frame_id = parent
    msg.child_frame_id = child
    t, q = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z, q.x, q.y, q.z, q.w = values
    broadcaster = tf2_ros.StaticTransformBroadcaster()
    broadcaster.sendTransform(msg)
    rospy.loginfo(f"Spinning until killed publishing {parent} to {child}")
    rospy.spin()
    return 0


def tf_main(argv: list[str] | None = None) -> int:
    """tf's legacy static_transform_publisher: re-sends on /tf every period (ms), future-dated."""
    import rospy
    import tf2_ros
    from ninjemys.tf2.buffer import to_ns

    full = ["static_transform_publisher", *(sys.argv[1:] if argv is None else argv)]
    args = rospy.myargv(full)[1:]
    if len(args) not in (9, 10):
        sys.stdout.write(TF_USAGE)
        sys.stdout.flush()
        sys.stderr.write(
            "[ERROR] static_transform_publisher exited due to not having the right number of arguments\n"
        )
        return 255
    rospy.init_node("static_transform_publisher", argv=full, anonymous=True)
    if not wait_for_master_like_roscpp(rospy.core.process_node()):
        return 0  # Ctrl-C while waiting for the master, as roscpp: a quiet exit
    period = atof(args[-1]) / 1000.0
    parent, child = args[-3], args[-2]
    if parent == child:
        rospy.logfatal(f"target_frame and source frame are the same ({parent}, {child}) this cannot work")
        return 1
    values = _normalized(parse_numbers(args[:-3]), _report(rospy))  # type: ignore[arg-type]
    if values is None:
        return 1
    if period <= 0.0:
        rospy.logfatal(f"the period must be a positive number of milliseconds, not {args[-1]!r}")
        return 1
    broadcaster = tf2_ros.TransformBroadcaster()
    ahead = int(period * 1e9)
    try:
        while not rospy.is_shutdown():
            broadcaster.send_items([(parent, child, to_ns(rospy.Time.now()) + ahead, *values)])
            rospy.sleep(period)
    except rospy.ROSInterruptException:
        pass
    return 0


console_main = entry(main)
tf_console_main = entry(tf_main)

if __name__ == "__main__":
    console_main()
