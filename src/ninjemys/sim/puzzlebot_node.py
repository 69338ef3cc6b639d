"""``rosrun puzzlebot_sim sim_node``: the PuzzleBot simulator as a ROS node (the role Gazebo plays).

It binds one :class:`~ninjemys.sim.simcore.Simulation` to ROS names; the pacing is
:mod:`~ninjemys.sim.stepper`'s, the messages are built by :mod:`~ninjemys.sim.messages` and the
``/gazebo/*`` services and topics live in :mod:`~ninjemys.sim.gazebo_api`. Per robot (relative names,
under ``<robot>/`` when the world has several robots or a spawned robot would clash with one, or under
a spawn's ``robot_namespace``), with our PuzzleBot's names by default and a description's drive and
sensor plugins' names otherwise: ``cmd_vel`` in; ``wl``, ``wr`` (std_msgs/Float32, rad/s),
``joint_states``, ``odom``, ``base_pose_ground_truth``, ``scan``, ``imu``, ``camera/color/image_raw``
(rgb8, and its ``/compressed``), ``camera/depth/image_rect_raw`` (16UC1, mm),
``camera/color/camera_info``, ``camera/depth/camera_info`` and ``contact`` (std_msgs/Bool, latched)
out. Global: ``/clock``, ``/tf`` (odom -> base_link), ``/tf_static`` (base_link -> sensors, for our
own descriptions; a URDF robot's come from robot_state_publisher, as in Gazebo).

Private parameters: ``~world`` (a shipped world name or a path; default ``square``), ``~map`` (a
map_server YAML used as the world instead), ``~rate`` (real-time factor; 0 runs as fast as
possible), ``~x ~y ~yaw`` (start pose of the first robot), ``~model`` (``puzzlebot``, a YAML or URDF
path), ``~update_rate`` (physics steps per simulated second, default 100), ``~seed`` (noise),
``~odom_alpha`` (amcl's α1-α4), ``~laser_noise``, ``~gui`` (serve the browser view),
``~pub_clock_frequency`` (/clock messages per simulated second; default
``/gazebo/pub_clock_frequency``, else 0: every physics step, as gazebo_ros),
``~cmd_vel_timeout`` (simulated seconds without a command after which the wheels are stopped, as
diff_drive_controller's ``cmd_vel_timeout`` does; default 0: off, the last command holds, as with
Gazebo's diff drive plugin), ``~no_robot`` (start with an empty world: robots come from
``spawn_model``, as in Gazebo), ``~paused`` (start with physics paused, Gazebo's ``-u``).

The first robot's names and sensors, as a student's launch file sets them (defaults: the model's):
``~cmd_vel_topic``, ``~publish_odom``, ``~publish_odom_tf``, ``~odom_topic``, ``~odom_frame``,
``~base_frame``, ``~scan_topic``, ``~scan_beams``, ``~scan_angle_min``, ``~scan_angle_max``,
``~image_topic``, ``~camera_info_topic``, ``~camera_frame``, ``~imu_topic``.

One thread steps the simulation and publishes; callbacks and services take the same lock. A topic
nobody subscribes to costs nothing: its sensor is not even computed (Gazebo's sensors behave alike).
"""

from __future__ import annotations

import argparse
import ctypes
import math
import signal
import struct
import sys
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ninjemys.commands import entry
from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.image_transport import CompressedPublisher
from ninjemys.maps.mapfile import MapFileError
from ninjemys.node import Node
from ninjemys.node.cli_args import parse_args
from ninjemys.node.log import NodeLog
from ninjemys.rostime import Time
from ninjemys.sim import messages
from ninjemys.sim.camera import Camera
from ninjemys.sim.gazebo_api import GazeboApi, parse_model_xml
from ninjemys.sim.gazebo_worlds import load_gazebo_world
from ninjemys.sim.robot_model import CameraSpec, RobotModel, load_robot_model
from ninjemys.sim.ros_control.hardware import ControlLoop
from ninjemys.sim.sensors import Scene
from ninjemys.sim.simcore import Robot, Simulation, SpawnError
from ninjemys.sim.stepper import Due, StepLock, Stepper
from ninjemys.sim.world2d import World, load_world, world_from_map
from ninjemys.sim.worlds import world_path
from ninjemys.tf2.math import quaternion_from_yaw

Twist: Any = get_message_class("geometry_msgs/Twist")
Float32: Any = get_message_class("std_msgs/Float32")
Bool: Any = get_message_class("std_msgs/Bool")
ContactsState: Any = get_message_class("gazebo_msgs/ContactsState")
ContactState: Any = get_message_class("gazebo_msgs/ContactState")
JointState: Any = get_message_class("sensor_msgs/JointState")
Odometry: Any = get_message_class("nav_msgs/Odometry")
LaserScan: Any = get_message_class("sensor_msgs/LaserScan")
Image: Any = get_message_class("sensor_msgs/Image")
CameraInfo: Any = get_message_class("sensor_msgs/CameraInfo")
Imu: Any = get_message_class("sensor_msgs/Imu")
TFMessage: Any = get_message_class("tf2_msgs/TFMessage")
Clock: Any = get_message_class("rosgraph_msgs/Clock")
Log: Any = get_message_class("rosgraph_msgs/Log")

#: a rosgraph_msgs/Clock TCPROS frame: its length (8), then secs and nsecs
_CLOCK_FRAME = struct.Struct("<III").pack

WORLD_FRAME = "map"  # ground truth frame: the shipped maps are rasterized in world coordinates

__all__ = ["SimNode", "RobotIO", "scoped", "StepLock", "Due", "parse_model_xml", "keep_freed_memory", "main"]


