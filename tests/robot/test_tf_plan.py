"""robot_state_publisher's fast path (a TfPlan per list of names, the previous list recognised by its
bytes, the throttle's streak) publishes what the general path publishes, message for message: the same
transforms in the same order to 1e-12, the same throttling, across lists that alternate, unknown
joints, a mimic joint, prismatic joints, a clock that moves backwards and malformed messages."""

from __future__ import annotations

import ast
import io
import math
import struct
from typing import Any

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.robot.kinematics import parse_urdf
from ninjemys.robot.state_publisher import StatePublisher
from ninjemys.robot.tf_plan import TfPlan
from ninjemys.rostime import Time

from .test_state_publisher import ARM, MOVING

JointState = get_message_class("sensor_msgs/JointState")
TFMessage = get_message_class("tf2_msgs/TFMessage")


class _Pub:
    def __init__(self) -> None:
        self.sent: list[bytes] = []

    def publish_raw(self, data: bytes) -> None:
        self.sent.append(bytes(data))

    def publish_framed(self, frame: bytes) -> None:
        (length,) = struct.unpack_from("<I", frame)
        assert length == len(frame) - 4  # the plan's constant length is the message's
        self.sent.append(bytes(frame[4:]))


class _Node:
    def __init__(self, params: dict[str, Any]) -> None:
        self.params = params
        self.clock = Time(1, 0)  # the node's ROS time: tests move it

    def get_param(self, key: str, default: Any = None) -> Any:
        return self.params.get(key, default)

    def search_param(self, key: str) -> str | None:
        return None

    def publisher(self, *args: Any, **kwargs: Any) -> _Pub:
        return _Pub()

    def subscriber(self, *args: Any, **kwargs: Any) -> None:
        return None

    def now(self) -> Time:
        return self.clock


class _Raw:
    def __init__(self, data: bytes) -> None:
        self.data = data


def _publisher(params: dict[str, Any]) -> tuple[StatePublisher, list[str]]:
    warnings: list[str] = []
    return StatePublisher(_Node(params), parse_urdf(ARM), warnings.append), warnings


