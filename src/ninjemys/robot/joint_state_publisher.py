"""joint_state_publisher: a JointState for every movable joint of the URDF, as ROS 1's node.

Free joints sit at their "zero" (``~zeros/<joint>``, else 0 when the limits allow it, else the
middle of the limits; continuous joints span -pi..pi) until a ``~source_list`` topic moves them;
mimic joints (``~use_mimic_tags``) and ``~dependent_joints`` follow their parent through chains,
``factor`` and ``offset``. Published on ``joint_states`` at ``~rate`` (10 Hz) in the URDF's joint
order, with positions/velocities/efforts as ``~publish_default_*`` say, limits narrowed by
``<safety_controller>`` under ``~use_smallest_joint_limits``, and ``~delta`` sweeping the free joints.

Differences, both ROS 1 bugs: a joint with no ``<limit>`` is left out with ROS 1's warning (ROS 1
then crashes in its publishing loop); ``~delta`` works (ROS 1's uses Python 2's ``iteritems``). Each
parameter is read as ROS 1 reads it: ``~name`` first, then ``name`` in the node's namespace.
"""

from __future__ import annotations

import math
import threading
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.node.run import run_node
from ninjemys.robot.kinematics import URDFError

_UNSET = object()


@dataclass
class FreeJoint:
    minimum: float
    maximum: float
    zero: float
    continuous: bool = False
    values: dict[str, float] = field(default_factory=dict)  # position / velocity / effort
    forward: bool = True


class JointStatePublisher:
    """The joints, their current values and the message of one cycle (no I/O here but logging)."""

    def __init__(self, description: str, params: Any, warn: Any) -> None:
        self.params, self.warn = params, warn
        self.use_mimic = bool(params("use_mimic_tags", True))
        self.use_small = bool(params("use_smallest_joint_limits", True))
        defaults = (
            ("position", params("publish_default_positions", True)),
            ("velocity", params("publish_default_velocities", False)),
            ("effort", params("publish_default_efforts", False)),
        )
        self.defaults = [kind for kind, on in defaults if on]
        dependent = params("dependent_joints", {}) or {}
        if not isinstance(dependent, dict):
            raise URDFError("~dependent_joints must be a dictionary of joint -> {parent, factor, offset}")
        self.dependent: dict[str, dict[str, Any]] = dict(dependent)
        self.free: dict[str, FreeJoint] = {}
        self.order: list[str] = []
        self.lock = threading.Lock()
        self._read_urdf(description)

    def _read_urdf(self, description: str) -> None:
        try:
            robot = ET.fromstring(description)
        except ET.ParseError as exc:
            line, column = exc.position
            raise URDFError(f"robot_description:{line}:{column}: malformed XML: {exc}") from None
        for el in robot.findall("joint"):
            kind, name = el.get("type", ""), el.get("name", "")
            if kind in ("fixed", "floating", "planar"):
                continue
            if kind == "continuous":
                low, high = -math.pi, math.pi
            else:
                limit = el.find("limit")
                try:
                    assert limit is not None
                    low, high = float(limit.get("lower", "")), float(limit.get("upper", ""))
                except (AssertionError, ValueError):
                    self.warn(f"{name} is not fixed, nor continuous, but limits are not specified!")
                    continue
            self.order.append(name)
            safety = el.findall("safety_controller")
            if self.use_small and len(safety) == 1:
                if safety[0].get("soft_lower_limit") is not None:
                    low = max(low, float(safety[0].get("soft_lower_limit", "0")))
                if safety[0].get("soft_upper_limit") is not None:
                    high = min(high, float(safety[0].get("soft_upper_limit", "0")))
            mimic = el.findall("mimic")
            if self.use_mimic and len(mimic) == 1:
                entry: dict[str, Any] = {"parent": mimic[0].get("joint", "")}
                if mimic[0].get("multiplier") is not None:
                    entry["factor"] = float(mimic[0].get("multiplier", "1"))
                if mimic[0].get("offset") is not None:
                    entry["offset"] = float(mimic[0].get("offset", "0"))
                self.dependent[name] = entry
                continue
            if name in self.dependent:
                continue
            zero = self.params(f"zeros/{name}", None)
            if not zero:
                zero = (high + low) / 2 if low > 0 or high < 0 else 0
            joint = FreeJoint(low, high, float(zero), continuous=kind == "continuous")
            joint.values = {kind: (joint.zero if kind == "position" else 0.0) for kind in self.defaults}
            self.free[name] = joint
        for name in self.order:
            if name in self.dependent:
                self._chain(name)

    def _chain(self, name: str) -> tuple[str, float, float]:
        """The free joint ``name`` follows, and the composed factor and offset."""
        entry = self.dependent[name]
        parent, factor, offset = entry["parent"], entry.get("factor", 1), entry.get("offset", 0)
        seen = [name]
        while parent in self.dependent:
            if parent in seen:
                raise URDFError(f"Found an infinite recursive mimic chain: [{', '.join(seen)}, {parent}]")
            seen.append(parent)
            entry = self.dependent[parent]
            parent = entry["parent"]
            offset += factor * entry.get("offset", 0)
            factor *= entry.get("factor", 1)
        if parent not in self.free:
            raise URDFError(f"joint '{name}' follows '{parent}', which is not a free joint of the robot")
        return parent, factor, offset

    def on_source(self, msg: Any) -> None:
        """A ``source_list`` JointState: the values it gives for free joints."""
        with self.lock:
            for i, name in enumerate(msg.name):
                joint = self.free.get(name)
                if joint is None:
                    continue
                for kind, values in (
                    ("position", msg.position),
                    ("velocity", msg.velocity),
                    ("effort", msg.effort),
                ):
                    if len(values) > i:
                        joint.values[kind] = float(values[i])

    def sweep(self, delta: float) -> None:
        """``~delta``: move every free joint by ``delta`` per cycle, back and forth between its limits."""
        with self.lock:
            for joint in self.free.values():
                position = joint.values.get("position", joint.zero)
                if joint.forward:
                    position += delta
                    if position > joint.maximum:
                        position = joint.minimum if joint.continuous else joint.maximum
                        joint.forward = joint.continuous
                else:
                    position -= delta
                    if position < joint.minimum:
                        position, joint.forward = joint.minimum, True
                joint.values["position"] = position

    def fill(self, msg: Any) -> bool:
        """Fill ``msg`` (names in URDF order, values as ROS 1 lays them out); False if it is empty."""
        with self.lock:
            kinds = {kind for joint in self.free.values() for kind in joint.values}
            if self.dependent:
                kinds.add("position")
            count = len(self.free) + len(self.dependent)
            arrays = {kind: [0.0] * count for kind in ("position", "velocity", "effort") if kind in kinds}
            names = []
            for i, name in enumerate(self.order):
                names.append(name)
                if name in self.free:
                    joint, factor, offset = self.free[name], 1.0, 0.0
                elif name in self.dependent:
                    parent, factor, offset = self._chain(name)
                    joint = self.free[parent]
                else:
                    continue
                if "position" in arrays and "position" in joint.values:
                    arrays["position"][i] = joint.values["position"] * factor + offset
                if "velocity" in arrays and "velocity" in joint.values:
                    arrays["velocity"][i] = joint.values["velocity"] * factor
                if "effort" in arrays and "effort" in joint.values:
                    arrays["effort"][i] = joint.values["effort"]
        msg.name = names
        msg.position = arrays.get("position", [])
        msg.velocity = arrays.get("velocity", [])
        msg.effort = arrays.get("effort", [])
        return bool(names or msg.position or msg.velocity or msg.effort)


