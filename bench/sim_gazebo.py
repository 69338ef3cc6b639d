"""The simulator under Gazebo's names, and the simulator node split, measured in one run.

1. ``empty_world.launch`` + ``spawn_model`` -> first ``/scan``: a launch file written the way the
   course packages are (robot_description from the URDF, ``$(find gazebo_ros)/launch/empty_world.launch``
   included with gui:=false, ``spawn_model -urdf -param robot_description``) is started with our
   ``roslaunch`` on a running master; the time until a subscriber (already waiting) gets the first
   LaserScan. The issue's target: at most 1 s. Gazebo itself is not installed here: its gzserver
   alone takes several seconds to load a world (the figure to compare with is from Gazebo users).
2. A/B of the simulator: the PuzzleBot run headless as fast as possible, with subscribers on scan,
   camera (colour and depth, 320x240 at 30 Hz) and odometry and with none, from our YAML model and
   from its URDF (``puzzlebot_sim/robots/puzzlebot.urdf``: the issue's row, "the PuzzleBot from its
   URDF with scan, camera and odometry"), by an older tree (``--before``, default: where this branch
   left main) and by this tree, alternating, in one run. The simulator is pinned to one core (CPU 0,
   ``sched_setaffinity``: the issue's "on one core"), and the subscribers and the master run on
   the other cores (``--readers-anywhere``: anywhere, as before); its speed is measured from outside, by the
   subscriber process: the odometry stamps' advance over the wall time they took to arrive (the
   real-time factor a student's node sees), next to simulated s per CPU s of the simulator process
   over the same window (its threads' schedstat: a shared machine disturbs it less; the simulator's
   exit summary also counts its unsubscribed start and end, several times faster). One row has image
   readers that lag (50 ms per image, queue_size 1): the simulation must not wait for them (ROS 1
   drops what a subscriber cannot take); one reads scan and odometry only (everything but the camera).

3. The camera alone: CPU time of one frame (colour + depth, 320x240) of the URDF PuzzleBot's camera
   turning and driving in the office world, rendered in a child process by the older tree and by this
   tree, alternating (process CPU time, the best of 5 repetitions of 300 frames each: a shared
   machine's load disturbs it less than the real-time factor).

4. One simulated second, stage by stage: the stepping thread's work for the URDF PuzzleBot in the
   office world (physics at 100 Hz, odometry at 100 Hz, the lidar at 10 Hz, colour + depth at 30 Hz,
   each message built and serialised as the node publishes it, camera_info too), timed with
   ``time.thread_time_ns`` around each stage, in a child process pinned to CPU 0, by the older tree
   and by this tree, alternating (the sends are left out: they depend on the subscribers).

5. The split of the simulator's wall time (``--only split``): over the subscriber's window, each of
   its threads' CPU, its wait for the CPU (schedstat run_delay: another process had the core) and its
   voluntary and involuntary context switches; the rest of the wall time the process slept.

6. Instructions per simulated second (``--only callgrind``, asked for by name: minutes under valgrind):
   the whole simulator process under callgrind over one circle of the robot's drive, collection
   switched on and off from outside at /odom stamps, by the older tree and by this one; scan + camera
   + odometry subscribed and scan + odometry. Deterministic where CPU time is not (memcpy counts
   about one instruction per byte, so copies weigh more than their time).

Run alone: ``.venv/bin/python bench/sim_gazebo.py [--quick] [--before REV] [--only launch|ab|camera|stages|split|callgrind]``.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ninjemys.testing import ninjemys_bin, run_master

ROOT = Path(__file__).resolve().parent.parent

LAUNCH = """<launch>
  <param name="robot_description" textfile="$(find puzzlebot_sim)/robots/puzzlebot.urdf"/>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="gui" value="false"/>
    <arg name="headless" value="{headless}"/>
  </include>
  <node name="spawn_urdf" pkg="gazebo_ros" type="spawn_model" args="-urdf -param robot_description -model puzzlebot"/>
