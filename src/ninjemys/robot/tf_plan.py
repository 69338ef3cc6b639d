"""A JointState stream's transforms computed from a plan made once per list of joint names.

robot_state_publisher's CPU is per message, and in a joint state stream only the numbers change: the
names (and so which joints move, which mimic joints follow, and every frame name of the TFMessage) are
the same message after message. A :class:`TfPlan` is made once per distinct list of names and then,
per message, takes the positions as they were unpacked from the received bytes and, per moving joint:

* its value: ``position[source] * a + b`` (a mimic joint: its leader's position, multiplier, offset);
* a revolute or continuous joint: rotation ``cos(value/2) * O + sin(value/2) * B``, O the origin's
  quaternion and B its product with the axis (the origin times the axis-angle quaternion in 8 products
  and 4 sums), with the sign KDL's GetQuaternion gives (the branch component made positive), and the
  origin's translation;
* a prismatic one: the origin's translation plus ``value`` times the rotated axis, the origin's rotation;

and packs the whole TFMessage with one precompiled ``struct`` (the frame names are constant arguments,
seq 0 as tf2 sends). For a robot of a few dozen joints this is cheaper in plain Python than in numpy,
whose per-call overhead (~1-3 us) outweighs the arithmetic of 20 rows.

The order of the transforms, the mimic semantics and the numbers (to rounding, ~1e-16) are those of
:meth:`ninjemys.robot.state_publisher.StatePublisher.on_joint_state`'s general path, which handles
what a plan does not (a list of names with duplicates).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Sequence

from ninjemys.robot.kinematics import Joint, apply_rotation, quaternion

_MOVING = frozenset(("revolute", "continuous", "prismatic"))


class TfPlan:
    """The transforms of one list of joint names (see the module docstring)."""

    def __init__(
        self,
        names: Sequence[str],
        joints: dict[str, Joint],
        mimics: dict[str, list[Joint]],
        frames: Callable[[Joint], bytes],
    ) -> None:
        #: the names the robot has, for the throttle's bookkeeping
        self.known = [n for n in names if n in joints]
        index = {n: i for i, n in enumerate(names)}
        values: dict[str, tuple[int, float, float]] = {n: (index[n], 1.0, 0.0) for n in self.known}
        moving = [joints[n] for n in values if joints[n].type in _MOVING]
        for name in list(values) if mimics else ():
            for mimic in mimics.get(name, ()):
                assert mimic.mimic is not None
                src, a, b = values[name]
                m = mimic.mimic
                values[mimic.name] = (src, a * m.multiplier, b * m.multiplier + m.offset)
                if mimic.type != "fixed":
                    moving.append(mimic)
        self.count = len(moving)
        fmt = ["<I"]
        self.rows: list[tuple] = []
        for joint in moving:
            src, a, b = values[joint.name]
            frame = frames(joint)
            fmt.append(f"III{len(frame)}s7d")
            ox, oy, oz, ow = quaternion(joint.rotation)
            x0, y0, z0 = joint.xyz
            if joint.type == "prismatic":
                dx, dy, dz = apply_rotation(joint.rotation, joint.axis)
                self.rows.append((False, src, a, b, frame, x0, y0, z0, dx, dy, dz, ox, oy, oz, ow))
                continue
            if joint.type not in _MOVING:  # a floating or planar mimic joint stays at its origin, as in KDL
                a = b = 0.0
            ax, ay, az = joint.axis
            self.rows.append(
                (
                    True,
                    src,
                    a * 0.5,
                    b * 0.5,
                    frame,
                    x0,
                    y0,
                    z0,
                    ox,
                    oy,
                    oz,
                    ow,
                    ow * ax + oy * az - oz * ay,
                    ow * ay - ox * az + oz * ax,
                    ow * az + ox * ay - oy * ax,
                    -(ox * ax + oy * ay + oz * az),
                )
            )
        self.struct = struct.Struct("".join(fmt))

    def message(self, positions: Sequence[float], secs: int, nsecs: int) -> bytes:
        """The serialized TFMessage for ``positions`` (the message's, in its order) at ``secs.nsecs``."""
        args: list = [self.count]
        extend = args.extend
        cos, sin = math.cos, math.sin
        for row in self.rows:
            if row[0]:
                _, src, a, b, frame, x0, y0, z0, ox, oy, oz, ow, bx, by, bz, bw = row
                half = positions[src] * a + b
                c, s = cos(half), sin(half)
                x, y, z, w = c * ox + s * bx, c * oy + s * by, c * oz + s * bz, c * ow + s * bw
                # kinematics._kdl_sign, written out on purpose: this loop runs per joint per
                # joint_states message, and the call (a tuple built and unpacked) cost more than the
                # sign choice itself. Change both together (tests/robot/test_tf_plan.py compares the paths).
                xx, yy, zz, ww = x * x, y * y, z * z, w * w
                if 4.0 * ww - (xx + yy + zz + ww) > 1e-12:
                    key = w
                elif xx > yy and xx > zz:
                    key = x
                elif yy > zz:
                    key = y
                else:
                    key = z
                if key < 0.0:
                    x, y, z, w = -x, -y, -z, -w
                extend((0, secs, nsecs, frame, x0, y0, z0, x, y, z, w))
            else:
                _, src, a, b, frame, x0, y0, z0, dx, dy, dz, ox, oy, oz, ow = row
                v = positions[src] * a + b
                extend((0, secs, nsecs, frame, x0 + dx * v, y0 + dy * v, z0 + dz * v, ox, oy, oz, ow))
        return self.struct.pack(*args)