def _param_reader(node: Any) -> Any:
    def read(name: str, default: Any = _UNSET) -> Any:
        for key in (f"~{name}", name):
            try:
                return node.get_param(key)
            except NinjemysError:
                continue
        return None if default is _UNSET else default

    return read


def start(node: Any, extra_sources: tuple[str, ...] = ()) -> int:
    """Read the parameters, subscribe the sources (``~source_list`` and ``extra_sources``) and publish
    ``joint_states`` on a timer; non-zero when the node cannot run (no or bad robot_description)."""
    params = _param_reader(node)
    # ``~use_gui`` (Melodic's deprecated way to get the GUI) is ignored, as Noetic's 1.15 ignores it
    description = params("robot_description")
    if not isinstance(description, str):
        node.log.fatal("The robot_description parameter is required and not set.")
        return 1
    try:
        jsp = JointStatePublisher(description, params, lambda text: node.log.warn("%s", text))
    except URDFError as exc:
        node.log.fatal("%s", exc)
        return 1
    JointState = get_message_class("sensor_msgs/JointState")
    for source in [*(params("source_list", []) or []), *extra_sources]:
        node.subscriber(str(source), JointState, jsp.on_source, queue_size=10)
    pub = node.publisher("joint_states", JointState, queue_size=5)
    delta = float(params("delta", 0.0) or 0.0)

    def cycle(_event: Any) -> None:
        if delta > 0:
            jsp.sweep(delta)
        msg = JointState()
        msg.header.stamp = node.now()
        if jsp.fill(msg):
            pub.publish(msg)

    node.timer(1.0 / float(params("rate", 10)), cycle)
    return 0


def main(argv: list[str] | None = None) -> int:
    """``rosrun joint_state_publisher joint_state_publisher``."""
    return run_node("joint_state_publisher", argv, start)