</launch>
"""


def first_scan_seconds(headless: bool, tmp: Path) -> float:
    from ninjemys.idl.loader import get_message_class
    from ninjemys.node import Node

    launch = tmp / f"gazebo_bench_{headless}.launch"
    launch.write_text(LAUNCH.format(headless=str(headless).lower()))
    with run_master() as master:
        node = Node("bench_first_scan", anonymous=True, master_uri=master)
        got = threading.Event()
        node.subscriber("/scan", get_message_class("sensor_msgs/LaserScan"), lambda _m: got.set(), raw=True)
        t0 = time.monotonic()
        proc = subprocess.Popen(
            [ninjemys_bin("roslaunch"), str(launch)],
            env=dict(os.environ, ROS_MASTER_URI=master),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        try:
            if not got.wait(60):
                raise RuntimeError("no /scan within 60 s")
            return time.monotonic() - t0
        finally:
            node.shutdown("bench over")
            os.killpg(proc.pid, 2)
            try:
                proc.wait(15)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, 9)
                proc.wait()


def bench_launch(repeat: int) -> None:
    print("\n## empty_world.launch + spawn_model -> first /scan (our roslaunch, master already up)")
    print("| gzserver | first /scan (median of %d) | best |" % repeat)
    print("|---|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for headless, label in ((False, "with its browser view served"), (True, "headless:=true")):
            times = [first_scan_seconds(headless, Path(tmp)) for _ in range(repeat)]
            print(f"| {label} | {statistics.median(times):.2f} s | {min(times):.2f} s |")
    print("target: at most 1 s (Gazebo's gzserver alone needs several seconds to load a world)")


def short_rev(rev: str) -> str:
    """The abbreviated commit of ``rev``, for the tables' headings."""
    return subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", rev], capture_output=True, text=True, check=True
    ).stdout.strip()


def print_ab_head(first: str) -> None:
    """The head of a before/after table whose rows are named in column ``first``."""
    print(f"| {first} | before | after | after / before |")
    print("|---|---:|---:|---:|")


def extract_tree(rev: str, dest: Path) -> Path:
    """``src/`` of ``rev`` (git archive), for running the simulator as it was."""
    data = subprocess.run(
        ["git", "-C", str(ROOT), "archive", rev, "src"], capture_output=True, check=True
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=data, check=True)
    return dest / "src"


URDF_MODEL = ROOT / "src/ninjemys/packages/share/puzzlebot_sim/robots/puzzlebot.urdf"


#: the core the simulator is pinned to (the issue's figure is "on one core")
SIM_CORE = 0


def _pin_to_one_core() -> None:
    """In the simulator's child process, before exec: run on :data:`SIM_CORE` only."""
    os.sched_setaffinity(0, {SIM_CORE})


def keep_readers_off_the_sim_core() -> bool:
    """Run this process (the subscribers, and the master it starts) on the other cores, so the
    simulator has its one core to itself, as a student's nodes on the other cores would leave it.

    Without this the readers' own work (3,600 odometry and /clock messages a wall second at 36x)
    lands on the simulator's core part of the time and the outside figure measures both. False (and
    nothing changed) on a one-core machine."""
    others = os.sched_getaffinity(0) - {SIM_CORE}
    if not others:
        return False
    os.sched_setaffinity(0, others)
    return True


@dataclass
class TaskStat:
    """One thread of the simulator, from /proc: CPU and waiting-for-CPU ns (schedstat), switches."""

    cpu_ns: int
    run_delay_ns: int
    voluntary: int
    involuntary: int


def task_stats(pid: int) -> dict[int, TaskStat]:
    """Every thread of ``pid`` now (a thread that ended between the listing and the read is left out)."""
    out: dict[int, TaskStat] = {}
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            cpu, delay, _ = (int(v) for v in (task / "schedstat").read_text().split())
            status = (task / "status").read_text()
        except (OSError, ValueError):
            continue
        switches = dict(re.findall(r"^(\w+_ctxt_switches):\s+(\d+)", status, re.M))
        out[int(task.name)] = TaskStat(
            cpu, delay, int(switches["voluntary_ctxt_switches"]), int(switches["nonvoluntary_ctxt_switches"])
        )
    return out


@dataclass
class SimRun:
    """What one run of the simulator measured, over the window the subscriber watched."""

    outside: float  #: real-time factor seen by the subscriber (odometry stamps over arrival times)
    per_cpu: float  #: simulated s per CPU s of the simulator process, in the window
    on_cpu: float  #: share of the window's wall time the process' threads ran (all threads summed)
    waiting: float  #: share its threads were runnable but another process had the core
    summary: float  #: the simulator's own exit figure (simulated s per CPU s over its whole run)


