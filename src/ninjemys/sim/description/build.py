"""A Gazebo robot description (URDF with ``<gazebo>`` blocks, after xacro) -> :class:`RobotModel`.

The geometry gives the body (wheels, footprint, height, colour) and where each sensor sits; the
plugins give what is driven and published, under which names, at which rates. What Gazebo would
not do, we do not either: a robot without a drive plugin stays where it is (``drive.kind="none"``,
with a warning naming the plugins that would move it), a sensor without a ROS plugin publishes
nothing, and the plugins we do not simulate are listed once in ``ignored_plugins``.
"""

from __future__ import annotations

import math

from ninjemys.sim.description.gazebo import DIFF_DRIVE, ROS_CONTROL, SKID_STEER, GazeboConfig, read_gazebo
from ninjemys.sim.description.geometry import (
    IDENTITY,
    Geometry,
    Wheel,
    apply,
    compose,
    link_colour,
    read_geometry,
)
from ninjemys.sim.description.xmltree import DescriptionError, Document, parse
from ninjemys.sim.robot_model import DriveSpec, RobotModel

#: accelerations and speeds Gazebo's plugins leave unlimited (0 or absent), as numbers the stepper takes
UNLIMITED_ACCEL = 1.0e6  # rad/s^2
UNLIMITED_SPEED = 1.0e3  # rad/s
#: what a body without collision geometry is given (our PuzzleBot's), with a warning
DEFAULT_BODY = (0.11, 0.2)
DEFAULT_COLOUR = (45, 45, 55)


def has_gazebo_blocks(text: str) -> bool:
    """Whether a URDF text carries ``<gazebo>`` extensions (then Gazebo's rules apply to it)."""
    return "<gazebo" in text


def model_from_description(text: str, source: str, *, robot_namespace: str | None = None) -> RobotModel:
    """Read a URDF under Gazebo's rules; DescriptionError names file, line, element and reason."""
    doc = parse(text, source)
    geo = read_geometry(doc)
    cfg = read_gazebo(doc, geo, robot_namespace)
    warnings: list[str] = []
    drive = cfg.drive
    if drive is None:
        drive = DriveSpec.silent("none")
        warnings.append(
            f"{source}: no drive plugin ({DIFF_DRIVE}, {SKID_STEER} or {ROS_CONTROL}) in a <gazebo> block:"
            " the robot is passive"
        )
    left, right = _wheels(doc, geo, cfg, drive)
    warnings = [*cfg.warnings, *warnings]  # the configuration's, with those choosing the wheels
    radius = _wheel_radius(doc, left, right, drive)
    separation = abs(left.pose[1][1] - right.pose[1][1]) if left is not right else 0.0
    if separation == 0.0:
        separation = drive.wheel_separation or 0.34
    body = geo.footprint()
    if body is None:
        warnings.append(
            f"{source}: the body ({geo.root}) has no collision geometry; a 0.11 m x 0.2 m cylinder is assumed"
        )
        body = DEFAULT_BODY
    colour = _colour(doc, geo, cfg)
    accel = cfg.wheel_accel
    max_accel = accel / radius if accel else UNLIMITED_ACCEL
    limit = _velocity_limit(doc, left.joint) if left.joint else None
    mass, inertia_z = _body_mass(doc, geo)
    managed = drive.kind == "ros_control" or cfg.control is not None
    control_joints = _control_joints(doc, geo, left, right) if managed else {}
    return RobotModel(
        name=geo.name or "robot",
        wheel_radius=radius,
        wheel_separation=separation,
        body_radius=max(body[0], 1e-3),
        body_height=max(body[1], 1e-3),
        color=colour,
        max_wheel_speed=limit or UNLIMITED_SPEED,
        max_wheel_accel=max_accel,
        left_joint=left.joint,
        right_joint=right.joint,
        laser=cfg.laser,
        camera=cfg.camera,
        extra_lasers=cfg.extra_lasers,
        extra_cameras=cfg.extra_cameras,
        imu=cfg.imu,
        odom_rate=drive.update_rate or 100.0,
        source=source,
        drive=drive,
        ignored_plugins=list(dict.fromkeys(cfg.ignored)),
        warnings=warnings,
        sensor_tf=False,
        control_joints=control_joints,
        control_beside=cfg.control,
        joint_velocity_limits={j: v for j in control_joints if (v := _velocity_limit(doc, j)) is not None},
        mass=mass,
        inertia_z=inertia_z,
        rest_z=-geo.ground_z() + 0.0,
        ground_truth=cfg.ground_truth,  # Gazebo publishes what the plugins ask for, nothing more
        contact_topic=None,
        bumper=cfg.bumper,  # (+ 0.0: never -0.0 in model_states)
        wheel_tf_joints=(
            [geo.joints[w.joint] for w in (left, right) if w.joint in geo.joints]
            if drive.publish_wheel_tf and left is not right
            else []
        ),
    )