@dataclass
class ExtraSensor:
    """A description's further lidar or camera (beyond its first of each): publishers and schedule."""

    kind: str  # "laser" or "camera"
    index: int  # into the model's extra_lasers or extra_cameras
    pubs: dict[str, Any]
    due: Due


@dataclass
class RobotIO:
    """The ROS endpoints of one robot and its output schedule."""

    robot: Robot
    prefix: str  # "" or "name/": topic prefix (relative names)
    frame_prefix: str  # "" or "name/": tf_prefix-style frame names
    pubs: dict[str, Any]
    cmd_sub: Any
    odom_due: Due | None
    scan_due: Due | None
    camera_due: Due | None
    imu_due: Due | None
    bad_cmd_warned: bool = False
    last_cmd: float | None = None  # sim time of the last command (for ~cmd_vel_timeout)
    last_contact: bool | None = None
    last_scan: np.ndarray | None = None
    static_tfs: list[Any] = field(default_factory=list)
    topics: dict[str, str] = field(default_factory=dict)  # role -> relative topic name (the view's)
    #: gazebo_ros_control's controller_manager for this robot (a ros_control description), else None
    control: ControlLoop | None = None
    extras: list[ExtraSensor] = field(default_factory=list)
    #: the odometry message, built at the first sample and refreshed in place after that
    odom_msg: Any = None
    #: a p3d plugin's ground truth and a bumper plugin's contacts, at their own rates (None: not asked for)
    truth_due: Due | None = None
    bumper_due: Due | None = None
    #: the drive's odometry and base frames under the robot's prefix (fixed at spawn: not rebuilt per step)
    odom_frame_id: str = ""
    base_frame_id: str = ""
    #: the odom -> base transform and the wheels' joint_states, built at the first sample and
    #: refreshed in place after that (as ``odom_msg``)
    odom_tf: Any = None
    joints_msg: Any = None
    #: the ground truth's nav_msgs/Odometry, refreshed in place (as ``odom_msg``)
    truth_msg: Any = None

    def frame(self, name: str) -> str:
        return scoped(self.frame_prefix, name)

    def close(self) -> None:
        if self.control is not None:
            self.control.close()
        if self.cmd_sub is not None:
            self.cmd_sub.unregister()
        for pubs in (self.pubs, *(e.pubs for e in self.extras)):
            for pub in pubs.values():
                pub.unregister()


def scoped(prefix: str, name: str) -> str:
    """``name`` under a robot's prefix (``""`` or ``"ns/"``), never as ``ns//name``.

    A description's plugin topics are absolute (gazebo_ros resolves them in the robot's namespace:
    ``/odom``, ``/heavy/odom``) and its frames may already carry the namespace (``heavy/odom``): a
    name already inside the prefix's namespace is kept, any other goes under the prefix, less its
    leading slash (``/odom`` of robot ``heavy`` in a multi-robot world is ``heavy/odom``)."""
    if not prefix:
        return name
    inner = name.lstrip("/")
    return name if inner.startswith(prefix) else prefix + inner


def _listened(pub: Any) -> bool:
    """Whether someone subscribes to ``pub`` now: its publication's connection tuples (replaced
    whole when a subscriber comes or goes), read without the calls of ``get_num_connections``."""
    publication = pub.publication
    return bool(publication.connections or publication.intra)


def _period(rate: float | None, default: float, dt: float) -> float:
    """A sensor's period in sim seconds; rate <= 0 means every physics step (Gazebo's updateRate 0)."""
    value = default if rate is None else rate
    return dt if value <= 0 else 1.0 / value


