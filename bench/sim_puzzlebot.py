"""PuzzleBot simulator benchmarks, ours side by side with ir-sim (the issue's anchor) in one run.

1. One 360-beam, 12 m scan: on the ``office`` world (segments), a 400 x 400 occupancy grid (our cell
   traversal, and our cast against the grid's outline), 1,000 random segments. The same office
   geometry and the same 1,000 segments go through ir-sim's Lidar2D (``pip install ir-sim``; skipped
   with a note when it is missing). The issue's reference figure: ir-sim took ~22 ms per scan (ir-sim#332).
Subscribers count raw messages (no deserialization: the bench process must not be the bottleneck);
the simulator's speeds come from the summary it logs on exit.

2. One PuzzleBot headless, as fast as possible, driving a tight circle, with subscribers on the 10 Hz scan, the 30 Hz
   320x240 RGB-D camera and the 100 Hz odometry: simulated seconds per wall second, and the
   simulator's CPU (one process: ``sim_node`` with ``_rate:=0``).
3. Ten robots driving circles with lidars at real time (``_rate:=1``, scans subscribed): the simulator's CPU as a
   share of one core.

Run alone: ``.venv/bin/python bench/sim_puzzlebot.py [--quick]``. The machine is shared: the load
average is printed with the figures.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from ninjemys.packages.shipped import shipped_executable
from ninjemys.sim.raycast import cast_grid, cast_segments, grid_edges
from ninjemys.sim.world2d import load_world, rasterize
from ninjemys.sim.worlds import world_path
from ninjemys.testing import run_master


def best_ms(fn, repeat: int) -> float:  # type: ignore[no-untyped-def]
    """Fastest of ``repeat`` timings in ms (after one warm-up): on a shared machine the minimum is the
    figure least disturbed by other work (timeit's rule); ours and ir-sim's are treated alike."""
    fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t) * 1e3)
    return float(np.min(times))


def random_segments(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    start = rng.uniform(-10, 10, (n, 2))
    return np.hstack([start, start + rng.uniform(-1, 1, (n, 2))])


def bench_grid() -> tuple[np.ndarray, float, float]:
    """A 400 x 400 map at 5 cm: rooms of walls plus 200 random boxes (a realistic indoor map)."""
    rng = np.random.default_rng(7)
    occ = np.zeros((400, 400), dtype=bool)
    occ[[0, -1], :] = True
    occ[:, [0, -1]] = True
    for k in range(40, 400, 80):
        occ[k : k + 2, :] = True
        occ[:, k : k + 2] = True
        for door in range(0, 400, 80):
            occ[k : k + 2, door + 20 : door + 40] = False
            occ[door + 20 : door + 40, k : k + 2] = False
    for _ in range(200):
        r, c = rng.integers(5, 390, 2)
        occ[r : r + rng.integers(2, 10), c : c + rng.integers(2, 10)] = True
    occ[195:205, 195:205] = False
    return occ, -10.0, -10.0


def irsim_scan_ms(segments: np.ndarray, repeat: int) -> float | None:
    """ir-sim's Lidar2D.step with 360 beams / 12 m among the given segments (as thin line obstacles)."""
    try:
        import irsim
    except ImportError:
        return None
    lines = [
        "world: {height: 30, width: 30, offset: [-15, -15], step_time: 0.01}",
        "robot:",
        "  - kinematics: {name: diff}",
        "    shape: {name: circle, radius: 0.11}",
        "    state: [0.5, 0.0, 0.0]",
        "    sensors:",
        "      - {type: lidar2d, range_min: 0.15, range_max: 12, angle_range: 6.283185307179586, number: 360}",
        "obstacle:",
    ]
    for x0, y0, x1, y1 in segments:
        lines.append(
            f"  - {{shape: {{name: linestring, vertices: [[{x0:.4f}, {y0:.4f}], [{x1:.4f}, {y1:.4f}]]}}, state: [0, 0, 0]}}"
        )
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "bench_world.yaml"
        path.write_text("\n".join(lines) + "\n")
        env = irsim.make(str(path), display=False, disable_all_plot=True, log_level="ERROR")
        robot = env.robot_list[0]
        lidar = robot.lidar
        state = robot.state
        return best_ms(lambda: lidar.step(state), repeat)


def scan_benchmarks(repeat: int) -> None:
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    office = load_world(world_path("office"))
    segs = office.segments
    rnd = random_segments(1000)
    occ, ox, oy = bench_grid()
    edges = grid_edges(occ, 0.05, ox, oy)
    print(f"\n## one 360-beam 12 m scan (best of {repeat}, ms)")
    rows = [
        (
            f"office world ({len(segs)} segments)",
            best_ms(lambda: cast_segments(0.5, 0.0, angles, segs, 12.0), repeat),
            segs,
        ),
        ("1,000 random segments", best_ms(lambda: cast_segments(0.0, 0.0, angles, rnd, 12.0), repeat), rnd),
        (
            "400x400 grid, cell traversal (exact DDA)",
            best_ms(lambda: cast_grid(0.0, 0.0, angles, occ, 0.05, ox, oy, 12.0), repeat),
            None,
        ),
        (
            f"400x400 grid, cast on its outline ({len(edges)} edges)",
            best_ms(lambda: cast_segments(0.0, 0.0, angles, edges, 12.0), repeat),
            None,
        ),
    ]
    office_map = rasterize(office)
    office_edges = grid_edges(office_map.occupied(), 0.05, office_map.origin[0], office_map.origin[1])
    rows.append(
        (
            f"office as a map ({office_map.width}x{office_map.height} grid, traversal)",
            best_ms(
                lambda: cast_grid(
                    0.5,
                    0.0,
                    angles,
                    office_map.occupied(),
                    0.05,
                    office_map.origin[0],
                    office_map.origin[1],
                    12.0,
                ),
                repeat,
            ),
            None,
        )
    )
    rows.append(
        (
            f"office as a map ({len(office_edges)} outline edges)",
            best_ms(lambda: cast_segments(0.5, 0.0, angles, office_edges, 12.0), repeat),
            None,
        )
    )
    print(f"| case | ours (ms) | ir-sim {irsim_version()} (ms) | ratio |")
    print("|---|---:|---:|---:|")
    for name, ours, geometry in rows:
        ref = irsim_scan_ms(geometry, max(5, repeat // 5)) if geometry is not None else None
        ref_text = f"{ref:.2f}" if ref is not None else "-"
        ratio = f"{ref / ours:.0f}x faster" if ref is not None else "(ir-sim#332: ~22 ms)"
        print(f"| {name} | {ours:.3f} | {ref_text} | {ratio} |")


def irsim_version() -> str:
    try:
        from irsim.version import __version__

        return __version__
    except ImportError:
        return "(not installed)"


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def start_sim(master: str, world: str, rate: float, lines: list[str] | None = None) -> subprocess.Popen:
    cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
        [f"_world:={world}", f"_rate:={rate}", "_gui:=false"]
    )
    proc = subprocess.Popen(
        cmd,
        env=dict(os.environ, ROS_MASTER_URI=master),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    for line in proc.stdout:  # type: ignore[union-attr]
        if "PuzzleBot simulator:" in line:
            break
    sink = lines if lines is not None else []
    drain = threading.Thread(target=lambda: sink.extend(proc.stdout), daemon=True)  # type: ignore[arg-type]
    drain.start()
    proc.drain = drain  # type: ignore[attr-defined]
    return proc


def summary_of(lines: list[str]) -> tuple[float, float]:
    """(simulated s per wall s, simulated s per CPU s) from the simulator's exit summary."""
    import re

    for line in lines:
        m = re.search(r"\(([\d.]+)x real time\), [\d.]+ s of CPU \(([\d.]+) simulated s per CPU s\)", line)
        if m:
            return float(m.group(1)), float(m.group(2))
    raise RuntimeError("the simulator printed no summary:\n" + "".join(lines[-20:]))


def stop(proc: subprocess.Popen) -> None:
    proc.terminate()
    try:
        proc.wait(10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
    drain = getattr(proc, "drain", None)
    if drain is not None:
        drain.join(5)


class Counter:
    """Counts messages."""

    def __init__(self) -> None:
        self.n = 0

    def __call__(self, _msg) -> None:  # type: ignore[no-untyped-def]
        self.n += 1


def fast_as_possible(duration: float) -> None:
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from ninjemys.node import Node
    from sensor_msgs.msg import Image, LaserScan

    print(
        f"\n## one PuzzleBot driving a tight circle in office, headless, as fast as possible ({duration:.0f} s)"
    )
    print("speeds from the simulator's own exit summary (its simulated time, wall time and CPU time)")
    print(
        "| subscribers | sim s / wall s | sim CPU (% of a core) | sim s per CPU s | scans/s | images/s (color+depth) | odom/s |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|")
    camera_per_cpu = 0.0
    for label, topics in (
        ("scan + camera + odom", ("scan", "camera", "odom")),
        ("scan + odom", ("scan", "odom")),
        ("none", ()),
    ):
        with run_master() as master:
            lines: list[str] = []
            proc = start_sim(master, "office", 0.0, lines)
            node = Node("bench_sub", anonymous=True, master_uri=master)
            counts = {k: Counter() for k in ("scan", "image", "depth", "odom")}
            if "scan" in topics:
                node.subscriber("/scan", LaserScan, counts["scan"], queue_size=100, raw=True)
            if "camera" in topics:
                node.subscriber("/camera/color/image_raw", Image, counts["image"], queue_size=100, raw=True)
                node.subscriber(
                    "/camera/depth/image_rect_raw", Image, counts["depth"], queue_size=100, raw=True
                )
            if "odom" in topics:
                node.subscriber("/odom", Odometry, counts["odom"], queue_size=1000, raw=True)
            drive = node.publisher("/cmd_vel", Twist, queue_size=1, latch=True)
            twist = Twist()
            twist.linear.x, twist.angular.z = 0.05, 0.5  # a tight circle: the views keep changing
            drive.publish(twist)
            w0 = time.monotonic()
            time.sleep(duration)
            cpu = cpu_seconds(proc.pid)
            wall = time.monotonic() - w0
            rates = {k: v.n / wall for k, v in counts.items()}
            node.shutdown("bench over")
            stop(proc)
        speed, per_cpu = summary_of(lines)
        print(
            f"| {label} | {speed:.1f}x | {100 * cpu / wall:.0f} | {per_cpu:.1f}x | {rates['scan']:.0f} | "
            f"{rates['image']:.0f}+{rates['depth']:.0f} | {rates['odom']:.0f} |"
        )
        if label == "scan + camera + odom":
            camera_per_cpu = per_cpu
    verdict = "met" if camera_per_cpu >= 20.0 else "missed"
    print(
        f"the issue's target, at least 20x real time on one core with the camera: {camera_per_cpu:.1f} "
        f"simulated s per CPU s of the simulator -> {verdict} (the wall-clock factor is that times the "
        "share of a core the simulator got on this shared machine)"
    )


def ten_robots(duration: float) -> None:
    from geometry_msgs.msg import Twist
    from ninjemys.node import Node
    from sensor_msgs.msg import LaserScan

    lines = ["name: ten", "bounds: [-6, -6, 6, 6]", "walls:"]
    for a, b in (((-5, -5), (5, -5)), ((5, -5), (5, 5)), ((5, 5), (-5, 5)), ((-5, 5), (-5, -5))):
        lines.append(f"  - {{from: [{a[0]}, {a[1]}], to: [{b[0]}, {b[1]}]}}")
    lines.append("robots:")
    for i in range(10):
        lines.append(f"  - {{name: robot{i}, pose: [{-4 + (i % 5) * 2}, {-1 if i < 5 else 1}, 0]}}")
    with tempfile.TemporaryDirectory() as d:
        world = Path(d) / "ten.yaml"
        world.write_text("\n".join(lines) + "\n")
        with run_master() as master:
            proc = start_sim(master, str(world), 1.0)
            node = Node("bench_sub", anonymous=True, master_uri=master)
            counts = [Counter() for _ in range(10)]
            drives = []
            for i in range(10):
                node.subscriber(f"/robot{i}/scan", LaserScan, counts[i], queue_size=10, raw=True)
                drive = node.publisher(f"/robot{i}/cmd_vel", Twist, queue_size=1, latch=True)
                twist = Twist()
                twist.linear.x, twist.angular.z = 0.1, 0.5  # every robot drives a 0.2 m circle
                drive.publish(twist)
                drives.append(drive)
            time.sleep(2.0)
            c0, w0 = cpu_seconds(proc.pid), time.monotonic()
            n0 = sum(c.n for c in counts)
            time.sleep(duration)
            c1, w1 = cpu_seconds(proc.pid), time.monotonic()
            scans = (sum(c.n for c in counts) - n0) / (w1 - w0)
            node.shutdown("bench over")
            stop(proc)
    print(
        f"\n## ten PuzzleBots driving circles with lidars at real time ({duration:.0f} s, scans subscribed)"
    )
    print("| robots | sim CPU (% of a core) | scans/s received (10 robots x 10 Hz = 100) |")
    print("|---|---:|---:|")
    print(f"| 10 | {100 * (c1 - c0) / (w1 - w0):.0f} | {scans:.0f} |")


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="fewer repetitions and shorter runs")
    p.add_argument("--only", choices=("scan", "fast", "ten"), help="run one part")
    options = p.parse_args()
    print(
        f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}   python {sys.version.split()[0]}   cores {os.cpu_count()}"
    )
    repeat = 30 if options.quick else 200
    duration = 5.0 if options.quick else 10.0
    if options.only in (None, "scan"):
        scan_benchmarks(repeat)
    if options.only in (None, "fast"):
        fast_as_possible(duration)
    if options.only in (None, "ten"):
        ten_robots(duration)
    print(f"\nload average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
