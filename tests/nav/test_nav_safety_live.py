"""The safety monitor as a running node: ``rosrun puzzlebot_safety safety_monitor`` against a master,
driven on sim time by a test node that owns ``/clock`` and publishes every input the monitor reads.

The rig's clock thread advances ``/clock`` in 10 ms steps, about twice as fast as real time, and
publishes the streamed commands (20 Hz), scan (10 Hz) and odometry from the same thread, so every
input and every ``cmd_vel`` received is placed on the sim time line; the watchdog is measured there.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.rostime import Time
from ninjemys.testing import NodeProcess, have_ros1, ninjemys_bin, ros1_env, run_master

PARAMS = (
    Path(__file__).resolve().parents[2]
    / "src/ninjemys/packages/share/puzzlebot_navigation/params/safety_params.yaml"
)
STEP = 0.01  # sim seconds per /clock message
WALL_PER_STEP = 0.005  # real seconds between them: sim time runs about twice as fast as real time

Twist = get_message_class("geometry_msgs/Twist")
Bool = get_message_class("std_msgs/Bool")


def wall_scan(distance: float | None) -> Any:
    """A 360-beam LaserScan in base_link: a 2 m wide wall ``distance`` ahead (None: nothing in range)."""
    scan = get_message_class("sensor_msgs/LaserScan")()
    scan.header.frame_id = "base_link"
    scan.angle_min, scan.angle_increment = -math.pi, 2 * math.pi / 360
    scan.angle_max = scan.angle_min + 359 * scan.angle_increment
    scan.range_min, scan.range_max = 0.05, 8.0
    a = scan.angle_min + np.arange(360) * scan.angle_increment
    ranges = np.full(360, np.inf)
    if distance is not None:
        ahead = np.cos(a) > 1e-3
        r = np.where(ahead, distance / np.where(ahead, np.cos(a), 1.0), np.inf)
        ranges = np.where(ahead & (np.abs(r * np.sin(a)) <= 1.0), r, np.inf)
    scan.ranges = ranges.tolist()
    return scan


class Rig:
    """A master on sim time, the monitor as a process, and a test node feeding it and watching it."""

    def __init__(self, tmp_path: Path, name: str = "safety_monitor", params: dict | None = None) -> None:
        self._master = run_master()
        self.uri = self._master.__enter__()
        self._running = False
        try:
            self._start(tmp_path, name, params or {})
        except BaseException:
            self.close()
            raise

    def _start(self, tmp_path: Path, name: str, params: dict) -> None:
        from ninjemys.node import Node

        self.env = dict(
            os.environ, ROS_MASTER_URI=self.uri, ROS_HOME=str(tmp_path / "ros_home"), PYTHONUNBUFFERED="1"
        )
        self.node = Node("safety_rig", anonymous=True, master_uri=self.uri, sim_time=False)
        self.node.set_param("/use_sim_time", True)
        for key, value in {**yaml.safe_load(PARAMS.read_text()), **params}.items():
            self.node.set_param(f"/{name}/{key}", value)
        self.lock = threading.Lock()
        self.now = 1.0
        self.streams: dict[str, tuple[float, float]] = {}
        self.flags: dict[str, tuple[Any, bool]] = {}  # Bool topics streamed: publisher, value
        self.last_sent: dict[str, float] = {}
        self.scan: Any = None
        self.odom_v: float | None = None
        self.cmds: list[tuple[float, float, float]] = []  # (sim time received, v, w)
        self.diags: list[Any] = []
        self.e_stop_active: list[bool] = []
        clock_cls = get_message_class("rosgraph_msgs/Clock")
        self._clock_msg = clock_cls()
        self._clock_pub = self.node.publisher("/clock", clock_cls, queue_size=1)
        self.pubs = {
            "teleop": self.node.publisher("/teleop/cmd_vel", Twist, queue_size=1),
            "navigation": self.node.publisher("/nav/cmd_vel", Twist, queue_size=1),
        }
        self._scan_pub = self.node.publisher(
            "/scan", get_message_class("sensor_msgs/LaserScan"), queue_size=1
        )
        self._odom_cls = get_message_class("nav_msgs/Odometry")
        self._odom_pub = self.node.publisher("/odom", self._odom_cls, queue_size=1)
        self._pose_cls = get_message_class("geometry_msgs/PoseWithCovarianceStamped")
        self._pose_pub = self.node.publisher("/amcl_pose", self._pose_cls, queue_size=1)
        self.e_stop_pub = self.node.publisher("/e_stop", Bool, queue_size=1)
        self.node.subscriber("/cmd_vel", Twist, self._on_cmd, queue_size=100)
        self.node.subscriber(
            "/diagnostics", get_message_class("diagnostic_msgs/DiagnosticArray"), self._on_diag, queue_size=10
        )
        self.node.subscriber(f"/{name}/e_stop_active", Bool, self._on_e_stop_active, queue_size=10)
        self._running = True
        self._clock_thread = threading.Thread(target=self._run_clock, name="rig-clock", daemon=True)
        self._clock_thread.start()
        self.proc = NodeProcess(
            [ninjemys_bin("rosrun"), "puzzlebot_safety", "safety_monitor", f"__name:={name}"],
            env=self.env,
            merge_stderr=True,
        )
        self.node.wait_for_service(f"/{name}/reset_e_stop", timeout=30.0)
        # the monitor connected to every fixed input (the command inputs depend on ~topics: stream())
        fixed = [self._clock_pub, self._scan_pub, self._odom_pub, self._pose_pub, self.e_stop_pub]
        assert self.wait_real(lambda: all(pub.get_num_connections() > 0 for pub in fixed), 30.0)

    # -- the clock thread: sim time and the periodic inputs --------------------------------------------

    def _run_clock(self) -> None:
        step = 0
        next_wall = time.monotonic()
        while self._running:
            with self.lock:
                self.now = round(self.now + STEP, 6)
                now = self.now
                streams, flags = dict(self.streams), dict(self.flags)
                scan, odom_v = self.scan, self.odom_v
            self._clock_msg.clock = _time(now)
            self._clock_pub.publish(self._clock_msg)
            step += 1
            if step % 5 == 0:
                for name, (v, w) in streams.items():
                    msg = Twist()
                    msg.linear.x, msg.angular.z = v, w
                    self.pubs[name].publish(msg)
                    with self.lock:
                        self.last_sent[name] = now
                for pub, value in flags.values():
                    pub.publish(Bool(data=value))
                if odom_v is not None:
                    odom = self._odom_cls()
                    odom.header.stamp = _time(now)
                    odom.twist.twist.linear.x = odom_v
                    self._odom_pub.publish(odom)
            if step % 10 == 0 and scan is not None:
                scan.header.stamp = _time(now)
                self._scan_pub.publish(scan)
            next_wall += WALL_PER_STEP
            time.sleep(max(0.0, next_wall - time.monotonic()))

    def _on_cmd(self, msg: Any) -> None:
        with self.lock:
            self.cmds.append((self.now, msg.linear.x, msg.angular.z))

    def _on_diag(self, msg: Any) -> None:
        with self.lock:
            self.diags.append(msg)

    def _on_e_stop_active(self, msg: Any) -> None:
        with self.lock:
            self.e_stop_active.append(msg.data)

    # -- what the tests use ----------------------------------------------------------------------------

    def stream(self, name: str, v: float | None, w: float = 0.0) -> None:
        """Publish (v, w) on input ``name`` at 20 Hz sim from now on (None: stop publishing)."""
        if v is not None:
            assert self.wait_real(lambda: self.pubs[name].get_num_connections() > 0)
        with self.lock:
            if v is None:
                self.streams.pop(name, None)
            else:
                self.streams[name] = (v, w)

    def set_scan(self, distance: float | None) -> None:
        with self.lock:
            self.scan = wall_scan(distance)

    def flag(self, topic: str, value: bool | None) -> None:
        """Publish std_msgs/Bool ``value`` on ``topic`` at 20 Hz sim from now on (None: stop)."""
        if value is None:
            with self.lock:
                self.flags.pop(topic, None)
            return
        pub = self.flags[topic][0] if topic in self.flags else self.node.publisher(topic, Bool, queue_size=1)
        assert self.wait_real(lambda: pub.get_num_connections() > 0)
        with self.lock:
            self.flags[topic] = (pub, value)

    def jump(self, seconds: float, stop: str | None = None) -> int:
        """Move sim time by ``seconds`` at once (negative: a simulation reset), in the same step
        stopping input ``stop`` if given (a loaded test thread must not let the watchdog fire
        before the jump); returns how many commands came before it (see :meth:`cmds_since`)."""
        with self.lock:
            if stop is not None:
                self.streams.pop(stop, None)
            self.now = round(self.now + seconds, 6)
            return len(self.cmds)

    def cmds_since(self, index: int) -> list[tuple[float, float, float]]:
        """The commands received after the first ``index`` ones (stamps repeat after a jump back)."""
        with self.lock:
            return self.cmds[index:]

    def scan_off(self) -> None:
        """The laser goes quiet."""
        with self.lock:
            self.scan = None

    def set_odom(self, v: float) -> None:
        with self.lock:
            self.odom_v = v

    def pose(self, variance: float) -> None:
        msg = self._pose_cls()
        msg.header.frame_id = "map"
        msg.header.stamp = _time(self.now)
        msg.pose.pose.orientation.w = 1.0
        cov = [0.0] * 36
        cov[0] = cov[7] = variance
        cov[35] = 0.05
        msg.pose.covariance = cov
        self._pose_pub.publish(msg)

    def cmds_from(self, t: float) -> list[tuple[float, float, float]]:
        with self.lock:
            return [c for c in self.cmds if c[0] >= t]

    def wait_real(self, predicate: Any, timeout: float = 20.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate():
                return True
            time.sleep(0.01)
        return False

    def settle(self, sim_seconds: float) -> float:
        """Let ``sim_seconds`` of sim time pass; returns the sim time it started at."""
        start = self.now
        assert self.wait_real(lambda: self.now >= start + sim_seconds, sim_seconds * 10 + 10)
        return start

    def output(self, sim_seconds: float = 0.4) -> tuple[float, float]:
        """The monitor's cmd_vel after ``sim_seconds``: the last twist received in the final 0.15 s, or
        the first after them. Waited for: the rig's clock runs on whether or not the monitor got CPU,
        and a loaded monitor answers later in sim time (two busy processes beside left 4 of 10 tests
        with no twist in those 0.15 s, about 75 ms of real time). Only twists received from now on
        count: after a jump back in time, older ones carry later stamps."""
        with self.lock:
            start, first = self.now, len(self.cmds)
        since = start + sim_seconds - 0.15

        def recent() -> list[tuple[float, float, float]]:
            return [c for c in self.cmds_since(first) if c[0] >= since]

        assert self.wait_real(lambda: self.now >= start + sim_seconds and recent(), sim_seconds * 10 + 10), (
            f"no cmd_vel since sim time {since:.2f} (now {self.now:.2f}); {self.log()}"
        )
        last = recent()[-1]
        return last[1], last[2]

    def log(self) -> str:
        """Everything the monitor printed so far."""
        return self.proc.text() if hasattr(self, "proc") else ""

    def status(self, since: float) -> Any:
        """The monitor's DiagnosticStatus from the first /diagnostics received after sim time ``since``."""
        assert self.wait_real(lambda: any(d.header.stamp.to_sec() > since for d in self.diags), 20.0)
        with self.lock:
            return next(d for d in self.diags if d.header.stamp.to_sec() > since).status[0]

    def close(self) -> None:
        """Stop whatever was started, in reverse order (also after a failed start)."""
        if hasattr(self, "proc"):
            self.proc.stop(grace=10)
        self._running = False
        if hasattr(self, "_clock_thread"):
            self._clock_thread.join(5)
        if hasattr(self, "node"):
            self.node.shutdown()
        self._master.__exit__(None, None, None)


