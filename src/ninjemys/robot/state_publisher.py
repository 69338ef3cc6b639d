"""robot_state_publisher: the robot's joint states in, its link frames out, as ROS 1's C++ node.

Reads the URDF from ``robot_description`` (found with searchParam, like urdf::Model::initParam),
subscribes ``joint_states`` and publishes, for every revolute, continuous and prismatic joint (and
every joint that mimics one), parent link -> child link on ``/tf`` stamped with the joint state's
stamp. Fixed joints go once on the latched ``/tf_static`` (``~use_tf_static``, default true), or
else on ``/tf`` every ``1/publish_frequency`` stamped half a second ahead, as ROS 1 does.

``~publish_frequency`` (50 Hz; below 1 Hz taken as 1, as ROS 1) throttles a joint's transforms to
that rate unless ``~ignore_timestamp`` is set: a message is published when its stamp is at least one
period after the joints' last, so a stream exactly at that rate goes out whole; the subscription's
queue holds one message, as ROS 1's (a backlog is published newest only); ``tf_prefix`` (searched up the namespace) prefixes frames with tf's
resolve rule. A message naming joints the robot does not have is used for the joints it does
have, with one warning per new set of unknown names (ROS 1 ignores them silently).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from ninjemys import names
from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.node.run import run_node
from ninjemys.robot.kinematics import Joint, Pose, RobotModel, URDFError, parse_urdf
from ninjemys.robot.tf_plan import TfPlan
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
        self.TFMessage = get_message_class("tf2_msgs/TFMessage")
        self.frequency = float(node.get_param("~publish_frequency", 50.0))
        self.interval = Duration.from_sec(1.0 / max(self.frequency, 1.0))  # as ROS 1: at least 1 Hz
        self.ignore_timestamp = bool(node.get_param("~ignore_timestamp", False))
        self.use_tf_static = bool(node.get_param("~use_tf_static", True))
        prefix_key = node.search_param("tf_prefix")
        self.prefix = str(node.get_param(prefix_key, "")) if prefix_key else ""
        self.encoded = {name: _JointEncoder(joint, self.prefix) for name, joint in model.joints.items()}
        self.mimics: dict[str, list[Joint]] = {}
        for joint in model.joints.values():
            if joint.mimic:
                self.mimics.setdefault(joint.mimic.joint, []).append(joint)
        self.interval_ns = int(self.interval.to_nsec())
        self.last_published: dict[str, int] = {}  # joint -> stamp (ns) of its last transform
        self.last_stamp_ns = 0
        self.last_clock_ns = 0  # the node's ROS time at the last message off the steady path
        self.unknown_seen: set[frozenset[str]] = set()
        self.tf = node.publisher("/tf", self.TFMessage, queue_size=100)
        self.tf_static = node.publisher("/tf_static", self.TFMessage, queue_size=100, latch=True)
        JointState = get_message_class("sensor_msgs/JointState")
        self.names_cache: dict[bytes, tuple[str, ...]] = {}
        self.plans: dict[bytes, _Entry] = {}
        self.last_entry: _Entry | None = None
        #: the list of names that followed itself, and its joints' last stamp (see :meth:`_admit`)
        self.streak: _Entry | None = None
        self.streak_ns = 0
        # a queue of one, as ROS 1's node: a backlog (a slow moment, a burst) is read and only the
        # newest message of it published
        self.sub = node.subscriber("joint_states", JointState, self.on_raw, queue_size=1, raw=True)

    def start(self) -> None:
        """Fixed joints: once, latched (use_tf_static), or on a timer on /tf."""
        if self.use_tf_static:
            self.tf_static.publish_raw(self._message(self.model.fixed, {}, self.node.now()))
        elif self.model.fixed:
            self.node.timer(self.interval, lambda _e: self._publish_fixed_on_tf())

    def _publish_fixed_on_tf(self) -> None:
        stamp = self.node.now() + Duration.from_sec(0.5)
        self.tf.publish_raw(self._message(self.model.fixed, {}, stamp))

    def on_raw(self, raw: Any) -> None:
        """A JointState as bytes: only the stamp, the names and the positions are read.

        The names are the same in every message of a stream: each distinct list is decoded once, and
        with it a :class:`TfPlan` is made that turns the positions into the TFMessage's frame. The list
        of the previous message is recognised by comparing its bytes where the names start, so a steady
        stream costs no walk through the names either. Called on the subscription's one thread (the
        throttle's record needs no lock); the steady case is written out inline, as this runs 50 times
        a second with cold caches, where every call and attribute costs."""
        data = raw.data
        if data.__class__ is memoryview:  # a view into a shared-memory ring (a message of >64 KiB)
            data = data.tobytes()
        try:
            secs, nsecs, frame_len = _STAMP_FRAME.unpack_from(data, 4)
            start = 16 + frame_len
            entry = self.last_entry
            # the names and the position count, as in the last message: one comparison of bytes
            if entry is None or not data.startswith(entry.head, start):
                key, count = self._names_section(data, start)
                entry = self.plans.get(key)
                if entry is None:
                    self._general(data, secs, nsecs, key, count, start + len(key))
                    return
                self.last_entry = entry
                if _COUNT.unpack_from(data, start + entry.size)[0] != entry.count:
                    self._general(data, secs, nsecs, key, count, start + entry.size)  # says what is wrong
                    return
            offset = start + entry.size  # the position count, then the positions
            # checked, not unpacked: a message the throttle drops (a third of a stream stamped at
            # publish_frequency with jitter) never has its positions made into floats
            if len(data) < offset + entry.span:
                self._general(data, secs, nsecs, entry.key, entry.count, offset)  # says what is wrong
                return
        except (struct.error, UnicodeDecodeError, IndexError, ValueError):
            self.warn("Robot state publisher ignored a malformed JointState message")
            return
        now_ns = secs * 1_000_000_000 + nsecs
        if self.streak is entry and now_ns >= self.last_stamp_ns:  # the steady case of _admit
            self.last_stamp_ns = now_ns
            if now_ns < self.streak_ns + self.interval_ns and not self.ignore_timestamp:
                return
            self.streak_ns = now_ns
        elif not self._admit(entry, now_ns):
            return
        if not entry.plan.count:
            return
        still = entry.still
        if still is not None and data.startswith(still, offset):
            # the positions of the last message published: only the stamps change
            if entry.segments is None:
                entry.segments = entry.plan.segments(entry.frame)
            self.tf.publish_framed(data[4:12].join(entry.segments))
            return
        entry.frame = frame = entry.plan.message(entry.positions.unpack_from(data, offset), data[4:12])
        entry.still, entry.segments = data[offset : offset + entry.span], None
        self.tf.publish_framed(frame)

    def _general(self, data: Any, secs: int, nsecs: int, key: bytes, count: int, offset: int) -> None:
        """A list of names without a plan yet (or positions that do not match it): decoded in full."""
        try:
            names = self.names_cache.get(key) or _names(key, count)
            (n,) = _COUNT.unpack_from(data, offset)
            if offset + 4 + 8 * n > len(data):
                raise struct.error("positions run past the end")
            values = struct.unpack_from(f"<{n}d", data, offset + 4)
        except (struct.error, UnicodeDecodeError, IndexError, ValueError):
            self.warn("Robot state publisher ignored a malformed JointState message")
            return
        if len(self.names_cache) < 64:
            self.names_cache[key] = names
        self.on_joint_state(names, values, secs, nsecs)
        if key not in self.plans and len(names) == n and len(set(names)) == n and len(self.plans) < 64:
            plan = TfPlan(names, self.model.joints, self.mimics, self._frames, skip=1, framed=True)
            self.plans[key] = self.last_entry = _Entry(key, n, plan)

    def _frames(self, joint: Joint) -> bytes:
        return self.encoded[joint.name].frames

    @staticmethod
    def _names_section(data: Any, start: int) -> tuple[bytes, int]:
        """The bytes of the names array (its count and every name: a plan's key) and the name count."""
        (count,) = _COUNT.unpack_from(data, start)
        offset = start + 4
        for _ in range(count):
            (length,) = _COUNT.unpack_from(data, offset)
            offset += 4 + length
        if offset > len(data):
            raise struct.error("names run past the end")
        return bytes(data[start:offset]), count

    def _admit(self, entry: _Entry, now_ns: int) -> bool:
        """ROS 1's throttle: publish when the stamp is at least one interval after the oldest last
        stamp of the joints named (``ignore_timestamp`` publishes all): a stream exactly at
        ``publish_frequency`` (simulated time) is published whole; the clock going back clears it.

        While one list of names follows itself, the record of its joints is one number (the streak,
        whose steady case :meth:`on_raw` checks inline) instead of a stamp per joint; another list (or
        the general path) writes it out first."""
        self._check_clock(now_ns)
        known = entry.known
        if not known:
            return False
        if self.streak is entry:
            if not self.ignore_timestamp and now_ns < self.streak_ns + self.interval_ns:
                return False
            self.streak_ns = now_ns
            return True
        self._flush_streak()
        last = self.last_published
        if not self.ignore_timestamp and now_ns < min(map(last.get, known, entry.zeros)) + self.interval_ns:
            return False
        self.streak, self.streak_ns = entry, now_ns
        return True

    def _admit_names(self, known: list[str], now_ns: int) -> bool:
        """:meth:`_admit` for a list of names without a plan (a stamp per joint)."""
        self._check_clock(now_ns)
        if not known:
            return False
        self._flush_streak()
        last = self.last_published
        if not self.ignore_timestamp and now_ns < min(last.get(n, 0) for n in known) + self.interval_ns:
            return False
        last.update(dict.fromkeys(known, now_ns))
        return True

    def _check_clock(self, now_ns: int) -> None:
        """The node's ROS time older than at the last message (a clock reset, a bag looping): every
        joint republished. As ROS 1's, this looks at the clock, not at the stamps: two publishers
        of one robot's joints (joint_state_publisher beside Gazebo's joint_state_controller, as the
        course launch files have them) interleave older and newer stamps with no reset."""
        clock_ns = self.node.now().to_nsec()
        if clock_ns < self.last_clock_ns:
            self.warn(
                "Moved backwards in time (probably because ROS clock was reset), re-publishing joint transforms!"
            )
            self.last_published.clear()
            self.streak = None
        self.last_clock_ns = clock_ns
        self.last_stamp_ns = now_ns

    def _flush_streak(self) -> None:
        """Write the streak's stamp to each of its joints."""
        if self.streak is not None:
            self.last_published.update(dict.fromkeys(self.streak.known, self.streak_ns))
            self.streak = None

    def on_joint_state(
        self, names: tuple[str, ...], positions: tuple[float, ...], secs: int, nsecs: int
    ) -> None:
        if len(names) != len(positions):
            if not positions:
                self.warn(
                    f'Robot state publisher ignored a JointState message about joint(s) "{", ".join(names)}"'
                    " without position"
                )
            else:
                self.warn("Robot state publisher ignored an invalid JointState message")
            return
        joints = self.model.joints
        known = [n for n in names if n in joints]
        if len(known) != len(names):
            unknown = frozenset(n for n in names if n not in joints)
            if unknown not in self.unknown_seen:
                self.unknown_seen.add(unknown)
                self.warn(
                    f"joint_states names joint(s) the robot does not have, ignored: {', '.join(sorted(unknown))}"
                )
        if not self._admit_names(known, secs * 1_000_000_000 + nsecs):
            return
        values = {n: p for n, p in zip(names, positions, strict=True) if n in joints}
        moving = [joints[n] for n in values if joints[n].type in _MOVING]
        mimics = self.mimics
        for name in list(values) if mimics else ():
            for mimic in mimics.get(name, ()):
                assert mimic.mimic is not None
                values[mimic.name] = values[name] * mimic.mimic.multiplier + mimic.mimic.offset
                if mimic.type != "fixed":
                    moving.append(mimic)
        if moving:
            self.tf.publish_raw(self._message(moving, values, Time(secs, nsecs)))

    def _message(self, joints: list[Joint], values: dict[str, float], stamp: Time) -> bytes:
        """The serialized TFMessage: one TransformStamped per joint (header seq 0, as tf2 sends)."""
        stamp_bytes = _STAMP.pack(0, stamp.secs, stamp.nsecs)
        parts = [_COUNT.pack(len(joints))]
        for joint in joints:
            parts.append(self.encoded[joint.name].encode(stamp_bytes, values.get(joint.name, 0.0)))
        return b"".join(parts)


_MOVING = frozenset(("revolute", "continuous", "prismatic"))
_COUNT = struct.Struct("<I")
_STAMP_FRAME = struct.Struct("<3I")  # after the seq: stamp secs, stamp nsecs, frame_id length
_STAMP = struct.Struct("<3I")
_POSE = struct.Struct("<7d")


class _Entry:
    """A list of names seen before: its bytes, the joints of it the robot has, its plan, and the
    precompiled unpacking of the position count and positions that follow it (the plan takes them
    as unpacked, count first)."""

    __slots__ = (
        "count",
        "frame",
        "head",
        "key",
        "known",
        "plan",
        "positions",
        "segments",
        "size",
        "span",
        "still",
        "zeros",
    )

    def __init__(self, key: bytes, count: int, plan: TfPlan) -> None:
        self.key, self.size, self.count, self.plan = key, len(key), count, plan
        #: the names and then the position count, as a message that matches the plan has them
        self.head = key + _COUNT.pack(count)
        self.known = plan.known
        self.zeros = [0] * len(self.known)
        self.positions = struct.Struct(f"<I{count}d")
        self.span = self.positions.size
        #: the count and positions (as received) of the last message published, and its frame; the
        #: frame cut around its stamps once a message repeats them (None until then)
        self.still: bytes | None = None
        self.frame = b""
        self.segments: list[bytes] | None = None


def _names(section: bytes, count: int) -> tuple[str, ...]:
    names, offset = [], 4
    for _ in range(count):
        (length,) = _COUNT.unpack_from(section, offset)
        names.append(section[offset + 4 : offset + 4 + length].decode("utf-8"))
        offset += 4 + length
    return tuple(names)


class _JointEncoder:
    """One joint's part of a TFMessage: its frame names serialized once, its pose per message."""

    def __init__(self, joint: Joint, prefix: str) -> None:
        parent = resolve_frame(prefix, joint.parent).encode()
        child = resolve_frame(prefix, joint.child).encode()
        self.frames = _COUNT.pack(len(parent)) + parent + _COUNT.pack(len(child)) + child
        self.pose: Callable[[float], Pose] = joint.pose_function()

    def encode(self, stamp: bytes, position: float) -> bytes:
        return stamp + self.frames + _POSE.pack(*self.pose(position))


def load_model(node: Any) -> RobotModel:
    """The URDF on the parameter server (``robot_description``, searched up the namespace)."""
    plain = names.resolve_name("robot_description", node.name, {})
    remapped = node.resolve_name("robot_description")  # roscpp's searchParam remaps the key first
    if remapped != plain or node.has_param(plain):
        key = remapped
    else:
        key = node.search_param("robot_description") or plain
    try:
        text = node.get_param(key)
    except NinjemysError:
        raise URDFError("Could not find parameter robot_description on parameter server") from None
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
