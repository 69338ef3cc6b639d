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
from typing import TYPE_CHECKING, Any

from ninjemys.tf2.math import quaternion_from_rpy
from ninjemys.tools.cli import entry, wait_for_master_like_roscpp
from ninjemys.tools.tf_echo import atof

if TYPE_CHECKING:
    from ninjemys.node import Node

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


def _normalized(t: tuple[float, ...] | None, log: Any) -> tuple[float, ...] | None:
    """``t`` with a unit quaternion; None (after one line) when it has none. ``t`` is None only when
    the numbers were not 6 or 7, which the argument count already ruled out."""
    if t is None:
        return None
    qx, qy, qz, qw = t[3:]
    n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    if not n or not math.isfinite(n):
        log(f"the quaternion ({qx:g} {qy:g} {qz:g} {qw:g}) has no direction: cannot make a rotation of it")
        return None
    if abs(n * n - 1.0) >= 10e-6:
        log(f"the quaternion ({qx:g} {qy:g} {qz:g} {qw:g}) has norm {n:g}; sending it normalized", warn=True)
        return (*t[:3], qx / n, qy / n, qz / n, qw / n)
    return t


def _from_param(node: Node, name: str) -> tuple[str, str, tuple[float, ...]] | None:
    node.log.info(f"Looking for TF in parameter: {name}")
    if not node.has_param(name):
        node.log.fatal(f"Could not read TF from parameter server: {name}")
        return None
    data = node.get_param(name)
    try:
        tr = data["transform"]["translation"]
        rot = data["transform"]["rotation"]
        values = tuple(float(v) for v in (tr["x"], tr["y"], tr["z"], rot["x"], rot["y"], rot["z"], rot["w"]))
        return str(data["header"]["frame_id"]), str(data["child_frame_id"]), values
    except (KeyError, TypeError, ValueError):
        node.log.fatal(f"Could not validate XmlRpcC for TF data: {data}")
        return None


def _report(node: Node) -> Any:
    def log(line: str, warn: bool = False) -> None:
        (node.log.warn if warn else node.log.fatal)(line)

    return log


def _arguments(argv: list[str] | None) -> tuple[list[str], list[str]]:
    """(the command line after the program name, the same without ROS's ``name:=value`` arguments)."""
    from ninjemys.names import strip_remap_args

    argv = sys.argv[1:] if argv is None else argv
    return argv, strip_remap_args(["static_transform_publisher", *argv])[1:]


def _wrong_count(usage: str) -> int:
    sys.stdout.write(usage)
    sys.stdout.flush()
    sys.stderr.write(
        "[ERROR] static_transform_publisher exited due to not having the right number of arguments\n"
    )
    return 255


def main(argv: list[str] | None = None) -> int:
    """tf2_ros's static_transform_publisher."""
    from ninjemys.node.run import run_main

    argv, args = _arguments(argv)
    if len(args) not in (1, 8, 9):
        return _wrong_count(TF2_USAGE)
    return run_main("static_transform_publisher", argv, lambda node: _latch(node, args), anonymous=True)


def _latch(node: Node, args: list[str]) -> int:
    from ninjemys.tf2.buffer import to_ns
    from ninjemys.tf2.node import StaticTransformBroadcaster

    if not wait_for_master_like_roscpp(node):
        return 0  # Ctrl-C while waiting for the master, as roscpp: a quiet exit
    values: tuple[float, ...] | None
    if len(args) == 1:
        got = _from_param(node, args[0])
        if got is None:
            return 255
        parent, child, values = got
    else:
        values = parse_numbers(args[:-2])
        parent, child = args[-2], args[-1]
    if parent == child:
        node.log.fatal(f"target_frame and source frame are the same ({parent}, {child}) this cannot work")
        return 1
    values = _normalized(values, _report(node))
    if values is None:
        return 1
    broadcaster = StaticTransformBroadcaster(node)
    broadcaster.send_items([(parent, child, to_ns(node.now()), *values)])
    node.log.info(f"Spinning until killed publishing {parent} to {child}")
    node.spin()
    return 0


def tf_main(argv: list[str] | None = None) -> int:
    """tf's legacy static_transform_publisher: re-sends on /tf every period (ms), future-dated."""
    from ninjemys.node.run import run_main

    argv, args = _arguments(argv)
    if len(args) not in (9, 10):
        return _wrong_count(TF_USAGE)
    return run_main("static_transform_publisher", argv, lambda node: _repeat(node, args), anonymous=True)


def _repeat(node: Node, args: list[str]) -> int:
    from ninjemys.tf2.buffer import to_ns
    from ninjemys.tf2.node import TransformBroadcaster

    if not wait_for_master_like_roscpp(node):
        return 0  # Ctrl-C while waiting for the master, as roscpp: a quiet exit
    period = atof(args[-1]) / 1000.0
    parent, child = args[-3], args[-2]
    if parent == child:
        node.log.fatal(f"target_frame and source frame are the same ({parent}, {child}) this cannot work")
        return 1
    values = _normalized(parse_numbers(args[:-3]), _report(node))
    if values is None:
        return 1
    if period <= 0.0:
        node.log.fatal(f"the period must be a positive number of milliseconds, not {args[-1]!r}")
        return 1
    broadcaster = TransformBroadcaster(node)
    ahead = int(period * 1e9)
    while not node.is_shutdown:
        broadcaster.send_items([(parent, child, to_ns(node.now()) + ahead, *values)])
        node.sleep(period)  # raises ShutdownError at Ctrl-C: run_main ends quietly
    return 0


console_main = entry(main)
tf_console_main = entry(tf_main)

if __name__ == "__main__":
    console_main()