def _time(t: float) -> Any:
    return Time.from_sec(t)


@pytest.fixture
def rig(tmp_path):
    r = Rig(tmp_path)
    try:
        yield r
    finally:
        r.close()
    assert "Traceback" not in r.log()


def test_safety_live_teleop_over_navigation_and_the_watchdog_on_sim_time(rig):
    rig.stream("navigation", 0.2, 0.1)
    assert rig.output() == pytest.approx((0.2, 0.1))
    rig.stream("teleop", 0.1, -0.5)
    assert rig.output() == pytest.approx((0.1, -0.5))  # teleop overrides navigation
    rig.stream("teleop", None)
    assert rig.output(0.8) == pytest.approx((0.2, 0.1))  # teleop went stale: navigation again
    rig.stream("navigation", None)
    last = rig.last_sent["navigation"]
    # the input's timeout is 0.5 s and the monitor runs at 20 Hz: it stops within a cycle of the
    # timeout, timed as twist_mux does from the command's arrival, by its own clock; it says the age.
    # Not on this rig's time line: sim time runs on at twice real time while a loaded machine carries
    # the last command and the stops (one stop came 0.9 s late here, at load 10)
    said = re.compile(r"navigation \(/nav/cmd_vel\) last came ([0-9.]+) s ago")
    assert rig.wait_real(lambda: said.search(rig.log()) is not None), rig.log()
    age = float(said.findall(rig.log())[-1])
    # not before its time (0.5 on the 10 ms /clock grid is stale in float: 0.5000000000000009, printed
    # 0.500), then within a cycle or two (the scan watchdog's bound)
    assert 0.5 <= age <= 0.5 + 0.1 + 0.1, age
    rig.settle(2.0)
    after = rig.cmds_from(last + 1e-6)
    # split in the order received, not by stamp: a loaded rig takes the last twists passed and the
    # first stop in one step of its clock, with one stamp
    cut = next(i for i, (t, v, w) in enumerate(after) if v == 0.0 and w == 0.0)
    assert all((v, w) == pytest.approx((0.2, 0.1)) for t, v, w in after[:cut])
    zeros = after[cut:]
    assert all(v == 0.0 and w == 0.0 for t, v, w in zeros), after
    # zero twists for one second, then silence (as twist_mux, no stream of stops forever): one a
    # cycle of its clock, 21 in a second; its Rate makes up a late cycle or two (22, 23 seen at load
    # 22) and skips starved ones
    assert 10 <= len(zeros) <= 21 + 3, zeros
    rig.stream("teleop", 0.05, 0.0)
    assert rig.output() == pytest.approx((0.05, 0.0))  # a fresh command passes again


