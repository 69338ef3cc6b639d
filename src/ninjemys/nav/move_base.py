"""move_base's brain with no ROS inside: goals, planning patience, control, progress, recoveries.

ROS 1's move_base is one node whose ``executeCycle`` walks three states (``PLANNING``,
``CONTROLLING``, ``CLEARING``); nav2 later split the same logic into servers behind small interfaces.
:class:`MoveBaseFsm` keeps ROS 1's single state machine and takes nav2's seams, so every rule here
is testable with a fake clock and fake poses, without a node, a socket or a thread:

- :class:`Planner` (the global planner: start and goal -> a path, or :class:`PlanError`),
- :class:`Controller` (the local planner: pose and velocity -> a command, with the final approach),
- :class:`ProgressChecker` (move_base's oscillation check: ``oscillation_distance`` within
  ``oscillation_timeout``),
- :class:`Recovery` (one behaviour of the recovery list; the default order is move_base's:
  conservative reset, rotate, aggressive reset, rotate).

The caller (``nav/move_base_node.py``) owns the threads and the I/O and holds one lock around every
call: it hands in goals (:meth:`MoveBaseFsm.accept`, :meth:`MoveBaseFsm.cancel`), runs
:meth:`MoveBaseFsm.cycle` at ``controller_frequency``, and runs the planner wherever it likes between
:meth:`MoveBaseFsm.take_plan_job` and :meth:`MoveBaseFsm.plan_done` (move_base's planner thread).
Each call returns a :class:`Step`: the velocity to send, and the goal that ended, with actionlib's
terminal status (:mod:`ninjemys.actionlib.states`) and move_base's text.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ninjemys.actionlib import states
from ninjemys.nav.dwa import Command
from ninjemys.nav.planner import PlanError
from ninjemys.tf2.math import Pose2D, angle_diff, se2_compose, se2_inverse

# move_base's MoveBaseState names, plus IDLE (no goal)
IDLE = "IDLE"
PLANNING = "PLANNING"
CONTROLLING = "CONTROLLING"
CLEARING = "CLEARING"

#: the statuses a goal that is not the current one can still be canceled from (actionlib's rule)
CANCELABLE = frozenset({states.PENDING, states.ACTIVE, states.PREEMPTING, states.RECALLING})

PREEMPTED_TEXT = "This goal was canceled because another goal was received by the simple action server"
#: how often a plan is asked for while one is being made or keeps failing (seconds)
PLAN_RETRY = 0.5
#: how much the final turn must shrink the heading error (rad) to count as progress
TURN_PROGRESS = 0.05
#: the longest gap (s) between a pose and a newer odometry message that the pose is carried over
#: (larger gaps are a clock reset or a stalled publisher, not transport lag: the pose is used as it is)
MAX_EXTRAPOLATION = 1.0


@dataclass
class MoveBaseParams:
    """move_base's own parameters (``~<name>`` in ROS 1), with ROS 1's defaults."""

    controller_frequency: float = 20.0
    planner_frequency: float = 0.0
    controller_patience: float = 15.0
    planner_patience: float = 5.0
    oscillation_timeout: float = 0.0
    oscillation_distance: float = 0.5
    recovery_behavior_enabled: bool = True
    clearing_rotation_allowed: bool = True
    conservative_reset_dist: float = 3.0


class Planner(Protocol):
    """The global planner seam (nav2's GlobalPlanner): a path (n, 3) of (x, y, yaw) in the global frame."""

    def make_plan(self, start: Pose2D, goal: Pose2D) -> np.ndarray:
        """The path from ``start`` to ``goal``; raises :class:`PlanError` when there is none."""
        ...


class Controller(Protocol):
    """The local planner seam (nav2's Controller): follows a plan, then turns to the goal's yaw."""

    def new_goal(self) -> None:
        """Forget the goal latch (a new goal, not a new plan for the same goal)."""
        ...

    def set_plan(self, plan: np.ndarray) -> None:
        """The plan (n, 3) in the controller's frame; keeps the goal latch of the current goal."""
        ...

    def compute(
        self,
        pose: Pose2D,
        velocity: tuple[float, float],
        period: float | None,
        stamps: tuple[float, float] | None = None,
    ) -> Command:
        """One cycle's command from the pose (controller's frame) and velocity (v, w). ``period`` is
        the longest recent cycle: how long the command may stand before the next one. ``stamps``:
        the ROS times of the pose and of the odometry (None: unknown); the goal is reached only on a
        pose no older than the odometry that showed the robot stopped."""
        ...

    def remaining(self) -> int:
        """How many points of the plan are left after the controller pruned what it passed."""
        ...


class ProgressChecker(Protocol):
    """nav2's ProgressChecker: has the robot made progress lately?"""

    def reset(self, pose: Pose2D | None, now: float) -> None:
        """Start counting afresh from ``pose`` (None: from the next pose seen) at ``now``."""
        ...

    def moved(self, pose: Pose2D, now: float) -> bool:
        """True when ``pose`` is real progress (a new reference; move_base then starts its recovery
        list over)."""
        ...

    def check(self, pose: Pose2D, now: float) -> bool:
        """False when the robot has been stuck too long (move_base then runs a recovery)."""
        ...

    def describe(self) -> str:
        """What the robot did since the last progress, for the log line of a recovery."""
        ...


class Recovery(Protocol):
    """One recovery behaviour: started once, then stepped every cycle until it says it is done."""

    name: str

    def start(self, now: float, gpose: Pose2D, lpose: Pose2D) -> None: ...

    def step(self, now: float, gpose: Pose2D, lpose: Pose2D) -> tuple[bool, float]:
        """(done, angular velocity to send meanwhile)."""
        ...


@dataclass
class Outcome:
    """A goal that ended: the caller's ``token`` for it (an action goal handle, or None for a
    ``move_base_simple`` goal), its actionlib status and move_base's text."""

    token: Any
    status: int
    text: str
    goal: Pose2D | None = None
    pose: Pose2D | None = None  # the robot's last pose in the global frame (None: not seen yet)

    @property
    def name(self) -> str:
        return states.STATUS_NAMES[self.status]


@dataclass
class Step:
    """What one call asks of the node. ``cmd``: the velocity to publish (None: publish nothing);
    ``ended``: goals that ended, in order; ``plan``: a new global plan to publish; ``plan_wanted``:
    wake the planner; ``log``: (level, text) lines for the node's log."""

    cmd: tuple[float, float] | None = None
    ended: list[Outcome] = field(default_factory=list)
    plan: np.ndarray | None = None
    plan_wanted: bool = False
    feedback: Pose2D | None = None
    log: list[tuple[str, str]] = field(default_factory=list)


class OscillationChecker:
    """move_base's oscillation check: the robot must move ``distance`` within ``timeout`` seconds
    (0 switches the check off)."""

    def __init__(self, params: MoveBaseParams) -> None:
        self.params = params
        self.pose: Pose2D | None = None
        self.since = 0.0
        # since the reference: control cycles checked, and the motion seen meanwhile
        self.cycles, self.turned, self.driven = 0, 0.0, 0.0
        self.last: Pose2D | None = None

    def reset(self, pose: Pose2D | None, now: float) -> None:
        self.pose, self.since = pose, now
        self.cycles, self.turned, self.driven = 0, 0.0, 0.0
        self.last = pose

    def moved(self, pose: Pose2D, now: float) -> bool:
        """True (and a new reference) when the robot got ``oscillation_distance`` away."""
        if self.pose is None:
            self.reset(pose, now)
            return False
        if math.hypot(pose[0] - self.pose[0], pose[1] - self.pose[1]) >= self.params.oscillation_distance:
            self.reset(pose, now)
            return True
        return False

    def check(self, pose: Pose2D, now: float) -> bool:
        if self.params.oscillation_timeout <= 0:
            return True
        if not self.moved(pose, now):
            self.cycles += 1
            if self.last is not None:
                self.turned += abs(angle_diff(pose[2], self.last[2]))
                self.driven += math.hypot(pose[0] - self.last[0], pose[1] - self.last[1])
            self.last = pose
        return now - self.since <= self.params.oscillation_timeout

    def describe(self) -> str:
        return (
            f"{self.cycles} control cycles, turned {self.turned:.2f} rad and drove {self.driven:.2f} m "
            "meanwhile"
        )


class ClearCostmaps:
    """clear_costmap_recovery: forget obstacle marks outside a ``size`` x ``size`` square around the
    robot in both costmaps (``size`` 0: everywhere). ``clear(gpose, lpose, size)`` does it."""

    def __init__(self, name: str, clear: Callable[[Pose2D, Pose2D, float], None], size: Callable[[], float]):
        self.name = name
        self._clear = clear
        self._size = size

    def start(self, now: float, gpose: Pose2D, lpose: Pose2D) -> None:
        self._clear(gpose, lpose, self._size())

    def step(self, now: float, gpose: Pose2D, lpose: Pose2D) -> tuple[bool, float]:
        return True, 0.0


class RotateRecovery:
    """rotate_recovery: one full turn in place (so the sensors see all around), or ``timeout``
    seconds; skipped when ``allowed()`` is false (move_base's ``clearing_rotation_allowed``)."""

    name = "rotate_recovery"

    def __init__(self, speed: Callable[[], float], allowed: Callable[[], bool], timeout: float = 30.0):
        self._speed = speed
        self._allowed = allowed
        self.timeout = timeout
        self.started = 0.0
        self.turned = 0.0
        self.last_yaw = 0.0

    def start(self, now: float, gpose: Pose2D, lpose: Pose2D) -> None:
        self.started, self.turned, self.last_yaw = now, 0.0, lpose[2]

    def step(self, now: float, gpose: Pose2D, lpose: Pose2D) -> tuple[bool, float]:
        if not self._allowed():
            return True, 0.0
        self.turned += abs(angle_diff(lpose[2], self.last_yaw))
        self.last_yaw = lpose[2]
        if self.turned < 2 * math.pi - 0.1 and now - self.started < self.timeout:
            return False, min(1.0, self._speed())
        return True, 0.0


class MoveBaseFsm:
    """ROS 1 move_base's ``executeCycle`` and goal handling over the four seams (see the module)."""

    def __init__(
        self,
        params: MoveBaseParams,
        planner: Planner,
        controller: Controller,
        recoveries: Sequence[Recovery],
        progress: ProgressChecker | None = None,
    ) -> None:
        self.params = params
        self.planner = planner
        self.controller = controller
        self.recoveries = list(recoveries)
        self.progress: ProgressChecker = progress or OscillationChecker(params)
        self.state = IDLE
        self.goal: Pose2D | None = None  # in the global frame
        self.token: Any = None
        self.seq = 0  # bumped by every goal: a plan made for an older goal is dropped
        self.plan: np.ndarray | None = None
        self.last_valid = 0.0  # move_base's last_valid_control_
        self.last_plan = 0.0  # when the last plan was made (or failed)
        self.planning_since = 0.0  # when the current run of planning began (planner_patience)
        self.plan_pending = False
        self.planner_busy = False
        self.last_request = -math.inf
        self.recovery_index = 0
        self.turn_best = math.inf  # the smallest heading error of the final turn so far
        self.replan_warned = -math.inf
        self.pose: Pose2D | None = None  # the last global pose a cycle saw
        self.started_recovery = False
        self.last_cycle: float | None = None
        self.periods: deque[float] = deque(maxlen=20)  # measured control periods

    # -- goals ------------------------------------------------------------------------------------------

    def accept(self, goal: Pose2D, token: Any, now: float) -> Step:
        """A new goal (already validated); the current one, if any, is preempted as SimpleActionServer
        does."""
        step = Step()
        if self.state != IDLE:
            step.ended.append(Outcome(self.token, states.PREEMPTED, PREEMPTED_TEXT, self.goal, self.pose))
        self.goal, self.token = goal, token
        self.seq += 1
        self.controller.new_goal()
        self.plan = None
        self.state = PLANNING
        self.plan_pending = True
        self.planning_since = self.last_valid = now
        self.last_request = -math.inf
        self.recovery_index = 0
        self.turn_best = math.inf
        self.progress.reset(None, now)
        step.plan_wanted = True
        return step

    def cancel(self, token: Any) -> Step:
        """A cancel request for the goal ``token``: the current goal stops and ends PREEMPTED."""
        step = Step()
        if self.state != IDLE and token is self.token:
            step.cmd = (0.0, 0.0)
            step.ended.append(Outcome(self.token, states.PREEMPTED, "", self.goal, self.pose))
            self._idle()
        return step

    def is_current(self, token: Any) -> bool:
        return self.state != IDLE and token is self.token

    def _idle(self) -> None:
        self.state = IDLE
        self.goal = self.token = self.plan = None
        self.seq += 1  # a plan being made now is for no goal

    def _finish(self, step: Step, status: int, text: str) -> Step:
        step.cmd = (0.0, 0.0)
        step.ended.append(Outcome(self.token, status, text, self.goal, self.pose))
        self._idle()
        return step

    # -- planning ---------------------------------------------------------------------------------------

    def take_plan_job(self, now: float) -> tuple[Pose2D, int] | None:
        """(goal, seq) for the planner when a plan is wanted, else None; marks the planner busy."""
        if self.goal is None or self.state not in (PLANNING, CONTROLLING):
            return None
        self.planner_busy = True
        self.last_request = now
        return self.goal, self.seq

    def plan_done(self, seq: int, now: float, plan: np.ndarray | None, error: str = "") -> Step:
        """The planner's answer for goal ``seq``: a plan (n, 3), or None with the reason."""
        step = Step()
        self.planner_busy = False
        if seq != self.seq or self.goal is None:
            return step  # made for a goal that is gone
        self.last_plan = now
        if plan is None:
            if self.state == CONTROLLING:
                if now - self.replan_warned >= 5.0:  # at most every 5 s, as a throttled ROS warning
                    self.replan_warned = now
                    step.log.append(("warn", f"replanning failed ({error}); keeping the current plan"))
            elif self.state == PLANNING and now - self.planning_since > self.params.planner_patience:
                self._start_recovery(
                    step,
                    now,
                    f"Failed to find a valid plan. Even after executing recovery behaviors. ({error})",
                )
            return step
        self.plan = plan
        self.plan_pending = False
        step.plan = plan
        if self.state == PLANNING:
            # controller_patience keeps counting from the last valid command (ROS 1's last_valid_control_):
            # a new plan the controller cannot follow either must not restart it, or the robot stands
            # replanning forever and no recovery ever runs
            self.state = CONTROLLING
        return step

    def plan_now(self, start: Pose2D, now: float) -> Step:
        """Run the planner seam in the caller's thread (tests, and callers with no planner thread)."""
        job = self.take_plan_job(now)
        if job is None:
            return Step()
        goal, seq = job
        try:
            return self.plan_done(seq, now, self.planner.make_plan(start, goal))
        except PlanError as exc:
            return self.plan_done(seq, now, None, str(exc))

    def _want_plan(self, step: Step, now: float) -> None:
        if not self.planner_busy and now - self.last_request >= PLAN_RETRY:
            self.last_request = now
            step.plan_wanted = True

    # -- control ----------------------------------------------------------------------------------------

    def cycle(
        self,
        now: float,
        gpose: Pose2D,
        lpose: Pose2D,
        velocity: tuple[float, float],
        stamps: tuple[float, float] | None = None,
        global_stamp: float | None = None,
    ) -> Step:
        """One control cycle with the robot's pose in the global and in the controller's frame.
        ``stamps``: (ROS time of ``lpose``, ROS time of the odometry ``velocity`` came from), when
        known; under load /tf and /odom arrive out of step, and the goal check needs both.
        ``global_stamp``: the ROS time of the transform that carries ``lpose`` into the global frame
        (amcl's ``map -> odom``), when there is one: the goal is judged in the global frame, so
        neither may predate the standstill."""
        step = Step()
        if self.state == IDLE or self.goal is None:
            return step
        self.pose = gpose
        if self.last_cycle is not None and now > self.last_cycle:
            self.periods.append(now - self.last_cycle)
        self.last_cycle = now
        step.feedback = gpose
        p = self.params
        replan_due = p.planner_frequency > 0 and now - self.last_plan >= 1.0 / p.planner_frequency
        if self.state == PLANNING or (self.state == CONTROLLING and replan_due):
            self._want_plan(step, now)
        if self.state == PLANNING:
            step.cmd = (0.0, 0.0)  # standing still until there is a plan, as ROS 1's move_base
            return step
        if self.state == CLEARING:
            return self._recovery_step(step, now, gpose, lpose)
        if self.plan is None:
            return step
        return self._control(step, now, gpose, lpose, velocity, stamps, global_stamp)

    def _control(
        self,
        step: Step,
        now: float,
        gpose: Pose2D,
        lpose: Pose2D,
        velocity: tuple[float, float],
        stamps: tuple[float, float] | None,
        global_stamp: float | None,
    ) -> Step:
        plan = self.plan
        assert plan is not None
        if stamps is not None:
            # under load /tf reaches move_base later than /odom: steer from where odometry says the
            # robot is now, not from where TF last saw it (the goal check still waits for a real pose
            # of the standstill, see the controller)
            gpose = extrapolate(gpose, velocity, stamps[1] - stamps[0])
            lpose = extrapolate(lpose, velocity, stamps[1] - stamps[0])
            if global_stamp is not None and global_stamp < stamps[0]:
                # the goal is judged through map -> odom too: under load amcl's newest correction
                # reaches move_base late, and a heading judged with an older one is off by it
                stamps = (global_stamp, stamps[1])
        self.controller.set_plan(to_frame(plan, se2_compose(lpose, se2_inverse(gpose))))
        cmd = self.controller.compute(lpose, velocity, max(self.periods, default=None), stamps)
        self.plan = plan[len(plan) - self.controller.remaining() :]  # pruned as the controller did
        if cmd.reached:
            return self._finish(step, states.SUCCEEDED, "Goal reached")
        if cmd.valid:
            self.last_valid = now
            step.cmd = (cmd.v, cmd.w)
            if cmd.turning:
                # the final turn at the goal is progress although the robot stays put, as long as the
                # heading error keeps shrinking: counted as oscillation, a slow turn in a narrow spot
                # ran the recoveries (whose full turns end anywhere) and then aborted the goal at
                # whatever heading the robot had. A turn that stalls or hunts still times out.
                assert self.goal is not None
                err = abs(angle_diff(self.goal[2], gpose[2]))
                if err < self.turn_best - TURN_PROGRESS:
                    self.turn_best = err
                    self.progress.reset(gpose, now)
            else:
                self.turn_best = math.inf  # driving (again, after a turn the controller re-approached)
                if self.progress.moved(gpose, now):
                    self.recovery_index = 0  # real progress: the recovery list starts over, as in ROS 1
            if not self.progress.check(gpose, now):
                self._start_recovery(
                    step,
                    now,
                    "Aborting because the robot appears to be oscillating over and over",
                    self.progress.describe(),
                )
            return step
        return self._control_failed(step, now)

    def _control_failed(self, step: Step, now: float) -> Step:
        """No valid command this cycle: stand still; replan, and after ``controller_patience`` recover."""
        step.cmd = (0.0, 0.0)
        if now - self.last_valid > self.params.controller_patience:
            self._start_recovery(step, now, "Aborting because a valid control could not be found")
        elif now - self.last_plan > 1.0:
            # ROS 1 replans when the local planner fails
            if not self.plan_pending:
                self.planning_since = now
            self.state = PLANNING
            self.plan_pending = True
        return step

    def pose_too_old(self, now: float) -> Step:
        """A cycle whose robot pose is older than the costmap's ``transform_tolerance``. ROS 1's local
        planner then fails ("Could not get robot pose"): move_base stands still and treats it as a
        failed control (replan; recoveries after ``controller_patience``). Planning and recovering
        wait with the robot stopped."""
        step = Step()
        if self.state == IDLE or self.goal is None:
            return step
        step.cmd = (0.0, 0.0)
        if self.state == CONTROLLING and self.plan is not None:
            return self._control_failed(step, now)
        return step

    # -- recoveries -------------------------------------------------------------------------------------

    def _start_recovery(self, step: Step, now: float, failure: str, detail: str = "") -> None:
        if not self.params.recovery_behavior_enabled or self.recovery_index >= len(self.recoveries):
            self._finish(step, states.ABORTED, failure)
            return
        self.state = CLEARING
        self.started_recovery = False
        step.cmd = (0.0, 0.0)
        where = ""
        if self.pose is not None and self.goal is not None:
            x, y, yaw = self.pose
            away = math.hypot(self.goal[0] - x, self.goal[1] - y)
            where = f" at ({x:.2f}, {y:.2f}, {yaw:.2f}), {away:.2f} m from the goal"
        step.log.append(
            (
                "warn",
                f"{failure.split('.')[0]}{where}{f' ({detail})' if detail else ''}; running recovery "
                f"behavior {self.recoveries[self.recovery_index].name}",
            )
        )

    def _recovery_step(self, step: Step, now: float, gpose: Pose2D, lpose: Pose2D) -> Step:
        behaviour = self.recoveries[self.recovery_index]
        if not self.started_recovery:
            self.started_recovery = True
            behaviour.start(now, gpose, lpose)
        done, w = behaviour.step(now, gpose, lpose)
        step.cmd = (0.0, w if not done else 0.0)
        if not done:
            return step
        self.recovery_index += 1
        self.state = PLANNING
        self.plan_pending = True
        self.planning_since = self.last_valid = now
        self.progress.reset(None, now)
        self._want_plan(step, now)
        return step


def extrapolate(pose: Pose2D, velocity: tuple[float, float], dt: float) -> Pose2D:
    """``pose`` carried ``dt`` seconds forward along the arc of ``velocity`` (v, w) in its own frame;
    unchanged for ``dt`` <= 0 or > :data:`MAX_EXTRAPOLATION`. Moving the global and the local pose by
    the same body motion keeps the transform between their frames (the plan lands where it was)."""
    if not 0.0 < dt <= MAX_EXTRAPOLATION:
        return pose
    v, w = velocity
    turn = w * dt
    return se2_compose(pose, (v * dt * math.cos(turn / 2), v * dt * math.sin(turn / 2), turn))


def to_frame(plan: np.ndarray, tf: Pose2D) -> np.ndarray:
    """A plan (n, 3) moved by the planar transform ``tf`` (x, y, yaw)."""
    c, s = math.cos(tf[2]), math.sin(tf[2])
    return np.column_stack(
        [
            tf[0] + c * plan[:, 0] - s * plan[:, 1],
            tf[1] + s * plan[:, 0] + c * plan[:, 1],
            plan[:, 2] + tf[2],
        ]
    )
