"""robot_state_publisher: the robot's joint states in, its link frames out, as ROS 1's C++ node.

Reads the URDF from ``robot_description`` (found with searchParam, like urdf::Model::initParam),
subscribes ``joint_states`` and publishes, for every revolute, continuous and prismatic joint (and
every joint that mimics one), parent link -> child link on ``/tf`` stamped with the joint state's
stamp. Fixed joints go once on the latched ``/tf_static`` (``~use_tf_static``, default true), or
else on ``/tf`` every ``1/publish_frequency`` stamped half a second ahead, as ROS 1 does.

``~publish_frequency`` (50 Hz) throttles a joint's transforms to that rate unless
``~ignore_timestamp`` is set; ``tf_prefix`` (searched up the namespace) prefixes frames with tf's
resolve rule. A message naming joints the robot does not have is used for the joints it does
have, with one warning per new set of unknown names (ROS 1 ignores them silently).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.node.run import run_node
from ninjemys.robot.kinematics import MOVING, Joint, RobotModel, URDFError, parse_urdf
from ninjemys.robot.tf_wire import Layout, WireJoint
from ninjemys.rostime import Duration, Time


def resolve_frame(prefix: str, frame: str) -> str:
    """tf's ``resolve(prefix, frame)``: a global frame loses its slash; else ``prefix/frame``."""
    if frame.startswith("/"):
        return frame.lstrip("/")
    if prefix:
        return f"{prefix.lstrip('/')}/{frame}"
    return frame


