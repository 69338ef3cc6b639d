"""The whole stack on the simulator: navigation in office and maze, amcl accuracy, safety, bad input.

Each session is one ``roslaunch puzzlebot_navigation navigation.launch gui:=false`` at a real-time
factor above 1, seeded; the tests check outcomes against the simulator's ground truth
(``base_pose_ground_truth``, ``contact``), never timings.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from .conftest import NavSession, pick_goals

pytest.importorskip("ninjemys.sim.puzzlebot_node", reason="the PuzzleBot simulator is not on this branch yet")
pytest.importorskip("ninjemys.actionlib.server", reason="actionlib is not on this branch yet")

# ``make test`` runs with ``--dist loadfile``: this file's tests run on one worker, in order, so there
# is one navigation session at a time (two stacks at a real-time factor of 4 on the same two cores
# starve each other's control loops) and the office session's tests follow its goals run.
pytestmark = [pytest.mark.slow, pytest.mark.timeout(900)]

DATA = Path(__file__).parent / "data"
RATE = "4"
BAD_GOALS = [(50.0, 50.0, 0.0), (6.0, 3.0, 0.0)]  # off the map; inside the meeting table
BAD_RESULTS: list[dict] = []  # what Debian's client got for them (sent by the office goals test)
OFFICE_RUN: dict = {}  # the office goals run's outcome, judged against the targets below


def ros1_env(session: NavSession) -> dict[str, str]:
    """Debian's ROS 1 Python environment pointed at the session's master (none of our paths)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env.update(ROS_MASTER_URI=session.uri, ROS_HOME=session.env["ROS_HOME"], PYTHONUNBUFFERED="1")
    env["PATH"] = "/usr/bin:/bin"
    return env


def yaw_err(a: float, b: float) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def start(world: str, tmp_path: Path, extra: list[str] | None = None) -> NavSession:
    session = NavSession(
        "navigation.launch",
        [f"world:={world}", "gui:=false", f"rate:={RATE}", "seed:=1", *(extra or [])],
        tmp_path,
    )
    probe = session.probe
    if not session.wait_for(lambda: probe.truth is not None and probe.localized() is not None, 90):
        log = session.log()
        session.close()
        pytest.fail(f"the navigation stack did not come up:\n{log[-3000:]}")
    # let the nodes' start-up work end before driving: on a loaded machine it starves the safety
    # monitor and move_base for seconds while the simulator runs on at its rate (a robot sent off at
    # once drove on its last command for 3 s of sim time, blind, into a door jamb)
    settle_until = time.monotonic() + 5.0
    probe.wait_sim(5.0)
    time.sleep(max(0.0, settle_until - time.monotonic()))
    return session


@pytest.fixture(scope="module")
def office(tmp_path_factory):
    session = start("office", tmp_path_factory.mktemp("office"))
    yield session
    session.close()