def _body_mass(doc: Document, geo: Geometry) -> tuple[float, float | None]:
    """The body's mass (kg) and moment of inertia about the vertical through the root (kg m^2), from
    the ``<inertial>`` of the links rigidly attached to the root (Gazebo lumps those into one body;
    each link's izz moved to the root's axis by the parallel-axis rule). Without any: 1 kg and None."""
    mass, izz = 0.0, 0.0
    for link in geo.body_links():
        el = geo.links.get(link)
        inertial = el.find("inertial") if el is not None else None
        mass_el = inertial.find("mass") if inertial is not None else None
        if inertial is None or mass_el is None:
            continue
        try:
            m = float(mass_el.get("value", ""))
        except ValueError:
            raise doc.error(mass_el, f"link '{link}': <mass value> is not a number") from None
        if not (m >= 0.0 and math.isfinite(m)):
            raise doc.error(mass_el, f"link '{link}': <mass value> must be a finite number >= 0")
        inertia = inertial.find("inertia")
        try:
            i_zz = float(inertia.get("izz", "0")) if inertia is not None else 0.0
        except ValueError:
            raise doc.error(inertia, f"link '{link}': <inertia izz> is not a number") from None
        if not (i_zz >= 0.0 and math.isfinite(i_zz)):
            raise doc.error(inertia, f"link '{link}': <inertia izz> must be a finite number >= 0")
        origin = inertial.find("origin")
        text = origin.get("xyz", "0 0 0") if origin is not None else "0 0 0"
        try:
            ox, oy, oz = ([float(v) for v in text.split()] + [0.0, 0.0, 0.0])[:3]
        except ValueError:
            raise doc.error(origin, f"link '{link}': <inertial><origin xyz> is not three numbers") from None
        cx, cy, _cz = apply(geo.pose_of(link), (ox, oy, oz))  # the centre of mass
        mass += m
        izz += i_zz + m * (cx * cx + cy * cy)
    if mass <= 0.0:
        return 1.0, None
    return mass, (izz if izz > 0.0 else None)


def _control_joints(doc: Document, geo: Geometry, left: Wheel, right: Wheel) -> dict[str, str]:
    """The joints gazebo_ros_control exposes (those named by a <transmission>), each with its side."""
    named = [j.get("name", "") for t in doc.root.findall("transmission") for j in t.findall("joint")]
    mid = (left.pose[1][1] + right.pose[1][1]) / 2.0
    sides: dict[str, str] = {left.joint: "left", right.joint: "right"} if left is not right else {}
    wheel_joints = {w.joint: w for w in geo.wheels} if left is not right else {}
    for name in named:
        if name not in geo.joints:
            for t in doc.root.findall("transmission"):
                for j in t.findall("joint"):
                    if j.get("name") == name:
                        raise doc.error(
                            j, f"transmission '{t.get('name', '')}' names joint '{name}', not in the robot"
                        )
        if name in sides:
            continue
        w = wheel_joints.get(name)
        sides[name] = ("left" if w.pose[1][1] > mid else "right") if w is not None else ""
    return sides


