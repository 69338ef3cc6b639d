"""``rosrun puzzlebot_sim sim_node``: the PuzzleBot simulator as a ROS node (the role Gazebo plays).

It binds one :class:`~ninjemys.sim.simcore.Simulation` to ROS names. Per robot (relative names, under
``<robot>/`` when the world has several robots or the robot was spawned later): ``cmd_vel`` in;
``wl``, ``wr`` (std_msgs/Float32, rad/s), ``joint_states``, ``odom``, ``base_pose_ground_truth``,
``scan``, ``imu``, ``camera/color/image_raw`` (rgb8), ``camera/depth/image_rect_raw`` (16UC1, mm),
``camera/color/camera_info``, ``camera/depth/camera_info`` and ``contact`` (std_msgs/Bool, latched)
out. Global: ``/clock``, ``/tf`` (odom -> base_link), ``/tf_static`` (base_link -> sensors), and the
Gazebo services ``/gazebo/reset_simulation``, ``/gazebo/reset_world``, ``/gazebo/pause_physics``,
``/gazebo/unpause_physics`` (std_srvs/Empty), ``/gazebo/spawn_urdf_model``,
``/gazebo/spawn_sdf_model`` (gazebo_msgs/SpawnModel) and ``/gazebo/delete_model``
(gazebo_msgs/DeleteModel).

Private parameters: ``~world`` (a shipped world name or a path; default ``square``), ``~map`` (a
map_server YAML used as the world instead), ``~rate`` (real-time factor; 0 runs as fast as
possible), ``~x ~y ~yaw`` (start pose of the first robot), ``~model`` (``puzzlebot``, a YAML or URDF
path), ``~update_rate`` (physics steps per simulated second, default 100), ``~seed`` (noise),
``~odom_alpha`` (amcl's α1-α4), ``~laser_noise``, ``~gui`` (serve the browser view),
``~cmd_vel_timeout`` (simulated seconds without a command after which the wheels are stopped, as
diff_drive_controller's ``cmd_vel_timeout`` does; default 0: off, the last command holds, as with
Gazebo's diff drive plugin).

One thread steps the simulation and publishes; callbacks and services take the same lock. A topic
nobody subscribes to costs nothing: its sensor is not even computed (Gazebo's sensors behave alike).
"""

from __future__ import annotations

import argparse
import ctypes
import math
import signal
import sys
import threading
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ninjemys.commands import entry
from ninjemys.errors import NinjemysError, ShutdownError
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.image_transport import CompressedPublisher
from ninjemys.maps.mapfile import MapFileError
from ninjemys.node import Node
from ninjemys.node.cli_args import parse_args
from ninjemys.node.log import NodeLog
from ninjemys.rostime import Time
from ninjemys.sim.robot_model import RobotModel, load_robot_model
from ninjemys.sim.simcore import Robot, Simulation, SpawnError
from ninjemys.sim.world2d import World, load_world, world_from_map
from ninjemys.sim.worlds import world_path
from ninjemys.tf2.math import quaternion_from_rpy, quaternion_from_yaw, yaw_from_quaternion

Twist = get_message_class("geometry_msgs/Twist")
TransformStamped = get_message_class("geometry_msgs/TransformStamped")
Float32 = get_message_class("std_msgs/Float32")
Bool = get_message_class("std_msgs/Bool")
JointState = get_message_class("sensor_msgs/JointState")
Odometry = get_message_class("nav_msgs/Odometry")
LaserScan = get_message_class("sensor_msgs/LaserScan")
Image = get_message_class("sensor_msgs/Image")
CameraInfo = get_message_class("sensor_msgs/CameraInfo")
Imu = get_message_class("sensor_msgs/Imu")
TFMessage = get_message_class("tf2_msgs/TFMessage")
Clock = get_message_class("rosgraph_msgs/Clock")
Log = get_message_class("rosgraph_msgs/Log")
Empty = get_service_class("std_srvs/Empty")
SpawnModel = get_service_class("gazebo_msgs/SpawnModel")
DeleteModel = get_service_class("gazebo_msgs/DeleteModel")

WORLD_FRAME = "map"  # ground truth frame: the shipped maps are rasterized in world coordinates


