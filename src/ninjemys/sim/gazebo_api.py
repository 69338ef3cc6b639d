"""Gazebo's ROS API on the simulator: the ``/gazebo/*`` services and topics gazebo_ros offers.

Services (gazebo_msgs and std_srvs types, Noetic's names and status texts): ``spawn_urdf_model``,
``spawn_sdf_model``, ``delete_model``, ``get_model_state``, ``set_model_state``,
``get_world_properties``, ``get_model_properties``, ``get_link_state``, ``get_physics_properties``,
``set_physics_properties`` (``max_update_rate``: the pace; ``time_step``: the physics step, as Gazebo takes it),
``set_model_configuration``, ``apply_body_wrench`` and ``clear_body_wrenches`` (a push: the body
gains the velocity the force gives its mass over the duration (the URDF's ``<inertial>`` masses of
the links fixed to its base, 1 kg without any), and its wheels stop it when the push ends), ``pause_physics``, ``unpause_physics``, ``reset_simulation``, ``reset_world``. Topics:
``/gazebo/model_states`` and ``/gazebo/link_states`` out (every physics step, while subscribed),
``/gazebo/set_model_state`` in.

The world is flat: a model's pose has no roll or pitch. Its height is where Gazebo's physics leaves
it: a robot stands on the floor (the z of its root link when its wheels touch it, whatever ``-z`` it
was spawned with), a static model stays where it was put, and a model with physics falls onto the
floor or onto what is under it (a box dropped over a table lands on the table top). Models
are the robots (links: the base, the wheels and the sensors) and the static obstacles (one link,
``link``, or the links of an SDF model of several pieces: spawned, moved and deleted whole).
Everything here runs under the simulation's lock; nothing here publishes per robot.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.maps.mapfile import MapFileError
from ninjemys.robot.kinematics import URDFError, parse_urdf
from ninjemys.rostime import Time
from ninjemys.sim.gazebo_materials import stock_colour
from ninjemys.sim.robot_model import load_robot_model, model_from_urdf
from ninjemys.sim.sdf import Support, rest_height, sdf_model_obstacles
from ninjemys.sim.simcore import Robot, SpawnError, wrap_angle
from ninjemys.sim.world2d import Obstacle, box_outline, circle_outline
from ninjemys.tf2.math import quaternion_from_yaw, yaw_from_quaternion

if TYPE_CHECKING:
    from ninjemys.sim.puzzlebot_node import SimNode

Empty: Any = get_service_class("std_srvs/Empty")
SpawnModel: Any = get_service_class("gazebo_msgs/SpawnModel")
DeleteModel: Any = get_service_class("gazebo_msgs/DeleteModel")
GetModelState: Any = get_service_class("gazebo_msgs/GetModelState")
SetModelState: Any = get_service_class("gazebo_msgs/SetModelState")
GetWorldProperties: Any = get_service_class("gazebo_msgs/GetWorldProperties")
GetModelProperties: Any = get_service_class("gazebo_msgs/GetModelProperties")
GetLinkState: Any = get_service_class("gazebo_msgs/GetLinkState")
GetPhysicsProperties: Any = get_service_class("gazebo_msgs/GetPhysicsProperties")
SetPhysicsProperties: Any = get_service_class("gazebo_msgs/SetPhysicsProperties")
ApplyBodyWrench: Any = get_service_class("gazebo_msgs/ApplyBodyWrench")
BodyRequest: Any = get_service_class("gazebo_msgs/BodyRequest")
SetModelConfiguration: Any = get_service_class("gazebo_msgs/SetModelConfiguration")
ModelState: Any = get_message_class("gazebo_msgs/ModelState")
ModelStates: Any = get_message_class("gazebo_msgs/ModelStates")
LinkStates: Any = get_message_class("gazebo_msgs/LinkStates")
Pose: Any = get_message_class("geometry_msgs/Pose")
Twist: Any = get_message_class("geometry_msgs/Twist")

WORLD_FRAMES = ("", "world", "map")
PUSH_INERTIA = 1.0  # kg m^2: what a torque turns when the description gives no inertia

#: a planar pose: x, y, z (the height it was spawned at), yaw
Planar = tuple[float, float, float, float]


@dataclass
class Push:
    """An apply_body_wrench in progress: a force (world frame) and torque about z, from ``start``
    to ``end`` in sim seconds (``end`` None: until cleared or reset); ``velocity`` is what it gave."""

    fx: float
    fy: float
    tz: float
    start: float
    end: float | None
    vx: float = 0.0
    vy: float = 0.0
    w: float = 0.0


def _pose_msg(p: Planar) -> Any:
    msg = Pose()
    msg.position.x, msg.position.y, msg.position.z = p[0], p[1], p[2]
    q = msg.orientation
    q.x, q.y, q.z, q.w = quaternion_from_yaw(p[3])
    return msg


def _twist_msg(vx: float, vy: float, w: float) -> Any:
    msg = Twist()
    msg.linear.x, msg.linear.y = vx, vy
    msg.angular.z = w
    return msg


def _planar(pose: Any) -> Planar:
    q = pose.orientation
    yaw = yaw_from_quaternion(q.x, q.y, q.z, q.w) if (q.x, q.y, q.z, q.w) != (0, 0, 0, 0) else 0.0
    return pose.position.x, pose.position.y, pose.position.z, yaw


def relative(pose: Planar, ref: Planar) -> Planar:
    """``pose`` seen from ``ref`` (both in the world frame)."""
    c, s = math.cos(ref[3]), math.sin(ref[3])
    dx, dy = pose[0] - ref[0], pose[1] - ref[1]
    return c * dx + s * dy, -s * dx + c * dy, pose[2] - ref[2], wrap_angle(pose[3] - ref[3])


def compose(ref: Planar, pose: Planar) -> Planar:
    """``pose`` given in ``ref``'s frame, in the world frame."""
    c, s = math.cos(ref[3]), math.sin(ref[3])
    return (
        ref[0] + c * pose[0] - s * pose[1],
        ref[1] + s * pose[0] + c * pose[1],
        ref[2] + pose[2],
        wrap_angle(ref[3] + pose[3]),
    )


