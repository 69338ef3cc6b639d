"""The step loop's outputs: every step's /clock, odometry, /tf and joint_states at the step's stamp,
in order, the odometry's transform carrying the odometry's pose; a topic subscribed while the
simulation runs is served from then on (who listens is read every step). ``bench/sim_outputs.py``
compares every topic byte for byte with an older tree; these check the parts that matter alone."""

from __future__ import annotations

import math
import threading
import time
from pathlib import Path

from test_sim_node import master, sims  # noqa: F401  (fixtures)

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.sim import messages
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import load_world
from ninjemys.sim.worlds import world_path
from ninjemys.testing import wait_until

URDF = Path(messages.__file__).parent.parent / "packages/share/puzzlebot_sim/robots/puzzlebot.urdf"
STEP_NS = 10_000_000


class Recorder:
    """Every message of a topic, in arrival order."""

    def __init__(self, node: Node, topic: str, kind: str) -> None:
        self.msgs: list = []
        self._lock = threading.Lock()
        self.sub = node.subscriber(topic, get_message_class(kind), self._on, queue_size=100_000)

    def _on(self, msg) -> None:  # type: ignore[no-untyped-def]
        with self._lock:
            self.msgs.append(msg)

    def all(self) -> list:
        with self._lock:
            return list(self.msgs)


def _ns(stamp) -> int:  # type: ignore[no-untyped-def]
    return stamp.secs * 1_000_000_000 + stamp.nsecs


def test_every_step_publishes_clock_odometry_tf_and_joints_at_its_stamp(sims, master):  # noqa: F811
    sims("_world:=office", "_rate:=4", f"_model:={URDF}", "_paused:=true")
    node = Node("step_outputs", anonymous=True, master_uri=master)
    try:
        clock = Recorder(node, "/clock", "rosgraph_msgs/Clock")
        odom = Recorder(node, "/odom", "nav_msgs/Odometry")
        tf = Recorder(node, "/tf", "tf2_msgs/TFMessage")
        joints = Recorder(node, "/joint_states", "sensor_msgs/JointState")
        twist_cls = get_message_class("geometry_msgs/Twist")
        drive = node.publisher("/cmd_vel", twist_cls, queue_size=1, latch=True)
        twist = twist_cls()
        twist.linear.x, twist.angular.z = 0.1, 0.5
        drive.publish(twist)
        subs = (clock, odom, tf, joints)
        wait_until(lambda: drive.get_num_connections() and all(r.sub.get_num_connections() for r in subs))
        empty = get_service_class("std_srvs/Empty")
        node.service_proxy("/gazebo/unpause_physics", empty).call()
        wait_until(lambda: len(clock.all()) >= 50, 30, "/clock running")
        # subscribed while the simulation runs: served from the next step on
        scan = Recorder(node, "/scan", "sensor_msgs/LaserScan")
        states = Recorder(node, "/gazebo/model_states", "gazebo_msgs/ModelStates")
        wait_until(lambda: len(scan.all()) >= 4 and len(states.all()) >= 3, 30, "late subscribers served")
        node.service_proxy("/gazebo/pause_physics", empty).call()
        time.sleep(0.5)  # what is on its way arrives
    finally:
        node.shutdown("test over")
    ticks = [_ns(m.clock) for m in clock.all()]
    assert all(b - a == STEP_NS for a, b in zip(ticks, ticks[1:], strict=False)), "a /clock step missing"
    odoms = odom.all()
    stamps = [_ns(m.header.stamp) for m in odoms]
    assert all(b - a == STEP_NS for a, b in zip(stamps, stamps[1:], strict=False)), "an odometry step missing"
    assert [m.header.seq for m in odoms] == list(range(odoms[0].header.seq, odoms[0].header.seq + len(odoms)))
    assert set(stamps) <= set(ticks)
    assert [_ns(m.header.stamp) for m in joints.all()] == stamps
    poses = {_ns(m.header.stamp): m.pose.pose for m in odoms}
    moved = 0
    for msg in tf.all():
        (t,) = [t for t in msg.transforms if t.child_frame_id == odoms[0].child_frame_id]
        pose = poses[_ns(t.header.stamp)]
        assert t.header.frame_id == odoms[0].header.frame_id
        assert (t.transform.translation.x, t.transform.translation.y) == (pose.position.x, pose.position.y)
        q = t.transform.rotation
        assert (q.z, q.w) == (pose.orientation.z, pose.orientation.w)
        moved += pose.position.x != 0.0
    assert moved > 0
    scans = [_ns(m.header.stamp) for m in scan.all()]
    # 10 Hz (the first a step early: an idle lidar's schedule restarts at the step before it is read)
    assert all(b - a == 10 * STEP_NS for a, b in zip(scans[1:], scans[2:], strict=False))
    assert all(len(m.name) == len(m.pose) == len(m.twist) >= 1 for m in states.all())


def test_clock_is_time_and_time_ns_in_one_call():
    sim = Simulation(load_world(world_path("square")), 0.01, 0)
    for _ in range(3):
        for _ in range(137):
            sim.step()
        assert sim.clock() == (sim.time, sim.time_ns)
        sim.set_time_step(sim.dt / 2 + 0.0013)  # time goes on from where it is, at another step
    sim.reset_simulation()
    sim.step()
    assert sim.clock() == (sim.time, sim.time_ns)


def test_odometry_refreshed_with_a_given_quaternion_is_the_same_message():
    stamp = messages.stamp_of(3, 0.01)
    for yaw in (0.0, -0.0, 1.234, -3.1, math.pi):
        pose, twist = (1.5, -0.25, yaw), (0.2, -0.4)
        a = messages.odometry(stamp, "odom", "base", (0.0, 0.0, 0.0), (0.0, 0.0), (0.1, 0.1, 0.1, 0.1))
        b = messages.odometry(stamp, "odom", "base", (0.0, 0.0, 0.0), (0.0, 0.0), (0.1, 0.1, 0.1, 0.1))
        messages.odometry_into(a, stamp, pose, twist)
        messages.odometry_into(b, stamp, pose, twist, (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)))
        assert a.frame_parts()[1] == b.frame_parts()[1]


def test_the_step_keeps_the_robots_motion_and_the_walkers_route():
    """The physics step over a simulated minute: the robot drives its circle (wheel speeds ramped
    within the acceleration limit, the pose on the arc), the office's walker walks its route."""
    sim = Simulation(load_world(world_path("office")), 0.01, 0)
    r = sim.add_robot("pb", load_robot_model(str(URDF)), 0.0, 0.0, 0.0)
    r.command(0.05, 0.5)
    walker = sim.world.moving[0]
    wl, wr = r.target
    limit = r.model.max_wheel_accel * sim.dt
    for _ in range(6000):
        before = (r.wl, r.wr)
        sim.step()
        assert abs(r.wl - before[0]) <= limit + 1e-12 and abs(r.wr - before[1]) <= limit + 1e-12
    assert (r.wl, r.wr) == (wl, wr)
    assert math.hypot(r.x - 0.0, r.y - 0.1) < 0.11  # on its circle of radius v / w = 0.1 m around (0, 0.1)
    assert walker.walked > 0.0 and -math.pi <= r.yaw < math.pi