class SimNode:
    """The simulator node: a :class:`Simulation`, its ROS endpoints, and the stepping thread."""

    def __init__(
        self, node: Node, log: NodeLog, sim: Simulation, rate: float, laser_noise: float | None
    ) -> None:
        self.node = node
        self.log = log
        self.sim = sim
        self.laser_noise = laser_noise
        self.lock = StepLock()
        self.io: dict[str, RobotIO] = {}
        self.stepper = Stepper(
            self._step_and_publish, lambda: sim.time, sim.dt, rate, self.lock, self._step_failed
        )
        self.cmd_timeout = 0.0  # ~cmd_vel_timeout (0: off)
        #: sim seconds between /clock messages (gazebo_ros' pub_clock_frequency; 0: every step)
        self.clock_period = 0.0
        self._last_clock: float | None = None
        #: each robot's scene (what its sensors see) in the step being published: built once for
        #: the lidar and the cameras firing in the same step, dropped when the step is over
        self._scenes: dict[tuple[str, bool], Scene] = {}
        self.view: Any = None
        self.clock_pub = node.publisher("/clock", Clock, queue_size=10)
        self.tf_pub = node.publisher("/tf", TFMessage, queue_size=100)
        self._tf_msg = TFMessage()  # each step's /tf: its transforms replaced, the message kept
        #: advertised with the first static transform (a Gazebo description's come from robot_state_publisher)
        self.tf_static_pub: Any = None
        self.gazebo = GazeboApi(self)

    @property
    def rate(self) -> float:
        return self.stepper.rate

    @property
    def paused(self) -> bool:
        return self.stepper.paused

    # -- robots ---------------------------------------------------------------------------------
    def add_robot(
        self,
        name: str,
        model: RobotModel,
        x: float,
        y: float,
        yaw: float,
        namespaced: bool,
        namespace: str | None = None,
        elevation: float = 0.0,
    ) -> RobotIO:
        """Place a robot and create its topics (raises SpawnError when the place is taken).

        ``namespace`` (a spawn's robot_namespace) puts the topics under it and leaves the frames as
        the description names them, as Gazebo's plugins do; ``namespaced`` puts topics and frames
        under ``<name>/`` (our multi-robot worlds)."""
        with self.lock:
            robot = self.sim.add_robot(name, model, x, y, yaw, elevation)
            if self.laser_noise is not None and model.laser is not None:
                model.laser.noise = self.laser_noise
            if namespace:
                prefix, frame_prefix = namespace.strip("/") + "/", ""
            else:
                prefix = frame_prefix = f"{name}/" if namespaced else ""
            io = self._endpoints(robot, prefix, frame_prefix)
            if model.drive.kind == "ros_control" or model.control_beside is not None:
                # the controllers drive the wheels; their manager's services live in the robot's namespace
                io.control = ControlLoop(self.node, model, namespace or None)
            self.io[name] = io
            self._publish_static()
            self._publish_contact(io)
        if robot.spawn_overlap is not None:
            what, depth = robot.spawn_overlap
            self.log.warn(
                "robot [%s] spawned %.3f m into '%s' (Gazebo's physics would push it out): it moves "
                "only away from it",
                name,
                depth,
                what,
            )
        self.log.info(
            "spawned robot [%s] (%s) at (%.3f, %.3f, %.3f)%s",
            name,
            model.name,
            x,
            y,
            yaw,
            f" in namespace /{prefix.rstrip('/')}" if prefix else "",
        )
        drive = model.drive
        if drive.kind == "none":
            self.log.warn(
                "robot [%s] has no drive plugin (gazebo_ros_diff_drive, gazebo_ros_skid_steer_drive or "
                "gazebo_ros_control): it is passive (no %s, no odometry)",
                name,
                drive.command_topic,
            )
        if model.ignored_plugins:
            self.log.warn(
                "robot [%s]: ignoring plugins this simulator does not provide: %s",
                name,
                ", ".join(model.ignored_plugins),
            )
        return io

    def _endpoints(self, robot: Robot, prefix: str, frame_prefix: str) -> RobotIO:
        """The publishers and the command subscriber the model's drive and sensors name."""
        n, model, dt, now = self.node, robot.model, self.sim.dt, self.sim.time
        drive = model.drive
        driven = drive.kind != "none"
        pubs: dict[str, Any] = {}
        # our PuzzleBot's ground truth and contact; a Gazebo description's only when a plugin asks
        if model.ground_truth is not None:
            pubs["ground_truth"] = n.publisher(
                scoped(prefix, model.ground_truth.topic), Odometry, queue_size=10
            )
        if model.contact_topic is not None:
            pubs["contact"] = n.publisher(scoped(prefix, model.contact_topic), Bool, queue_size=1, latch=True)
        if model.bumper is not None:
            pubs["bumper"] = n.publisher(scoped(prefix, model.bumper.topic), ContactsState, queue_size=1)
        topics = {  # what the browser view subscribes to (the camera's defaults when it has none)
            "cmd_vel": scoped(prefix, drive.command_topic),
            "color": scoped(prefix, "camera/color/image_raw"),
            "depth": scoped(prefix, "camera/depth/image_rect_raw"),
        }
        if driven and drive.publish_wheel_speeds:
            pubs["wl"] = n.publisher(scoped(prefix, "wl"), Float32, queue_size=10)
            pubs["wr"] = n.publisher(scoped(prefix, "wr"), Float32, queue_size=10)
        if driven and drive.publish_wheel_joint_state:
            pubs["joint_states"] = n.publisher(scoped(prefix, "joint_states"), JointState, queue_size=10)
        if driven and drive.publish_odom:
            pubs["odom"] = n.publisher(scoped(prefix, drive.odom_topic), Odometry, queue_size=10)
        laser, camera, imu = model.laser, model.camera, model.imu
        if laser is not None:
            pubs["scan"] = n.publisher(scoped(prefix, laser.topic), LaserScan, queue_size=10)
        if camera is not None:
            topics["color"] = scoped(prefix, camera.image_topic)
            if camera.depth_topic:
                topics["depth"] = scoped(prefix, camera.depth_topic)
            pubs.update(self._camera_pubs(prefix, camera))
        if imu is not None:
            pubs["imu"] = n.publisher(scoped(prefix, imu.topic), Imu, queue_size=10)
        io = RobotIO(
            robot,
            prefix,
            frame_prefix,
            pubs,
            None,
            Due(_period(drive.update_rate, model.odom_rate, dt), now),
            Due(_period(laser.rate, 10.0, dt), now) if laser else None,
            Due(_period(camera.rate, 30.0, dt), now) if camera else None,
            Due(_period(imu.rate, 100.0, dt), now) if imu else None,
            topics=topics,
        )
        io.odom_frame_id, io.base_frame_id = io.frame(drive.odom_frame), io.frame(drive.base_frame)
        gt = model.ground_truth
        if gt is not None and gt.rate is not None:  # a p3d plugin's own rate (ours: with the odometry)
            io.truth_due = Due(_period(gt.rate, 0.0, dt), now)
        if model.bumper is not None:
            io.bumper_due = Due(_period(model.bumper.rate, 0.0, dt), now)
        for i, spec in enumerate(model.extra_lasers):
            scan_pub = n.publisher(scoped(prefix, spec.topic), LaserScan, queue_size=10)
            io.extras.append(
                ExtraSensor("laser", i, {"scan": scan_pub}, Due(_period(spec.rate, 10.0, dt), now))
            )
        for i, cam in enumerate(model.extra_cameras):
            due = Due(_period(cam.rate, 30.0, dt), now)
            io.extras.append(ExtraSensor("camera", i, self._camera_pubs(prefix, cam), due))
        if driven and drive.command_topic:  # ros_control: the controllers subscribe their own cmd_vel
            io.cmd_sub = n.subscriber(
                scoped(prefix, drive.command_topic),
                Twist,
                self._on_cmd_vel,
                callback_args=robot.name,
                queue_size=1,
            )
        if drive.kind == "puzzlebot":  # a URDF robot's sensor frames come from robot_state_publisher
            io.static_tfs = messages.static_transforms(model, frame_prefix, self._stamp())
        return io

    def _camera_pubs(self, prefix: str, camera: CameraSpec) -> dict[str, Any]:
        """A camera's publishers: image (and image_transport's <base>/compressed, encoded only while
        subscribed), camera_info, and the depth image and its camera_info for an RGB-D camera."""
        n = self.node
        pubs: dict[str, Any] = {
            "image": n.publisher(scoped(prefix, camera.image_topic), Image, queue_size=2),
            "image_compressed": CompressedPublisher(n, scoped(prefix, camera.image_topic)),
            "color_info": n.publisher(scoped(prefix, camera.info_topic), CameraInfo, queue_size=2),
        }
        if camera.depth_topic:
            pubs["depth"] = n.publisher(scoped(prefix, camera.depth_topic), Image, queue_size=2)
            if camera.depth_info_topic:
                pubs["depth_info"] = n.publisher(
                    scoped(prefix, camera.depth_info_topic), CameraInfo, queue_size=2
                )
        return pubs

    def remove_robot(self, name: str) -> None:
        with self.lock:
            self.sim.remove_robot(name)
            io = self.io.pop(name)
            self._publish_static()
        io.close()

    def _publish_static(self) -> None:
        """/tf_static is latched: one message holds every robot's static transforms. Gazebo publishes
        none, so with only Gazebo descriptions it is not even advertised."""
        transforms = [t for io in self.io.values() for t in io.static_tfs]
        if self.tf_static_pub is None:
            if not transforms:
                return
            self.tf_static_pub = self.node.publisher("/tf_static", TFMessage, queue_size=100, latch=True)
        self.tf_static_pub.publish(TFMessage(transforms=transforms))

    def _publish_contact(self, io: RobotIO) -> None:
        pub = io.pubs.get("contact")
        if pub is not None and io.last_contact != io.robot.contact:
            io.last_contact = io.robot.contact
            pub.publish(Bool(data=io.robot.contact))

    def _ground_truth(self, io: RobotIO, stamp: Time) -> None:
        """The true pose: ours in ``map`` (Stage's way), a p3d plugin's in its frameName, for its bodyName."""
        pub, spec, r = io.pubs.get("ground_truth"), io.robot.model.ground_truth, io.robot
        if pub is None or spec is None or not _listened(pub):
            return
        pose, twist = (r.x, r.y, r.yaw), (r.v, r.w)
        if io.truth_msg is None:
            own = r.model.sensor_tf  # our own description: frames under the robot's prefix
            frame, body = (WORLD_FRAME, io.frame(spec.body)) if own else (spec.frame, spec.body)
            io.truth_msg = messages.odometry(stamp, frame, body, pose, twist)
        else:
            messages.odometry_into(io.truth_msg, stamp, pose, twist)
        pub.publish(io.truth_msg)

    def _bumper(self, io: RobotIO, stamp: Time) -> None:
        """gazebo_ros_bumper: every update, the contacts of the watched collision (none: an empty list)."""
        pub, spec, r = io.pubs.get("bumper"), io.robot.model.bumper, io.robot
        if pub is None or spec is None or not pub.get_num_connections():
            return
        msg = ContactsState()
        msg.header.stamp, msg.header.frame_id = stamp, spec.frame
        if r.contact:
            state = ContactState()
            state.info = f"Debug:  i:(0/1)     my geom:{spec.collision}   other geom:{r.contact_with}"
            state.collision1_name = f"{r.name}::{spec.collision}"
            state.collision2_name = r.contact_with
            msg.states.append(state)
        pub.publish(msg)

    def _on_cmd_vel(self, msg: Any, name: str) -> None:
        """Runs on the subscriber's thread without the simulation lock (a command is one atomic
        assignment), so commands get through even when the stepping thread runs flat out."""
        io = self.io.get(name)
        if io is None:
            return
        lin, ang = msg.linear, msg.angular
        if not all(math.isfinite(v) for v in (lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)):
            if not io.bad_cmd_warned:
                io.bad_cmd_warned = True
                self.log.warn(
                    "%s%s: ignoring a command with a non-finite value (linear.x=%s, angular.z=%s); "
                    "further ones are ignored silently until a valid command arrives",
                    "/" + io.prefix if io.prefix else "",
                    io.robot.model.drive.command_topic,
                    lin.x,
                    ang.z,
                )
            return
        io.bad_cmd_warned = False
        io.robot.command(lin.x, ang.z)
        io.last_cmd = self.sim.time

    # -- after the Gazebo services changed the world ----------------------------------------------
    def after_reset(self) -> None:
        """Outputs due now, contact re-announced, the stepping thread re-reads the clock."""
        now = self.sim.time
        for io in self.io.values():
            for due in (io.odom_due, io.scan_due, io.camera_due, io.imu_due, *(e.due for e in io.extras)):
                if due is not None:
                    due.next = now
            self._publish_contact(io)
        self.stepper.wake()

    # -- the stepping thread --------------------------------------------------------------------
    def start(self) -> None:
        self.stepper.start()

    def stop(self) -> None:
        if self.stepper.stop():
            self.log.info("%s", self.summary())

    def summary(self) -> str:
        """How fast the simulation ran: simulated seconds per wall second and per CPU second."""
        return self.stepper.summary()

    def _step_failed(self, exc: Exception) -> None:
        self.log.error("simulation step failed: %s: %s", type(exc).__name__, exc)

    def _stamp(self) -> Time:
        secs, nsecs = divmod(self.sim.time_ns, 1_000_000_000)
        return Time._raw(secs, nsecs)  # wire integers, already valid: no re-validation per step

    def _scene(self, r: Robot, solid_only: bool = False) -> Scene:
        """Robot ``r``'s scene now, for a camera or (``solid_only``) a lidar, built at most once per
        step (the lock is held all the step); one scene serves both when nothing is only drawn."""
        key = (r.name, solid_only and self.sim.has_visuals)
        scene = self._scenes.get(key)
        if scene is None:
            scene = self._scenes[key] = self.sim.scene(r.name, solid_only=solid_only)
        return scene

    def _step_and_publish(self) -> None:
        try:
            self._publish_step()
        finally:
            if self._scenes:
                self._scenes.clear()  # the world moves on: no scene outlives its step

    def _publish_step(self) -> None:
        sim, gazebo = self.sim, self.gazebo
        if gazebo.pushes:
            gazebo.before_step()
        ios = self.io.values()
        for io in ios:
            if io.control is not None:
                io.control.step_robot(io.robot, sim.time, sim.dt)
        touched = sim.step()
        now, ns = sim.clock()
        secs, nsecs = divmod(ns, 1_000_000_000)
        stamp = Time._raw(secs, nsecs)  # _stamp() inlined (every step)
        # who listens is read from each publication's connection tuples, without a call (every step)
        clock = self.clock_pub.publication
        if (clock.connections or clock.intra) and self._clock_due(now):  # nobody listening: nothing
            # rosgraph_msgs/Clock is two uint32s: its frame is packed here, with no message object
            self.clock_pub.publish_framed(_CLOCK_FRAME(8, secs, nsecs))
        for r in touched:
            self.log.warn(
                "robot [%s] hit '%s' at (%.3f, %.3f): stopped at contact", r.name, r.contact_with, r.x, r.y
            )
        tf = self.tf_pub.publication
        tfs: list[Any] | None = [] if tf.connections or tf.intra else None
        view = self.view  # one read: the browser view attaches while the simulation runs
        timeout = self.cmd_timeout
        soon = now + 1e-9  # Due.fire's test, made here first: most outputs are not due at most steps
        for io in ios:
            r = io.robot
            last = io.last_cmd
            if timeout > 0 and last is not None and not 0.0 <= now - last <= timeout:
                io.last_cmd = None  # a driver that went quiet (or starved) does not drive on blind
                r.command(0.0, 0.0)
            if io.last_contact != r.contact:
                self._publish_contact(io)
            due = io.odom_due
            if due is not None and due.next <= soon and due.fire(now):
                self._odometry(io, stamp, tfs)
            due = io.truth_due
            if due is not None and due.next <= soon and due.fire(now):
                self._ground_truth(io, stamp)
            pubs = io.pubs
            due = io.bumper_due
            if due is not None and due.next <= soon and due.fire(now):
                self._bumper(io, stamp)
            due = io.imu_due
            if due is not None and due.next <= soon and due.fire(now):
                imu = pubs.get("imu")
                if imu is not None and (imu.publication.connections or imu.publication.intra):
                    self._imu(io, imu, stamp)
            due = io.scan_due  # idle (nobody reads it) or due: see _scan
            if due is not None and (due.next <= soon or not _listened(pubs["scan"])):
                self._scan(io, stamp, now, view)
            due = io.camera_due
            if due is not None and due.next <= soon and due.fire(now):
                for key in ("image", "image_compressed", "depth", "color_info", "depth_info"):
                    pub = pubs.get(key)
                    if pub is not None and pub.get_num_connections():
                        # a browser view watches the cameras as ROS topics too (through its gateway)
                        self._camera(io, stamp)
                        break
            for extra in io.extras:
                if extra.due.fire(now):
                    self._extra_sensor(io, extra, stamp)
        if tfs:
            tf_msg = self._tf_msg  # one message, its list of transforms replaced each step
            tf_msg.transforms = tfs
            self.tf_pub.publish(tf_msg)
        gazebo.after_step(stamp)
        if view is not None:
            view.publish(now)

    def _imu(self, io: RobotIO, imu: Any, stamp: Time) -> None:
        spec = io.robot.model.imu
        if spec is not None:
            imu.publish(messages.imu(stamp, io.frame(spec.pose.frame), spec, self.sim.imu(io.robot)))

    def _scan(self, io: RobotIO, stamp: Time, now: float, view: Any) -> None:
        """The lidar's scan when due, to its subscribers and the browser view (nobody: not cast)."""
        r, due = io.robot, io.scan_due
        laser = r.model.laser
        if laser is None or due is None:
            return
        scan = io.pubs["scan"]
        subscribed = _listened(scan)
        if not subscribed and not (view is not None and view.wants_scans()):
            due.next = now  # idle: a new subscriber's first scan goes out at once
        elif due.fire(now):
            ranges = self.sim.scan(r, scene=self._scene(r, solid_only=True))
            io.last_scan = ranges
            if subscribed:
                scan.publish(messages.laser_scan(stamp, io.frame(laser.pose.frame), laser, ranges))

    def _clock_due(self, now: float) -> bool:
        """Whether /clock goes out this step: every step, or with ``clock_period`` set, once that much
        simulated time has passed since the last one (gazebo_ros' publishSimTime); a clock set back
        (reset_world) publishes at once."""
        last = self._last_clock
        if self.clock_period > 0 and last is not None and 0.0 <= now - last < self.clock_period - 1e-9:
            return False
        self._last_clock = now
        return True

    def _odometry(self, io: RobotIO, stamp: Time, tfs: list[Any] | None) -> None:
        """Advance the robot's odometry; publish odom, ground truth, wl/wr and joint_states to whoever
        listens, and append odom -> base to ``tfs`` (None: nobody listens to /tf)."""
        r = io.robot
        pubs = io.pubs
        drive = r.model.drive
        if drive.odometry_source == "world":
            pose = (r.x, r.y, r.yaw)  # gazebo_ros_diff_drive's odometrySource world: the true pose
        else:
            pose = self.sim.odometry(r)  # advanced whoever listens: its noise draws are the same
        q = None
        odom = pubs.get("odom")
        if odom is not None and (odom.publication.connections or odom.publication.intra):
            q = quaternion_from_yaw(pose[2])
            if io.odom_msg is None:
                io.odom_msg = messages.odometry(
                    stamp, io.odom_frame_id, io.base_frame_id, pose, (r.v, r.w), r.model.odom_alpha
                )
            else:
                messages.odometry_into(io.odom_msg, stamp, pose, (r.v, r.w), q)
            odom.publish(io.odom_msg)
        truth = pubs.get("ground_truth")
        if truth is not None and io.truth_due is None and _listened(truth):
            self._ground_truth(io, stamp)
        wl, wr = pubs.get("wl"), pubs.get("wr")
        if wl is not None and (wl.publication.connections or wl.publication.intra):
            wl.publish(Float32(data=r.wl))
        if wr is not None and (wr.publication.connections or wr.publication.intra):
            wr.publish(Float32(data=r.wr))
        js = pubs.get("joint_states")
        if js is not None and (js.publication.connections or js.publication.intra):
            positions, speeds = [r.left_angle, r.right_angle], [r.wl, r.wr]
            if io.joints_msg is None:
                joints = [r.model.left_joint, r.model.right_joint]
                io.joints_msg = messages.joint_state(stamp, joints, positions, speeds)
            else:
                messages.joint_state_into(io.joints_msg, stamp, positions, speeds)
            js.publish(io.joints_msg)
        if tfs is None or drive.kind == "none":
            return
        if drive.publish_odom_tf:
            xyz = (pose[0], pose[1], 0.0)
            if q is None:
                q = quaternion_from_yaw(pose[2])
            if io.odom_tf is None:
                io.odom_tf = messages.transform(stamp, io.odom_frame_id, io.base_frame_id, xyz, q)
            else:
                messages.transform_into(io.odom_tf, stamp, xyz, q)
            tfs.append(io.odom_tf)
        # gazebo_ros_diff_drive's publishWheelTF: each wheel link in its parent's frame, turned by its angle
        for joint, angle in zip(r.model.wheel_tf_joints, (r.left_angle, r.right_angle), strict=False):
            x, y, z, qx, qy, qz, qw = joint.transform(angle)
            tfs.append(
                messages.transform(
                    stamp, io.frame(joint.parent), io.frame(joint.child), (x, y, z), (qx, qy, qz, qw)
                )
            )

    def _extra_sensor(self, io: RobotIO, extra: ExtraSensor, stamp: Time) -> None:
        """A further lidar's scan or camera's images, to whoever reads them (nobody: not computed)."""
        model = io.robot.model
        if extra.kind == "laser":
            laser = model.extra_lasers[extra.index]
            if extra.pubs["scan"].get_num_connections():
                ranges = self.sim.scan(io.robot, scene=self._scene(io.robot, solid_only=True), laser=laser)
                extra.pubs["scan"].publish(
                    messages.laser_scan(stamp, io.frame(laser.pose.frame), laser, ranges)
                )
            return
        if any(pub.get_num_connections() for pub in extra.pubs.values()):
            spec = model.extra_cameras[extra.index]
            self._camera_images(io, spec, io.robot.extra_cameras[extra.index], extra.pubs, stamp, extra.index)

    def _camera(self, io: RobotIO, stamp: Time) -> None:
        """Render and publish the camera's images, each only when someone reads it (camera_info
        alone needs no image at all)."""
        r = io.robot
        spec = r.model.camera
        if spec is None or r.camera is None:
            return
        self._camera_images(io, spec, r.camera, io.pubs, stamp, None)

    def _camera_images(
        self,
        io: RobotIO,
        spec: CameraSpec,
        camera: Camera,
        pubs: dict[str, Any],
        stamp: Time,
        extra: int | None,
    ) -> None:
        r = io.robot
        frame = io.frame(spec.frame)
        depth_frame = io.frame(spec.depth_frame)
        want_raw = pubs["image"].get_num_connections()
        want_colour = bool(want_raw or pubs["image_compressed"].get_num_connections())
        want_depth = bool("depth" in pubs and pubs["depth"].get_num_connections())
        if want_colour or want_depth:
            # the images are drawn straight into the publishers' loans: in a shared-memory slot of
            # an SHMROS subscriber's ring, publish then copies nothing (else a heap array, as before)
            h, w = camera.height, camera.width
            colour_loan = pubs["image"].loan(h * w * 3) if want_raw else None
            depth_loan = pubs["depth"].loan(h * w * 2) if want_depth else None
            try:
                with camera.drawing_into(
                    None if colour_loan is None else colour_loan.msg.data.reshape(h, w, 3),
                    None if depth_loan is None else depth_loan.msg.data.view("<u2").reshape(h, w),
                ):
                    rgb, depth = self.sim.render(
                        r, scene=self._scene(r), colour=want_colour, depth=want_depth, extra=extra
                    )
                if want_colour:
                    img = messages.rgb_image(
                        stamp, frame, rgb, None if colour_loan is None else colour_loan.msg
                    )
                    if want_raw:
                        pubs["image"].publish(img)
                    pubs["image_compressed"].publish(img)
                if depth_loan is not None:
                    pubs["depth"].publish(messages.depth_image(stamp, depth_frame, depth, depth_loan.msg))
            finally:
                for loan in (colour_loan, depth_loan):
                    if loan is not None:
                        loan.release()
        intrinsics = camera.intrinsics()
        for key, frame_id in (("color_info", frame), ("depth_info", depth_frame)):
            if key in pubs and pubs[key].get_num_connections():
                pubs[key].publish(messages.camera_info(stamp, frame_id, spec, intrinsics))


