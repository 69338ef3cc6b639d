"""move_base's state machine alone (ninjemys.nav.move_base): goals and preemption, planning patience,
control patience, oscillation, the recovery order and the final approach, on a fake clock with fake
poses and fake seams. No node, no process: the whole file runs in well under a second."""

from __future__ import annotations

import math

import numpy as np

from ninjemys.actionlib import states
from ninjemys.nav.dwa import Command
from ninjemys.nav.move_base import (
    CLEARING,
    CONTROLLING,
    IDLE,
    PLANNING,
    ClearCostmaps,
    MoveBaseFsm,
    MoveBaseParams,
    RotateRecovery,
)
from ninjemys.nav.planner import PlanError


class FakePlanner:
    def __init__(self) -> None:
        self.fail = False
        self.calls = 0

    def make_plan(self, start, goal):
        self.calls += 1
        if self.fail:
            raise PlanError("no path")
        xs = np.linspace(start[0], goal[0], 10)
        ys = np.linspace(start[1], goal[1], 10)
        return np.column_stack([xs, ys, np.full(10, goal[2])])


class FakeController:
    """Answers with whatever ``answer`` says; records the plans it was given."""

    def __init__(self) -> None:
        self.answer = Command(0.2, 0.0)
        self.plans: list[np.ndarray] = []
        self.new_goals = 0

    def new_goal(self) -> None:
        self.new_goals += 1

    def set_plan(self, plan):
        self.plans.append(plan)

    def compute(self, pose, velocity, period, stamps=None):
        return self.answer

    def remaining(self) -> int:
        return len(self.plans[-1])


def make(**overrides):
    params = MoveBaseParams(**overrides)
    cleared: list[float] = []
    recoveries = [
        ClearCostmaps("conservative_reset", lambda g, lp, size: cleared.append(size), lambda: 3.0),
        RotateRecovery(lambda: 1.5, lambda: params.clearing_rotation_allowed),
        ClearCostmaps("aggressive_reset", lambda g, lp, size: cleared.append(size), lambda: 0.0),
        RotateRecovery(lambda: 1.5, lambda: params.clearing_rotation_allowed),
    ]
    fsm = MoveBaseFsm(params, FakePlanner(), FakeController(), recoveries)
    return fsm, cleared


POSE = (0.0, 0.0, 0.0)
GOAL = (2.0, 0.0, 0.0)


def test_goal_plan_control_and_success_with_actionlib_statuses():
    fsm, _ = make()
    step = fsm.accept(GOAL, "h1", 0.0)
    assert fsm.state == PLANNING and step.plan_wanted and not step.ended
    assert fsm.cycle(0.05, POSE, POSE, (0, 0)).cmd == (0.0, 0.0)  # standing still while planning
    step = fsm.plan_now(POSE, 0.1)
    assert fsm.state == CONTROLLING and step.plan is not None
    step = fsm.cycle(0.15, POSE, POSE, (0, 0))
    assert step.cmd == (0.2, 0.0) and step.feedback == POSE
    fsm.controller.answer = Command(0.0, 0.0, reached=True)
    step = fsm.cycle(0.2, POSE, POSE, (0, 0))
    assert [(o.token, o.status, o.text) for o in step.ended] == [("h1", states.SUCCEEDED, "Goal reached")]
    assert step.ended[0].name == "SUCCEEDED"
    assert fsm.state == IDLE and step.cmd == (0.0, 0.0)
    assert fsm.cycle(0.25, POSE, POSE, (0, 0)).cmd is None  # idle: nothing published


def test_new_goal_preempts_and_cancel_stops_only_the_current_goal():
    fsm, _ = make()
    fsm.accept(GOAL, "h1", 0.0)
    step = fsm.accept((1.0, 1.0, 0.0), None, 1.0)  # a move_base_simple goal through the same inbox
    assert [(o.token, o.status) for o in step.ended] == [("h1", states.PREEMPTED)]
    assert fsm.controller.new_goals == 2
    assert not fsm.cancel("h1").ended  # no longer current: the node cancels it on its own
    fsm.accept(GOAL, "h2", 2.0)
    step = fsm.cancel("h2")
    assert [(o.token, o.status) for o in step.ended] == [("h2", states.PREEMPTED)]
    assert step.cmd == (0.0, 0.0) and fsm.state == IDLE


def test_a_plan_for_an_older_goal_is_dropped():
    fsm, _ = make()
    fsm.accept(GOAL, "h1", 0.0)
    goal, seq = fsm.take_plan_job(0.0)
    fsm.accept((1.0, 1.0, 0.0), "h2", 0.5)
    fsm.plan_done(seq, 1.0, FakePlanner().make_plan(POSE, goal))
    assert fsm.state == PLANNING and fsm.plan is None