def test_safety_live_watchdog_survives_time_moving_backwards(rig):
    rig.jump(20.0)
    rig.stream("navigation", 0.2, 0.0)
    assert rig.output() == pytest.approx((0.2, 0.0))
    diags = len(rig.diags)
    # /gazebo/reset_simulation: navigation stops and the last command now lies 15 s in the future
    before = rig.jump(-15.0, stop="navigation")
    back = rig.now
    assert rig.output(1.0) == (0.0, 0.0)
    first_zero = next(t for t, v, w in rig.cmds_since(before) if v == 0.0)
    assert first_zero - back <= 0.5 + 0.1
    rig.settle(1.5)
    assert len(rig.diags) > diags + 1  # diagnostics go on after the jump
    rig.stream("teleop", 0.1, 0.0)
    assert rig.output() == pytest.approx((0.1, 0.0))
    assert "ROS time moved backwards" in rig.log()


LOCKS = [
    {"name": "pause", "topic": "pause_navigation", "timeout": 0.0, "priority": 50},
    {"name": "heartbeat", "topic": "nav_heartbeat", "timeout": 0.5, "priority": 20},
]


def test_safety_live_twist_mux_locks_mask_lower_priorities(tmp_path):
    rig = Rig(tmp_path, params={"locks": LOCKS})
    try:
        rig.stream("navigation", 0.2, 0.0)
        start = rig.settle(0.5)
        # a lock with a timeout that has never spoken is locked (twist_mux): navigation is masked
        assert all(v == 0.0 for t, v, w in rig.cmds_from(start))
        rig.flag("/nav_heartbeat", False)
        assert rig.output() == pytest.approx((0.2, 0.0))
        rig.flag("/pause_navigation", True)
        assert rig.output() == (0.0, 0.0)
        values = {kv.key: kv.value for kv in rig.status(rig.now).values}
        assert values["lock pause"].startswith("locked") and values["current priority"] == "50"
        assert values["velocity navigation"].startswith("masked")
        rig.stream("teleop", 0.1, 0.3)  # teleop's priority 100 is above the lock's 50
        assert rig.output() == pytest.approx((0.1, 0.3))
        rig.stream("teleop", None)
        rig.flag("/pause_navigation", False)
        assert rig.output(0.8) == pytest.approx((0.2, 0.0))
        rig.flag("/nav_heartbeat", None)  # the heartbeat stops: locked again after its 0.5 s
        stopped = rig.now
        assert rig.output(0.8) == (0.0, 0.0)
        cut = next(t for t, v, w in rig.cmds_from(stopped) if v == 0.0)
        assert cut - stopped <= 0.5 + 0.1 + 0.1
        assert "no fresh command" not in rig.log()  # the locks stopped it, not the watchdog
    finally:
        rig.close()
    assert "Traceback" not in rig.log()