class GazeboApi:
    """The ``/gazebo`` services and topics of one simulator node."""

    def __init__(self, sim_node: SimNode) -> None:
        self.sn = sim_node
        self.heights: dict[str, float] = {}  # model -> the z it was spawned at
        self.spawned: dict[str, None] = {}  # the models spawned since the start, in order (robots aside)
        world = sim_node.sim.world
        #: models with nothing the floor plan holds (a ground plane): Gazebo lists them all the same
        self.bare: dict[str, Planar] = {
            name: (
                *world.model_poses[name][:2],
                world.model_heights.get(name, 0.0),
                world.model_poses[name][2],
            )
            for name in world.bare_models
            if name in world.model_poses
        }
        self.pushes: dict[str, Push] = {}
        #: models with physics (they fall when put in the air): the world file's, then spawned ones
        self.dynamic: set[str] = set(world.dynamic_models)
        #: models spawned or set while physics is paused, and the z they were put at: Gazebo reports
        #: that pose until physics runs again (they settle then)
        self.unsettled: dict[str, float] = {}
        n = sim_node.node
        for name, cls, handler in (
            ("reset_simulation", Empty, self._reset_simulation),
            ("reset_world", Empty, self._reset_world),
            ("pause_physics", Empty, self._pause),
            ("unpause_physics", Empty, self._unpause),
            ("spawn_urdf_model", SpawnModel, self._spawn),
            ("spawn_sdf_model", SpawnModel, self._spawn),
            ("delete_model", DeleteModel, self._delete),
            ("get_model_state", GetModelState, self._get_model_state),
            ("set_model_state", SetModelState, self._set_model_state),
            ("get_world_properties", GetWorldProperties, self._get_world_properties),
            ("get_model_properties", GetModelProperties, self._get_model_properties),
            ("get_link_state", GetLinkState, self._get_link_state),
            ("get_physics_properties", GetPhysicsProperties, self._get_physics_properties),
            ("set_physics_properties", SetPhysicsProperties, self._set_physics_properties),
            ("apply_body_wrench", ApplyBodyWrench, self._apply_body_wrench),
            ("clear_body_wrenches", BodyRequest, self._clear_body_wrenches),
            ("set_model_configuration", SetModelConfiguration, self._set_model_configuration),
        ):
            n.service("/gazebo/" + name, cls, handler)
        self.model_states_pub = n.publisher("/gazebo/model_states", ModelStates, queue_size=1)
        self.link_states_pub = n.publisher("/gazebo/link_states", LinkStates, queue_size=1)
        self.set_state_sub = n.subscriber("/gazebo/set_model_state", ModelState, self._on_set_model_state)

    # -- the model tree ----------------------------------------------------------------------------
    def model_names(self) -> list[str]:
        """Gazebo's order: the world file's models as the file has them (a ground plane first, as
        empty_world's is), then the models spawned since, then the robots."""
        sim = self.sn.sim
        solid = dict.fromkeys(o.model_name for o in sim.world.obstacles)
        exists = [*sim.world.model_poses, *self.spawned, *solid, *self.bare]
        return [n for n in dict.fromkeys(exists) if n in solid or n in self.bare] + list(sim.robots)

    def obstacle_links(self, name: str) -> dict[str, list[str]]:
        """A static model's links and, per link, its collisions (``link`` for a model of one piece)."""
        if name in self.bare:
            return {"link": ["collision"]}  # a ground plane's one link and its plane
        links: dict[str, list[str]] = {}
        for o in self.sn.sim.world.obstacles:
            if o.model_name != name:
                continue
            if not o.model:
                links.setdefault("link", []).append("collision")
                continue
            parts = o.name.partition("#")[0].split("::")
            link, geom = (parts[-2], parts[-1]) if len(parts) >= 3 else ("link", parts[-1])
            if geom not in links.setdefault(link, []):
                links[link].append(geom)
        return links

    def model_pose(self, name: str) -> Planar | None:
        pose = self.settled_pose(name)
        held = self.unsettled.get(name)
        if pose is None or held is None:
            return pose
        return pose[0], pose[1], held, pose[3]  # paused: still where it was put

    def settled_pose(self, name: str) -> Planar | None:
        """A model's pose once physics has run: where it landed."""
        sim = self.sn.sim
        if name in self.bare:
            return self.bare[name]
        r = sim.robots.get(name)
        if r is not None:
            # a robot stands on the floor or on what it landed on, whatever height it was spawned or
            # set at (Gazebo drops it)
            return r.x, r.y, r.model.rest_z + r.elevation, r.yaw
        try:
            x, y, yaw = sim.obstacle_pose(name)
        except SpawnError:
            return None
        z = self.heights.get(name)
        if z is None:  # one of the world file's models, where it settled
            z = sim.world.model_heights.get(name, 0.0)
        return x, y, z, yaw

    def model_twist(self, name: str) -> tuple[float, float, float]:
        r = self.sn.sim.robots.get(name)
        if r is None:
            return 0.0, 0.0, 0.0
        push = self.pushes.get(name)
        vx, vy, w = r.v * math.cos(r.yaw), r.v * math.sin(r.yaw), r.w
        if push is not None:
            vx, vy, w = vx + push.vx, vy + push.vy, w + push.w
        return vx, vy, w

    @staticmethod
    def robot_links(r: Robot) -> dict[str, Planar]:
        """A robot's links in its model's frame (the root link, ``rest_z`` above the floor): the base,
        the wheels (their axles a wheel radius above the floor) and the sensors (their poses are
        kept above the floor)."""
        m = r.model
        links: dict[str, Planar] = {m.drive.base_frame: (0.0, 0.0, 0.0, 0.0)}
        half = m.wheel_separation / 2.0
        for joint, side in ((m.left_joint, half), (m.right_joint, -half)):
            links[joint.removesuffix("_joint")] = (0.0, side, m.wheel_radius - m.rest_z, 0.0)
        for spec in (m.laser, m.camera, m.imu):
            if spec is not None:
                xyz, rpy = spec.pose.xyz, spec.pose.rpy
                links[spec.pose.frame] = (xyz[0], xyz[1], xyz[2] - m.rest_z, rpy[2])
        return links

    def links(self, model: str) -> dict[str, Planar] | None:
        """A model's links, in the world frame (None: no such model)."""
        pose = self.model_pose(model)
        if pose is None:
            return None
        r = self.sn.sim.robots.get(model)
        if r is None:
            # a static model's links: at its pose (the pieces' own offsets are in their outlines)
            return dict.fromkeys(self.obstacle_links(model), pose)
        return {name: compose(pose, rel) for name, rel in self.robot_links(r).items()}

    def entity_pose(self, name: str) -> Planar | None:
        """A model (``name``) or a link (``model::link``), in the world frame."""
        model, _, link = name.partition("::")
        if not link:
            return self.model_pose(model)
        links = self.links(model)
        return None if links is None else links.get(link)

    def _supports(self, x: float, y: float, yaw: float) -> list[Support]:
        """The world's pieces as a model spawned at (x, y, yaw) sees them from its own frame: what it
        may land on when it falls (call with the sim lock held)."""
        c, s = math.cos(yaw), math.sin(yaw)
        out = []
        for o in self.sn.sim.world.obstacles:
            if not o.solid:
                continue  # a visual without collision holds nothing up
            dx, dy = o.outline[:, 0] - x, o.outline[:, 1] - y
            out.append(Support(np.column_stack([c * dx + s * dy, -s * dx + c * dy]), o.height))
        return out

    # -- services ----------------------------------------------------------------------------------
    def _reset_simulation(self, _req: Any) -> Any:
        with self.sn.lock:
            self.sn.sim.reset_simulation()
            self.pushes.clear()
            self.sn.after_reset()
        self.sn.log.info("simulation reset: time and robots back to the start")
        return Empty._response_class()

    def _reset_world(self, _req: Any) -> Any:
        with self.sn.lock:
            self.sn.sim.reset_world()
            self.pushes.clear()
            self.sn.after_reset()
        self.sn.log.info("world reset: robots back to their start poses")
        return Empty._response_class()

    def _pause(self, _req: Any) -> Any:
        self.sn.stepper.set_paused(True)
        return Empty._response_class()

    def _unpause(self, _req: Any) -> Any:
        with self.sn.lock:
            self.unsettled.clear()  # physics runs: what was put in the air while paused lands
        self.sn.stepper.set_paused(False)
        return Empty._response_class()

    def hold_world_models(self) -> None:
        """A world loaded with physics paused (``paused:=true``): its models with physics are where
        the file puts them until unpause_physics, as Gazebo shows them."""
        world = self.sn.sim.world
        with self.sn.lock:
            self.unsettled.update(world.placed_heights)

    def _hold_while_paused(self, name: str, z: float) -> None:
        """Gazebo's physics settles nothing while paused: remember the z a model was put at."""
        if self.sn.paused:
            self.unsettled[name] = z
        else:
            self.unsettled.pop(name, None)

    def _robot_level(self, model: Any, x: float, y: float, z: float) -> float:
        """Where a robot put at height ``z`` (its root link's) lands: the highest top under its
        centre below its body's middle (a table top it was dropped over), else the floor."""
        bottom = z - model.rest_z
        return self.sn.sim.ground_under(x, y, bottom + model.body_height / 2.0)

    def _obstacle_landing(self, name: str) -> Any:
        """How far a model with physics falls from where its pieces were put: onto the highest top
        under it (the other models' pieces), else the floor (rest_height's rule)."""
        ground = [
            Support(o.outline, o.height)
            for o in self.sn.sim.world.obstacles
            if o.model_name != name and len(o.outline) > 2 and o.solid
        ]

        def land(pieces: list[Obstacle]) -> float:
            return min(p.base - rest_height(p.outline, p.base, p.height, ground) for p in pieces)

        return land

    def _spawn(self, req: Any) -> Any:
        resp = SpawnModel._response_class()
        name = req.model_name.strip()
        sn = self.sn
        try:
            if not name or not name.replace("_", "a").isalnum() or not name[0].isalpha():
                raise SpawnError(f"model_name [{req.model_name}] is not a valid ROS name")
            if name in self.model_names():
                resp.success, resp.status_message = False, "SpawnModel: Failure - entity already exists."
                sn.log.error("SpawnModel: Failure - model name %s already exist.", name)
                return resp
            pose = _planar(req.initial_pose)
            if req.reference_frame not in WORLD_FRAMES:
                ref = self.entity_pose(req.reference_frame)
                if ref is None:
                    resp.success = False
                    resp.status_message = "SpawnModel: reference reference_frame not found, did you forget to scope the link by model name?"
                    return resp
                pose = compose(ref, pose)
            x, y, z, yaw = pose
            drops: dict[str, float] = {}
            models: list[str] = []
            with sn.lock:
                supports = self._supports(x, y, yaw)
            kind, spec = parse_model_xml(req.model_xml, z, drops, supports, models)
            if kind == "robot":
                namespace = req.robot_namespace.strip("/")
                clash = any(io.prefix == "" for io in sn.io.values())
                with sn.lock:
                    level = self._robot_level(spec, x, y, z)
                self._hold_while_paused(name, z)
                sn.add_robot(name, spec, x, y, yaw, clash and not namespace, namespace or None, level)
                # it falls onto the floor or a table top (or is pushed up out of it) on its wheels
                z = spec.rest_z + level
            elif kind == "sdf":
                if not spec:
                    if models:  # a ground plane: a model all the same, with nothing the floor plan holds
                        self.bare[name] = (x, y, z, yaw)
                        self.spawned[name] = None
                        sn.log.info(
                            "model [%s] has no collision this simulator sees: listed, nothing added", name
                        )
                    else:  # a light (Gazebo's sun): not a model
                        sn.log.info("[%s] is a light: nothing added", name)
                    return _spawned(resp)
                pieces = _placed(name, spec, x, y, yaw)
                with sn.lock:
                    sn.sim.add_model(name, pieces, yaw, (x, y))
                self._hold_while_paused(name, z)
                if drops:
                    self.dynamic.add(name)
                z -= max(drops.values(), default=0.0)  # a model with physics settles on what is under it
                what = pieces[0].kind if len(pieces) == 1 else f"{len(pieces)} pieces"
                sn.log.info("spawned SDF model [%s] (%s) at (%.3f, %.3f, %.3f)", name, what, x, y, z)
            else:
                self._hold_while_paused(name, z)
                z = self._add_urdf_shape(name, spec, x, y, z, yaw, supports)
                if not spec.static and spec.solid:
                    self.dynamic.add(name)
            self.heights[name] = z
            if kind != "robot":
                self.spawned[name] = None
        except (SpawnError, MapFileError) as exc:
            sn.log.error("spawn refused: %s", exc)
            resp.success, resp.status_message = False, f"SpawnModel: Failure - {exc}"
            return resp
        return _spawned(resp)

    def _add_urdf_shape(
        self, name: str, shape: UrdfShape, x: float, y: float, z: float, yaw: float, supports: list[Support]
    ) -> float:
        """Place a URDF box or cylinder: a static one at ``z``, one with physics on the floor or on
        what is under it; returns its model's z as Gazebo reports it then."""
        sim = self.sn.sim
        outline = (
            circle_outline(x, y, shape.size[0])
            if shape.kind == "cylinder"
            else box_outline(x, y, shape.size[0], shape.size[1], yaw)
        )
        base = z + shape.bottom
        if not shape.static and shape.solid:
            c, s = math.cos(yaw), math.sin(yaw)
            dx, dy = outline[:, 0] - x, outline[:, 1] - y
            local = np.column_stack([c * dx + s * dy, -s * dx + c * dy])
            base = rest_height(local, base, base + shape.height, supports)
            z = base - shape.bottom
        top = base + shape.height
        if top <= 0.0:
            raise SpawnError(f"a static {shape.kind} at z {z:g} is under the floor")
        with self.sn.lock:
            sim.add_outline(name, shape.kind, outline, yaw, top, shape.colour, max(base, 0.0), shape.solid)
        self.sn.log.info("spawned %s [%s] at (%.3f, %.3f, %.3f)", shape.kind, name, x, y, z)
        return z

    def _delete(self, req: Any) -> Any:
        resp = DeleteModel._response_class()
        name = req.model_name
        sn = self.sn
        try:
            if name in self.bare:
                del self.bare[name]
            elif name in sn.sim.robots:
                sn.remove_robot(name)
            else:
                with sn.lock:
                    sn.sim.remove_obstacle(name)
        except SpawnError as exc:
            sn.log.error("DeleteModel: model [%s] does not exist", name)
            resp.success, resp.status_message = False, f"DeleteModel: model does not exist ({exc})"
            return resp
        self.heights.pop(name, None)
        self.pushes.pop(name, None)
        self.spawned.pop(name, None)
        self.unsettled.pop(name, None)
        self.dynamic.discard(name)
        sn.log.info("deleted model [%s]", name)
        resp.success, resp.status_message = True, "DeleteModel: successfully deleted model"
        return resp

    def _get_model_state(self, req: Any) -> Any:
        resp = GetModelState._response_class()
        with self.sn.lock:
            pose = self.model_pose(req.model_name)
            if pose is None:
                self.sn.log.error("GetModelState: model [%s] does not exist", req.model_name)
                resp.success, resp.status_message = False, "GetModelState: model does not exist"
                return resp
            vx, vy, w = self.model_twist(req.model_name)
            frame = req.relative_entity_name
            if frame not in WORLD_FRAMES:
                ref = self.entity_pose(frame)
                if ref is None:
                    resp.success = False
                    resp.status_message = "GetModelState: reference relative_entity_name not found, did you forget to scope the body by model name?"
                    return resp
                pose = relative(pose, ref)
                c, s = math.cos(ref[3]), math.sin(ref[3])
                vx, vy = c * vx + s * vy, -s * vx + c * vy
            resp.header.stamp = self.sn._stamp()
            resp.header.frame_id = frame
            resp.pose = _pose_msg(pose)
            resp.twist = _twist_msg(vx, vy, w)
        resp.success, resp.status_message = True, "GetModelState: got properties"
        return resp

    def set_model_state(self, state: Any) -> tuple[bool, str]:
        """Move a model (Gazebo's set_model_state): (success, status_message)."""
        sn = self.sn
        name = state.model_name
        with sn.lock:
            if self.model_pose(name) is None:
                sn.log.error("Updating ModelState: model [%s] does not exist", name)
                return False, "SetModelState: model does not exist"
            pose = _planar(state.pose)
            if state.reference_frame not in WORLD_FRAMES:
                ref = self.entity_pose(state.reference_frame)
                if ref is None:
                    return False, "SetModelState: specified reference frame entity does not exist"
                pose = compose(ref, pose)
            x, y, z, yaw = pose
            put_at = z
            try:
                if name in self.bare:
                    self.bare[name] = (x, y, z, yaw)
                elif name in sn.sim.robots:
                    model = sn.sim.robots[name].model
                    r = sn.sim.place_robot(name, x, y, yaw, self._robot_level(model, x, y, z))
                    lin, ang = state.twist.linear, state.twist.angular
                    if all(math.isfinite(v) for v in (lin.x, lin.y, ang.z)):
                        # the twist, in the robot's own terms: forward speed and turn rate
                        forward = lin.x * math.cos(yaw) + lin.y * math.sin(yaw)
                        r.command(forward, ang.z)
                else:
                    before = self.settled_pose(name)
                    assert before is not None
                    land = self._obstacle_landing(name) if name in self.dynamic else None
                    # a static model is held where it is put; one with physics falls from there
                    z = before[2] + sn.sim.move_obstacle(name, x, y, yaw, z - before[2], land)
            except SpawnError as exc:
                sn.log.error("SetModelState refused: %s", exc)
                return False, f"SetModelState: {exc}"
            self.heights[name] = z
            self._hold_while_paused(name, put_at)
            self.pushes.pop(name, None)
        return True, "SetModelState: set model state done"

    def _set_model_state(self, req: Any) -> Any:
        resp = SetModelState._response_class()
        resp.success, resp.status_message = self.set_model_state(req.model_state)
        return resp

    def _on_set_model_state(self, msg: Any) -> None:
        ok, status = self.set_model_state(msg)
        if not ok:
            self.sn.log.warn("/gazebo/set_model_state: %s", status)

    def _get_world_properties(self, _req: Any) -> Any:
        resp = GetWorldProperties._response_class()
        with self.sn.lock:
            resp.sim_time = self.sn.sim.time
            resp.model_names = self.model_names()
        resp.rendering_enabled = True
        resp.success, resp.status_message = True, "GetWorldProperties: got properties"
        return resp

    def _get_model_properties(self, req: Any) -> Any:
        resp = GetModelProperties._response_class()
        with self.sn.lock:
            name = req.model_name
            if self.model_pose(name) is None:
                self.sn.log.error("GetModelProperties: model [%s] does not exist", name)
                resp.success, resp.status_message = False, "GetModelProperties: model does not exist"
                return resp
            r = self.sn.sim.robots.get(name)
            resp.parent_model_name = ""
            if r is not None:
                bodies = list(self.robot_links(r))
                resp.geom_names = [f"{b}_collision" for b in bodies]
            else:
                links = self.obstacle_links(name)
                bodies = list(links)
                resp.geom_names = [g for geoms in links.values() for g in geoms]
            resp.canonical_body_name = bodies[0]
            resp.body_names = bodies
            resp.joint_names = [r.model.left_joint, r.model.right_joint] if r is not None else []
            resp.child_model_names = []
            resp.is_static = r is None
        resp.success, resp.status_message = True, "GetModelProperties: got properties"
        return resp

    def _get_link_state(self, req: Any) -> Any:
        resp = GetLinkState._response_class()
        not_found = "GetLinkState: link not found, did you forget to scope the link by model name?"
        with self.sn.lock:
            model, _, link = req.link_name.partition("::")
            links = self.links(model) if link else None
            pose = links.get(link) if links is not None else None
            if pose is None:
                resp.success, resp.status_message = False, not_found
                return resp
            vx, vy, w = self.model_twist(model)
            if req.reference_frame not in WORLD_FRAMES:
                ref = self.entity_pose(req.reference_frame)
                if ref is None:
                    resp.success = False
                    resp.status_message = "GetLinkState: reference reference_frame not found, did you forget to scope the link by model name?"
                    return resp
                pose = relative(pose, ref)
            state = resp.link_state
            state.link_name = req.link_name
            state.pose = _pose_msg(pose)
            state.twist = _twist_msg(vx, vy, w)
            state.reference_frame = req.reference_frame
        resp.success, resp.status_message = True, "GetLinkState: got state"
        return resp

    def _get_physics_properties(self, _req: Any) -> Any:
        resp = GetPhysicsProperties._response_class()
        resp.time_step = self.sn.sim.dt
        resp.pause = self.sn.paused
        rate = self.sn.rate
        resp.max_update_rate = rate / self.sn.sim.dt if rate > 0 else 0.0
        resp.gravity.z = -9.8
        resp.success, resp.status_message = True, "GetPhysicsProperties: got properties"
        return resp

    def _set_physics_properties(self, req: Any) -> Any:
        """Gazebo's pacing knobs: ``time_step`` (the physics step, seconds; 0 keeps it) and
        ``max_update_rate`` steps per wall second (0: as fast as possible), so the real-time factor
        is max_update_rate x time_step, as in Gazebo. Time goes on from where it is; sensors keep
        their rates (each fires at the first step at or after it is due). Gravity and ODE's
        solver settings have nothing to act on in this kinematic simulator and are left alone."""
        resp = SetPhysicsProperties._response_class()
        sn = self.sn
        rate = req.max_update_rate
        if not math.isfinite(rate) or rate < 0:
            resp.success, resp.status_message = (
                False,
                f"SetPhysicsProperties: max_update_rate {rate} must be >= 0",
            )
            return resp
        step = req.time_step
        with sn.lock:
            if step and abs(step - sn.sim.dt) > 1e-15:
                try:
                    sn.sim.set_time_step(step)
                except SpawnError as exc:
                    resp.success, resp.status_message = False, f"SetPhysicsProperties: {exc}"
                    return resp
                sn.stepper.dt = step
                sn.log.info("physics: time_step %g s", step)
            dt = sn.sim.dt
        sn.stepper.set_rate(rate * dt)
        sn.log.info(
            "physics: max_update_rate %g (real-time factor %s)",
            rate,
            f"{rate * dt:g}" if rate else "unlimited",
        )
        resp.success, resp.status_message = True, "physics engine updated"
        return resp

    def _apply_body_wrench(self, req: Any) -> Any:
        resp = ApplyBodyWrench._response_class()
        sn = self.sn
        model = req.body_name.partition("::")[0]
        with sn.lock:
            pose = self.entity_pose(req.body_name)
            if pose is None:
                sn.log.error("ApplyBodyWrench: body [%s] does not exist", req.body_name)
                resp.success, resp.status_message = False, "ApplyBodyWrench: body does not exist"
                return resp
            f, t = req.wrench.force, req.wrench.torque
            fx, fy = f.x, f.y
            if req.reference_frame not in WORLD_FRAMES:
                ref = self.entity_pose(req.reference_frame)
                if ref is None:
                    sn.log.error("ApplyBodyWrench: reference_frame is not a valid entity name")
                    resp.success, resp.status_message = False, "ApplyBodyWrench: reference_frame not found"
                    return resp
                c, s = math.cos(ref[3]), math.sin(ref[3])
                fx, fy = c * f.x - s * f.y, s * f.x + c * f.y
            if not all(math.isfinite(v) for v in (fx, fy, t.z)):
                resp.success, resp.status_message = False, "ApplyBodyWrench: the wrench is not finite"
                return resp
            now = sn.sim.time
            start = max(req.start_time.to_sec(), now) if req.start_time.to_sec() > 0 else now
            duration = req.duration.to_sec()
            end = None if duration < 0 else start + duration
            if model in sn.sim.robots:  # static obstacles do not move, as Gazebo's static models
                self.pushes[model] = Push(fx, fy, t.z, start, end)
        resp.success, resp.status_message = True, ""
        return resp

    def _clear_body_wrenches(self, req: Any) -> Any:
        with self.sn.lock:
            self.pushes.pop(req.body_name.partition("::")[0], None)
        return BodyRequest._response_class()

    def _set_model_configuration(self, req: Any) -> Any:
        resp = SetModelConfiguration._response_class()
        with self.sn.lock:
            r = self.sn.sim.robots.get(req.model_name)
            if r is None:
                self.sn.log.error("SetModelConfiguration: model [%s] does not exist", req.model_name)
                resp.success, resp.status_message = False, "SetModelConfiguration: model does not exist"
                return resp
            if len(req.joint_names) != len(req.joint_positions):
                resp.success = False
                resp.status_message = (
                    "SetModelConfiguration: joint name and position list have different lengths"
                )
                return resp
            for joint, position in zip(req.joint_names, req.joint_positions, strict=True):
                if joint == r.model.left_joint:
                    r.left_angle = position
                elif joint == r.model.right_joint:
                    r.right_angle = position
        resp.success, resp.status_message = True, "SetModelConfiguration: success"
        return resp

    # -- every step ----------------------------------------------------------------------------------
    def before_step(self) -> None:
        """Apply the pushes due now (the stepping thread, under the lock)."""
        if not self.pushes:
            return
        sim = self.sn.sim
        now, dt = sim.time, sim.dt
        for name, push in list(self.pushes.items()):
            r = sim.robots.get(name)
            if r is None or (push.end is not None and now >= push.end):
                del self.pushes[name]  # the push is over: the wheels' grip stops the slide
                continue
            if now < push.start:
                continue
            mass, inertia = r.model.mass, r.model.inertia_z or PUSH_INERTIA
            push.vx += push.fx / mass * dt
            push.vy += push.fy / mass * dt
            push.w += push.tz / inertia * dt
            try:
                sim.place_robot(name, r.x + push.vx * dt, r.y + push.vy * dt, r.yaw + push.w * dt)
            except SpawnError:
                del self.pushes[name]  # pushed against something: it stops there
                r.contact = True
                self.sn.log.warn("robot [%s] pushed into an obstacle: stopped", name)

    def after_step(self, stamp: Time) -> None:
        """Publish /gazebo/model_states and /gazebo/link_states to whoever listens (every step: who
        listens is read from the publications' connection tuples, without a call)."""
        model_pub, link_pub = self.model_states_pub.publication, self.link_states_pub.publication
        if model_pub.connections or model_pub.intra:
            names = self.model_names()
            poses = [self.model_pose(n) for n in names]
            self.model_states_pub.publish(
                ModelStates(
                    name=names,
                    pose=[_pose_msg(p) for p in poses if p is not None],
                    twist=[_twist_msg(*self.model_twist(n)) for n in names],
                )
            )
        if link_pub.connections or link_pub.intra:
            names, poses, twists = [], [], []
            for model in self.model_names():
                links = self.links(model) or {}
                twist = _twist_msg(*self.model_twist(model))
                for link, pose in links.items():
                    names.append(f"{model}::{link}")
                    poses.append(_pose_msg(pose))
                    twists.append(twist)
            self.link_states_pub.publish(LinkStates(name=names, pose=poses, twist=twists))