class StepLock:
    """The simulation's lock: the stepping thread steps with it, services, the browser view and
    spawns take it with ``with lock:`` (reentrant).

    Running as fast as possible, the stepping thread would take a plain lock again right after
    releasing it (it holds the GIL) and starve everyone else. Yielding the CPU after every step
    (``time.sleep(0)``) fixed that at a price: on a loaded machine each yield let other processes
    run, ~90 us per 10 ms step. Here the others announce that they wait, and the stepping thread
    steps aside (:meth:`give_way`) only then."""

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._count_lock = threading.Lock()
        self._waiting = 0
        self._nobody_waits = threading.Event()
        self._nobody_waits.set()

    def __enter__(self) -> StepLock:
        with self._count_lock:
            self._waiting += 1
            self._nobody_waits.clear()
        try:
            self._lock.acquire()
        except BaseException:  # interrupted while waiting (KeyboardInterrupt): no longer a waiter
            self._done_waiting()
            raise
        return self

    def __exit__(self, *_exc: object) -> None:
        self._lock.release()
        self._done_waiting()

    def _done_waiting(self) -> None:
        with self._count_lock:
            self._waiting -= 1
            if not self._waiting:
                self._nobody_waits.set()

    @property
    def stepping(self) -> threading.RLock:
        """The lock itself, for the stepping thread (which does not announce itself)."""
        return self._lock

    def give_way(self, timeout: float) -> None:
        """Between two steps: return once nobody waits for the lock (at most ``timeout`` s)."""
        if self._waiting:
            self._nobody_waits.wait(timeout)


@dataclass
class Due:
    """A periodic output in simulated time: fires at the first step at or after ``next``."""

    period: float
    next: float = 0.0

    def fire(self, now: float) -> bool:
        if now + 1e-9 < self.next:
            return False
        self.next = max(self.next + self.period, now - self.period)  # no burst after a pause or reset
        return True


@dataclass
class RobotIO:
    """The ROS endpoints of one robot and its output schedule."""

    robot: Robot
    prefix: str  # "" or "name/": topic prefix (relative names)
    frame_prefix: str  # "" or "name/": tf_prefix-style frame names
    pubs: dict[str, Any]
    cmd_sub: Any
    odom_due: Due
    scan_due: Due | None
    camera_due: Due | None
    imu_due: Due | None
    bad_cmd_warned: bool = False
    last_cmd: float | None = None  # sim time of the last command (for ~cmd_vel_timeout)
    last_contact: bool | None = None
    last_scan: np.ndarray | None = None
    static_tfs: list[Any] = field(default_factory=list)

    def frame(self, name: str) -> str:
        return self.frame_prefix + name

    def close(self) -> None:
        self.cmd_sub.unregister()
        for pub in self.pubs.values():
            pub.unregister()