def test_safety_live_mux_parameters_are_checked_one_line_each(tmp_path):
    rig = Rig(
        tmp_path,
        params={
            "topics": [
                {"name": "joystick", "topic": "joy_vel", "timeout": 0.0, "priority": 300},
                {"name": "navigation", "topic": "nav/cmd_vel", "timeout": "soon", "priority": 10},
            ],
            "locks": [{"name": "nowhere", "priority": 5}],
            "footprint": "[[0.3, 0.2], [0.3",
            "localization_inputs": "joystick",  # one name, not a list: still a name, not letters
        },
    )
    try:
        assert rig.wait_real(lambda: "~locks[0]" in rig.log())
        log = rig.log()
        assert len([line for line in log.splitlines() if "~topics[1]" in line]) == 1
        assert "could not convert string to float: 'soon'" in log
        assert "~locks[0]: missing 'topic'" in log
        assert "input joystick (/joy_vel) has no timeout" in log
        lines = [line for line in log.splitlines() if "~footprint" in line]
        assert len(lines) == 1 and "using robot_radius 0.110" in lines[0]
        joy = rig.node.publisher("/joy_vel", Twist, queue_size=1)
        assert rig.wait_real(lambda: joy.get_num_connections() > 0)
        msg = Twist()
        msg.linear.x = 0.1
        joy.publish(msg)  # once: with no timeout it holds, as in twist_mux
        assert rig.output(1.5) == pytest.approx((0.1, 0.0))
        rig.pose(0.4)  # 0.8 > 0.5: lost, and the joystick is the input that needs localization
        assert rig.output() == (0.0, 0.0)
        rig.pose(0.01)
        assert rig.output() == pytest.approx((0.1, 0.0))
        msg.linear.x = float("nan")
        joy.publish(msg)  # ignored with one line; the last good command still holds
        assert rig.output(0.5) == pytest.approx((0.1, 0.0))
        assert rig.wait_real(lambda: "/joy_vel: NaN/inf velocity ignored" in rig.log())
    finally:
        rig.close()
    assert "Traceback" not in rig.log()


