"""A URDF's kinematic tree and the transform of each joint at a position, as KDL computes it.

robot_state_publisher only needs the joints: parent and child link, origin (xyz, rpy), axis, type
and ``<mimic>``. The arithmetic follows KDL (which ROS 1's robot_state_publisher uses through
kdl_parser): the origin's rotation is ``Rz(yaw)·Ry(pitch)·Rx(roll)``, a revolute joint turns about
its axis after the origin, a prismatic one slides along it, and the quaternion is taken from the
rotation matrix with KDL's ``GetQuaternion`` branches, so the numbers (and signs) match Debian's node.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass

from ninjemys.errors import NinjemysError

Matrix = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]
Vector = tuple[float, float, float]
#: (x, y, z, qx, qy, qz, qw)
Pose = tuple[float, float, float, float, float, float, float]

MOVING = ("revolute", "continuous", "prismatic")
JOINT_TYPES = (*MOVING, "fixed", "floating", "planar")


class URDFError(NinjemysError, ValueError):
    """A robot description that cannot be read: says which file (or parameter), element and why."""


@dataclass(frozen=True)
class Mimic:
    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Joint:
    name: str
    type: str
    parent: str
    child: str
    xyz: Vector
    rotation: Matrix
    axis: Vector
    mimic: Mimic | None = None

    def transform(self, position: float = 0.0) -> Pose:
        """parent -> child at ``position`` (radians or metres)."""
        return _pose_function(self)(position)

    def pose_function(self) -> Callable[[float], Pose]:
        """:meth:`transform` with what does not move computed once (for a stream of positions)."""
        return _pose_function(self)


def _pose_function(joint: Joint) -> Callable[[float], Pose]:
    """``position -> pose`` for one joint, with everything that does not move computed once.

    A revolute joint's rotation is the origin's quaternion times the axis-angle one (16 products
    instead of two matrices), with the sign KDL's GetQuaternion would give the same rotation:
    the branch that KDL picks from the matrix diagonal is picked here from the squared components
    (trace = 4w^2 - 1, R00 > R11 <=> x^2 > y^2 ...), and that component is made positive.
    """
    x0, y0, z0 = joint.xyz
    ox, oy, oz, ow = quaternion(joint.rotation)
    if joint.type in ("revolute", "continuous"):
        ax, ay, az = joint.axis

        def revolute(position: float) -> Pose:
            half = 0.5 * position
            s, c = math.sin(half), math.cos(half)
            bx, by, bz = ax * s, ay * s, az * s
            qx = ow * bx + ox * c + oy * bz - oz * by
            qy = ow * by - ox * bz + oy * c + oz * bx
            qz = ow * bz + ox * by - oy * bx + oz * c
            qw = ow * c - ox * bx - oy * by - oz * bz
            return (x0, y0, z0, *kdl_sign(qx, qy, qz, qw))

        return revolute
    if joint.type == "prismatic":
        dx, dy, dz = apply_rotation(joint.rotation, joint.axis)
        rotation = (ox, oy, oz, ow)

        def prismatic(position: float) -> Pose:
            return (x0 + dx * position, y0 + dy * position, z0 + dz * position, *rotation)

        return prismatic
    fixed = (x0, y0, z0, ox, oy, oz, ow)
    return lambda _position: fixed


def kdl_sign(x: float, y: float, z: float, w: float) -> tuple[float, float, float, float]:
    """The unit quaternion with the sign KDL's GetQuaternion gives its rotation: GetQuaternion takes
    the branch of the largest of trace, R00, R11 and R22 (``4w^2 - 1``, and for x, y, z compared in
    pairs: ``R00 > R11`` iff ``x^2 > y^2``) and makes that component positive. The ``w`` branch
    (trace > 1e-12, so ``|w| > 0.5``) is looked at first: it is the common case."""
    if w > 0.5:
        return x, y, z, w
    if w < -0.5:
        return -x, -y, -z, -w
    xx, yy, zz = x * x, y * y, z * z
    if xx > yy and xx > zz:
        key = x
    elif yy > zz:
        key = y
    else:
        key = z
    return (x, y, z, w) if key >= 0.0 else (-x, -y, -z, -w)


@dataclass(frozen=True)
class RobotModel:
    name: str
    links: tuple[str, ...]
    joints: dict[str, Joint]

    @property
    def moving(self) -> list[Joint]:
        return [j for j in self.joints.values() if j.type in MOVING]

    @property
    def fixed(self) -> list[Joint]:
        return [j for j in self.joints.values() if j.type == "fixed"]


def parse_urdf(text: str, source: str = "robot_description") -> RobotModel:
    """The kinematic tree of a URDF document; URDFError names ``source``, the element and the reason."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line, column = exc.position
        raise URDFError(
            f"{source}:{line}:{column}: malformed XML: {exc.msg if hasattr(exc, 'msg') else exc}"
        ) from None
    if root.tag != "robot":
        raise URDFError(f"{source}: the root element is <{root.tag}>, not <robot>")
    links = tuple(el.get("name", "") for el in root.findall("link"))
    for el in root.findall("link"):
        if not el.get("name"):
            raise URDFError(f"{source}: a <link> has no name")
    joints: dict[str, Joint] = {}
    for el in root.findall("joint"):
        joint = _joint(el, source)
        if joint.name in joints:
            raise URDFError(f"{source}: joint '{joint.name}' is not unique")
        joints[joint.name] = joint
    _check_links(joints, set(links), source)
    for joint in joints.values():
        if joint.mimic and joint.mimic.joint not in joints:
            raise URDFError(
                f"{source}: joint '{joint.name}' mimics '{joint.mimic.joint}', which is not in the robot"
            )
    return RobotModel(name=root.get("name", ""), links=links, joints=joints)