def sim_run(
    src: Path | None,
    subscribe: bool,
    duration: float,
    model: Path | None = None,
    slow: float = 0.0,
    window: Callable[[int], None] | None = None,
    camera: bool = True,
) -> SimRun:
    """One headless run, the simulator pinned to one core (``src``: that tree on PYTHONPATH; None:
    this tree). From outside: the advance of ``/odom``'s stamps over the wall time between their
    arrivals here, after a 1 s warm-up; per CPU s: that advance over the simulator process' CPU time
    in the same window (its threads' schedstat), not over the whole run: the simulator runs from
    its start until the subscribers connect, and after they leave, with nothing to render, several
    times faster (its exit summary counts those seconds, see :class:`SimRun`). ``camera`` False:
    ``subscribe`` reads the scan only (everything but the camera).
    ``slow``: the image subscribers take that long per image, with queue_size 1 (a reader that lags:
    ROS 1 drops what it cannot take, the simulation must not wait for it). ``window``: called with
    the simulator's pid at the start and at the end of the measured window."""
    from ninjemys.idl.loader import get_message_class
    from ninjemys.node import Node

    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    with run_master() as master:
        env["ROS_MASTER_URI"] = master
        cmd = [sys.executable, "-m", "ninjemys.packages.run_shipped", "puzzlebot_sim", "sim_node"]
        cmd += ["_world:=office", "_rate:=0", "_gui:=false"]
        if model is not None:
            cmd.append(f"_model:={model}")
        proc = subprocess.Popen(
            cmd,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            preexec_fn=_pin_to_one_core,
        )
        lines: list[str] = []
        for line in proc.stdout:  # type: ignore[union-attr]
            lines.append(line)
            if "PuzzleBot simulator:" in line:
                break
        drain = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)  # type: ignore[arg-type]
        drain.start()
        node = Node("bench_ab", anonymous=True, master_uri=master)
        odom: list[tuple[float, float]] = []  # (wall time of arrival, stamp)

        def on_odom(msg: object) -> None:
            stamp = msg.header.stamp  # type: ignore[attr-defined]
            odom.append((time.monotonic(), stamp.secs + stamp.nsecs * 1e-9))

        node.subscriber("/odom", get_message_class("nav_msgs/Odometry"), on_odom, queue_size=100)
        if subscribe:
            for topic, kind in (
                ("/scan", "sensor_msgs/LaserScan"),
                ("/camera/color/image_raw", "sensor_msgs/Image"),
                ("/camera/depth/image_rect_raw", "sensor_msgs/Image"),
            )[: 3 if camera else 1]:
                lagging = slow > 0 and kind == "sensor_msgs/Image"
                node.subscriber(
                    topic,
                    get_message_class(kind),
                    (lambda _m: time.sleep(slow)) if lagging else (lambda _m: None),
                    queue_size=1 if lagging else 100,
                    raw=True,
                )
        twist_cls = get_message_class("geometry_msgs/Twist")
        twist = twist_cls()
        twist.linear.x, twist.angular.z = 0.05, 0.5
        node.publisher("/cmd_vel", twist_cls, queue_size=1, latch=True).publish(twist)
        time.sleep(1.0)  # warm-up: connections made, first frames out
        start = len(odom)
        if window is not None:
            window(proc.pid)
        t0, before = time.monotonic(), task_stats(proc.pid)
        time.sleep(duration)
        seen = odom[start:]
        t1, after = time.monotonic(), task_stats(proc.pid)
        if window is not None:
            window(proc.pid)
        node.shutdown("bench over")
        proc.terminate()
        proc.wait(15)
        drain.join(5)
    if len(seen) < 2 or seen[-1][0] <= seen[0][0]:
        raise RuntimeError("too few /odom messages to measure:\n" + "".join(lines[-10:]))
    simulated = seen[-1][1] - seen[0][1]
    outside = simulated / (seen[-1][0] - seen[0][0])
    zero = TaskStat(0, 0, 0, 0)
    cpu = sum(end.cpu_ns - before.get(tid, zero).cpu_ns for tid, end in after.items()) / 1e9
    waited = sum(end.run_delay_ns - before.get(tid, zero).run_delay_ns for tid, end in after.items()) / 1e9
    for line in lines:
        m = re.search(r"\(([\d.]+) simulated s per CPU s\)", line)
        if m:
            wall = t1 - t0
            return SimRun(
                outside, outside * wall / max(cpu, 1e-9), cpu / wall, waited / wall, float(m.group(1))
            )
    raise RuntimeError("no summary from the simulator:\n" + "".join(lines[-10:]))