def _wheels(doc: Document, geo: Geometry, cfg: GazeboConfig, drive: DriveSpec) -> tuple[Wheel, Wheel]:
    by_joint = {w.joint: w for w in geo.wheels}
    if cfg.left_joint and cfg.right_joint:
        found = []
        for name in (cfg.left_joint, cfg.right_joint):
            if name in by_joint:
                found.append(by_joint[name])
                continue
            j = geo.joints[name]
            # a drive may turn a revolute joint too; it is a wheel all the same
            found.append(Wheel(name, j.child, compose(geo.pose_of(j.parent), (j.rotation, j.xyz)), None))
        return found[0], found[1]
    wheels = geo.wheels
    if drive.kind == "ros_control" and not drive.wheel_radius:
        # gazebo_ros_control drives whatever joints the controllers name: the continuous joints of an
        # arm (RRBot's) are no wheels, and only a joint with a round collision can roll
        wheels = [w for w in wheels if w.radius]
    if len(wheels) >= 2:
        pair = sorted(wheels, key=lambda w: -w.pose[1][1])
        if len(wheels) > 2 and drive.kind != "none":
            cfg.warnings.append(
                f"{doc.source}: {len(wheels)} continuous joints; {pair[0].joint} and {pair[-1].joint}"
                " are taken as the left and right wheels"
            )
        return pair[0], pair[-1]
    if drive.kind == "ros_control":
        # Gazebo spawns an arm or any other model without wheels under ros_control as well
        cfg.warnings.append(
            f"{doc.source}: no two continuous joints with a cylinder or sphere collision to roll on:"
            " the base stays where it is spawned"
        )
    elif drive.kind in ("diff_drive", "skid_steer"):
        raise doc.error(
            doc.root,
            f"a {drive.kind} robot needs two wheel joints (continuous), found {len(wheels)}",
            "robot",
        )
    ghost = Wheel("", geo.root, IDENTITY, None)
    return ghost, ghost


def _wheel_radius(doc: Document, left: Wheel, right: Wheel, drive: DriveSpec) -> float:
    if left is right:  # no wheels (a passive or wheel-less model): the radius is never used
        return drive.wheel_radius or 0.05
    for w in (left, right):
        if w.radius:
            return w.radius
    if drive.wheel_radius:
        return drive.wheel_radius
    if drive.kind == "none":
        return 0.05
    raise doc.error(
        doc.root,
        f"wheel link '{left.link}' has no collision cylinder or sphere to give the wheel radius",
        "robot",
    )


def _velocity_limit(doc: Document, joint: str) -> float | None:
    for el in doc.root.findall("joint"):
        if el.get("name") == joint:
            lim = el.find("limit")
            if lim is not None and lim.get("velocity"):
                try:
                    v = float(lim.get("velocity", ""))
                except ValueError:
                    raise doc.error(
                        lim, f"joint '{joint}': velocity='{lim.get('velocity')}' is not a number"
                    ) from None
                return v if v > 0 and math.isfinite(v) else None
    return None


def _colour(doc: Document, geo: Geometry, cfg: GazeboConfig) -> tuple[int, int, int]:
    """Gazebo's own ``<material>`` for a body link wins (Gazebo draws that), then the URDF visual's."""
    body = geo.body_links()
    for link in body:
        if link in cfg.materials:
            return cfg.materials[link]
    for link in body:
        rgba = link_colour(geo, doc, link)
        if rgba is not None:
            return (round(rgba[0] * 255), round(rgba[1] * 255), round(rgba[2] * 255))
    return DEFAULT_COLOUR


def expand_xacro(path: str, mappings: dict[str, str] | None = None) -> str:
    """A xacro file expanded as ``xacro path key:=value ...`` would print it."""
    import xacro  # untyped: pyproject lets mypy see it as Any

    try:
        return str(xacro.process_file(path, mappings=dict(mappings or {})).toprettyxml(indent="  "))
    except (xacro.XacroException, OSError) as exc:
        raise DescriptionError(f"{path}: xacro: {exc}") from None


__all__ = ["DescriptionError", "expand_xacro", "has_gazebo_blocks", "model_from_description"]