def test_planner_patience_then_recoveries_in_move_base_order_then_abort():
    fsm, cleared = make(planner_patience=5.0, clearing_rotation_allowed=False)
    fsm.planner.fail = True
    fsm.accept(GOAL, "h1", 0.0)
    t, names = 0.0, []
    for _ in range(2000):
        t += 0.05
        step = fsm.cycle(t, POSE, POSE, (0, 0))
        if step.plan_wanted:
            step = fsm.plan_now(POSE, t)
        if fsm.state == CLEARING:
            names.append(fsm.recoveries[fsm.recovery_index].name)
        if step.ended:
            break
    assert step.ended[0].status == states.ABORTED and "Failed to find a valid plan" in step.ended[0].text
    order = [n for i, n in enumerate(names) if i == 0 or names[i - 1] != n]
    assert order == ["conservative_reset", "rotate_recovery", "aggressive_reset", "rotate_recovery"]
    assert cleared == [3.0, 0.0]
    assert 5 * 5.0 <= t < 5 * (5.0 + 0.5) + 0.5  # patience (plans retried every 0.5 s) before each
    assert fsm.state == IDLE


def test_controller_patience_replans_then_recovers():
    fsm, _ = make(controller_patience=3.0, recovery_behavior_enabled=False)
    fsm.accept(GOAL, "h1", 0.0)
    fsm.plan_now(POSE, 0.0)
    fsm.controller.answer = Command(0.0, 0.0, valid=False)
    t, states_seen = 0.0, set()
    while True:
        t += 0.05
        step = fsm.cycle(t, POSE, POSE, (0, 0))
        states_seen.add(fsm.state)
        if step.plan_wanted:
            fsm.plan_now(POSE, t)  # new plans come, but the controller still finds nothing
        if step.ended:
            break
    assert PLANNING in states_seen  # ROS 1 replans when the local planner fails
    assert step.ended[0].status == states.ABORTED
    assert step.ended[0].text == "Aborting because a valid control could not be found"
    assert 3.0 < t < 3.2  # patience counts from the last valid command, not from the last plan


def test_a_pose_older_than_transform_tolerance_stops_replans_then_recovers():
    """ROS 1's local planner fails on a pose the costmap refuses as too old: move_base stands still
    at once, replans, and after controller_patience of refused poses runs its recoveries."""
    fsm, _ = make(controller_patience=3.0, recovery_behavior_enabled=False)
    fsm.accept(GOAL, "h1", 0.0)
    fsm.plan_now(POSE, 0.0)
    assert fsm.cycle(0.05, POSE, POSE, (0, 0)).cmd == (0.2, 0.0)  # driving on a fresh pose
    step = fsm.pose_too_old(0.1)
    assert step.cmd == (0.0, 0.0) and fsm.state == CONTROLLING and not step.ended  # stopped at once
    t, states_seen = 0.1, set()
    while not step.ended:
        t += 0.05
        step = fsm.pose_too_old(t)
        assert step.cmd == (0.0, 0.0)
        states_seen.add(fsm.state)
        if fsm.state == PLANNING:
            fsm.plan_now(POSE, t)  # plans come, but the pose stays too old to drive on
    assert PLANNING in states_seen
    assert step.ended[0].status == states.ABORTED
    assert step.ended[0].text == "Aborting because a valid control could not be found"
    assert 3.0 < t < 3.2


def test_a_pose_too_old_while_idle_or_planning_commands_nothing_new():
    fsm, _ = make()
    assert fsm.pose_too_old(0.0).cmd is None  # no goal: move_base says nothing
    fsm.accept(GOAL, "h1", 0.0)
    assert fsm.state == PLANNING
    step = fsm.pose_too_old(0.1)
    assert step.cmd == (0.0, 0.0) and fsm.state == PLANNING and not step.ended


def test_the_oscillation_recovery_says_what_the_robot_did_meanwhile():
    """Loaded maze runs stalled at the corners: the log line tells a starved controller (few cycles)
    from a robot standing under valid commands (cycles at full rate, no motion)."""
    fsm, _ = make(oscillation_timeout=2.0, oscillation_distance=0.2)
    fsm.accept(GOAL, "h1", 0.0)
    fsm.plan_now(POSE, 0.0)
    t, yaw = 0.0, 0.0
    while fsm.state != CLEARING:
        t += 0.05
        yaw += 0.01
        step = fsm.cycle(t, (0.05, 0.0, yaw), (0.05, 0.0, yaw), (0, 0))
    (level, text), *_ = step.log
    assert level == "warn" and "oscillating over and over at (0.05, 0.00, 0." in text, text
    assert "(41 control cycles, turned 0.40 rad and drove 0.00 m meanwhile)" in text, text