class StatePublisher:
    """The node's state: the model, the last publish time of each joint, the publishers."""

    def __init__(self, node: Any, model: RobotModel, log: Callable[[str], None]) -> None:
        self.node, self.model, self.warn = node, model, log
        self.TransformStamped = get_message_class("geometry_msgs/TransformStamped")
        self.TFMessage = get_message_class("tf2_msgs/TFMessage")
        self.frequency = float(node.get_param("~publish_frequency", 50.0))
        self.interval = Duration.from_sec(1.0 / self.frequency) if self.frequency > 0 else Duration(0)
        self.ignore_timestamp = bool(node.get_param("~ignore_timestamp", False))
        self.use_tf_static = bool(node.get_param("~use_tf_static", True))
        prefix_key = node.search_param("tf_prefix")
        self.prefix = str(node.get_param(prefix_key, "")) if prefix_key else ""
        self.mimics: dict[str, list[Joint]] = {}
        for joint in model.joints.values():
            if joint.mimic:
                self.mimics.setdefault(joint.mimic.joint, []).append(joint)
        self.interval_ns = self.interval.to_nsec()
        self.wire = {
            j.name: WireJoint(j, resolve_frame(self.prefix, j.parent), resolve_frame(self.prefix, j.child))
            for j in model.joints.values()
        }
        self.plans: dict[tuple[str, ...], tuple[tuple[str, ...], Layout | None, tuple[Any, ...]]] = {}
        self.last_published: dict[str, int] = {}
        self.last_stamp: int | None = None
        self.unknown_seen: set[frozenset[str]] = set()
        self.lock = threading.Lock()
        self.tf = node.publisher("/tf", self.TFMessage, queue_size=100)
        self.tf_static = node.publisher("/tf_static", self.TFMessage, queue_size=100, latch=True)
        JointState = get_message_class("sensor_msgs/JointState")
        self.sub = node.subscriber("joint_states", JointState, self.on_joint_state, queue_size=100)

    def start(self) -> None:
        """Fixed joints: once, latched (use_tf_static), or on a timer on /tf."""
        if self.use_tf_static:
            self.tf_static.publish(self._message(self.model.fixed, {}, self.node.now()))
        elif self.model.fixed and self.frequency > 0:
            self.node.timer(self.interval, lambda _e: self._publish_fixed_on_tf())

    def _publish_fixed_on_tf(self) -> None:
        stamp = self.node.now() + Duration.from_sec(0.5)
        self.tf.publish(self._message(self.model.fixed, {}, stamp))

    def on_joint_state(self, msg: Any) -> None:
        names, positions = msg.name, msg.position
        if len(names) != len(positions):
            if not positions:
                self.warn(
                    f'Robot state publisher ignored a JointState message about joint(s) "{", ".join(names)}"'
                    " without position"
                )
            else:
                self.warn("Robot state publisher ignored an invalid JointState message")
            return
        key = tuple(names)
        plan = self.plans.get(key)
        if plan is None:
            plan = self._plan(key)
        known, layout, mimics = plan
        stamp = msg.header.stamp
        secs, nsecs = stamp.secs, stamp.nsecs
        now = secs * 1_000_000_000 + nsecs
        with self.lock:
            if self.last_stamp is not None and now < self.last_stamp:
                self.warn(
                    "Moved backwards in time (probably because ROS clock was reset), re-publishing joint transforms!"
                )
                self.last_published.clear()
            self.last_stamp = now
            if not known:
                return
            last = self.last_published
            oldest = min([last.get(n, 0) for n in known])
            if not (self.ignore_timestamp or now > oldest + self.interval_ns):
                return
            for name in known:
                last[name] = now
        if layout is None:
            return
        values = dict(zip(names, positions, strict=True))
        for source, name, multiplier, offset in mimics:
            values[name] = values[source] * multiplier + offset
        self.tf.publish_raw(layout.pack(values, secs, nsecs))

    def _plan(self, names: tuple[str, ...]) -> tuple[tuple[str, ...], Layout | None, tuple[Any, ...]]:
        """What a message naming ``names`` publishes: worked out once per list of names."""
        joints = self.model.joints
        unknown = frozenset(n for n in names if n not in joints)
        if unknown and unknown not in self.unknown_seen:
            self.unknown_seen.add(unknown)
            self.warn(
                f"joint_states names joint(s) the robot does not have, ignored: {', '.join(sorted(unknown))}"
            )
        known = tuple(dict.fromkeys(n for n in names if n in joints))
        moving = [self.wire[n] for n in known if joints[n].type in MOVING]
        mimics = []
        for name in known:
            for mimic in self.mimics.get(name, ()):
                assert mimic.mimic is not None
                mimics.append((name, mimic.name, mimic.mimic.multiplier, mimic.mimic.offset))
                if mimic.type != "fixed":
                    moving.append(self.wire[mimic.name])
        plan = (known, Layout(moving) if moving else None, tuple(mimics))
        if len(self.plans) < 64:  # a stream keeps one list of names; a bounded cache for odd ones
            self.plans[names] = plan
        return plan

    def _message(self, joints: list[Joint], values: dict[str, float], stamp: Time) -> Any:
        transforms = []
        for joint in joints:
            x, y, z, qx, qy, qz, qw = joint.transform(values.get(joint.name, 0.0))
            t = self.TransformStamped()
            t.header.stamp = stamp
            t.header.frame_id = resolve_frame(self.prefix, joint.parent)
            t.child_frame_id = resolve_frame(self.prefix, joint.child)
            tr, rot = t.transform.translation, t.transform.rotation
            tr.x, tr.y, tr.z = x, y, z
            rot.x, rot.y, rot.z, rot.w = qx, qy, qz, qw
            transforms.append(t)
        return self.TFMessage(transforms=transforms)


def load_model(node: Any) -> RobotModel:
    """The URDF on the parameter server (``robot_description``, searched up the namespace)."""
    key = node.search_param("robot_description") or "robot_description"
    try:
        text = node.get_param(key)
    except NinjemysError:
        raise URDFError(f"Could not find parameter {key} on parameter server") from None
    if not isinstance(text, str):
        raise URDFError(f"parameter {key} is not a string (a URDF document)")
    return parse_urdf(text, source=f"parameter {node.resolve_name(key)}")


def main(argv: list[str] | None = None, legacy: bool = False) -> int:
    """``rosrun robot_state_publisher robot_state_publisher`` (and the legacy ``state_publisher``)."""

    def build(node: Any) -> int:
        if legacy:
            node.log.warn(
                "The 'state_publisher' executable is deprecated. Please use 'robot_state_publisher' instead"
            )
        try:
            model = load_model(node)
        except URDFError as exc:
            node.log.error("%s", exc)
            return 1
        StatePublisher(node, model, lambda text: node.log.warn("%s", text)).start()
        return 0

    return run_node("robot_state_publisher", argv, build)


def legacy_main(argv: list[str] | None = None) -> int:
    return main(argv, legacy=True)