def test_safety_live_e_stop_topic_and_services_latch_until_reset(rig):
    SetBool = get_service_class("std_srvs/SetBool")
    Trigger = get_service_class("std_srvs/Trigger")
    e_stop = rig.node.service_proxy("/safety_monitor/e_stop", SetBool)
    reset = rig.node.service_proxy("/safety_monitor/reset_e_stop", Trigger)
    assert rig.wait_real(lambda: rig.e_stop_active[-1:] == [False])  # latched state at start
    rig.stream("navigation", 0.2, 0.0)
    assert rig.output() == pytest.approx((0.2, 0.0))

    rig.e_stop_pub.publish(Bool(data=True))
    assert rig.output() == (0.0, 0.0)
    assert rig.wait_real(lambda: rig.e_stop_active[-1:] == [True])
    rig.e_stop_pub.publish(Bool(data=False))  # releasing the button does not reset it
    rig.stream("teleop", 0.1, 0.3)  # nor does any input, teleop included
    assert rig.output(0.6) == (0.0, 0.0)
    status = rig.status(rig.now)
    assert status.level == status.ERROR and "E-stop" in status.message

    # a late subscriber gets the latched state (ROS 1 latching, std_msgs/Bool)
    seen: list[bool] = []
    late = rig.node.subscriber("/safety_monitor/e_stop_active", Bool, lambda m: seen.append(m.data))
    assert rig.wait_real(lambda: seen == [True])
    late.unregister()

    answer = reset(Trigger._request_class())
    assert answer.success and answer.message
    assert rig.wait_real(lambda: rig.e_stop_active[-1:] == [False])
    assert rig.output() == pytest.approx((0.1, 0.3))

    answer = e_stop(SetBool._request_class(data=True))
    assert answer.success
    assert rig.output(0.6) == (0.0, 0.0)
    rig.stream("teleop", None)
    assert rig.output(0.8) == (0.0, 0.0)  # navigation alone is stopped too
    assert e_stop(SetBool._request_class(data=False)).success
    assert rig.output() == pytest.approx((0.2, 0.0))
    assert rig.e_stop_active[-1] is False
    assert "e-stop ENGAGED" in rig.log() and "e-stop reset" in rig.log()


