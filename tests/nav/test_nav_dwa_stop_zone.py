"""The local planner and the safety monitor agree: DWA never picks an arc the monitor refuses.

Loaded maze runs stalled at corners: "oscillating", aborted after the recoveries. The poses below are
from those runs' logs. There the planner, which keeps the inscribed radius (0.16 m), chose arcs past
the corner that the monitor, keeping 0.3-0.36 m (its stop zone), refused: it cut the linear speed cycle
after cycle and the robot stood. With the monitor's stop zone the planner drops those arcs itself.
No processes: the shipped maze, a numpy laser, the shipped parameters.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from ninjemys.nav.costmap import Costmap, CostmapParams
from ninjemys.nav.dwa import DWAParams, DWAPlanner
from ninjemys.nav.planner import plan_path
from ninjemys.nav.safety import StopZone, blocked, blocked_arcs, judged_speed

from .conftest import SHARE, cast, world_map

PARAMS = SHARE / "puzzlebot_navigation" / "params"
ANGLES = np.linspace(-math.pi, math.pi, 360, endpoint=False)

#: (pose, goal) of corner stalls in loaded maze runs (move_base's "oscillating" warnings)
CORNERS = [
    ((1.22, 2.29, 2.07), (-0.02, 3.18, -2.96)),
    ((4.23, 2.70, -2.06), (3.78, 0.98, -0.1)),
    ((3.29, 4.78, 0.51), (5.03, 4.48, -2.33)),
    ((2.30, 3.22, -0.47), (2.92, -0.07, 2.49)),
]


def shipped_zone() -> StopZone:
    """The monitor's stop zone from the shipped safety_params.yaml (what move_base reads at run time)."""
    p = yaml.safe_load((PARAMS / "safety_params.yaml").read_text())
    return StopZone(
        p["robot_radius"], p["safety_margin"], p["max_decel"], p["reaction_time"], p["obstacle_speed"]
    )


def shipped_dwa() -> DWAParams:
    params = DWAParams()
    params.update(yaml.safe_load((PARAMS / "dwa_local_planner_params.yaml").read_text())["DWAPlannerROS"])
    return params


class Maze:
    """The maze's costmaps as move_base builds them (shipped radii), and a laser on its ground truth."""

    def __init__(self) -> None:
        common = yaml.safe_load((PARAMS / "costmap_common_params.yaml").read_text())
        radii = dict(
            robot_radius=common["robot_radius"],
            inflation_radius=common["inflation_radius"],
            cost_scaling_factor=common["cost_scaling_factor"],
        )
        self.grid = world_map("maze")
        ox, oy = self.grid.origin[0], self.grid.origin[1]
        self.glob = Costmap(CostmapParams(**radii))
        self.glob.set_static_map(self.grid.data, self.grid.resolution, ox, oy)
        self.glob.update()
        self.local = Costmap(CostmapParams(rolling_window=True, width=3.0, height=3.0, **radii))
        self.local.set_static_map(self.grid.data, self.grid.resolution, ox, oy)

    def plan(self, pose: tuple, goal: tuple) -> np.ndarray:
        g = self.glob
        return plan_path(g.costs, g.resolution, (self.grid.origin[0], self.grid.origin[1]), pose[:2], goal)

    def path_length(self, pose: tuple, goal: tuple) -> float:
        plan = self.plan(pose, goal)
        return float(np.hypot(np.diff(plan[:, 0]), np.diff(plan[:, 1])).sum())

    def scan(self, pose: tuple) -> np.ndarray:
        """The laser's returns in the robot's frame (the laser sits at base_link's origin)."""
        r = cast(self.grid, pose, ANGLES, 5.0)
        ok = np.isfinite(r)
        return np.column_stack([r[ok] * np.cos(ANGLES[ok]), r[ok] * np.sin(ANGLES[ok])])

    def command(
        self, dwa: DWAPlanner, pose: tuple, vel: tuple[float, float], points: np.ndarray | None = None
    ):
        """DWA's command at ``pose``, its stop zone against ``points`` (default: the laser there)."""
        dwa.stop_points = self.scan(pose) if points is None else points
        self.local.update_origin(pose[0], pose[1])
        self.local.update()
        return dwa.compute(pose, vel, self.local)


@pytest.fixture(scope="module")
def maze() -> Maze:
    return Maze()


def refused(zone: StopZone, points: np.ndarray, v: float, w: float, v_now: float) -> bool:
    """The monitor's verdict (safety_node.decide): the stop zone at the speed it judges ``v`` at."""
    speed = float(judged_speed(v, v_now))
    return v != 0.0 and blocked(
        points, speed, w, zone.radius, zone.margin, zone.max_decel, zone.reaction_time, zone.obstacle_speed
    )


@pytest.mark.parametrize(("pose", "goal"), CORNERS)
def test_planner_alone_picks_a_corner_arc_the_monitor_refuses(maze, pose, goal):
    """The stall's cause, as it was: DWA without the stop zone, standing at the corner, chooses to
    drive on, and the monitor refuses it (the robot gets v = 0 again and again)."""
    zone = shipped_zone()
    dwa = DWAPlanner(shipped_dwa())
    dwa.set_plan(maze.plan(pose, goal))
    cmd = maze.command(dwa, pose, (0.0, 0.0))
    assert cmd.valid and cmd.v > 0.0
    assert refused(zone, maze.scan(pose), cmd.v, cmd.w, 0.0)