def _spawned(resp: Any) -> Any:
    resp.success, resp.status_message = True, "SpawnModel: Successfully spawned entity"
    return resp


def _placed(name: str, pieces: list[Obstacle], x: float, y: float, yaw: float) -> list[Obstacle]:
    """An SDF model's pieces (outlines in the model's frame) at the spawn pose, named as Gazebo
    names them: the model's name for a model of one piece, ``name::link::collision`` otherwise."""
    c, s = math.cos(yaw), math.sin(yaw)
    placed = []
    for piece in pieces:
        rel = piece.outline
        outline = np.column_stack([x + c * rel[:, 0] - s * rel[:, 1], y + s * rel[:, 0] + c * rel[:, 1]])
        if len(pieces) == 1:
            placed.append(replace(piece, name=name, outline=outline, model=""))
        else:
            scoped = piece.name.partition("::")[2] if piece.model else piece.name
            placed.append(replace(piece, name=f"{name}::{scoped}", outline=outline, model=name))
    return placed


def parse_model_xml(
    text: str,
    z: float = 0.0,
    drops: dict[str, float] | None = None,
    supports: list[Support] | None = None,
    models: list[str] | None = None,
) -> tuple[str, Any]:
    """What a SpawnModel request's ``model_xml`` describes: ("robot", RobotModel),
    ("obstacle", UrdfShape) for a URDF box or cylinder, or ("sdf", [Obstacle])
    for an SDF document (a ``<model>``, or spawn_model -database's ``<world>`` of one ``model://``
    include, found on GAZEBO_MODEL_PATH or among the shipped models), its pieces in the model's
    frame with their heights as the model settles when spawned at height ``z`` (static: held there;
    else on the floor; ``drops``: how far it fell), none for a model with nothing solid (a light, a
    ground plane; ``supports``: what it may land on besides the floor). Empty text or ``puzzlebot``
    is the PuzzleBot."""
    body = text.strip()
    if not body:
        return "robot", load_robot_model("puzzlebot")
    if not body.startswith("<"):
        return "robot", load_robot_model(body)
    try:
        root = ET.fromstring(body)
    except ET.ParseError as exc:
        raise SpawnError(f"model_xml is not valid XML: {exc}") from None
    if root.tag == "robot":
        try:  # Gazebo's URDF import goes through urdfdom: what it refuses is never spawned
            parse_urdf(body, "model_xml")
        except URDFError as exc:
            raise SpawnError(str(exc)) from None
    if root.tag == "sdf":
        # SdfError (a MapFileError) names the element and the reason
        return "sdf", sdf_model_obstacles(body, z=z, drops=drops, supports=supports, models=models)
    if root.tag == "robot" and any(j.get("type") == "continuous" for j in root.iter("joint")):
        # a robot with wheels: the URDF reader says what it is, or why it cannot be simulated
        return "robot", model_from_urdf(body, "model_xml")
    shape = _urdf_shape(root)
    if shape is not None:
        return "obstacle", shape
    raise SpawnError(
        "model_xml describes neither a differential-drive robot (URDF with 2 continuous joints) nor a box or cylinder"
    )


