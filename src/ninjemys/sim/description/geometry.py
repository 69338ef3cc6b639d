"""What the simulator needs from a URDF's links and joints: wheels, footprint, height, colour, poses.

The robot is a rigid body on the ground plane: the links fixed to the root link (through any chain
of fixed joints) make its body; continuous joints whose child has a collision cylinder (or sphere)
are wheels. Every pose is taken in the root link's frame (the model frame, which Gazebo's drive
plugins report as the robot's pose), with movable joints at position 0, using the same joint
arithmetic as robot_state_publisher (:mod:`ninjemys.robot.kinematics`).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from ninjemys.robot.kinematics import Joint, Matrix, URDFError, Vector, parse_urdf, rpy_matrix
from ninjemys.sim.description.xmltree import Document

#: (rotation, translation) of a child frame in a parent frame
Transform = tuple[Matrix, Vector]
IDENTITY: Transform = (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), (0.0, 0.0, 0.0))


def compose(a: Transform, b: Transform) -> Transform:
    """``a ∘ b``: b's frame expressed in a's parent frame."""
    (ra, ta), (rb, tb) = a, b
    rot = tuple(tuple(sum(ra[i][k] * rb[k][j] for k in range(3)) for j in range(3)) for i in range(3))
    pos = tuple(ta[i] + sum(ra[i][k] * tb[k] for k in range(3)) for i in range(3))
    return rot, pos  # type: ignore[return-value]


def apply(t: Transform, v: Vector) -> Vector:
    r, p = t
    return (
        p[0] + r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
        p[1] + r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
        p[2] + r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2],
    )


def rpy_of(r: Matrix) -> Vector:
    """Roll, pitch, yaw of a rotation (the inverse of KDL's RPY)."""
    pitch = math.atan2(-r[2][0], math.hypot(r[0][0], r[1][0]))
    if abs(math.cos(pitch)) < 1e-9:
        return (math.atan2(-r[1][2], r[1][1]), pitch, 0.0)
    return (math.atan2(r[2][1], r[2][2]), pitch, math.atan2(r[1][0], r[0][0]))


@dataclass
class Shape:
    """One collision geometry of a link, in the link's frame."""

    kind: str  # box, cylinder, sphere, mesh
    size: tuple[float, ...]  # box: x y z; cylinder: radius length; sphere: radius; mesh: ()
    origin: Transform

    def points(self) -> list[Vector]:
        """Points on the surface that bound the shape (corners, rims), in the link frame."""
        if self.kind == "box":
            hx, hy, hz = (s / 2 for s in self.size)
            local = [(sx * hx, sy * hy, sz * hz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        elif self.kind == "cylinder":
            r, half = self.size[0], self.size[1] / 2
            local = [
                (r * math.cos(a * math.pi / 12), r * math.sin(a * math.pi / 12), z)
                for a in range(24)
                for z in (-half, half)
            ]
        elif self.kind == "sphere":
            r = self.size[0]
            local = [(r * sx, 0.0, 0.0) for sx in (-1, 1)] + [(0.0, r * s, 0.0) for s in (-1, 1)]
            local += [(0.0, 0.0, r * s) for s in (-1, 1)]
        else:
            return []
        return [apply(self.origin, p) for p in local]


@dataclass
class Wheel:
    joint: str
    link: str
    pose: Transform  # the joint's frame in the root frame
    radius: float | None


@dataclass
class Geometry:
    name: str
    root: str
    links: dict[str, ET.Element]
    joints: dict[str, Joint]
    link_poses: dict[str, Transform]
    shapes: dict[str, list[Shape]]
    materials: dict[str, tuple[float, float, float, float]]
    wheels: list[Wheel] = field(default_factory=list)

    def pose_of(self, link: str) -> Transform:
        return self.link_poses.get(link, IDENTITY)

    def body_links(self) -> list[str]:
        """The links rigidly attached to the root (fixed joints only), the root included."""
        children: dict[str, list[Joint]] = {}
        for j in self.joints.values():
            children.setdefault(j.parent, []).append(j)
        out: list[str] = []
        todo = [self.root]
        while todo:
            link = todo.pop()
            out.append(link)
            todo.extend(j.child for j in children.get(link, []) if j.type == "fixed")
        return out

    def ground_z(self) -> float:
        """Height of the ground in the root frame: under the wheels, or under the lowest body point."""
        bottoms = [w.pose[1][2] - w.radius for w in self.wheels if w.radius]
        if bottoms:
            return min(bottoms)
        pts = [p[2] for _, p in self._body_points()]
        return min(pts) if pts else 0.0

    def _body_points(self) -> list[tuple[str, Vector]]:
        out: list[tuple[str, Vector]] = []
        for link in self.body_links():
            pose = self.pose_of(link)
            for shape in self.shapes.get(link, []):
                out.extend((link, apply(pose, p)) for p in shape.points())
        return out

    def footprint(self) -> tuple[float, float] | None:
        """(radius about the root's origin, top height above the ground) of the body's collision shapes."""
        pts = [p for _, p in self._body_points()]
        if not pts:
            return None
        radius = max(math.hypot(p[0], p[1]) for p in pts)
        top = max(p[2] for p in pts) - self.ground_z()
        return radius, top


def _floats(
    doc: Document, el: ET.Element, attr: str, n: int, default: str | None = None
) -> tuple[float, ...]:
    text = el.get(attr, default)
    if text is None:
        raise doc.error(el, f"attribute {attr} is required")
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise doc.error(el, f"{attr}='{text}' is not {n} finite number(s)")
    return values


def _origin(doc: Document, parent: ET.Element) -> Transform:
    el = parent.find("origin")
    if el is None:
        return IDENTITY
    xyz = _floats(doc, el, "xyz", 3, "0 0 0")
    rpy = _floats(doc, el, "rpy", 3, "0 0 0")
    return rpy_matrix(*rpy), (xyz[0], xyz[1], xyz[2])


def _shape(doc: Document, link: str, holder: ET.Element) -> Shape | None:
    geo = holder.find("geometry")
    if geo is None or len(geo) == 0:
        return None
    g = geo[0]
    sizes = {"box": ("size", 3), "cylinder": None, "sphere": ("radius", 1)}
    if g.tag == "box":
        size = _floats(doc, g, "size", 3)
    elif g.tag == "cylinder":
        size = _floats(doc, g, "radius", 1) + _floats(doc, g, "length", 1)
    elif g.tag == "sphere":
        size = _floats(doc, g, "radius", 1)
    elif g.tag == "mesh":
        size = ()
    else:
        raise doc.error(g, f"link '{link}': unknown geometry (one of {', '.join([*sizes, 'mesh'])})")
    if any(s < 0 for s in size):
        raise doc.error(g, f"link '{link}': a {g.tag}'s dimensions must be >= 0")
    return Shape(g.tag, size, _origin(doc, holder))


def _rgba(doc: Document, el: ET.Element) -> tuple[float, float, float, float]:
    r, g, b, a = _floats(doc, el, "rgba", 4)
    return (r, g, b, a)


def read_geometry(doc: Document) -> Geometry:
    """Links, joints, poses and shapes of a URDF document; errors name the file, line and element."""
    root = doc.root
    if root.tag != "robot":
        raise doc.error(root, "the root element of a URDF must be <robot>")
    try:
        model = parse_urdf(ET.tostring(root, encoding="unicode"), doc.source)
    except URDFError as exc:
        raise doc.error(root, str(exc).removeprefix(f"{doc.source}: "), "robot") from None
    links = {el.get("name", ""): el for el in root.findall("link")}
    materials: dict[str, tuple[float, float, float, float]] = {}
    for m in root.findall("material"):
        colour = m.find("color")
        if m.get("name") and colour is not None:
            materials[m.get("name", "")] = _rgba(doc, colour)
    shapes: dict[str, list[Shape]] = {}
    for name, el in links.items():
        found = [s for c in el.findall("collision") if (s := _shape(doc, name, c)) is not None]
        shapes[name] = found
    children = {j.child for j in model.joints.values()}
    roots = [n for n in model.links if n not in children]
    if len(roots) != 1:
        raise doc.error(
            root, f"a robot has one root link; found {len(roots)} ({', '.join(roots) or 'a cycle'})"
        )
    by_parent: dict[str, list[Joint]] = {}
    for j in model.joints.values():
        by_parent.setdefault(j.parent, []).append(j)
    poses: dict[str, Transform] = {roots[0]: IDENTITY}
    todo = [roots[0]]
    while todo:
        link = todo.pop()
        for j in by_parent.get(link, []):
            poses[j.child] = compose(poses[link], (j.rotation, j.xyz))
            todo.append(j.child)
    geo = Geometry(model.name, roots[0], links, dict(model.joints), poses, shapes, materials)
    for j in model.joints.values():
        if j.type != "continuous":
            continue
        radius = None
        for s in shapes.get(j.child, []):
            if s.kind in ("cylinder", "sphere"):
                radius = s.size[0]
                break
        geo.wheels.append(Wheel(j.name, j.child, compose(poses[j.parent], (j.rotation, j.xyz)), radius))
    return geo


def link_colour(geo: Geometry, doc: Document, link: str) -> tuple[float, float, float, float] | None:
    """The colour of a link's first visual material (inline ``<color>`` or a named top-level one)."""
    el = geo.links.get(link)
    if el is None:
        return None
    for visual in el.findall("visual"):
        mat = visual.find("material")
        if mat is None:
            continue
        colour = mat.find("color")
        if colour is not None:
            return _rgba(doc, colour)
        if mat.get("name") in geo.materials:
            return geo.materials[mat.get("name", "")]
    return None
