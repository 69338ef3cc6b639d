"""The moving joints' ``tf2_msgs/TFMessage``, computed and serialized in one pass per joint state.

robot_state_publisher's cost is per message: 20 joints at 50 Hz is 1000 transforms a second. Built
as message objects (a TransformStamped, its header, Time, Transform, Vector3, Quaternion per joint)
and then serialized, most of the time goes to creating objects. Here each joint keeps its
constant part (the origin's rotation and translation, the axis, the two frame names already encoded
with their length prefixes) and a message is one ``struct.pack`` over a format built once per set of
joints. The arithmetic is :meth:`ninjemys.robot.kinematics.Joint.transform`'s (KDL's), written out
on floats so the numbers are the same.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence

from ninjemys.robot.kinematics import Joint, quaternion


class WireJoint:
    """One joint's constant part: its type, origin, axis and encoded frame names."""

    __slots__ = ("name", "kind", "r", "xyz", "axis", "frames")

    def __init__(self, joint: Joint, parent_frame: str, child_frame: str) -> None:
        self.name = joint.name
        self.kind = {"revolute": 0, "continuous": 0, "prismatic": 1}.get(joint.type, 2)
        self.r = tuple(v for row in joint.rotation for v in row)
        self.xyz = joint.xyz
        self.axis = joint.axis
        parent, child = parent_frame.encode(), child_frame.encode()
        self.frames = (parent, child)

    def pose(self, q: float) -> tuple[float, float, float, float, float, float, float]:
        """parent -> child at ``q``: as ``Joint.transform`` (R0·Rot(axis, q), or a slide along R0·axis)."""
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = self.r
        x, y, z = self.xyz
        if self.kind == 0:
            ax, ay, az = self.axis
            c, s = math.cos(q), math.sin(q)
            t = 1.0 - c
            b00, b01, b02 = t * ax * ax + c, t * ax * ay - s * az, t * ax * az + s * ay
            b10, b11, b12 = t * ax * ay + s * az, t * ay * ay + c, t * ay * az - s * ax
            b20, b21, b22 = t * ax * az - s * ay, t * ay * az + s * ax, t * az * az + c
            m = (
                (
                    r00 * b00 + r01 * b10 + r02 * b20,
                    r00 * b01 + r01 * b11 + r02 * b21,
                    r00 * b02 + r01 * b12 + r02 * b22,
                ),
                (
                    r10 * b00 + r11 * b10 + r12 * b20,
                    r10 * b01 + r11 * b11 + r12 * b21,
                    r10 * b02 + r11 * b12 + r12 * b22,
                ),
                (
                    r20 * b00 + r21 * b10 + r22 * b20,
                    r20 * b01 + r21 * b11 + r22 * b21,
                    r20 * b02 + r21 * b12 + r22 * b22,
                ),
            )
            return (x, y, z, *quaternion(m))
        if self.kind == 1:
            ax, ay, az = self.axis[0] * q, self.axis[1] * q, self.axis[2] * q
            x += r00 * ax + r01 * ay + r02 * az
            y += r10 * ax + r11 * ay + r12 * az
            z += r20 * ax + r21 * ay + r22 * az
        m0 = ((r00, r01, r02), (r10, r11, r12), (r20, r21, r22))
        return (x, y, z, *quaternion(m0))


class Layout:
    """The struct format of a TFMessage for one list of joints (frames fixed, numbers filled in)."""

    __slots__ = ("struct", "joints")

    def __init__(self, joints: Sequence[WireJoint]) -> None:
        parts = ["<I"]
        for joint in joints:
            parent, child = joint.frames
            # header: seq, stamp secs, nsecs, frame_id; child_frame_id; translation and rotation
            parts.append(f"IIII{len(parent)}sI{len(child)}s7d")
        self.struct = struct.Struct("".join(parts))
        self.joints = tuple(joints)

    def pack(self, values: dict[str, float], secs: int, nsecs: int) -> bytes:
        """The serialized TFMessage (without the length prefix), every transform stamped alike."""
        args: list[object] = [len(self.joints)]
        append, extend = args.append, args.extend
        for joint in self.joints:
            parent, child = joint.frames
            extend((0, secs, nsecs))
            append(len(parent))
            append(parent)
            append(len(child))
            append(child)
            extend(joint.pose(values.get(joint.name, 0.0)))
        return self.struct.pack(*args)