def _stream() -> list[tuple[list[str], list[float], int, int]]:
    """(names, positions, secs, nsecs): two alternating lists (one naming an unknown joint), messages
    closer than the 50 Hz throttle, a reordered list, a clock reset, a list that names only the mimic
    leader, and the first list again."""
    out = []
    for k in range(40):
        names = MOVING + (["not_a_joint"] if k % 3 == 1 else [])
        positions = [0.37 * k - 1.1 * i for i in range(len(MOVING))] + ([5.0] if k % 3 == 1 else [])
        out.append((names, positions, 100 + k // 4, (k % 4) * 7_000_000))  # 7 ms apart within a second
    out.append((list(reversed(MOVING)), [0.2 * i for i in range(len(MOVING))], 200, 0))
    out.append((MOVING, [1.0] * len(MOVING), 50, 0))  # backwards: everything republished
    out.append((["finger_l_joint"], [0.03], 60, 0))
    out.append((["j3", "finger_l_joint"], [2.0, 0.01], 60, 5_000_000))
    out += [(MOVING, [0.1 * k] * len(MOVING), 61 + k, 0) for k in range(3)]
    return out


def _encode(names: list[str], positions: list[float], secs: int, nsecs: int) -> bytes:
    msg = JointState(name=names, position=positions)
    msg.header.stamp = Time(secs, nsecs)
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue()


def _transforms(data: bytes) -> list[tuple[str, str, int, int, tuple[float, ...]]]:
    msg = TFMessage().deserialize(data)
    out = []
    for t in msg.transforms:
        r, q = t.transform.translation, t.transform.rotation
        pose = (r.x, r.y, r.z, q.x, q.y, q.z, q.w)
        out.append((t.header.frame_id, t.child_frame_id, t.header.stamp.secs, t.header.stamp.nsecs, pose))
    return out


@pytest.mark.parametrize("ignore_timestamp", [False, True])
def test_the_fast_path_publishes_what_the_general_path_publishes(ignore_timestamp: bool) -> None:
    params = {"~ignore_timestamp": ignore_timestamp}
    fast, fast_warnings = _publisher(params)
    general, general_warnings = _publisher(params)
    for names, positions, secs, nsecs in _stream():
        fast.node.clock = general.node.clock = Time(secs, nsecs)  # a clock the stamps follow (a bag)
        fast.on_raw(_Raw(_encode(names, positions, secs, nsecs)))
        general.on_joint_state(tuple(names), tuple(positions), secs, nsecs)
    assert fast.plans  # the stream went through plans
    sent, expected = fast.tf.sent, general.tf.sent
    assert len(sent) == len(expected) and len(sent) > 10
    for ours, theirs in zip(sent, expected, strict=True):
        a, b = _transforms(ours), _transforms(theirs)
        assert [t[:4] for t in a] == [t[:4] for t in b]
        for ta, tb in zip(a, b, strict=True):
            assert max(abs(x - y) for x, y in zip(ta[4], tb[4], strict=True)) < 1e-12, ta[1]
    assert fast_warnings == general_warnings
    assert sum("not_a_joint" in w for w in fast_warnings) == 1
    assert sum("Moved backwards in time" in w for w in fast_warnings) == 1


def test_plan_of_a_mimic_and_a_prismatic_joint_in_closed_form() -> None:
    model = parse_urdf(ARM)
    mimics = {"finger_l_joint": [model.joints["finger_r_joint"]]}
    plan = TfPlan(["finger_l_joint", "j1"], model.joints, mimics, lambda joint: b"")
    assert plan.count == 3 and plan.known == ["finger_l_joint", "j1"]
    values = struct.unpack("<I" + "III0s7d" * 3, plan.message((0.009, math.pi / 2), struct.pack("<II", 7, 8)))
    rows = [values[1 + 11 * i : 12 + 11 * i] for i in range(3)]
    # finger_l slides along y from y = 0.02; j1 turns about z from yaw 0.3; finger_r mimics -x + 0.001
    assert rows[0][:3] == (0, 7, 8) and rows[0][4:7] == pytest.approx((0.0, 0.029, 0.05))
    half = (0.3 + math.pi / 2) / 2
    assert rows[1][4:] == pytest.approx((0, 0, 0.1, 0, 0, math.sin(half), math.cos(half)), abs=1e-12)
    assert rows[2][4:7] == pytest.approx((0.0, -0.02 - 0.009 + 0.001, 0.05))


def test_malformed_messages_are_ignored_with_one_line_each() -> None:
    fast, warnings = _publisher({})
    good = _encode(MOVING, [0.1] * len(MOVING), 10, 0)
    fast.on_raw(_Raw(good))
    fast.on_raw(_Raw(good[:-9]))  # the same names, positions cut short
    fast.on_raw(_Raw(good[:30]))  # cut inside the names
    assert len(fast.tf.sent) == 1
    assert warnings == ["Robot state publisher ignored a malformed JointState message"] * 2


def test_a_floating_mimic_joint_stays_at_its_origin_as_on_the_general_path() -> None:
    urdf = ARM.replace(
        "</robot>",
        '<link name="float"/><joint name="f" type="floating"><parent link="hand"/><child link="float"/>'
        '<origin xyz="0.1 0.2 0.3" rpy="0.3 0.2 0.1"/><mimic joint="j1" multiplier="2"/></joint></robot>',
    )
    fast, _ = _publisher({})
    general, _ = _publisher({})
    fast.model = general.model = parse_urdf(urdf)
    for sp in (fast, general):
        sp.mimics = {"j1": [sp.model.joints["f"]]}
        sp.encoded = {n: type(sp.encoded["j1"])(j, "") for n, j in sp.model.joints.items()}
    for k in range(3):
        fast.on_raw(_Raw(_encode(["j1"], [0.5 * k], 10 + k, 0)))
        general.on_joint_state(("j1",), (0.5 * k,), 10 + k, 0)
    assert len(fast.tf.sent) == 3
    for ours, theirs in zip(fast.tf.sent, general.tf.sent, strict=True):
        a, b = _transforms(ours), _transforms(theirs)
        assert [t[:4] for t in a] == [t[:4] for t in b] and a[1][1] == "float"
        for ta, tb in zip(a, b, strict=True):
            assert max(abs(x - y) for x, y in zip(ta[4], tb[4], strict=True)) < 1e-12


def test_two_publishers_with_interleaved_stamps_are_no_clock_reset() -> None:
    """joint_state_publisher beside Gazebo's joint_state_controller (the maker's course launch files)
    publish the wheels with stamps a step apart; ROS 1's robot_state_publisher compares its clock,
    not the stamps, and says nothing; a clock that really goes back is reported once."""
    rsp, warnings = _publisher({})
    for k in range(200):
        rsp.node.clock = Time(100, k * 5_000_000)
        stamp = k * 5_000_000 - (7_000_000 if k % 2 else 0)  # the second publisher lags 7 ms
        rsp.on_raw(_Raw(_encode(MOVING, [0.01 * k] * len(MOVING), 100, max(stamp, 0))))
    assert warnings == [] and rsp.tf.sent
    rsp.node.clock = Time(5, 0)
    rsp.on_raw(_Raw(_encode(MOVING, [0.0] * len(MOVING), 5, 0)))
    assert warnings == [
        "Moved backwards in time (probably because ROS clock was reset), re-publishing joint transforms!"
    ]


def test_a_robot_at_rest_gets_the_same_transforms_with_each_new_stamp() -> None:
    """Positions repeated from the last message published (joint_state_publisher's robot at rest)
    reuse that message with the new stamps: still what the general path publishes, message for
    message, also when the stream moves again, repeats an older position or skips a stamp."""
    fast, _ = _publisher({})
    general, _ = _publisher({})
    rest = [0.3 - 0.2 * i for i in range(len(MOVING))]
    moved = [0.1 * i for i in range(len(MOVING))]
    stream = [rest] * 4 + [moved] * 3 + [rest] * 2 + [moved] * 2
    for k, positions in enumerate(stream):
        stamp = (300 + k, 5_000_000 * k)
        fast.node.clock = general.node.clock = Time(*stamp)
        fast.on_raw(_Raw(_encode(MOVING, positions, *stamp)))
        general.on_joint_state(tuple(MOVING), tuple(positions), *stamp)
    entry = next(iter(fast.plans.values()))
    assert entry.segments is not None  # the last message repeated the one before
    assert len(fast.tf.sent) == len(general.tf.sent) == len(stream)
    for ours, theirs in zip(fast.tf.sent, general.tf.sent, strict=True):
        a, b = _transforms(ours), _transforms(theirs)
        assert [t[:4] for t in a] == [t[:4] for t in b]
        for ta, tb in zip(a, b, strict=True):
            assert max(abs(x - y) for x, y in zip(ta[4], tb[4], strict=True)) < 1e-12, ta[1]


def test_joints_without_origin_rotation_about_each_axis_match_the_general_pose() -> None:
    """The generated code leaves out the terms a zero constant removes (an origin without rotation,
    an axis along x, y, z or -z: most URDFs): the same poses as the general pose function."""
    axes = ["1 0 0", "0 1 0", "0 0 1", "0 0 -1"]
    urdf = (
        '<robot name="r"><link name="l0"/>'
        + "".join(
            f'<link name="l{i + 1}"/><joint name="j{i}" type="continuous"><parent link="l{i}"/>'
            f'<child link="l{i + 1}"/><origin xyz="0.1 0 {i}"/><axis xyz="{axis}"/></joint>'
            for i, axis in enumerate(axes)
        )
        + "</robot>"
    )
    model = parse_urdf(urdf)
    names = [f"j{i}" for i in range(len(axes))]
    plan = TfPlan(names, model.joints, {}, lambda joint: b"")
    assert "c * 0.0" not in plan.source.text and "s * 1.0" not in plan.source.text
    for angle in (0.0, 0.4, 2.0, 3.0, -2.5, 6.0):
        values = struct.unpack("<" + "4x8s0s7d" * len(axes), plan.message([angle] * len(axes), bytes(8))[4:])
        for i, name in enumerate(names):
            expected = model.joints[name].transform(angle)
            assert values[2 + 9 * i : 9 + 9 * i] == pytest.approx(expected, abs=1e-12), (name, angle)


@pytest.mark.parametrize("fast", [True, False])
def test_a_stream_exactly_at_publish_frequency_is_published_whole(fast: bool) -> None:
    """ROS 1 publishes when the stamp is at least one period after the joints' last one
    (``stamp >= last + interval``, measured: Debian's node publishes all 50 of a stream stamped
    20 ms apart at the default 50 Hz); closer stamps are throttled."""
    rsp, _ = _publisher({})
    steps = [20_000_000] * 6 + [10_000_000] * 4  # 6 at the period, then 4 at half of it
    nsecs = 0
    for step in steps:
        nsecs += step
        rsp.node.clock = Time(300, nsecs)
        if fast:
            rsp.on_raw(_Raw(_encode(MOVING, [nsecs * 1e-9] * len(MOVING), 300, nsecs)))
        else:
            rsp.on_joint_state(tuple(MOVING), (nsecs * 1e-9,) * len(MOVING), 300, nsecs)
    assert len(rsp.tf.sent) == 6 + 2


def test_publish_frequency_below_one_hertz_is_one_hertz() -> None:
    assert _publisher({"~publish_frequency": 0.0})[0].interval_ns == 1_000_000_000
    assert _publisher({"~publish_frequency": 0.25})[0].interval_ns == 1_000_000_000
    assert _publisher({"~publish_frequency": 10.0})[0].interval_ns == 100_000_000


def test_positions_that_do_not_match_the_plan_are_reported_even_inside_the_throttle() -> None:
    """The fast path checks the position count before the throttle (and unpacks the positions only
    for a message it publishes): a message with fewer positions than names is reported as invalid
    though it comes within the interval, as ROS 1 checks the sizes first; the next good message
    after the interval is published with its own positions."""
    fast, warnings = _publisher({})
    fast.on_raw(_Raw(_encode(MOVING, [0.1] * len(MOVING), 10, 0)))
    fast.on_raw(_Raw(_encode(MOVING, [0.2] * (len(MOVING) - 1), 10, 1_000_000)))
    fast.on_raw(_Raw(_encode(MOVING, [0.3] * len(MOVING), 10, 2_000_000)))  # throttled: 2 ms after
    fast.on_raw(_Raw(_encode(MOVING, [0.4] * len(MOVING), 10, 30_000_000)))
    assert warnings == ["Robot state publisher ignored an invalid JointState message"]
    general, _ = _publisher({})
    general.on_joint_state(tuple(MOVING), (0.1,) * len(MOVING), 10, 0)
    general.on_joint_state(tuple(MOVING), (0.4,) * len(MOVING), 10, 30_000_000)
    assert len(fast.tf.sent) == len(general.tf.sent) == 2
    for ours, theirs in zip(fast.tf.sent, general.tf.sent, strict=True):
        for ta, tb in zip(_transforms(ours), _transforms(theirs), strict=True):
            assert ta[:4] == tb[:4]
            assert max(abs(x - y) for x, y in zip(ta[4], tb[4], strict=True)) < 1e-12


def test_a_long_chain_is_packed_in_short_calls_with_the_general_paths_bytes() -> None:
    """A plan of 30 joints packs its message in calls of at most 28 arguments (a longer call is built
    as a list, one append per argument), joined: the same bytes as the general path's message."""
    count = 30
    urdf = (
        '<robot name="r"><link name="l0"/>'
        + "".join(
            f'<link name="l{i + 1}"/><joint name="j{i}" type="{"prismatic" if i % 4 == 3 else "revolute"}">'
            f'<parent link="l{i}"/><child link="l{i + 1}"/><origin xyz="0.{i % 7} 0.1 0.2" rpy="0.{i % 5} -0.3 1"/>'
            f'<axis xyz="0 {i % 2} 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
            for i in range(count)
        )
        + "</robot>"
    )
    model = parse_urdf(urdf)
    names = [f"j{i}" for i in range(count)]
    general = StatePublisher(_Node({}), model, print)
    plan = TfPlan(names, model.joints, {}, lambda joint: general.encoded[joint.name].frames)
    calls = [node for node in ast.walk(ast.parse(plan.source.text)) if isinstance(node, ast.Call)]
    assert max(len(call.args) for call in calls) <= 28
    assert sum(len(call.args) for call in calls) > 2 * 28  # several packs
    for k in range(5):
        positions = [0.7 * k - 0.3 * i for i in range(count)]
        stamp = Time(10 + k, 5)
        general.on_joint_state(tuple(names), tuple(positions), stamp.secs, stamp.nsecs)
        ours = _transforms(plan.message(positions, struct.pack("<II", stamp.secs, stamp.nsecs)))
        theirs = _transforms(general.tf.sent[-1])
        assert [t[:4] for t in ours] == [t[:4] for t in theirs]
        for ta, tb in zip(ours, theirs, strict=True):
            assert max(abs(x - y) for x, y in zip(ta[4], tb[4], strict=True)) < 1e-12, ta[1]