class SimNode:
    """The simulator node: a :class:`Simulation`, its ROS endpoints, and the stepping thread."""

    def __init__(
        self, node: Node, log: NodeLog, sim: Simulation, rate: float, laser_noise: float | None
    ) -> None:
        self.node = node
        self.log = log
        self.sim = sim
        self.rate = rate
        self.laser_noise = laser_noise
        self.lock = StepLock()
        self.io: dict[str, RobotIO] = {}
        self.paused = False
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._started = (time.monotonic(), time.process_time())
        self._stepped = 0.0  # simulated seconds stepped (resets of time do not undo them)
        self.cmd_timeout = 0.0  # ~cmd_vel_timeout (0: off)
        self.view: Any = None
        self.clock_pub = node.publisher("/clock", Clock, queue_size=10)
        self.tf_pub = node.publisher("/tf", TFMessage, queue_size=100)
        self.tf_static_pub = node.publisher("/tf_static", TFMessage, queue_size=100, latch=True)
        self.namespaced = False
        node.service("/gazebo/reset_simulation", Empty, self._reset_simulation)
        node.service("/gazebo/reset_world", Empty, self._reset_world)
        node.service("/gazebo/pause_physics", Empty, self._pause)
        node.service("/gazebo/unpause_physics", Empty, self._unpause)
        node.service("/gazebo/spawn_urdf_model", SpawnModel, self._spawn)
        node.service("/gazebo/spawn_sdf_model", SpawnModel, self._spawn)
        node.service("/gazebo/delete_model", DeleteModel, self._delete)

    # -- robots ---------------------------------------------------------------------------------
    def add_robot(
        self, name: str, model: RobotModel, x: float, y: float, yaw: float, namespaced: bool
    ) -> RobotIO:
        """Place a robot and create its topics (raises SpawnError when the place is taken)."""
        with self.lock:
            robot = self.sim.add_robot(name, model, x, y, yaw)
            if self.laser_noise is not None and model.laser is not None:
                model.laser.noise = self.laser_noise
            prefix = f"{name}/" if namespaced else ""
            n = self.node
            pubs = {
                "wl": n.publisher(prefix + "wl", Float32, queue_size=10),
                "wr": n.publisher(prefix + "wr", Float32, queue_size=10),
                "joint_states": n.publisher(prefix + "joint_states", JointState, queue_size=10),
                "odom": n.publisher(prefix + "odom", Odometry, queue_size=10),
                "ground_truth": n.publisher(prefix + "base_pose_ground_truth", Odometry, queue_size=10),
                "contact": n.publisher(prefix + "contact", Bool, queue_size=1, latch=True),
            }
            if model.laser is not None:
                pubs["scan"] = n.publisher(prefix + "scan", LaserScan, queue_size=10)
            if model.camera is not None:
                pubs["image"] = n.publisher(prefix + "camera/color/image_raw", Image, queue_size=2)
                # image_transport's <base>/compressed, encoded only while subscribed
                pubs["image_compressed"] = CompressedPublisher(n, prefix + "camera/color/image_raw")
                pubs["depth"] = n.publisher(prefix + "camera/depth/image_rect_raw", Image, queue_size=2)
                pubs["color_info"] = n.publisher(
                    prefix + "camera/color/camera_info", CameraInfo, queue_size=2
                )
                pubs["depth_info"] = n.publisher(
                    prefix + "camera/depth/camera_info", CameraInfo, queue_size=2
                )
            if model.imu is not None:
                pubs["imu"] = n.publisher(prefix + "imu", Imu, queue_size=10)
            io = RobotIO(
                robot,
                prefix,
                prefix,
                pubs,
                None,
                Due(1.0 / model.odom_rate, self.sim.time),
                Due(1.0 / model.laser.rate, self.sim.time) if model.laser else None,
                Due(1.0 / model.camera.rate, self.sim.time) if model.camera else None,
                Due(1.0 / model.imu.rate, self.sim.time) if model.imu else None,
            )
            io.cmd_sub = n.subscriber(
                prefix + "cmd_vel", Twist, self._on_cmd_vel, callback_args=name, queue_size=1
            )
            io.static_tfs = self._static_transforms(io)
            self.io[name] = io
            self._publish_static()
            self._publish_contact(io)
        self.log.info(
            "spawned robot [%s] (%s) at (%.3f, %.3f, %.3f)%s",
            name,
            model.name,
            x,
            y,
            yaw,
            f" in namespace /{name}" if namespaced else "",
        )
        return io

    def remove_robot(self, name: str) -> None:
        with self.lock:
            self.sim.remove_robot(name)
            io = self.io.pop(name)
            self._publish_static()
        io.close()

    def _static_transforms(self, io: RobotIO) -> list[Any]:
        """base_link -> each sensor's frame, and camera_link -> the optical frames the images name
        (z forward, x right, y down: rpy -pi/2, 0, -pi/2, as the RealSense driver publishes)."""
        m = io.robot.model
        pairs: list[tuple[str, str, tuple[float, float, float], tuple[float, float, float]]] = []
        for spec in (m.laser, m.camera, m.imu):
            if spec is not None:
                pairs.append(("base_link", spec.pose.frame, spec.pose.xyz, spec.pose.rpy))
        if m.camera is not None:
            optical = (-math.pi / 2, 0.0, -math.pi / 2)
            for child in ("camera_color_optical_frame", "camera_depth_optical_frame"):
                pairs.append((m.camera.pose.frame, child, (0.0, 0.0, 0.0), optical))
        out = []
        for parent, child, xyz, rpy in pairs:
            t = TransformStamped()
            t.header.stamp = self._stamp()
            t.header.frame_id = io.frame(parent)
            t.child_frame_id = io.frame(child)
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
            q = t.transform.rotation
            q.x, q.y, q.z, q.w = quaternion_from_rpy(*rpy)
            out.append(t)
        return out

    def _publish_static(self) -> None:
        """/tf_static is latched: one message holds every robot's static transforms."""
        self.tf_static_pub.publish(
            TFMessage(transforms=[t for io in self.io.values() for t in io.static_tfs])
        )

    def _publish_contact(self, io: RobotIO) -> None:
        if io.last_contact != io.robot.contact:
            io.last_contact = io.robot.contact
            io.pubs["contact"].publish(Bool(data=io.robot.contact))

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
                    "%scmd_vel: ignoring a command with a non-finite value (linear.x=%s, angular.z=%s); "
                    "further ones are ignored silently until a valid command arrives",
                    "/" + io.prefix if io.prefix else "",
                    lin.x,
                    ang.z,
                )
            return
        io.bad_cmd_warned = False
        io.robot.command(lin.x, ang.z)
        io.last_cmd = self.sim.time

    # -- services -------------------------------------------------------------------------------
    def _reset_simulation(self, _req: Any) -> Any:
        with self.lock:
            self.sim.reset_simulation()
            self._after_reset()
        self.log.info("simulation reset: time and robots back to the start")
        return Empty._response_class()

    def _reset_world(self, _req: Any) -> Any:
        with self.lock:
            self.sim.reset_world()
            self._after_reset()
        self.log.info("world reset: robots back to their start poses")
        return Empty._response_class()

    def _after_reset(self) -> None:
        now = self.sim.time
        for io in self.io.values():
            for due in (io.odom_due, io.scan_due, io.camera_due, io.imu_due):
                if due is not None:
                    due.next = now
            self._publish_contact(io)
        self._wake.set()

    def _pause(self, _req: Any) -> Any:
        with self.lock:
            self.paused = True
        return Empty._response_class()

    def _unpause(self, _req: Any) -> Any:
        with self.lock:
            self.paused = False
        self._wake.set()
        return Empty._response_class()

    def _spawn(self, req: Any) -> Any:
        resp = SpawnModel._response_class()
        name = req.model_name.strip()
        x, y = req.initial_pose.position.x, req.initial_pose.position.y
        q = req.initial_pose.orientation
        yaw = yaw_from_quaternion(q.x, q.y, q.z, q.w)
        try:
            if not name or not name.replace("_", "a").isalnum() or not name[0].isalpha():
                raise SpawnError(f"model_name [{req.model_name}] is not a valid ROS name")
            if req.reference_frame not in ("", "world", "map"):
                raise SpawnError(
                    f"reference_frame [{req.reference_frame}] is not supported (use '' or 'world')"
                )
            kind, spec = parse_model_xml(req.model_xml)
            if kind == "robot":
                self.add_robot(name, spec, x, y, yaw, True)
            else:
                shape, size, height, colour = spec
                with self.lock:
                    self.sim.add_obstacle(name, shape, size, x, y, yaw, height, colour)
                self.log.info("spawned %s [%s] at (%.3f, %.3f)", shape, name, x, y)
        except (SpawnError, MapFileError) as exc:
            self.log.error("spawn refused: %s", exc)
            resp.success, resp.status_message = False, f"SpawnModel: Failure - {exc}"
            return resp
        resp.success, resp.status_message = True, f"SpawnModel: Successfully spawned entity [{name}]"
        return resp

    def _delete(self, req: Any) -> Any:
        resp = DeleteModel._response_class()
        name = req.model_name
        try:
            if name in self.sim.robots:
                self.remove_robot(name)
            else:
                with self.lock:
                    self.sim.remove_obstacle(name)
        except SpawnError as exc:
            resp.success, resp.status_message = False, f"DeleteModel: {exc}"
            return resp
        self.log.info("deleted model [%s]", name)
        resp.success, resp.status_message = True, f"DeleteModel: successfully deleted model [{name}]"
        return resp

    # -- the stepping thread --------------------------------------------------------------------
    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="puzzlebot-sim", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(5.0)
            self.log.info("%s", self.summary())

    def summary(self) -> str:
        """How fast the simulation ran: simulated seconds per wall second and per CPU second."""
        wall = max(time.monotonic() - self._started[0], 1e-9)
        cpu = max(time.process_time() - self._started[1], 1e-9)
        stepped = self._stepped
        return (
            f"simulated {stepped:.2f} s in {wall:.2f} s of wall time ({stepped / wall:.1f}x real time), "
            f"{cpu:.2f} s of CPU ({stepped / cpu:.1f} simulated s per CPU s)"
        )

    def _stamp(self) -> Time:
        ns = round(self.sim.steps * self.sim.dt * 1e9)
        return Time(ns // 1_000_000_000, ns % 1_000_000_000)

    def _run(self) -> None:
        self._started = (time.monotonic(), time.process_time())
        wall0 = time.monotonic()
        sim0 = self.sim.time
        while not self._stop.is_set():
            with self.lock.stepping:
                paused = self.paused
            if paused:
                self._wake.wait(0.5)
                self._wake.clear()
                wall0, sim0 = time.monotonic(), self.sim.time
                continue
            try:
                with self.lock.stepping:
                    if self.sim.time < sim0:  # reset_simulation: time went back
                        wall0, sim0 = time.monotonic(), self.sim.time
                    self._step_and_publish()
            except ShutdownError:
                return  # the node shut down under the stepping thread
            except Exception as exc:  # a bug in one step must not freeze the simulation for good
                self.log.error("simulation step failed: %s: %s", type(exc).__name__, exc)
            if self.rate <= 0:
                self.lock.give_way(0.5)  # as fast as possible, yet services and the view get the lock
            else:
                target = wall0 + (self.sim.time - sim0) / self.rate
                delay = target - time.monotonic()
                if delay > 0:
                    self._wake.wait(delay)
                    self._wake.clear()
                elif delay < -0.25:  # far behind (machine busy): run on from now, no burst to catch up
                    wall0, sim0 = time.monotonic(), self.sim.time

    def _step_and_publish(self) -> None:
        sim = self.sim
        touched = sim.step()
        self._stepped += sim.dt
        now = sim.time
        stamp = self._stamp()
        if self.clock_pub.get_num_connections():  # nobody listening costs nothing (checked every step)
            self.clock_pub.publish(Clock(clock=stamp))
        for r in touched:
            self.log.warn(
                "robot [%s] hit '%s' at (%.3f, %.3f): stopped at contact", r.name, r.contact_with, r.x, r.y
            )
        tfs: list[Any] | None = [] if self.tf_pub.get_num_connections() else None
        for io in self.io.values():
            r = io.robot
            last = io.last_cmd
            if self.cmd_timeout > 0 and last is not None and not 0.0 <= now - last <= self.cmd_timeout:
                io.last_cmd = None  # a driver that went quiet (or starved) does not drive on blind
                r.command(0.0, 0.0)
            self._publish_contact(io)
            pubs = io.pubs
            if io.odom_due.fire(now):
                self._odometry(io, stamp, tfs)
            if io.imu_due is not None and io.imu_due.fire(now) and pubs["imu"].get_num_connections():
                self._imu(io, stamp)
            if io.scan_due is not None and io.scan_due.fire(now):
                want_view = self.view is not None and self.view.wants_scans()
                if pubs["scan"].get_num_connections() or want_view:
                    ranges = sim.scan(r)
                    io.last_scan = ranges
                    if pubs["scan"].get_num_connections():
                        self._scan(io, stamp, ranges)
            if io.camera_due is not None and io.camera_due.fire(now):
                want = any(
                    pubs[k].get_num_connections()
                    for k in ("image", "image_compressed", "depth", "color_info", "depth_info")
                )
                if want:  # a browser view watches the cameras as ROS topics too (through its gateway)
                    self._camera(io, stamp)
        if tfs:
            self.tf_pub.publish(TFMessage(transforms=tfs))
        if self.view is not None:
            self.view.publish(now)

    def _odometry(self, io: RobotIO, stamp: Time, tfs: list[Any] | None) -> None:
        """Advance the robot's odometry; publish odom, ground truth, wl/wr and joint_states to whoever
        listens, and append odom -> base_link to ``tfs`` (None: nobody listens to /tf)."""
        r = io.robot
        pubs = io.pubs
        ox, oy, oyaw = self.sim.odometry(r)
        if pubs["odom"].get_num_connections():
            msg = Odometry()
            msg.header.stamp = stamp
            msg.header.frame_id = io.frame("odom")
            msg.child_frame_id = io.frame("base_link")
            p = msg.pose.pose
            p.position.x, p.position.y = ox, oy
            p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = quaternion_from_yaw(oyaw)
            msg.twist.twist.linear.x = r.v
            msg.twist.twist.angular.z = r.w
            a1, a2, a3, a4 = r.model.odom_alpha
            var_xy = 1e-4 + a3 * 0.01
            var_yaw = 1e-4 + a1 * 0.01
            msg.pose.covariance = [
                var_xy,
                0,
                0,
                0,
                0,
                0,
                0,
                var_xy,
                0,
                0,
                0,
                0,
                0,
                0,
                1e6,
                0,
                0,
                0,
                0,
                0,
                0,
                1e6,
                0,
                0,
                0,
                0,
                0,
                0,
                1e6,
                0,
                0,
                0,
                0,
                0,
                0,
                var_yaw,
            ]
            msg.twist.covariance = msg.pose.covariance
            pubs["odom"].publish(msg)
        if pubs["ground_truth"].get_num_connections():
            gt = Odometry()
            gt.header.stamp = stamp
            gt.header.frame_id = WORLD_FRAME
            gt.child_frame_id = io.frame("base_link")
            gp = gt.pose.pose
            gp.position.x, gp.position.y = r.x, r.y
            gp.orientation.x, gp.orientation.y, gp.orientation.z, gp.orientation.w = quaternion_from_yaw(
                r.yaw
            )
            gt.twist.twist.linear.x = r.v
            gt.twist.twist.angular.z = r.w
            pubs["ground_truth"].publish(gt)
        if pubs["wl"].get_num_connections():
            pubs["wl"].publish(Float32(data=r.wl))
        if pubs["wr"].get_num_connections():
            pubs["wr"].publish(Float32(data=r.wr))
        if pubs["joint_states"].get_num_connections():
            js = JointState()
            js.header.stamp = stamp
            js.name = [r.model.left_joint, r.model.right_joint]
            js.position = [r.left_angle, r.right_angle]
            js.velocity = [r.wl, r.wr]
            pubs["joint_states"].publish(js)
        if tfs is None:
            return
        t = TransformStamped()
        t.header.stamp = stamp
        t.header.frame_id = io.frame("odom")
        t.child_frame_id = io.frame("base_link")
        t.transform.translation.x, t.transform.translation.y = ox, oy
        q = t.transform.rotation
        q.x, q.y, q.z, q.w = quaternion_from_yaw(oyaw)
        tfs.append(t)

    def _imu(self, io: RobotIO, stamp: Time) -> None:
        r = io.robot
        spec = r.model.imu
        yaw, wz, ax, ay = self.sim.imu(r)
        msg = Imu()
        msg.header.stamp = stamp
        msg.header.frame_id = io.frame(spec.pose.frame)
        o = msg.orientation
        o.x, o.y, o.z, o.w = quaternion_from_yaw(yaw)
        msg.angular_velocity.z = wz
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, 9.80665
        g, a = max(spec.gyro_noise**2, 1e-9), max(spec.accel_noise**2, 1e-9)
        msg.orientation_covariance = [1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4]
        msg.angular_velocity_covariance = [g, 0, 0, 0, g, 0, 0, 0, g]
        msg.linear_acceleration_covariance = [a, 0, 0, 0, a, 0, 0, 0, a]
        io.pubs["imu"].publish(msg)

    def _scan(self, io: RobotIO, stamp: Time, ranges: np.ndarray) -> None:
        spec = io.robot.model.laser
        msg = LaserScan()
        msg.header.stamp = stamp
        msg.header.frame_id = io.frame(spec.pose.frame)
        inc = 2.0 * math.pi / spec.beams
        msg.angle_min = -math.pi
        msg.angle_max = -math.pi + inc * (spec.beams - 1)
        msg.angle_increment = inc
        msg.time_increment = 0.0
        msg.scan_time = 1.0 / spec.rate
        msg.range_min = spec.range_min
        msg.range_max = spec.range_max
        msg.ranges = ranges
        msg.intensities = []
        io.pubs["scan"].publish(msg)

    def _camera(self, io: RobotIO, stamp: Time) -> None:
        r = io.robot
        spec = r.model.camera
        rgb, depth = self.sim.render(r)
        pubs = io.pubs
        frame = io.frame("camera_color_optical_frame")
        depth_frame = io.frame("camera_depth_optical_frame")
        want_raw = pubs["image"].get_num_connections()
        if want_raw or pubs["image_compressed"].get_num_connections():
            img = Image()
            img.header.stamp = stamp
            img.header.frame_id = frame
            img.height, img.width = rgb.shape[0], rgb.shape[1]
            img.encoding = "rgb8"
            img.is_bigendian = 0
            img.step = rgb.shape[1] * 3
            img.data = rgb.reshape(-1)  # a view: uint8[] fields take numpy arrays without a copy
            if want_raw:
                pubs["image"].publish(img)
            pubs["image_compressed"].publish(img)
        if pubs["depth"].get_num_connections():
            d = Image()
            d.header.stamp = stamp
            d.header.frame_id = depth_frame
            d.height, d.width = depth.shape[0], depth.shape[1]
            d.encoding = "16UC1"
            d.is_bigendian = 0
            d.step = depth.shape[1] * 2
            d.data = depth.astype("<u2", copy=False).view(np.uint8).reshape(-1)
            pubs["depth"].publish(d)
        fx, fy, cx, cy = r.camera.intrinsics()
        for key, frame_id in (("color_info", frame), ("depth_info", depth_frame)):
            if pubs[key].get_num_connections():
                info = CameraInfo()
                info.header.stamp = stamp
                info.header.frame_id = frame_id
                info.height, info.width = spec.height, spec.width
                info.distortion_model = "plumb_bob"
                info.D = [0.0, 0.0, 0.0, 0.0, 0.0]
                info.K = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
                info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
                info.P = [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
                pubs[key].publish(info)


def parse_model_xml(text: str) -> tuple[str, Any]:
    """What a SpawnModel request's ``model_xml`` describes: ("robot", RobotModel) or
    ("obstacle", (shape, size, height, colour)). Empty text or ``puzzlebot`` is the PuzzleBot."""
    body = text.strip()
    if not body:
        return "robot", load_robot_model("puzzlebot")
    if not body.startswith("<"):
        return "robot", load_robot_model(body)
    try:
        root = ET.fromstring(body)
    except ET.ParseError as exc:
        raise SpawnError(f"model_xml is not valid XML: {exc}") from None
    if root.tag == "robot" and len([j for j in root.iter("joint") if j.get("type") == "continuous"]) == 2:
        return "robot", load_robot_model(body)
    for geom in root.iter("geometry"):
        box = geom.find("box")
        cyl = geom.find("cylinder")
        if box is not None:
            size_text = box.get("size") or (box.findtext("size") or "")
            try:
                sx, sy, sz = (float(v) for v in size_text.split())
            except ValueError:
                raise SpawnError(f"box size {size_text!r} is not three numbers") from None
            return "obstacle", ("box", (sx, sy), sz, (180, 130, 80))
        if cyl is not None:
            try:
                radius = float(cyl.get("radius") or cyl.findtext("radius") or "")
                length = float(cyl.get("length") or cyl.findtext("length") or "")
            except ValueError:
                raise SpawnError("cylinder needs numeric radius and length") from None
            return "obstacle", ("cylinder", (radius, radius), length, (60, 90, 200))
    raise SpawnError(
        "model_xml describes neither a differential-drive robot (URDF with 2 continuous joints) nor a box or cylinder"
    )


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


def load_sim_world(log: NodeLog, world_arg: str, map_arg: str) -> World:
    if map_arg:
        log.info("world from map_server map %s", map_arg)
        return world_from_map(map_arg)
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
        except MapFileError as exc:
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
        app = SimNode(node, log, sim, rate, float(laser_noise) if laser_noise is not None else None)
        app.cmd_timeout = max(0.0, _param(node, log, "cmd_vel_timeout", 0.0, float))
        starts = list(world.robots) or []
        if not starts:
            from ninjemys.sim.world2d import RobotStart

            starts = [RobotStart("puzzlebot", 0.0, 0.0, 0.0)]
        first = starts[0]
        x = _param(node, log, "x", first.x, float)
        y = _param(node, log, "y", first.y, float)
        yaw = _param(node, log, "yaw", first.yaw, float)
        namespaced = len(starts) > 1
        for i, s in enumerate(starts):
            pose = (x, y, yaw) if i == 0 else (s.x, s.y, s.yaw)
            try:
                robot_model = model if s.model == "puzzlebot" else load_robot_model(s.model)
                app.add_robot(s.name, robot_model, *pose, namespaced)
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
        if gui and view is not None:
            stop_view = view(app, options, log)
            if stop_view is None:
                return 1
        app.start()
        try:
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