def test_safety_live_localization_loss_stops_navigation_and_recovery_resumes_it(rig):
    rig.stream("navigation", 0.2, 0.0)
    rig.pose(0.02)  # 0.04 m^2 of xx + yy: localized (limit 0.5)
    assert rig.output() == pytest.approx((0.2, 0.0))
    rig.pose(0.3)  # 0.6 > 0.5: lost
    assert rig.output() == (0.0, 0.0)
    status = rig.status(rig.now)
    assert status.level == status.WARN and "Localization lost" in status.message
    assert dict((kv.key, kv.value) for kv in status.values)["position_covariance"] == "0.6000"
    # turning in place stays allowed (move_base's rotate recovery is how amcl finds itself again);
    # an arc loses its translation and keeps its turn
    rig.stream("navigation", 0.0, 0.6)
    assert rig.output() == pytest.approx((0.0, 0.6))
    rig.stream("navigation", 0.2, -0.4)
    assert rig.output() == pytest.approx((0.0, -0.4))
    rig.stream("navigation", 0.2, 0.0)
    assert rig.output() == (0.0, 0.0)
    rig.stream("teleop", 0.1, 0.2)  # a person driving does not need amcl
    assert rig.output() == pytest.approx((0.1, 0.2))
    rig.stream("teleop", None)
    assert rig.output(0.8) == (0.0, 0.0)
    rig.pose(float("nan"))  # a broken covariance is no localization either
    assert rig.output() == (0.0, 0.0)
    rig.pose(0.05)  # it comes back
    assert rig.output() == pytest.approx((0.2, 0.0))
    status = rig.status(rig.now)
    assert status.level == status.OK and "navigation" in status.message