@dataclass
class UrdfShape:
    """A URDF model of one box or cylinder (no wheels): a body that falls (or, ``<static>`` in a
    ``<gazebo>`` block, stays where it is spawned)."""

    kind: str  # box | cylinder
    size: tuple[float, float]  # box: length, width; cylinder: radius, radius
    height: float
    colour: tuple[int, int, int]
    bottom: float  # its collision's lowest point in the model's frame (the origin's z - height / 2)
    static: bool
    #: False: a visual without a collision (a marker board): seen by cameras only, held where put
    solid: bool = True


#: a URDF shape without a colour of its own is drawn as the simulator's boxes and cylinders are
_URDF_COLOURS = {"box": (180, 130, 80), "cylinder": (60, 90, 200)}


def _urdf_shape(root: ET.Element) -> UrdfShape | None:
    """The first box or cylinder collision (else visual) of a URDF, its colour (a ``<gazebo>``
    block's stock material, else the visual's ``<color rgba>``) and whether Gazebo holds it still."""
    found: tuple[ET.Element, ET.Element] | None = None
    for tag in ("collision", "visual"):
        for holder in root.iter(tag):
            geom = holder.find("geometry")
            if geom is not None and (geom.find("box") is not None or geom.find("cylinder") is not None):
                found = (holder, geom)
                break
        if found is not None:
            break
    if found is None:
        return None
    holder, geom = found
    solid = holder.tag == "collision"
    origin = holder.find("origin")
    xyz = (origin.get("xyz") if origin is not None else None) or "0 0 0"
    try:
        oz = float(xyz.split()[2])
    except (ValueError, IndexError):
        raise SpawnError(f"<{holder.tag}><origin xyz> {xyz!r} is not three numbers") from None
    box = geom.find("box")
    if box is not None:
        size_text = box.get("size") or (box.findtext("size") or "")
        try:
            sx, sy, sz = (float(v) for v in size_text.split())
        except ValueError:
            raise SpawnError(f"box size {size_text!r} is not three numbers") from None
        kind, size, height = "box", (sx, sy), sz
    else:
        cyl = geom.find("cylinder")
        assert cyl is not None
        try:
            radius = float(cyl.get("radius") or cyl.findtext("radius") or "")
            length = float(cyl.get("length") or cyl.findtext("length") or "")
        except ValueError:
            raise SpawnError("cylinder needs numeric radius and length") from None
        kind, size, height = "cylinder", (radius, radius), length
    colour = _URDF_COLOURS[kind]
    rgba = root.find(".//visual/material/color")
    if rgba is not None:
        try:
            r, g, b = (min(max(float(v), 0.0), 1.0) for v in (rgba.get("rgba") or "").split()[:3])
            colour = (round(r * 255), round(g * 255), round(b * 255))
        except ValueError:
            raise SpawnError(f"<color rgba> {rgba.get('rgba')!r} is not four numbers in 0-1") from None
    static = False
    for block in root.findall("gazebo"):
        stock = stock_colour(block.findtext("material") or "")
        if stock is not None:
            colour = stock
        if (block.findtext("static") or "").strip().lower() in ("true", "1"):
            static = True
    return UrdfShape(kind, size, height, colour, oz - height / 2.0, static, solid)