def bench_ab(before: str, duration: float, rounds: int) -> None:
    rev = short_rev(before)
    print(f"\n## the simulator, A/B: {rev} (before) and this tree (after), alternating")
    print(
        f"the simulator pinned to CPU {SIM_CORE}, office world, as fast as possible, {duration:.0f} s runs; "
        "real-time factor measured from outside (/odom stamps over wall time, medians), and simulated s "
        "per CPU s of the simulator process over the same window"
    )
    print(
        "| robot | subscribers | before: outside / per CPU s | after: outside / per CPU s | after / before (outside) |"
    )
    print("|---|---|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        old = extract_tree(before, Path(tmp))
        for model, subscribe, slow, robot, label, camera in (
            (None, True, 0.0, "PuzzleBot (YAML)", "scan + camera + odom", True),
            (URDF_MODEL, True, 0.0, "PuzzleBot from its URDF", "scan + camera + odom", True),
            (
                URDF_MODEL,
                True,
                0.05,
                "PuzzleBot from its URDF",
                "the same, images read in 50 ms (lagging)",
                True,
            ),
            (
                URDF_MODEL,
                True,
                0.0,
                "PuzzleBot from its URDF",
                "scan + odom (everything but the camera)",
                False,
            ),
            (None, False, 0.0, "PuzzleBot (YAML)", "/odom only (nothing rendered)", True),
        ):
            a: list[SimRun] = []
            b: list[SimRun] = []
            for _ in range(rounds):
                a.append(sim_run(old, subscribe, duration, model, slow, camera=camera))
                b.append(sim_run(None, subscribe, duration, model, slow, camera=camera))
            ao, ac = statistics.median(v.outside for v in a), statistics.median(v.per_cpu for v in a)
            bo, bc = statistics.median(v.outside for v in b), statistics.median(v.per_cpu for v in b)
            print(f"| {robot} | {label} | {ao:.1f}x / {ac:.1f}x | {bo:.1f}x / {bc:.1f}x | {bo / ao:.2f} |")
            print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


def bench_split(duration: float, rounds: int) -> None:
    """Where the simulator's wall time goes: on the CPU, waiting for the CPU (another process had its
    core), or asleep (blocked: a lock, a wait, a send the kernel made wait)."""
    print("\n## the simulator's wall time: on CPU / runnable but not running / asleep, per thread")
    print(
        f"URDF PuzzleBot, scan + camera + odom subscribed, pinned to CPU {SIM_CORE}, {duration:.0f} s "
        "windows; per wall second of the window: thread CPU, its wait for the CPU (schedstat run_delay), "
        "voluntary / involuntary context switches"
    )
    for i in range(2 * rounds):
        slow = 0.05 if i % 2 else 0.0  # every other run: image readers that lag (the publisher may yield)
        marks: list[tuple[float, dict[int, TaskStat]]] = []
        run = sim_run(
            None,
            True,
            duration,
            URDF_MODEL,
            slow,
            window=lambda pid, marks=marks: marks.append((time.monotonic(), task_stats(pid))),
        )
        (t0, a), (t1, b) = marks
        wall = t1 - t0
        rows = []
        for tid, end in b.items():
            beg = a.get(tid, TaskStat(0, 0, 0, 0))
            rows.append(
                (
                    (end.cpu_ns - beg.cpu_ns) / 1e9 / wall,
                    (end.run_delay_ns - beg.run_delay_ns) / 1e9 / wall,
                    (end.voluntary - beg.voluntary) / wall,
                    (end.involuntary - beg.involuntary) / wall,
                    tid,
                )
            )
        rows.sort(reverse=True)
        print("images read in 50 ms (lagging readers):" if slow else "readers keeping up:")
        print(
            f"{run.outside:.1f}x real time from outside; {run.per_cpu:.1f} simulated s per CPU s in the window "
            f"({run.summary:.1f} by the simulator's summary of its whole run); the process on CPU "
            f"{run.on_cpu:.1%} of the window, runnable but off its core {run.waiting:.1%}, asleep "
            f"{max(0.0, 1.0 - run.on_cpu - run.waiting):.1%}; load {' '.join(f'{v:.2f}' for v in os.getloadavg())}"
        )
        print("| thread | on CPU | waiting for CPU | voluntary switches/s | involuntary/s |")
        print("|---|---:|---:|---:|---:|")
        for share, delay, vol, invol, tid in rows:
            if share > 0.001 or vol > 10:
                print(f"| {tid} | {share:.1%} | {delay:.1%} | {vol:.0f} | {invol:.0f} |")


CAMERA_FRAMES = """
import math, sys, time
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import load_world
from ninjemys.sim.worlds import world_path
sim = Simulation(load_world(world_path(sys.argv[2])), 0.01, 0)
r = sim.add_robot("pb", load_robot_model(sys.argv[1]), 0.0, 0.0, 0.0)
poses = [(0.5 * math.cos(i * 0.05), 0.5 * math.sin(i * 0.05), i * 0.05) for i in range(300)]
for r.x, r.y, r.yaw in poses[:30]:
    sim.render(r)
best = math.inf
for _ in range(5):
    t = time.process_time()
    for r.x, r.y, r.yaw in poses:
        sim.render(r)
    best = min(best, (time.process_time() - t) / len(poses))
print(best * 1e3)
"""


def camera_frame_ms(src: Path | None, world: str = "office") -> float:
    """CPU ms of one camera frame (colour + depth) in ``world`` by the tree at ``src`` (None: this
    tree)."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    out = subprocess.run(
        [sys.executable, "-c", CAMERA_FRAMES, str(URDF_MODEL), world],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    return float(out.stdout.strip().splitlines()[-1])


def bench_camera(before: str, rounds: int) -> None:
    rev = short_rev(before)
    print(f"\n## the camera alone, A/B: {rev} (before) and this tree (after), alternating")
    print("CPU time of a frame (colour + depth, 320x240, URDF PuzzleBot turning and driving), median")
    print_ab_head("world")
    with tempfile.TemporaryDirectory() as tmp:
        old = extract_tree(before, Path(tmp))
        # office: walls and furniture; square: the course's floor markings looked up per floor pixel
        for world in ("office", "square"):
            a: list[float] = []
            b: list[float] = []
            for _ in range(rounds):
                a.append(camera_frame_ms(old, world))
                b.append(camera_frame_ms(None, world))
            am, bm = statistics.median(a), statistics.median(b)
            print(f"| {world}, median of {rounds} | {am:.3f} ms | {bm:.3f} ms | {bm / am:.2f} |")
            print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


STAGES = """
import json, sys, time
from ninjemys.rostime import Time
from ninjemys.sim import messages
from ninjemys.sim.puzzlebot_node import keep_freed_memory
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import load_world
from ninjemys.sim.worlds import world_path
keep_freed_memory()
sim = Simulation(load_world(world_path("office")), 0.01, 0)
r = sim.add_robot("pb", load_robot_model(sys.argv[1]), 0.0, 0.0, 0.0)
r.command(0.05, 0.5)
m, secs, clock = r.model, float(sys.argv[2]), time.thread_time_ns
t = dict.fromkeys(("physics", "odometry", "lidar cast", "camera render", "messages"), 0)
odom = None
for i in range(int(secs * 100)):
    t0 = clock(); sim.step(); t1 = clock()
    stamp = Time._raw(*divmod(sim.time_ns, 1_000_000_000))
    pose = sim.odometry(r); t2 = clock()
    if odom is None:
        odom = messages.odometry(stamp, "odom", "base_link", pose, (r.v, r.w), m.odom_alpha)
    else:
        messages.odometry_into(odom, stamp, pose, (r.v, r.w))
    odom.frame_parts(); t3 = clock()
    t["physics"] += t1 - t0; t["odometry"] += t2 - t1; t["messages"] += t3 - t2
    scene = sim.scene(r.name) if i % 10 in (0, 3, 6) else None
    if i % 10 == 0:
        t4 = clock(); ranges = sim.scan(r, scene); t5 = clock()
        messages.laser_scan(stamp, "laser", m.laser, ranges).frame_parts()
        t["lidar cast"] += t5 - t4; t["messages"] += clock() - t5
    if scene is not None:
        t6 = clock(); rgb, depth = sim.render(r, scene); t7 = clock()
        messages.rgb_image(stamp, "camera", rgb).frame_parts()
        messages.depth_image(stamp, "camera", depth).frame_parts()
        for _ in range(2):
            messages.camera_info(stamp, "camera", m.camera, r.camera.intrinsics()).frame_parts()
        t["camera render"] += t7 - t6; t["messages"] += clock() - t7
print(json.dumps({k: v / 1e6 / secs for k, v in t.items()}))
"""


def stage_ms(src: Path | None, secs: float) -> dict[str, float]:
    """ms of thread CPU per simulated second, by stage, of the tree at ``src`` (None: this tree)."""
    import json

    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    out = subprocess.run(
        [sys.executable, "-c", STAGES, str(URDF_MODEL), str(secs)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        preexec_fn=_pin_to_one_core,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def bench_stages(before: str, rounds: int, secs: float) -> None:
    rev = short_rev(before)
    print(
        f"\n## one simulated second, stage by stage, A/B: {rev} (before) and this tree (after), alternating"
    )
    print(
        f"URDF PuzzleBot, office world, {secs:.0f} simulated s per run, thread CPU ms per simulated s "
        f"(median of {rounds}), pinned to CPU {SIM_CORE}; sends not included"
    )
    print_ab_head("stage")
    with tempfile.TemporaryDirectory() as tmp:
        old = extract_tree(before, Path(tmp))
        a: list[dict[str, float]] = []
        b: list[dict[str, float]] = []
        for _ in range(rounds):
            a.append(stage_ms(old, secs))
            b.append(stage_ms(None, secs))
    for stage in (*a[0], "total"):
        am = statistics.median(sum(v.values()) if stage == "total" else v[stage] for v in a)
        bm = statistics.median(sum(v.values()) if stage == "total" else v[stage] for v in b)
        print(f"| {stage} | {am:.2f} ms | {bm:.2f} ms | {bm / am:.2f} |")
    print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


def sim_instructions(src: Path | None, camera: bool, secs: float = 4 * math.pi) -> float:
    """Instructions (callgrind, every thread of the simulator process) per simulated second, over
    ``secs`` simulated seconds from the second simulated second on (default: one full circle of the
    robot's 0.05 m/s, 0.5 rad/s drive, so that both trees see the same views), the URDF PuzzleBot
    in the office with scan + camera + odometry subscribed (``camera`` False: scan + odometry).
    Collection is switched on and off from outside (``callgrind_control``) at those /odom stamps.
    Deterministic where CPU time is not, but memcpy counts about one instruction per byte."""
    from ninjemys.idl.loader import get_message_class, get_service_class
    from ninjemys.node import Node

    env = dict(os.environ, PYTHONHASHSEED="0")
    if src is not None:
        env["PYTHONPATH"] = str(src)
    with tempfile.TemporaryDirectory() as tmp, run_master() as master:
        out = Path(tmp) / "callgrind.out"
        env["ROS_MASTER_URI"] = master
        cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", f"--callgrind-out-file={out}"]
        cmd += [sys.executable, "-m", "ninjemys.packages.run_shipped", "puzzlebot_sim", "sim_node"]
        # paused until every subscriber and the drive command are connected: both trees then
        # simulate the very same run, the robot driving from the first step on
        cmd += ["_world:=office", "_rate:=0", "_gui:=false", f"_model:={URDF_MODEL}", "_paused:=true"]
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        node = Node("bench_callgrind", anonymous=True, master_uri=master)
        stamp = [0.0]
        odom = get_message_class("nav_msgs/Odometry")
        node.subscriber(
            "/odom", odom, lambda m: stamp.__setitem__(0, m.header.stamp.to_sec()), queue_size=100
        )
        topics = (("/scan", "sensor_msgs/LaserScan"), ("/camera/color/image_raw", "sensor_msgs/Image"))
        topics += (("/camera/depth/image_rect_raw", "sensor_msgs/Image"),)
        subs = [node.subscriber("/odom", odom, lambda _m: None, queue_size=1)]
        for topic, kind in topics[: 3 if camera else 1]:
            subs.append(
                node.subscriber(topic, get_message_class(kind), lambda _m: None, queue_size=100, raw=True)
            )
        twist_cls = get_message_class("geometry_msgs/Twist")
        twist = twist_cls()
        twist.linear.x, twist.angular.z = 0.05, 0.5
        drive = node.publisher("/cmd_vel", twist_cls, queue_size=1, latch=True)
        drive.publish(twist)
        try:
            while not (drive.get_num_connections() and all(s.get_num_connections() for s in subs)):
                time.sleep(0.05)
            time.sleep(1.0)  # the latched command taken in
            node.wait_for_service("/gazebo/unpause_physics", 120)
            node.service_proxy("/gazebo/unpause_physics", get_service_class("std_srvs/Empty")).call()
            while stamp[0] < 2.0:
                time.sleep(0.005)
            control = ["callgrind_control", "-i"]
            subprocess.run([*control, "on", str(proc.pid)], capture_output=True, check=True)
            t0 = stamp[0]
            while stamp[0] < t0 + secs:
                time.sleep(0.005)
            subprocess.run([*control, "off", str(proc.pid)], capture_output=True, check=True)
            t1 = stamp[0]
        finally:
            node.shutdown("bench over")
            proc.terminate()
            proc.wait(60)
        text = out.read_text(errors="replace")
        # "totals" (what was collected); "summary" is 0 when collection started switched off
        found = re.search(r"^totals:\s*(\d+)", text, re.M) or re.search(r"^summary:\s*(\d+)", text, re.M)
    if found is None:
        raise RuntimeError("callgrind wrote no totals")
    return int(found.group(1)) / (t1 - t0)


def bench_callgrind(before: str) -> None:
    rev = short_rev(before)
    print(f"\n## instructions per simulated second (callgrind), {rev} (before) and this tree (after)")
    print("URDF PuzzleBot, office, one circle of its drive (12.6 simulated s), the whole simulator process")
    print_ab_head("subscribers")
    with tempfile.TemporaryDirectory() as tmp:
        old = extract_tree(before, Path(tmp))
        for camera, label in ((True, "scan + camera + odom"), (False, "scan + odom")):
            a, b = sim_instructions(old, camera), sim_instructions(None, camera)
            print(f"| {label} | {a / 1e6:.1f} M | {b / 1e6:.1f} M | {b / a:.3f} |")


def default_before() -> str:
    out = subprocess.run(
        ["git", "-C", str(ROOT), "merge-base", "HEAD", "main"], capture_output=True, text=True
    ).stdout.strip()
    return out or "HEAD~1"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="fewer repetitions and shorter runs")
    p.add_argument("--before", default=None, help="the older tree (default: merge-base with main)")
    p.add_argument(
        "--readers-anywhere",
        action="store_true",
        help="let the subscribers run on the simulator's core too (the figures before 2026-11-29 16:00)",
    )
    p.add_argument(
        "--only", choices=("launch", "ab", "camera", "stages", "split", "callgrind"), help="run one part"
    )
    args = p.parse_args()
    print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    if not args.readers_anywhere and keep_readers_off_the_sim_core():
        print(f"the simulator runs on CPU {SIM_CORE}; this process (subscribers, master) on the others")
    if args.only in (None, "launch"):
        bench_launch(2 if args.quick else 5)
    if args.only in (None, "ab"):
        bench_ab(args.before or default_before(), 5.0 if args.quick else 10.0, 1 if args.quick else 2)
    if args.only in (None, "camera"):
        bench_camera(args.before or default_before(), 3 if args.quick else 5)
    if args.only in (None, "split"):
        bench_split(5.0 if args.quick else 10.0, 1 if args.quick else 2)
    if args.only == "callgrind":  # minutes under valgrind: asked for by name only
        bench_callgrind(args.before or default_before())
    if args.only in (None, "stages"):
        bench_stages(args.before or default_before(), 3 if args.quick else 5, 10.0 if args.quick else 20.0)
    print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