def test_safety_live_stop_zone_from_footprint_and_velocity_against_the_latest_scan(rig):
    # safety_params.yaml: radius 0.11, margin 0.08, reaction 0.35 s, decel 1.5, obstacle_speed 0.3
    rig.set_scan(0.55)
    rig.stream("navigation", 0.1, 0.0)
    assert rig.output() == pytest.approx((0.1, 0.0))  # slow: stops short of the wall
    rig.stream("navigation", 0.5, 0.0)
    assert rig.output() == (0.0, 0.0)  # fast: the stopping distance reaches the wall
    status = rig.status(rig.now)
    assert status.level == status.WARN and "stop zone" in status.message
    rig.stream("navigation", 0.1, 0.0)
    rig.set_odom(0.5)  # still rolling at 0.5 m/s: the current velocity counts, not the command
    assert rig.output() == (0.0, 0.0)
    rig.set_odom(0.1)
    assert rig.output() == pytest.approx((0.1, 0.0))

    rig.set_scan(0.25)  # the wall right at the bumper
    assert rig.output() == (0.0, 0.0)
    rig.stream("navigation", 0.15, 0.8)  # arcing into it: forward cut, the turn kept
    assert rig.output() == pytest.approx((0.0, 0.8))
    rig.stream("navigation", 0.0, 1.0)  # turning in place
    assert rig.output() == pytest.approx((0.0, 1.0))
    rig.set_odom(-0.1)
    rig.stream("navigation", -0.1, 0.0)  # backing away
    assert rig.output() == pytest.approx((-0.1, 0.0))
    rig.set_odom(0.0)
    rig.set_scan(None)  # the wall is gone from the latest scan
    rig.stream("navigation", 0.5, 0.0)
    assert rig.output() == pytest.approx((0.5, 0.0))

    # the latest scan grows old: it no longer shows the way, so only turning is left
    rig.stream("navigation", 0.2, 0.4)
    rig.scan_off()
    off = rig.now
    timeout = yaml.safe_load(PARAMS.read_text())["scan_timeout"]
    assert rig.output(timeout + 0.5) == pytest.approx((0.0, 0.4))
    assert any(v == 0.0 for t, v, w in rig.cmds_from(off))
    # when it cut, by its own clock: the age of the last scan it had, which it logs. The time the cut
    # reached this rig is no measure: sim time runs on at twice real time while a loaded machine
    # delivers the command (it came 2.32 s after the scan stopped, 0.12 s past the bound, at load 7)
    said = re.compile(r"no scan on \S+ for ([0-9.]+) s")
    assert rig.wait_real(lambda: said.search(rig.log()) is not None), rig.log()
    age = float(said.findall(rig.log())[-1])
    # not before its time (the age is printed to 0.01 s); then within a cycle or two
    assert timeout - 0.005 <= age <= timeout + 0.1 + 0.1, age
    status = rig.status(rig.now)
    assert status.level == status.WARN and "Scan stale" in status.message
    rig.set_scan(None)
    assert rig.output() == pytest.approx((0.2, 0.4))
    rig.set_scan(0.25)
    assert rig.output() == pytest.approx((0.0, 0.4))
    rig.stream("navigation", None)  # nothing drives any more: nothing is blocked either
    rig.settle(0.8)
    status = rig.status(rig.now)
    assert status.level == status.OK and status.message == "Idle (no fresh command)"


@pytest.fixture
def renamed_rig(tmp_path):
    r = Rig(tmp_path, name="base_guard")
    try:
        yield r
    finally:
        r.close()
    assert "Traceback" not in r.log()


def test_safety_live_stop_zone_from_a_footprint_polygon(tmp_path):
    # a 0.4 m long box reaching 0.3 m ahead: circumscribed radius 0.36 m instead of robot_radius 0.11
    footprint = [[0.3, 0.2], [0.3, -0.2], [-0.1, -0.2], [-0.1, 0.2]]
    rig = Rig(tmp_path, params={"footprint": str(footprint)})  # costmap_2d's string form
    try:
        rig.set_scan(0.55)
        rig.stream("navigation", 0.1, 0.0)  # passes with the round 0.11 m robot (test above)
        assert rig.output() == (0.0, 0.0)
        rig.stream("navigation", 0.0, 0.5)
        assert rig.output() == pytest.approx((0.0, 0.5))
        rig.set_scan(1.2)
        rig.stream("navigation", 0.1, 0.0)
        assert rig.output() == pytest.approx((0.1, 0.0))
    finally:
        rig.close()
    assert "Traceback" not in rig.log()


