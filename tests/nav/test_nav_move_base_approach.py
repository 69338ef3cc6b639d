"""move_base's final approach in narrow spaces: the state machine (ninjemys.nav.move_base) over the real
DWA, a fake unicycle whose commands arrive late, and a corridor costmap; fake clock, no process."""

from __future__ import annotations

import math

import numpy as np

from ninjemys.actionlib import states
from ninjemys.nav.move_base import ClearCostmaps, MoveBaseFsm, MoveBaseParams

# -- the final approach: the state machine over the real DWA, a fake unicycle and a narrow corridor --------


def corridor_costmap(width_m: float, rolling: bool = True):
    """A rolling local costmap over a straight corridor along x, ``width_m`` wide, closed at x = 2.0 m."""
    from ninjemys.nav.costmap import Costmap, CostmapParams

    res = 0.05
    data = np.full((80, 80), 100, dtype=np.int8)
    half = int(round(width_m / 2 / res))
    data[40 - half : 40 + half, 0:40] = 0  # free: y in [2 - w/2, 2 + w/2], x < 2.0
    cm = Costmap(
        CostmapParams(
            rolling_window=rolling,
            width=3.0,
            height=3.0,
            robot_radius=0.16,
            inflation_radius=0.4,
            cost_scaling_factor=8.0,
        )
    )
    cm.set_static_map(data, res, 0.0, 0.0)
    return cm


class DwaSeam:
    def __init__(self, dwa, cm) -> None:
        self.dwa, self.cm = dwa, cm

    def new_goal(self) -> None:
        self.dwa.new_goal()

    def set_plan(self, plan) -> None:
        latched = self.dwa.xy_latched
        self.dwa.set_plan(plan)
        self.dwa.xy_latched = latched

    def compute(self, pose, velocity, period, stamps=None):
        self.cm.update_origin(pose[0], pose[1])
        self.cm.update()
        return self.dwa.compute(pose, velocity, self.cm, period, stamps)

    def remaining(self) -> int:
        return len(self.dwa.plan)


def approach(start, goal, width=0.9, latency=2, seconds=120.0, oscillation_timeout=15.0):
    """Drive the state machine over DWA with a unicycle whose commands arrive ``latency`` cycles late;
    returns (outcome, pose, recoveries run, worst cell cost visited)."""
    from ninjemys.nav.dwa import DWAParams, DWAPlanner

    params = MoveBaseParams(
        oscillation_timeout=oscillation_timeout, oscillation_distance=0.2, controller_patience=10.0
    )
    dparams = DWAParams(yaw_goal_tolerance=0.1, xy_goal_tolerance=0.1)
    cm = corridor_costmap(width)
    ground = corridor_costmap(width, rolling=False)
    ground.update()
    runs: list[str] = []

    class Planner:
        def make_plan(self, s, g):
            n = max(2, int(math.hypot(g[0] - s[0], g[1] - s[1]) / 0.05))
            return np.column_stack([np.linspace(s[0], g[0], n), np.linspace(s[1], g[1], n), np.full(n, g[2])])

    rec = [
        ClearCostmaps(name, lambda g, lp, size: runs.append("clear"), lambda: 0.0) for name in ("a", "b", "c")
    ]
    fsm = MoveBaseFsm(params, Planner(), DwaSeam(DWAPlanner(dparams), cm), rec)
    fsm.accept(goal, "h", 0.0)
    x, y, th = start
    v = w = 0.0
    dt = 1.0 / params.controller_frequency
    queue = [(0.0, 0.0)] * latency
    worst = 0
    t = 0.0
    while t < seconds:
        pose = (x, y, th)
        step = fsm.cycle(t, pose, pose, (v, w))
        if step.plan_wanted:
            step = fsm.plan_now(pose, t)
        if step.ended:
            return step.ended[0], pose, runs, worst
        queue.append(step.cmd or (v, w))
        cv, cw = queue.pop(0)
        v += max(-1.5 * dt, min(1.5 * dt, cv - v))
        w += max(-4.0 * dt, min(4.0 * dt, cw - w))
        x, y = x + v * math.cos(th) * dt, y + v * math.sin(th) * dt
        th = (th + w * dt + math.pi) % (2 * math.pi) - math.pi
        worst = max(worst, ground.cost_at(x, y))
        t += dt
    raise AssertionError(f"no outcome in {seconds} s: at {(x, y, th)}, state {fsm.state}")


def test_final_approach_turns_in_place_at_the_goal_in_a_narrow_corridor():
    """The maze's misses: the goal's position reached in a narrow spot, its heading never. The robot
    must stop within xy_goal_tolerance and turn in place to the yaw (here almost a half turn, against
    the way it came), with no recovery run, within yaw_goal_tolerance."""
    from ninjemys.nav.costmap import INSCRIBED

    for goal_yaw in (-2.96, 2.9, 0.58, -1.6):
        goal = (1.4, 2.0, goal_yaw)
        # an oscillation_timeout shorter than the final turn: turning to the heading is progress
        outcome, (x, y, th), runs, worst = approach((0.6, 2.0, 0.0), goal, width=0.9, oscillation_timeout=2.5)
        assert outcome.status == states.SUCCEEDED, (goal_yaw, outcome)
        assert math.hypot(x - goal[0], y - goal[1]) <= 0.1 + 0.02
        assert abs((th - goal_yaw + math.pi) % (2 * math.pi) - math.pi) <= 0.1
        assert runs == [] and worst < INSCRIBED


def test_final_approach_where_no_arc_is_safe_near_the_goal_still_turns_to_the_heading():
    """A corridor 0.4 m wide and the robot 0.06 m off its centre line, 0.12 m from the goal: its own cell
    is inscribed in the costmap (a tight spot, or a wall marked a little off), so no arc at all is safe.
    Within 1.5 x xy_goal_tolerance, standing, that ends the approach with the turn in place, instead of
    controller_patience, the recoveries and an abort at whatever heading the robot had."""
    goal = (1.65, 2.0, 2.9)
    outcome, (x, y, th), runs, _ = approach((1.55, 2.06, 0.0), goal, width=0.4)
    assert outcome.status == states.SUCCEEDED, outcome
    assert abs((th - goal[2] + math.pi) % (2 * math.pi) - math.pi) <= 0.1
    assert math.hypot(x - goal[0], y - goal[1]) <= 0.2 and runs == []
    # farther out, no safe arc is still a failure: the controller's patience and the recoveries run
    outcome, _, runs, _ = approach((1.35, 2.06, 0.0), goal, width=0.4)
    assert outcome.status == states.ABORTED and runs == ["clear"] * 3
    assert outcome.text == "Aborting because a valid control could not be found"