def run_ros1_goals(session: NavSession, goals: list[tuple]) -> list[dict]:
    """Send ``goals`` with Debian's SimpleActionClient; each result carries the ground truth at its end."""
    proc = subprocess.Popen(
        ["/usr/bin/python3", str(DATA / "ros1_goals.py"), *(f"{x},{y},{a}" for x, y, a in goals)],
        env=ros1_env(session),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    results = []
    lines = []
    assert proc.stdout is not None
    try:
        for line in proc.stdout:
            lines.append(line)
            try:
                item = json.loads(line)
            except ValueError:
                continue
            # the ground truth and amcl's pose at the outcome's instant (move_base's result stamp): the
            # client sends the next goal at once, and on a loaded machine this line is read late, after
            # the robot has set off again (a goal judged that way 0.81 rad
            # off was 0.07 rad off by move_base's estimate at its outcome, the run at load 20)
            probe, stamp = session.probe, item.get("stamp")
            item["truth"] = (probe.truth_at(stamp) if stamp else None) or probe.truth
            item["est"] = (probe.localized_at(stamp) if stamp else None) or probe.localized()
            item["late"] = probe.sim_time - stamp if stamp else math.nan  # how late the line was read
            results.append(item)
        proc.wait(30)
    finally:  # an interrupted or failed run leaves no client behind
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, "".join(lines) + (proc.stderr.read() if proc.stderr else "")
    return results


@pytest.mark.ros1
def test_office_goals_through_ros1_simple_action_client(office):
    probe = office.probe
    goals = pick_goals("office", 20, seed=7)
    errors: list[float] = []
    stop = threading.Event()
    start_time = probe.sim_time
    contacts = probe.contacts

    lagged: list[float] = []

    def sample() -> None:  # amcl's pose (through TF) against the ground truth, every 0.1 s of sim time
        last = -1.0
        while not stop.is_set():
            if probe.sim_time - last >= 0.1:
                last = probe.sim_time
                pair = probe.localized_with_truth()  # both of one instant: amcl's error, not our lag
                if pair is not None:
                    (ex, ey, _), (tx, ty, _) = pair
                    errors.append(math.hypot(ex - tx, ey - ty))
                est, truth = probe.localized(), probe.truth
                if est is not None and truth is not None:
                    lagged.append(math.hypot(est[0] - truth[0], est[1] - truth[1]))
            time.sleep(0.01)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    try:
        # the same ROS 1 client then sends a goal off the map and one inside the meeting table
        results = run_ros1_goals(office, [*goals, *BAD_GOALS])
    finally:
        stop.set()
        sampler.join()
    assert len(results) == len(goals) + len(BAD_GOALS)
    BAD_RESULTS.extend(results[len(goals) :])
    results = results[: len(goals)]
    reached = 0
    report = []
    for item in results:
        gx, gy, ga = item["goal"]
        tx, ty, ta = item["truth"]
        d, a = math.hypot(tx - gx, ty - gy), yaw_err(ta, ga)
        ok = item["state"] == 3 and d <= 0.2 and a <= 0.3
        reached += ok
        est = item["est"] or (math.nan, math.nan, math.nan)
        report.append(
            f"{item['goal']} state={item['state']} d={d:.3f} yaw={a:.3f} {item['text']!r} "
            f"amcl-truth {math.hypot(est[0] - tx, est[1] - ty):.3f} m, amcl-goal {math.hypot(est[0] - gx, est[1] - gy):.3f} m, "
            f"read {item['late']:.1f} s after the outcome"
        )
        assert item["feedback"] > 0  # move_base's feedback reached the ROS 1 client
        assert item["state"] in (3, 4) and item["text"], item  # SUCCEEDED or ABORTED, with its text
    # the action interface works end to end with Debian's client: most goals are reached
    assert reached >= 15, "\n".join(report)
    # the simulator's own account of each contact: which robot moved into what, and where
    hits = [line for line in office.log().splitlines() if "] hit '" in line]
    report.append(f"load average {os.getloadavg()[0]:.1f}; contacts: {hits or 'none'}")
    OFFICE_RUN.update(
        reached=reached,
        contacts=probe.contacts - contacts,
        driven=probe.sim_time - start_time,
        rms=math.sqrt(float(np.mean(np.square(errors)))),
        lagged_rms=math.sqrt(float(np.mean(np.square(lagged)))),
        samples=len(errors),
        report="\n".join(report),
    )


def test_office_run_meets_the_navigation_targets():
    """The targets on the run above: all 20 goals, no contact, amcl RMS < 0.10 m over 5 min.

    Issue 22 asks the full count on a loaded machine. Beside two busy loops, runs with the earlier amcl
    parameters missed goal (2.98, 0.23, 3.11) by 1-11 mm with move_base right by its own estimate: amcl
    was 0.11-0.13 m off along the corridor there (100 particles resampled at every update and odometry
    noise twice the robot's diffused the set along it, the more so as load spaced the updates out). The
    corridor drive in test_nav_amcl.py reproduces it offline; the shipped parameters fix it."""
    if not OFFICE_RUN:
        pytest.skip("the office goals run did not finish")
    run = OFFICE_RUN
    print(
        run["report"],
        f"\namcl RMS {run['rms']:.3f} m over {run['driven']:.0f} s ({run['samples']} samples; "
        f"{run['lagged_rms']:.3f} m against the newest ground truth instead of the TF stamp's)",
    )  # shown by -rA
    assert run["reached"] == 20, run["report"]
    assert run["contacts"] == 0, run["report"]
    assert run["driven"] >= 300, f"only {run['driven']:.0f} s of driving\n{run['report']}"  # 5-minute run
    assert run["rms"] < 0.10, f"amcl RMS error {run['rms']:.3f} m over {run['driven']:.0f} s\n{run['report']}"


@pytest.mark.ros1
def test_bad_goals_are_rejected_with_the_reason(office):
    if not BAD_RESULTS:
        pytest.skip("the office goals test did not get to send the bad goals")
    results = BAD_RESULTS
    assert [r["state"] for r in results] == [5, 5]  # REJECTED
    assert "off the global costmap" in results[0]["text"]
    assert "in an obstacle" in results[1]["text"]
    log = office.log()
    assert "The goal (50.00, 50.00) is off the global costmap" in log
    assert office.alive()


def connected(pub, what: str) -> None:
    """Wait until ``pub`` has a subscriber: a publisher's first messages go nowhere until the safety
    monitor has connected, which took over a second under load right after the stack started (a fixed
    1 s sleep here left the robot still, or half way to its speed, after the 1 s of teleop below)."""
    from ninjemys.testing import wait_until

    wait_until(lambda: pub.get_num_connections() > 0, timeout=60, what=what)


def test_stale_teleop_command_stops_the_robot(office):
    probe = office.probe
    pub = probe.node.publisher("/teleop/cmd_vel", probe.twist_cls, queue_size=1)
    connected(pub, "the safety monitor to subscribe /teleop/cmd_vel")
    msg = probe.twist_cls()
    msg.angular.z = 1.0
    end = probe.sim_time + 1.0
    while probe.sim_time < end:
        pub.publish(msg)
        time.sleep(0.02)
    assert probe.truth_w > 0.8  # teleop drives the robot through the monitor
    stale_at = probe.sim_time
    probe.wait_sim(0.5 + 0.3)  # the watchdog's 0.5 s, then the wheels' deceleration
    assert abs(probe.truth_w) < 0.05 and abs(probe.truth_v) < 0.02, (
        f"still moving {probe.sim_time - stale_at:.2f} s after"
    )
    pub.unregister()


def test_teleop_overrides_navigation(office):
    probe = office.probe
    goal_pub = probe.node.publisher("/move_base_simple/goal", probe.pose_cls, queue_size=1, latch=True)
    teleop = probe.node.publisher("/teleop/cmd_vel", probe.twist_cls, queue_size=1)
    connected(goal_pub, "move_base to subscribe /move_base_simple/goal")
    connected(teleop, "the safety monitor to subscribe /teleop/cmd_vel")
    contacts = probe.contacts
    target = (-1.0, 0.0, math.pi)
    if probe.truth and math.hypot(probe.truth[0] - target[0], probe.truth[1] - target[1]) < 1.0:
        target = (2.0, 0.0, 0.0)
    goal = probe.pose_cls()
    goal.header.frame_id = "map"
    goal.pose.position.x, goal.pose.position.y = target[0], target[1]
    goal.pose.orientation.z, goal.pose.orientation.w = math.sin(target[2] / 2), math.cos(target[2] / 2)
    goal_pub.publish(goal)
    probe.wait_sim(3.0)
    msg = probe.twist_cls()
    msg.angular.z = -0.8
    samples = []
    end = probe.sim_time + 2.0
    while probe.sim_time < end:
        teleop.publish(msg)
        time.sleep(0.02)
        samples.append((probe.truth_v, probe.truth_w))
    late = samples[len(samples) // 2 :]
    assert all(abs(w + 0.8) < 0.15 and abs(v) < 0.03 for v, w in late), late[:5]
    # teleop goes quiet: navigation takes over again and reaches its goal
    ok = office.wait_for(
        lambda: (
            probe.truth is not None
            and math.hypot(probe.truth[0] - target[0], probe.truth[1] - target[1]) < 0.2
            and abs(probe.truth_v) < 0.01
        ),
        120,
    )
    assert ok and probe.contacts == contacts, (
        f"target {target}: truth {probe.truth}, v {probe.truth_v}, contacts {probe.contacts - contacts}"
    )
    teleop.unregister()
    goal_pub.unregister()


def test_spawned_obstacle_stops_then_replans_around(office):
    from ninjemys.idl.loader import get_service_class

    probe = office.probe
    goal_pub = probe.node.publisher("/move_base_simple/goal", probe.pose_cls, queue_size=1, latch=True)
    time.sleep(1.0)

    def go(x: float, y: float, yaw: float) -> bool:
        goal = probe.pose_cls()
        goal.header.frame_id = "map"
        goal.pose.position.x, goal.pose.position.y = x, y
        goal.pose.orientation.z, goal.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        goal_pub.publish(goal)
        return office.wait_for(
            lambda: (
                probe.truth is not None
                and math.hypot(probe.truth[0] - x, probe.truth[1] - y) < 0.2
                and abs(probe.truth_v) < 0.01
                and abs(probe.truth_w) < 0.05
            ),
            150,
        )

    assert go(-1.0, -0.3, 0.0)
    probe.wait_sim(1.0)
    target = (3.0, -0.3, 0.0)
    goal = probe.pose_cls()
    goal.header.frame_id = "map"
    goal.pose.position.x, goal.pose.position.y = target[0], target[1]
    goal.pose.orientation.w = 1.0
    goal_pub.publish(goal)
    assert office.wait_for(lambda: probe.truth is not None and probe.truth[0] > -0.4, 60)
    spawn = probe.node.service_proxy("/gazebo/spawn_urdf_model", get_service_class("gazebo_msgs/SpawnModel"))
    req = (
        spawn.request_class()
        if hasattr(spawn, "request_class")
        else get_service_class("gazebo_msgs/SpawnModel")._request_class()
    )
    req.model_name = "crate"
    req.model_xml = '<robot name="crate"><link name="l"><collision><geometry><box size="0.4 0.4 0.5"/></geometry></collision></link></robot>'
    req.initial_pose.position.x = probe.truth[0] + 1.0
    req.initial_pose.position.y = -0.3
    req.initial_pose.orientation.w = 1.0
    contacts = probe.contacts
    assert spawn(req).success
    reached = office.wait_for(
        lambda: (
            math.hypot(probe.truth[0] - target[0], probe.truth[1] - target[1]) < 0.2
            and abs(probe.truth_v) < 0.01
        ),
        180,
    )
    assert probe.contacts == contacts, "the robot touched the spawned crate"
    assert reached, f"did not get around the crate: at {probe.truth}"
    goal_pub.unregister()


def test_nan_inf_scans_are_reported_once_and_skipped(office):
    log = office.log()
    assert log.count("amcl: scan from laser has") == 1
    assert log.count("move_base: scan on laser has NaN/inf ranges") == 1
    assert office.alive()


def wait_goal(session: NavSession, goal: tuple, limit: float) -> bool:
    probe = session.probe
    start = probe.sim_time

    def arrived() -> bool:
        t = probe.truth
        return (
            t is not None
            and math.hypot(t[0] - goal[0], t[1] - goal[1]) <= 0.2
            and yaw_err(t[2], goal[2]) <= 0.3
            and abs(probe.truth_v) < 0.01
            and abs(probe.truth_w) < 0.05
        )

    while probe.sim_time - start < limit and session.alive():
        if arrived():
            probe.wait_sim(0.3)
            if arrived():  # stopped there for 0.3 s; a pause on the way (before the final turn) is not
                return True  # the end: the robot is judged where it comes to rest, within the limit
        time.sleep(0.05)
    return False


#: the maze's 20 goals take about 1,400-1,600 s of simulated time (178 m of winding paths at 0.3 m/s)
MAZE_RATE = os.environ.get("NINJEMYS_MAZE_RATE", "8")


def test_maze_goals_through_move_base_simple(tmp_path):
    """The issue's acceptance run in the maze: 20 seeded goals through /move_base_simple/goal, each
    judged on the simulator's ground truth (within 0.2 m and 0.3 rad, stopped); all 20 reached (issue 22's
    acceptance: the full goal count, also on a loaded machine), no contact."""
    session = NavSession(
        "navigation.launch", ["world:=maze", "gui:=false", f"rate:={MAZE_RATE}", "seed:=1"], tmp_path
    )
    try:
        probe = session.probe
        if not session.wait_for(lambda: probe.truth is not None and probe.localized() is not None, 90):
            pytest.fail(f"the navigation stack did not come up:\n{session.log()[-3000:]}")
        # as start(): the nodes' start-up work ends before the robot is sent off
        settle_until = time.monotonic() + 5.0
        probe.wait_sim(5.0)
        time.sleep(max(0.0, settle_until - time.monotonic()))
        pub = probe.node.publisher("/move_base_simple/goal", probe.pose_cls, queue_size=1, latch=True)
        time.sleep(1.0)
        reached, report = 0, []
        for x, y, a in pick_goals("maze", 20, seed=11, clearance=0.4, spacing=1.2):
            msg = probe.pose_cls()
            msg.header.frame_id = "map"
            msg.pose.position.x, msg.pose.position.y = x, y
            msg.pose.orientation.z, msg.pose.orientation.w = math.sin(a / 2), math.cos(a / 2)
            sent = probe.sim_time
            pub.publish(msg)
            probe.wait_sim(0.5)
            ok = wait_goal(session, (x, y, a), 300.0)
            reached += ok
            truth, est = probe.truth, probe.localized()
            report.append(
                f"({x}, {y}, {a}) {'ok' if ok else 'MISSED'} after {probe.sim_time - sent:.0f} s: "
                f"truth {tuple(round(v, 2) for v in truth or ())}, "
                f"amcl {tuple(round(v, 2) for v in est or ())}, contacts {probe.contacts}"
            )
        print("\n".join(report))  # shown with -s / -rP: the outcome of every goal, passed or not
        assert reached == 20, "\n".join(report)
        assert probe.contacts == 0, "\n".join(report)
    finally:
        session.close()


def test_global_localization_converges_in_office(tmp_path):
    from ninjemys.idl.loader import get_service_class

    session = start("office", tmp_path)
    try:
        probe = session.probe
        spread = probe.node.service_proxy("/global_localization", get_service_class("std_srvs/Empty"))
        spread(get_service_class("std_srvs/Empty")._request_class())
        probe.wait_sim(1.0)
        start_time = probe.sim_time
        converged_at = None
        errors = []
        while probe.sim_time - start_time < 60.0:
            probe.wander(2.0)
            est, truth = probe.localized(), probe.truth
            if est is not None and truth is not None:
                err = (math.hypot(est[0] - truth[0], est[1] - truth[1]), yaw_err(est[2], truth[2]))
                errors.append(err)
                if err[0] < 0.25 and err[1] < 0.25:
                    converged_at = converged_at or probe.sim_time
                else:
                    converged_at = None
            if converged_at is not None and probe.sim_time - converged_at > 6.0:
                break
        assert converged_at is not None, errors[-5:]
        assert converged_at - start_time <= 60.0
    finally:
        session.close()


def test_slam_map_of_office_agrees_with_ground_truth(tmp_path):
    from ninjemys.idl.loader import get_service_class
    from ninjemys.nav.rosglue import grid_from_msg

    from .conftest import world_map

    session = NavSession("slam.launch", ["world:=office", "gui:=false", f"rate:={RATE}", "seed:=1"], tmp_path)
    try:
        probe = session.probe
        assert session.wait_for(lambda: probe.truth is not None, 90), session.log()[-2000:]
        probe.wander(150.0)
        get_map = probe.node.service_proxy("/dynamic_map", get_service_class("nav_msgs/GetMap"))
        built = grid_from_msg(get_map(get_service_class("nav_msgs/GetMap")._request_class()).map)
        truth = world_map("office")
        rows, cols = np.nonzero(built.data >= 0)
        xs = built.origin[0] + (cols + 0.5) * built.resolution
        ys = built.origin[1] + (rows + 0.5) * built.resolution
        tc = np.floor((xs - truth.origin[0]) / truth.resolution).astype(int)
        tr = np.floor((ys - truth.origin[1]) / truth.resolution).astype(int)
        inside = (tc >= 0) & (tc < truth.width) & (tr >= 0) & (tr < truth.height)
        mine = built.data[rows[inside], cols[inside]] >= 50
        theirs_raw = truth.data[tr[inside], tc[inside]]
        known = theirs_raw >= 0
        agree = float(np.mean(mine[known] == (theirs_raw[known] >= 50)))
        assert known.sum() > 5000, known.sum()  # the drive saw a good part of the office
        assert agree >= 0.95, agree
    finally:
        session.close()