def test_safety_live_diagnostics_in_diagnostic_updater_layout(renamed_rig):
    rig = renamed_rig  # started as __name:=base_guard: the status is named after the node
    rig.stream("navigation", 0.2, 0.0)
    assert rig.output() == pytest.approx((0.2, 0.0))
    status = rig.status(rig.now)
    msg = rig.diags[-1]
    assert msg._type == "diagnostic_msgs/DiagnosticArray" and len(msg.status) == 1
    assert status.name == "base_guard: Safety"  # diagnostic_updater's "<node>: <task>"
    assert status.hardware_id and status.level == status.OK and status.message == "Passing navigation"
    values = {kv.key: kv.value for kv in status.values}
    assert values["active_input"] == "navigation" and values["e_stop"] == "False"
    # and twist_mux's own keys
    assert values["velocity navigation"].startswith("unmasked (listening to /nav/cmd_vel @ 0.5")
    assert values["velocity teleop"].startswith("masked") and values["current priority"] == "0"
    # once a second of ROS time, as diagnostic_updater's default ~diagnostic_period
    stamps = sorted({d.header.stamp.to_sec() for d in rig.diags})
    assert all(b - a == pytest.approx(1.0, abs=0.15) for a, b in zip(stamps, stamps[1:], strict=False))
    out = subprocess.run(
        [ninjemys_bin("rostopic"), "echo", "-n", "1", "/diagnostics"],
        env=rig.env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr
    echoed = yaml.safe_load(out.stdout.split("---")[0])
    assert echoed["status"][0]["name"] == "base_guard: Safety"
    assert {kv["key"] for kv in echoed["status"][0]["values"]} >= {"active_input", "e_stop"}


@pytest.mark.ros1
@pytest.mark.skipif(not have_ros1(), reason="Debian's ROS 1 is not installed")
def test_safety_live_diagnostics_read_by_debian_rostopic(rig, tmp_path):
    """Debian's rostopic and rosservice drive the e-stop and read /diagnostics: the types are ROS 1's."""
    env = ros1_env(rig.uri, ROS_HOME=str(tmp_path / "ros1_home"))

    def ros1(*args: str) -> str:
        out = subprocess.run(args, env=env, capture_output=True, text=True, timeout=60)
        assert out.returncode == 0, out.stderr
        return out.stdout

    def echoed_status() -> dict:
        return yaml.safe_load(ros1("/usr/bin/rostopic", "echo", "-n", "1", "/diagnostics").split("---")[0])[
            "status"
        ][0]

    rig.stream("navigation", 0.2, 0.0)
    ros1("/usr/bin/rostopic", "pub", "-1", "/e_stop", "std_msgs/Bool", "data: true")
    assert rig.wait_real(lambda: rig.e_stop_active[-1:] == [True])
    status = echoed_status()
    assert status["name"] == "safety_monitor: Safety" and status["level"] == 2  # ERROR
    assert status["message"] == "E-stop engaged" and status["hardware_id"] == "puzzlebot"
    assert {kv["key"]: kv["value"] for kv in status["values"]}["e_stop"] == "True"
    assert "True" in ros1("/usr/bin/rostopic", "echo", "-n", "1", "/safety_monitor/e_stop_active")

    reply = yaml.safe_load(ros1("/usr/bin/rosservice", "call", "/safety_monitor/reset_e_stop"))
    assert reply["success"] is True
    assert rig.output() == pytest.approx((0.2, 0.0))
    reply = yaml.safe_load(ros1("/usr/bin/rosservice", "call", "/safety_monitor/e_stop", "data: true"))
    assert reply["success"] is True
    assert rig.output() == (0.0, 0.0)
    ros1("/usr/bin/rosservice", "call", "/safety_monitor/e_stop", "data: false")
    assert rig.output() == pytest.approx((0.2, 0.0))
    status = echoed_status()
    assert status["level"] == 0 and status["message"] == "Passing navigation"