def test_oscillation_runs_a_full_rotation_and_progress_resets_the_recovery_list():
    fsm, _ = make(oscillation_timeout=2.0, oscillation_distance=0.2)
    fsm.accept(GOAL, "h1", 0.0)
    fsm.plan_now(POSE, 0.0)
    t = 0.0
    while fsm.state != CLEARING:  # commands valid, but the robot never gets 0.2 m away
        t += 0.05
        fsm.cycle(t, (0.05, 0.0, 0.0), (0.05, 0.0, 0.0), (0, 0))
    assert 2.0 < t < 2.2
    fsm.cycle(t, POSE, POSE, (0, 0))  # conservative reset: done at once
    assert fsm.state == PLANNING and fsm.recovery_index == 1
    fsm.plan_now(POSE, t)
    while fsm.state != CLEARING:
        t += 0.05
        fsm.cycle(t, POSE, POSE, (0, 0))
    yaw, turned = 0.0, []
    while fsm.state == CLEARING:  # rotate_recovery: one full turn, then planning again
        step = fsm.cycle(t, POSE, (0.0, 0.0, yaw), (0, 0))
        turned.append(step.cmd[1])
        yaw = (yaw + step.cmd[1] * 0.05 + math.pi) % (2 * math.pi) - math.pi
        t += 0.05
    assert sum(w * 0.05 for w in turned) > 2 * math.pi - 0.2
    fsm.plan_now(POSE, t)
    fsm.cycle(t, POSE, POSE, (0, 0))
    fsm.cycle(t + 0.05, (0.5, 0.0, 0.0), (0.5, 0.0, 0.0), (0, 0))  # real progress
    assert fsm.recovery_index == 0


def test_final_turn_is_progress_only_while_the_heading_error_shrinks():
    fsm, _ = make(oscillation_timeout=2.0, oscillation_distance=0.2)
    goal = (0.0, 0.0, 3.0)
    fsm.accept(goal, "h1", 0.0)
    fsm.plan_now(POSE, 0.0)
    fsm.controller.answer = Command(0.0, 0.5, turning=True)
    t, yaw = 0.0, 0.0
    while yaw < 2.9:  # turning towards the goal's heading at 0.5 rad/s: 6 s, far past the timeout
        t += 0.05
        yaw += 0.5 * 0.05
        fsm.cycle(t, (0.0, 0.0, yaw), (0.0, 0.0, yaw), (0.0, 0.5))
        assert fsm.state == CONTROLLING, t
    stalled = t
    while fsm.state == CONTROLLING:  # the turn stalls (or hunts): the oscillation check fires again
        t += 0.05
        fsm.cycle(t, (0.0, 0.0, yaw), (0.0, 0.0, yaw), (0.0, 0.0))
    assert fsm.state == CLEARING and 1.8 < t - stalled < 2.2  # from the last 0.05 rad of progress


def test_a_turn_after_a_drive_back_in_is_progress_again():
    """The controller re-approaches after a final turn (the estimate left the xy tolerance): the next
    turn starts from a larger heading error than the first one ended with, and must count as progress
    from there, not from the first turn's best (else a 0.1 m re-approach, under the oscillation
    distance, ran into the oscillation check)."""
    fsm, _ = make(oscillation_timeout=2.0, oscillation_distance=0.2)
    fsm.accept((0.0, 0.0, 0.0), "h1", 0.0)
    fsm.plan_now(POSE, 0.0)
    t, yaw = 0.0, 1.5
    fsm.controller.answer = Command(0.0, -0.5, turning=True)
    while yaw > 0.05:  # the first final turn, down to the goal's heading
        t, yaw = t + 0.05, yaw - 0.025
        fsm.cycle(t, (0.0, 0.0, yaw), (0.0, 0.0, yaw), (0.0, -0.5))
    fsm.controller.answer = Command(0.05, 0.5)  # the drive back in turns away and creeps 0.05 m
    for _ in range(20):
        t, yaw = t + 0.05, yaw + 0.05
        fsm.cycle(t, (0.0, 0.0, yaw), (0.0, 0.0, yaw), (0.05, 0.5))
    fsm.controller.answer = Command(0.0, -0.5, turning=True)
    while yaw > 0.05:  # the second final turn: 2 s, as long as the oscillation timeout
        t, yaw = t + 0.05, yaw - 0.025
        fsm.cycle(t, (0.0, 0.0, yaw), (0.0, 0.0, yaw), (0.0, -0.5))
        assert fsm.state == CONTROLLING, t


def test_the_state_machine_imports_no_ros_socket_or_thread():
    """The brain stays testable without a process: no node, rospy, socket or thread below it."""
    import ast
    import importlib.util

    path = importlib.util.find_spec("ninjemys.nav.move_base").origin
    tree = ast.parse(open(path, encoding="utf-8").read())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    banned = ("rospy", "ninjemys.node", "socket", "threading", "ninjemys.net", "_thread", "asyncio")
    assert not [n for n in names if n.startswith(banned)], names