def _check_links(joints: dict[str, Joint], links: set[str], source: str) -> None:
    """urdfdom's tree check, in its words (robot_state_publisher, check_urdf and Gazebo's URDF import
    print them): joints in name order, a joint's child link before its parent."""
    for name in sorted(joints):
        joint = joints[name]
        if joint.child not in links:
            raise URDFError(
                f"{source}: Failed to build tree: child link [{joint.child}] of joint [{name}] not found"
            )
        if joint.parent not in links:
            raise URDFError(
                f"{source}: Failed to build tree: parent link [{joint.parent}] of joint [{name}] not found.  This is"
                " not valid according to the URDF spec. Every link you refer to from a joint needs to be explicitly"
                f" defined in the robot description. To fix this problem you can either remove this joint [{name}]"
                f' from your urdf file, or add "<link name="{joint.parent}" />" to your urdf file.'
            )


def _joint(el: ET.Element, source: str) -> Joint:
    name = el.get("name")
    if not name:
        raise URDFError(f"{source}: a <joint> has no name")
    where = f"{source}: joint '{name}'"
    kind = el.get("type", "")
    if kind not in JOINT_TYPES:
        raise URDFError(f"{where}: unknown type '{kind}' (one of {', '.join(JOINT_TYPES)})")
    parent, child = el.find("parent"), el.find("child")
    if parent is None or not parent.get("link") or child is None or not child.get("link"):
        raise URDFError(f"{where}: <parent link=...> and <child link=...> are required")
    origin = el.find("origin")
    xyz = _floats(origin.get("xyz", "0 0 0") if origin is not None else "0 0 0", 3, f"{where} <origin xyz>")
    rpy = _floats(origin.get("rpy", "0 0 0") if origin is not None else "0 0 0", 3, f"{where} <origin rpy>")
    axis_el = el.find("axis")
    axis = _floats(axis_el.get("xyz", "1 0 0") if axis_el is not None else "1 0 0", 3, f"{where} <axis xyz>")
    norm = math.sqrt(sum(a * a for a in axis))
    if kind in MOVING and norm == 0.0:
        raise URDFError(f"{where}: <axis xyz> has zero length")
    if norm:
        axis = tuple(a / norm for a in axis)
    mimic = None
    mimic_el = el.find("mimic")
    if mimic_el is not None:
        if not mimic_el.get("joint"):
            raise URDFError(f"{where}: <mimic> has no joint attribute")
        multiplier = _floats(mimic_el.get("multiplier", "1"), 1, f"{where} <mimic multiplier>")[0]
        offset = _floats(mimic_el.get("offset", "0"), 1, f"{where} <mimic offset>")[0]
        mimic = Mimic(mimic_el.get("joint", ""), multiplier, offset)
    return Joint(
        name=name,
        type=kind,
        parent=parent.get("link", ""),
        child=child.get("link", ""),
        xyz=xyz,  # type: ignore[arg-type]
        rotation=rpy_matrix(*rpy),
        axis=axis,  # type: ignore[arg-type]
        mimic=mimic,
    )


def _floats(text: str, count: int, where: str) -> tuple[float, ...]:
    parts = text.split()
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise URDFError(f"{where}: '{text}' is not {count} number(s)") from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise URDFError(f"{where}: '{text}' is not {count} finite number(s)")
    return values


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
    """KDL's ``Rotation::RPY``: Rz(yaw)·Ry(pitch)·Rx(roll)."""
    ca, sa = math.cos(yaw), math.sin(yaw)
    cb, sb = math.cos(pitch), math.sin(pitch)
    cg, sg = math.cos(roll), math.sin(roll)
    return (
        (ca * cb, ca * sb * sg - sa * cg, ca * sb * cg + sa * sg),
        (sa * cb, sa * sb * sg + ca * cg, sa * sb * cg - ca * sg),
        (-sb, cb * sg, cb * cg),
    )


def _axis_angle(axis: Vector, angle: float) -> Matrix:
    """KDL's ``Rotation::Rot2`` (Rodrigues) for a unit axis."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return (
        (t * x * x + c, t * x * y - s * z, t * x * z + s * y),
        (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
        (t * x * z - s * y, t * y * z + s * x, t * z * z + c),
    )


def _matmul(a: Matrix, b: Matrix) -> Matrix:
    return tuple(  # type: ignore[return-value]
        tuple(a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] for j in range(3)) for i in range(3)
    )


def apply_rotation(m: Matrix, v: Vector) -> Vector:
    """``m · v``."""
    return (
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    )


def quaternion(m: Matrix) -> tuple[float, float, float, float]:
    """KDL's ``Rotation::GetQuaternion`` (x, y, z, w), branch for branch."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 1e-12:
        s = 0.5 / math.sqrt(trace + 1.0)
        return ((m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s, 0.25 / s)
    if m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
        return (0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    if m[1][1] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
        return ((m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
    return ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s)