@pytest.mark.parametrize(("pose", "goal"), CORNERS)
@pytest.mark.parametrize("v_now", [0.0, 0.1, 0.3])
def test_planner_with_the_stop_zone_picks_only_arcs_the_monitor_allows(maze, pose, goal, v_now):
    zone = shipped_zone()
    dwa = DWAPlanner(shipped_dwa(), stop_zone=zone)
    dwa.set_plan(maze.plan(pose, goal))
    cmd = maze.command(dwa, pose, (v_now, 0.0))
    assert not refused(zone, maze.scan(pose), cmd.v, cmd.w, v_now), cmd
    if v_now == 0.0:  # standing: there is always a way on (a turn in place sweeps nothing new)
        assert cmd.valid


def test_corner_is_passed_with_no_command_refused(maze):
    """Closed loop through the first corner above, the monitor in the loop: it refuses nothing the
    planner sends, and the robot gets round the corner (before: stuck, every cycle refused)."""
    zone = shipped_zone()
    pose, goal = CORNERS[0]
    dwa = DWAPlanner(shipped_dwa(), stop_zone=zone)
    x, y, th = pose
    v = w = 0.0
    dt = 1.0 / dwa.params.controller_frequency
    vetoes = 0
    start_left = maze.path_length((x, y, th), goal)
    for i in range(400):  # 20 s
        if i % 20 == 0:  # planner_frequency 1 Hz
            dwa.set_plan(maze.plan((x, y, th), goal))
        points = maze.scan((x, y, th))  # one scan a cycle, for the planner and the monitor
        cmd = maze.command(dwa, (x, y, th), (v, w), points)
        if refused(zone, points, cmd.v, cmd.w, v):
            vetoes += 1
            cmd.v = 0.0
        v, w = cmd.v, cmd.w
        x, y = x + v * math.cos(th) * dt, y + v * math.sin(th) * dt
        th = (th + w * dt + math.pi) % (2 * math.pi) - math.pi
    assert vetoes == 0
    left = maze.path_length((x, y, th), goal)
    assert left < start_left - 1.5, (start_left, left)  # round the corner and well on the way


def test_blocked_arcs_is_blocked_for_each_command():
    """The vectorised test the planner uses is the monitor's test, command by command."""
    rng = np.random.default_rng(3)
    points = rng.uniform(-0.8, 0.8, (60, 2))
    zone = StopZone(0.11, 0.08, 1.5, 0.35, 0.3)
    V = rng.uniform(-0.3, 0.3, 200)
    V[:10] = 0.0
    W = rng.uniform(-1.5, 1.5, 200)
    W[10:20] = 0.0
    many = blocked_arcs(points, V, W, zone)
    one = [blocked(points, v, w, 0.11, 0.08, 1.5, 0.35, 0.3) for v, w in zip(V, W, strict=True)]
    assert many.tolist() == one
    assert 0 < many.sum() < len(V)


def test_judged_speed_is_the_odometry_while_braking():
    assert judged_speed(0.1, 0.3).item() == 0.3  # slowing down: still moving at 0.3
    assert judged_speed(0.3, 0.1).item() == 0.3  # speeding up: the command
    assert judged_speed(-0.1, 0.3).item() == -0.1  # reversing: the command
    assert judged_speed(np.array([0.0, 0.2]), 0.25).tolist() == [0.0, 0.25]  # a stop is never refused


def test_navigation_launch_points_move_base_at_the_monitor():
    """One set of stop-zone numbers: move_base reads the monitor's own parameters."""
    launch = (SHARE / "puzzlebot_navigation" / "launch").joinpath
    assert '<arg name="stop_zone_from" value="/safety_monitor"/>' in launch("navigation.launch").read_text()
    assert 'name="DWAPlannerROS/stop_zone_from"' in launch("move_base.launch").read_text()
    assert "safety_monitor" in launch("safety.launch").read_text()
    assert Path(PARAMS / "safety_params.yaml").exists()


class FakeNode:
    """Just what the parameter readers use: a parameter dict under full names, a log, a name."""

    name = "/move_base"

    def __init__(self, params: dict) -> None:
        self.params = params
        self.lines: list[str] = []
        self.log = self

    def get_param(self, name: str, default=None):
        return self.params.get(self.resolve_name(name), default)

    def has_param(self, name: str) -> bool:
        return self.resolve_name(name) in self.params

    def resolve_name(self, name: str) -> str:
        return self.name + "/" + name[1:] if name.startswith("~") else name

    def error(self, fmt: str, *args) -> None:
        self.lines.append("ERROR " + fmt % args)

    def warn(self, fmt: str, *args) -> None:
        self.lines.append("WARN " + fmt % args)


def test_move_base_reads_the_monitors_own_parameters():
    from ninjemys.nav.move_base_node import stop_zone

    monitor = {
        "/safety_monitor/footprint": "[[-0.1, -0.1], [0.2, -0.1], [0.2, 0.1], [-0.1, 0.1]]",
        "/safety_monitor/robot_radius": 0.11,
        "/safety_monitor/safety_margin": 0.08,
        "/safety_monitor/max_decel": 1.5,
        "/safety_monitor/reaction_time": "fast",
    }
    node = FakeNode({"/move_base/DWAPlannerROS/stop_zone_from": "/safety_monitor", **monitor})
    zone = stop_zone(node)
    assert zone is not None
    assert zone.radius == pytest.approx(math.hypot(0.2, 0.1))  # the footprint's circumscribed radius
    assert (zone.margin, zone.max_decel, zone.reaction_time, zone.obstacle_speed) == (0.08, 1.5, 0.15, 0.0)
    assert node.lines == [
        "ERROR /move_base: parameter /safety_monitor/reaction_time: expected a float, got 'fast'; using 0.15"
    ]
    assert stop_zone(FakeNode({})) is None  # not asked for: ROS 1's move_base, no such check
    lone = FakeNode({"/move_base/DWAPlannerROS/stop_zone_from": "/nobody"})
    assert stop_zone(lone) == StopZone()
    assert lone.lines and "/nobody, but it has no robot_radius" in lone.lines[0]