# -- process entry point -------------------------------------------------------------------------


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sim_node", description="The PuzzleBot simulator (pure Python, Gazebo's role)."
    )
    p.add_argument("--headless", action="store_true", help="no browser view (same as _gui:=false)")
    p.add_argument("--port", type=int, default=0, help="browser view port (default: any free port)")
    p.add_argument("--host", default="127.0.0.1", help="browser view address (default: localhost only)")
    p.add_argument("--no-browser", action="store_true", help="only print the view URL (no browser tab)")
    return p


def _param(node: Node, log: NodeLog, key: str, default: Any, kind: type) -> Any:
    try:
        value = node.get_param("~" + key, default)
    except NinjemysError as exc:
        log.warn("~%s: %s; using %r", key, exc, default)
        return default
    if kind is float:
        try:
            value = float(value)
        except (TypeError, ValueError):
            log.warn("~%s: %r is not a number, using %r", key, value, default)
            return default
        if not math.isfinite(value):
            log.warn("~%s: %r is not finite, using %r", key, value, default)
            return default
    elif kind is bool:
        value = value if isinstance(value, bool) else str(value).lower() in ("1", "true", "yes")
    elif kind is str:
        value = str(value)
    return value


def keep_freed_memory() -> bool:
    """Ask glibc's malloc to keep freed memory for reuse instead of returning it to the kernel.

    Each camera frame allocates about 1 MB of short-lived arrays (images, masks). With glibc's
    defaults these blocks go back to the kernel when freed (mmap'ed, or trimmed off the heap's top),
    so every frame page-faults its memory in again: on these VMs over a third of the render's time.
    Raising the mmap and trim thresholds keeps the blocks in the heap (the process grows by a few
    MB at most). Returns False where there is no glibc (the simulator then just runs slower)."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    m_trim_threshold, m_mmap_threshold = -1, -3  # glibc's malloc.h
    return bool(mallopt(m_mmap_threshold, 16 << 20)) and bool(mallopt(m_trim_threshold, 64 << 20))


def configure_model(
    model: RobotModel, param: Callable[[str, Any, type], Any], has_param: Callable[[str], bool]
) -> None:
    """Apply the node's private parameters that rename or reshape the first robot's outputs (item 5
    of the Gazebo issue: what a student's launch file sets where the maker's plugins would)."""
    drive = model.drive
    drive.command_topic = param("cmd_vel_topic", drive.command_topic, str)
    drive.publish_odom = param("publish_odom", drive.publish_odom, bool)
    drive.publish_odom_tf = param("publish_odom_tf", drive.publish_odom_tf, bool)
    drive.odom_topic = param("odom_topic", drive.odom_topic, str)
    drive.odom_frame = param("odom_frame", drive.odom_frame, str)
    drive.base_frame = param("base_frame", drive.base_frame, str)
    laser = model.laser
    if laser is not None:
        laser.topic = param("scan_topic", laser.topic, str)
        beams = int(param("scan_beams", laser.beams, float))
        laser.beams = beams if beams >= 1 else laser.beams
        laser.angle_min = param("scan_angle_min", laser.angle_min, float)
        if has_param("~scan_angle_max"):
            top = param("scan_angle_max", laser.angle_max if laser.angle_max is not None else math.pi, float)
            laser.angle_max = top if top > laser.angle_min else None
    camera = model.camera
    if camera is not None:
        camera.image_topic = param("image_topic", camera.image_topic, str)
        camera.info_topic = param("camera_info_topic", camera.info_topic, str)
        camera.frame = param("camera_frame", camera.frame, str)
    if model.imu is not None:
        model.imu.topic = param("imu_topic", model.imu.topic, str)


def _gazebo_clock_frequency(node: Node) -> float:
    """/gazebo/pub_clock_frequency when set (a number), else 0: /clock every physics step."""
    try:
        value = node.get_param("/gazebo/pub_clock_frequency", 0.0)
        return float(value)
    except (NinjemysError, TypeError, ValueError):
        return 0.0


def load_sim_world(log: NodeLog, world_arg: str, map_arg: str) -> World:
    if map_arg:
        log.info("world from map_server map %s", map_arg)
        return world_from_map(map_arg)
    if world_arg.endswith(".world"):  # Gazebo's world_name (gzserver, empty_world.launch)
        log.info("world from Gazebo world file %s", world_arg)
        return load_gazebo_world(world_arg)
    return load_world(world_path(world_arg))


#: starts a browser view of a running sim: ``(sim, options, log) -> stop`` (None: it failed, logged)
ViewStarter = Callable[["SimNode", argparse.Namespace, NodeLog], "Callable[[], None] | None"]


def main(argv: list[str] | None = None, view: ViewStarter | None = None) -> int:
    """Run the simulator. Its browser view is not the simulator's business: the ``sim_node``
    command (:mod:`ninjemys.web.puzzlebot_view`) passes ``view``; without it, with ``~gui:=false``
    or ``--headless``, the simulator runs the same with no web server."""
    argv = sys.argv[1:] if argv is None else argv
    ros_args = [a for a in argv if ":=" in a]
    options = _parser().parse_args([a for a in argv if ":=" not in a])
    args = parse_args([sys.argv[0], *ros_args])
    node = Node(
        args.node_name("puzzlebot_sim"),
        namespace=args.namespace,
        remappings=args.remappings,
        master_uri=args.master_uri,
        params=args.private_params,
    )
    log = NodeLog(node.name, log_file=args.log_file)
    log.attach_rosout(
        node.publisher("/rosout", Log, queue_size=100, latch=True),
        Log,
        lambda: [t for t, _ in node.get_publications()],
    )
    stop = threading.Event()

    def on_signal(_signum: int, _frame: Any) -> None:
        stop.set()
        node.shutdown("signal")

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, on_signal)
        signal.signal(signal.SIGTERM, on_signal)
    try:
        try:
            if not node.has_param("/use_sim_time"):
                node.set_param("/use_sim_time", True)
                log.info("/use_sim_time was not set: set it to true (this simulator publishes /clock)")
        except NinjemysError as exc:
            log.warn("could not set /use_sim_time: %s", exc)
        world_arg = _param(node, log, "world", "square", str)
        map_arg = _param(node, log, "map", "", str)
        try:
            world = load_sim_world(log, world_arg, map_arg)
            model = load_robot_model(_param(node, log, "model", "puzzlebot", str))
        except NinjemysError as exc:  # MapFileError, or the SDF reader's errors
            log.fatal("%s", exc)
            return 1
        update_rate = _param(node, log, "update_rate", 100.0, float)
        if update_rate <= 0:
            log.warn("~update_rate must be > 0; using 100")
            update_rate = 100.0
        rate = _param(node, log, "rate", 1.0, float)
        if rate < 0:
            log.warn("~rate must be >= 0 (0: as fast as possible); using 1")
            rate = 1.0
        alpha = node.get_param("~odom_alpha", None) if node.has_param("~odom_alpha") else None
        if alpha is not None:
            try:
                values = [float(a) for a in alpha]
                if len(values) != 4 or any(a < 0 or not math.isfinite(a) for a in values):
                    raise ValueError
                model.odom_alpha = (values[0], values[1], values[2], values[3])
            except (TypeError, ValueError):
                log.warn("~odom_alpha: expected 4 numbers >= 0, got %r; using %r", alpha, model.odom_alpha)
        laser_noise = node.get_param("~laser_noise", None) if node.has_param("~laser_noise") else None
        keep_freed_memory()
        sim = Simulation(world, 1.0 / update_rate, int(_param(node, log, "seed", 0, float)))
        configure_model(
            model, lambda key, default, kind: _param(node, log, key, default, kind), node.has_param
        )
        app = SimNode(node, log, sim, rate, float(laser_noise) if laser_noise is not None else None)
        app.cmd_timeout = max(0.0, _param(node, log, "cmd_vel_timeout", 0.0, float))
        # gazebo_ros reads /gazebo/pub_clock_frequency (empty_world.launch's use_clock_frequency sets it)
        clock_hz = _param(node, log, "pub_clock_frequency", _gazebo_clock_frequency(node), float)
        app.clock_period = 1.0 / clock_hz if clock_hz > 0 else 0.0
        starts = list(world.robots) or []
        if not starts:
            from ninjemys.sim.world2d import RobotStart

            starts = [RobotStart("puzzlebot", 0.0, 0.0, 0.0)]
        if _param(node, log, "no_robot", False, bool):
            starts = []  # Gazebo's way: an empty world, robots come from spawn_model
        first = starts[0] if starts else None
        x = _param(node, log, "x", first.x if first else 0.0, float)
        y = _param(node, log, "y", first.y if first else 0.0, float)
        yaw = _param(node, log, "yaw", first.yaw if first else 0.0, float)
        namespaced = len(starts) > 1
        for i, s in enumerate(starts):
            pose = (x, y, yaw) if i == 0 else (s.x, s.y, s.yaw)
            try:
                robot_model = model if s.model == "puzzlebot" else load_robot_model(s.model)
                app.add_robot(s.name, robot_model, pose[0], pose[1], pose[2], namespaced)
            except (SpawnError, MapFileError) as exc:
                log.fatal("%s", exc)
                return 1
        log.info(
            "PuzzleBot simulator: world '%s', %d robot(s), real-time factor %s, physics %.0f Hz",
            world.name,
            len(starts),
            f"{rate:g}" if rate > 0 else "unlimited",
            update_rate,
        )
        stop_view = None
        gui = _param(node, log, "gui", True, bool) and not options.headless
        if _param(node, log, "paused", False, bool):
            app.stepper.paused = True  # Gazebo's -u: physics waits for unpause_physics
            app.gazebo.hold_world_models()  # nothing has fallen yet
            log.info("physics paused (call /gazebo/unpause_physics to start)")
        app.start()  # the physics and the sensors first: the view's server starts beside them
        try:
            if gui and view is not None:
                stop_view = view(app, options, log)
                if stop_view is None:
                    return 1
            node.spin()
        finally:
            app.stop()
            if stop_view is not None:
                stop_view()
        return 0
    finally:
        node.shutdown("exit")
        log.close()


console_main = entry(main)


if __name__ == "__main__":
    console_main()
