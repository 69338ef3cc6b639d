"""``rosrun tf tf_echo source_frame target_frame [echo_rate]``: print a transform as ROS 1's tf_echo does.

The transform printed takes data from ``target_frame`` into ``source_frame`` (tf_echo's own
wording), looked up at the latest common time, ``echo_rate`` times a second (``~rate``, default 1);
``~precision`` sets the decimals (default 3). Output lines are tf_echo's, character for character.
"""

from __future__ import annotations

import math
import re
import sys
from typing import TYPE_CHECKING

from ninjemys.tools.cli import entry, wait_for_master_like_roscpp

if TYPE_CHECKING:
    from ninjemys.node import Node

USAGE = (
    "Usage: tf_echo source_frame target_frame [echo_rate]\n\n"
    "This will echo the transform from the coordinate frame of the source_frame\n"
    "to the coordinate frame of the target_frame. \n"
    "Note: This is the transform to get data from target_frame into the source_frame.\n"
    "Default echo rate is 1 if echo_rate is not given.\n"
)

_FLOAT_PREFIX = re.compile(r"\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def atof(text: str) -> float:
    """C's ``atof``: the longest leading number, 0.0 when there is none (ROS 1 parses arguments so)."""
    m = _FLOAT_PREFIX.match(text)
    return float(m.group(0)) if m else 0.0


def rpy(qx: float, qy: float, qz: float, qw: float) -> tuple[float, float, float]:
    """Roll, pitch, yaw of a quaternion (fixed axes x, y, z: tf's ``getRPY``)."""
    sinp = 2.0 * (qw * qy - qz * qx)
    if abs(sinp) >= 1.0 - 1e-12:  # gimbal lock: one of the many equivalent answers
        from ninjemys.tf2.transformations import euler_from_quaternion

        return euler_from_quaternion((qx, qy, qz, qw), "sxyz")
    roll = math.atan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
    yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return roll, math.asin(sinp), yaw


def format_transform(stamp_ns: int, t: tuple, precision: int = 3) -> str:
    """tf_echo's block for one transform (``t`` is the 7-tuple)."""
    p = precision
    x, y, z, qx, qy, qz, qw = t
    roll, pitch, yaw = rpy(qx, qy, qz, qw)
    secs, nsecs = divmod(stamp_ns, 1_000_000_000)
    d = 180.0 / math.pi
    return (
        f"At time {secs + 1e-9 * nsecs:.{p}f}\n"
        f"- Translation: [{x:.{p}f}, {y:.{p}f}, {z:.{p}f}]\n"
        f"- Rotation: in Quaternion [{qx:.{p}f}, {qy:.{p}f}, {qz:.{p}f}, {qw:.{p}f}]\n"
        f"            in RPY (radian) [{roll:.{p}f}, {pitch:.{p}f}, {yaw:.{p}f}]\n"
        f"            in RPY (degree) [{roll * d:.{p}f}, {pitch * d:.{p}f}, {yaw * d:.{p}f}]\n"
    )


def main(argv: list[str] | None = None) -> int:
    from ninjemys.names import strip_remap_args
    from ninjemys.node.run import run_main

    argv = sys.argv[1:] if argv is None else argv
    args = strip_remap_args(["tf_echo", *argv])
    if len(args) < 3 or len(args) > 4:
        sys.stdout.write(USAGE)
        return 255
    return run_main("tf_echo", argv, lambda node: echo(node, args), anonymous=True)


def echo(node: Node, args: list[str]) -> int:
    """tf_echo's loop on a core node (a roscpp program in ROS 1: it waits for the master as roscpp does)."""
    from ninjemys.tf2.core import BufferCore
    from ninjemys.tf2.errors import TransformException
    from ninjemys.tf2.node import TransformListener

    if not wait_for_master_like_roscpp(node):
        return 0  # Ctrl-C while waiting for the master, as roscpp: a quiet exit
    rate_hz = atof(args[3]) if len(args) == 4 else float(node.get_param("~rate", 1.0))
    if rate_hz <= 0.0:
        sys.stderr.write("Echo rate must be > 0.0\n")
        return 255
    precision = 3
    if node.has_param("~precision"):
        precision = int(node.get_param("~precision"))
        if precision < 1:
            sys.stderr.write("Precision must be > 0\n")
            return 255
        print(f"Precision default value was overriden, new value: {precision}")
    buffer = BufferCore()
    TransformListener(node, buffer, now=node.get_time, report=node.log.warn)
    source, target = args[1].lstrip("/"), args[2].lstrip("/")
    buffer.wait_for_transform(
        lambda: buffer.can_transform(source, target, 0), 1.0, node.get_time, lambda: node.is_shutdown
    )
    rate = node.rate(rate_hz)
    while not node.is_shutdown:
        try:
            stamp, t = buffer.lookup(source, target, 0)
            sys.stdout.write(format_transform(stamp, t, precision))
        except TransformException as ex:
            now = node.now()
            sys.stdout.write(
                f"Failure at {now.secs}.{now.nsecs:09d}\nException thrown:{ex}\n"
                f"The current list of frames is:\n{buffer.all_frames_as_string()}\n"
            )
        sys.stdout.flush()
        rate.sleep()  # raises ShutdownError at Ctrl-C: run_main ends quietly
    return 0


console_main = entry(main)

if __name__ == "__main__":
    console_main()
