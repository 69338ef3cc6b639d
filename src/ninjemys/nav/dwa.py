"""The local planner: the Dynamic Window Approach with dwa_local_planner's parameters and scoring.

No ROS in here. Each control cycle samples ``vx_samples x vth_samples`` velocities inside the window
reachable within one cycle (``acc_lim_x``, ``acc_lim_theta``, ``1 / controller_frequency``), rolls each
out for ``sim_time`` as an arc, drops those that touch an inscribed, lethal or unknown cell, and scores
the rest as dwa_local_planner does (all distances in cells of the local costmap)::

    cost = path_distance_bias * 0.5 * res * (distance from the arc's end to the plan)
         + goal_distance_bias * 0.5 * res * (distance from the arc's end to the local goal)
         + occdist_scale * (highest cell cost along the arc)
         + the same two distance terms for a point ``forward_point_distance`` ahead (alignment),
           left out near the goal

Within ``xy_goal_tolerance`` of the goal the robot stops and turns in place to the goal's yaw
(``yaw_goal_tolerance``), like dwa's LatchedStopRotateController (``latch_xy_goal_tolerance``). In
a narrow spot the last centimetres may have no safe arc at all; within ``NEAR_GOAL`` tolerances of
the goal, standing, that also ends the approach with the turn in place (ours; dwa fails the cycle).
The latch holds while the robot turns, but when the turn ends with the pose estimate out of
``xy_goal_tolerance`` (amcl corrected ``map -> odom`` during the turn) the robot drives in again, to
half the tolerance, at most ``MAX_REAPPROACHES`` times and ``REAPPROACH_CYCLES`` cycles per goal (ours; ROS 1's latched controller reports success wherever
the estimate has gone, which in the office left the robot 0.21 m from its goal in truth).
With a :class:`~ninjemys.nav.safety.StopZone` (the safety monitor's parameters, ``stop_zone_from`` in
move_base) and the newest laser returns, the arcs the monitor would refuse are dropped as well, by the
monitor's own test on the monitor's own data (ours: in ROS 1 the planner's checks are move_base's only
brake). Without it the planner chose arcs past corners at the inscribed radius (0.16 m) that the
monitor, keeping 0.3-0.36 m, refused: it cut the linear speed cycle after cycle, the robot turned on
the spot, and move_base saw an oscillation and ran its recoveries.
Everything for one cycle is a handful of numpy operations over all samples at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ninjemys.nav.costmap import INSCRIBED, NO_INFORMATION, Costmap
from ninjemys.nav.safety import StopZone, blocked_arcs, judged_speed
from ninjemys.tf2.math import angle_diff

#: within this many xy_goal_tolerance of the goal, a standing robot with no safe arc ends the approach:
#: it turns in place to the goal's yaw
NEAR_GOAL = 1.5

#: how many times per goal the final turn may end in a drive back in, because the pose estimate moved
#: out of xy_goal_tolerance while the robot turned in place (ours; see DWAPlanner.compute)
MAX_REAPPROACHES = 2

#: the longest wait (s of odometry time) of a robot stopped inside the tolerances for a pose newer than
#: its standstill; then the goal is judged on the pose there is (a transform published seldom, or no
#: more: ROS 1's rule), rather than never
MAX_FRESH_WAIT = 3.0

#: control cycles (5 s at controller_frequency 20) that the drives back in of one goal may take in all;
#: then the approach ends with the turn where the robot stands, as the latched approach did
REAPPROACH_CYCLES = 100


@dataclass
class DWAParams:
    """dwa_local_planner's main parameters (``~DWAPlannerROS/<name>`` in ROS 1)."""

    max_vel_x: float = 0.3
    min_vel_x: float = 0.0
    max_vel_trans: float = 0.3
    min_vel_trans: float = 0.05
    max_vel_theta: float = 1.5
    min_vel_theta: float = 0.3
    acc_lim_x: float = 1.5
    acc_lim_theta: float = 4.0
    sim_time: float = 1.5
    sim_granularity: float = 0.05
    vx_samples: int = 8
    vth_samples: int = 21
    controller_frequency: float = 20.0
    path_distance_bias: float = 32.0
    goal_distance_bias: float = 20.0
    occdist_scale: float = 0.02
    forward_point_distance: float = 0.2
    xy_goal_tolerance: float = 0.1
    yaw_goal_tolerance: float = 0.15
    latch_xy_goal_tolerance: bool = True
    #: below this angular speed (rad/s, from odometry) the robot counts as stopped: the goal is judged
    #: then (base_local_planner's ``rot_stopped_vel``, same default)
    rot_stopped_vel: float = 0.01
    #: and below this speed (m/s; base_local_planner's ``trans_stopped_vel``, same default)
    trans_stopped_vel: float = 0.01
    prune_plan: bool = True

    def update(self, values: dict[str, object]) -> list[str]:
        """Set the fields named in ``values`` (ints and floats coerced); return the unknown names."""
        known = {f.name: f.type for f in fields(self)}
        unknown = []
        for key, value in values.items():
            if key not in known:
                unknown.append(key)
                continue
            current = getattr(self, key)
            if isinstance(current, bool):
                setattr(self, key, bool(value))
            elif isinstance(current, int):
                setattr(self, key, int(value))  # type: ignore[call-overload]
            else:
                setattr(self, key, float(value))  # type: ignore[arg-type]
        return unknown


@dataclass
class Command:
    """One cycle's answer: a velocity, and whether the goal is reached or no arc was safe.
    ``turning``: the final turn in place to the goal's yaw (the goal's position is reached)."""

    v: float
    w: float
    reached: bool = False
    valid: bool = True
    turning: bool = False


class DWAPlanner:
    """Holds the plan and the latched goal state; :meth:`compute` runs one cycle."""

    def __init__(self, params: DWAParams | None = None, stop_zone: StopZone | None = None) -> None:
        self.params = params or DWAParams()
        #: the safety monitor's stop zone: arcs it would refuse are no candidates (None: no such check)
        self.stop_zone = stop_zone
        #: the newest laser returns in the robot's frame (n, 2), the monitor's data (set per scan by the
        #: node; None: none yet, and the monitor, with none either, refuses nothing)
        self.stop_points: np.ndarray | None = None
        self.plan = np.zeros((0, 3))
        self.xy_latched = False
        self.reapproaches = 0  # drives back in after the final turn found the estimate out of tolerance
        self.reapproach_cycles = 0  # control cycles spent driving back in, for this goal
        #: the odometry stamp from which the robot has been seen stopped (None: moving, or not known)
        self.stopped_since: float | None = None
        #: cycles this goal waited, stopped inside the tolerances, for a pose newer than the stop
        self.fresh_waits = 0

    def set_plan(self, plan: np.ndarray) -> None:
        """A new global plan (n, 3) in the local costmap's frame; resets the goal latch."""
        self.plan = np.asarray(plan, dtype=float).reshape(-1, 3)
        self.xy_latched = False

    def new_goal(self) -> None:
        """A new goal (not a new plan for the same goal): forget the latch and the re-approaches."""
        self.xy_latched = False
        self.reapproaches = 0
        self.reapproach_cycles = 0
        self.stopped_since = None
        self.fresh_waits = 0

    def stopped(self, vel: tuple[float, float]) -> bool:
        """base_local_planner's ``stopped()``: odometry says the robot stands (``trans_stopped_vel``,
        ``rot_stopped_vel``)."""
        return abs(vel[0]) <= self.params.trans_stopped_vel and abs(vel[1]) <= self.params.rot_stopped_vel

    def _track_stop(self, vel: tuple[float, float], stamps: tuple[float, float] | None) -> None:
        """Remember the odometry stamp at which the current standstill was first seen."""
        if stamps is None or not self.stopped(vel):
            self.stopped_since = None
        elif self.stopped_since is None or stamps[1] < self.stopped_since:  # (time went back: a reset)
            self.stopped_since = stamps[1]

    def _drifted(self, x: float, y: float) -> bool:
        """At the end of the final turn, the robot's estimate is out of ``xy_goal_tolerance`` again
        and there is a re-approach left (``MAX_REAPPROACHES`` per goal, so a standing robot whose
        estimate jitters at the edge cannot hunt for ever)."""
        return not self.goal_reached_xy(x, y) and self.reapproaches < MAX_REAPPROACHES

    def goal_reached_xy(self, x: float, y: float, scale: float = 1.0) -> bool:
        """Within ``scale`` x ``xy_goal_tolerance`` of the plan's end."""
        if len(self.plan) == 0:
            return False
        gx, gy, _ = self.plan[-1]
        return math.hypot(gx - x, gy - y) <= scale * self.params.xy_goal_tolerance

    def _prune(self, x: float, y: float) -> None:
        if not self.params.prune_plan or len(self.plan) < 2:
            return
        d = np.hypot(self.plan[:, 0] - x, self.plan[:, 1] - y)
        window = min(len(d), 60)  # look for the closest point near the start only (no shortcuts)
        i = int(np.argmin(d[:window]))
        if i > 0:
            self.plan = self.plan[i:]

    def compute(
        self,
        pose: tuple[float, float, float],
        vel: tuple[float, float],
        costmap: Costmap,
        period: float | None = None,
        stamps: tuple[float, float] | None = None,
    ) -> Command:
        """The velocity for this cycle from the robot's pose and velocity (costmap frame).

        ``period`` is how long the command will actually stand (the measured cycle period, when the
        controller runs late); the turn to the goal's yaw never goes further than it can stop within
        that time, so a late cycle does not swing the robot past ``yaw_goal_tolerance``.

        ``stamps`` (ROS times of the pose and of the odometry that gave ``vel``) make the goal check
        wait for a pose no older than the moment odometry first showed the robot stopped (see
        :meth:`_rotate_to`); None judges on the pose as it is, as ROS 1 does."""
        p = self.params
        x, y, th = pose
        self._track_stop(vel, stamps)
        if len(self.plan) == 0:
            return Command(0.0, 0.0, valid=False)
        self._prune(x, y)
        gx, gy, gyaw = self.plan[-1]
        # a drive back in aims for half the tolerance: the next turn's corrections have room to spare
        inner = 0.5 if self.reapproaches else 1.0
        if self.goal_reached_xy(x, y, inner) or (self.xy_latched and p.latch_xy_goal_tolerance):
            self.xy_latched = True
            cmd = self._rotate_to(th, gyaw, vel, period, stamps)
            if not (cmd.reached and self._drifted(x, y)):
                return cmd
            # the turn is done but the pose estimate has left the xy tolerance while the robot stood
            # and turned (amcl corrects map -> odom on every 0.1 rad of turn): drive in again
            self.reapproaches += 1
            self.xy_latched = False
        if self.reapproaches and not self.xy_latched:
            self.reapproach_cycles += 1
            if self.reapproach_cycles > REAPPROACH_CYCLES:
                # a drive back in that cannot get there (a narrow spot, costs near the goal) ends as the
                # latched approach would have ended: with the turn, never with the recoveries
                self.xy_latched = True
                return self._rotate_to(th, gyaw, vel, period, stamps)
        cmd = self._sample(x, y, th, vel, costmap)
        stopped = abs(vel[0]) <= p.acc_lim_x / p.controller_frequency  # turning in place was sampled
        if not cmd.valid and stopped and math.hypot(gx - x, gy - y) <= NEAR_GOAL * p.xy_goal_tolerance:
            # the last centimetres of a narrow spot: standing next to the goal, even the turns in
            # place touch an inscribed cell (the robot's own cell reads inscribed), but the goal is
            # practically reached and a turn in place sweeps nothing new for a round robot. Without
            # this the robot stood there until controller_patience ran out, and the recoveries and
            # the abort left it at any heading. (A robot still moving first stops: no arc is safe.)
            self.xy_latched = True
            return self._rotate_to(th, gyaw, vel, period, stamps)
        return cmd

    def _rotate_to(
        self,
        th: float,
        goal_yaw: float,
        vel: tuple[float, float],
        period: float | None = None,
        stamps: tuple[float, float] | None = None,
    ) -> Command:
        p = self.params
        dt = 1.0 / p.controller_frequency
        if abs(vel[0]) > 0.02:  # stop first, then turn
            v = math.copysign(max(0.0, abs(vel[0]) - p.acc_lim_x * dt), vel[0])
            return Command(v, 0.0, turning=True)
        err = angle_diff(goal_yaw, th)
        if abs(err) <= p.yaw_goal_tolerance:
            if not self.stopped(vel):
                # still turning: stop, and judge the heading once stopped (ROS 1's isGoalReached asks
                # base_local_planner::stopped too). Ended at once, a late pose or a late stop under load
                # carried the turn on past the tolerance after the goal had been reported reached.
                return Command(0.0, 0.0, turning=True)
            if (
                stamps is not None
                and self.stopped_since is not None
                and stamps[0] < self.stopped_since
                and stamps[1] - self.stopped_since <= MAX_FRESH_WAIT
            ):
                # odometry says stopped, but the pose (TF) is from before that: under load /tf lags
                # /odom, and a pose from the middle of the turn (or of its braking) read "in tolerance"
                # while the robot came to rest 0.3 rad further on. Wait for a pose of the standstill;
                # the local costmap's transform_tolerance bounds the wait for odom -> base_link (an
                # older pose is refused), MAX_FRESH_WAIT the wait for the rest of the chain.
                self.fresh_waits += 1
                return Command(0.0, 0.0, turning=True)
            return Command(0.0, 0.0, reached=True)
        # the fastest turn that can still stop at the goal yaw within the acceleration limits, and no
        # faster than 2 rad/s per radian left: a late or missed cycle near the goal overshoots little
        w_stop = math.sqrt(2 * p.acc_lim_theta * abs(err))
        w = min(p.max_vel_theta, w_stop, 2.0 * abs(err), abs(vel[1]) + p.acc_lim_theta * dt)
        w = max(w, p.min_vel_theta)
        # a command stands until the next cycle: turning for the whole (measured) period must end inside
        # the tolerance window, else a late cycle swings past it and the robot hunts back and forth
        hold = max(dt, period or 0.0)
        w = min(w, (abs(err) + 0.5 * p.yaw_goal_tolerance) / hold)
        return Command(0.0, math.copysign(w, err), turning=True)

    def _sample(self, x: float, y: float, th: float, vel: tuple[float, float], cm: Costmap) -> Command:
        p = self.params
        dt = 1.0 / p.controller_frequency
        v0, w0 = vel
        v_lo = max(p.min_vel_x, v0 - p.acc_lim_x * dt)
        v_hi = min(p.max_vel_x, v0 + p.acc_lim_x * dt)
        w_lo = max(-p.max_vel_theta, w0 - p.acc_lim_theta * dt)
        w_hi = min(p.max_vel_theta, w0 + p.acc_lim_theta * dt)
        vs = np.linspace(v_lo, max(v_lo, v_hi), max(1, p.vx_samples))
        ws = np.linspace(w_lo, max(w_lo, w_hi), max(1, p.vth_samples))
        if w_lo < 0 < w_hi:
            ws = np.append(ws, 0.0)
        V, Wv = (a.ravel() for a in np.meshgrid(vs, ws))
        slow = (np.abs(V) < p.min_vel_trans) & (np.abs(Wv) < p.min_vel_theta)
        V, Wv = V[~slow], Wv[~slow]
        if v_lo <= 0.0:  # turning in place at the slowest allowed rate is always a candidate
            V = np.append(V, [0.0, 0.0])
            Wv = np.append(Wv, [p.min_vel_theta, -p.min_vel_theta])
        if V.size == 0:
            return Command(0.0, 0.0, valid=False)
        # roll out arcs: steps of at most sim_granularity along the fastest sample
        n = max(2, int(math.ceil(max(p.max_vel_x, 0.05) * p.sim_time / p.sim_granularity)))
        t = np.linspace(p.sim_time / n, p.sim_time, n)
        ang = th + Wv[:, None] * t[None, :]
        straight = np.abs(Wv) < 1e-6
        wsafe = np.where(straight, 1.0, Wv)[:, None]
        px = np.where(
            straight[:, None],
            x + V[:, None] * t * math.cos(th),
            x + V[:, None] / wsafe * (np.sin(ang) - math.sin(th)),
        )
        py = np.where(
            straight[:, None],
            y + V[:, None] * t * math.sin(th),
            y - V[:, None] / wsafe * (np.cos(ang) - math.cos(th)),
        )
        res = cm.resolution
        cx = np.floor((px - cm.origin_x) / res).astype(np.intp)
        cy = np.floor((py - cm.origin_y) / res).astype(np.intp)
        inside = (cx >= 0) & (cx < cm.size_x) & (cy >= 0) & (cy < cm.size_y)
        # one gather for all points (indices clipped), then off-map points read as unknown
        cost = np.where(
            inside, cm.costs[np.clip(cy, 0, cm.size_y - 1), np.clip(cx, 0, cm.size_x - 1)], NO_INFORMATION
        )
        occ = cost.max(axis=1)
        valid = occ < INSCRIBED
        if self.stop_zone is not None:
            valid &= ~self._refused(v0, V, Wv, valid)
        if not valid.any():
            return Command(0.0, 0.0, valid=False)
        # distance maps over the local costmap: to the plan's cells and to the local goal
        local = self._local_plan(cm)
        if len(local) == 0:
            return Command(0.0, 0.0, valid=False)
        # distances measured along the plan: to the nearest plan point, and from there to the local
        # goal along the plan (a wall between an arc's end and the local goal cannot make a shortcut)
        seg = np.hypot(np.diff(local[:, 0]), np.diff(local[:, 1]))
        remaining = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]])

        ex, ey, eth = px[:, -1], py[:, -1], ang[:, -1]
        gx, gy = self.plan[-1, 0], self.plan[-1, 1]
        qx, qy = ex, ey
        if math.hypot(gx - x, gy - y) > p.forward_point_distance:  # the arcs' ends and points ahead, at once
            qx = np.concatenate([ex, ex + p.forward_point_distance * np.cos(eth)])
            qy = np.concatenate([ey, ey + p.forward_point_distance * np.sin(eth)])
        d2 = np.square(qx[:, None] - local[None, :, 0]) + np.square(qy[:, None] - local[None, :, 1])
        j = np.argmin(d2, axis=1)
        near = np.sqrt(d2[np.arange(len(qx)), j])
        # each point's score: its distance to the plan, and to the local goal along the plan
        score = p.path_distance_bias * 0.5 * near + p.goal_distance_bias * 0.5 * (remaining[j] + near)
        total = score[: len(ex)] + p.occdist_scale * occ
        if len(qx) > len(ex):
            total += score[len(ex) :]
        total = np.where(valid, total, np.inf)
        best = int(np.argmin(total))
        return Command(float(V[best]), float(Wv[best]))

    def _refused(self, v0: float, V: np.ndarray, W: np.ndarray, valid: np.ndarray) -> np.ndarray:
        """Which samples the safety monitor would refuse: its stop-zone test, at the speed it judges
        each command at, on the laser returns it judges them on (``stop_points``; none yet: none)."""
        out = np.zeros(V.shape, dtype=bool)
        check = valid & (V != 0.0)
        if self.stop_zone is None or self.stop_points is None or not check.any():
            return out
        out[check] = blocked_arcs(self.stop_points, judged_speed(V[check], v0), W[check], self.stop_zone)
        return out

    def _local_plan(self, cm: Costmap) -> np.ndarray:
        """The plan's points (m, 2) inside the local costmap, up to where it first leaves it."""
        res = cm.resolution
        cx = np.floor((self.plan[:, 0] - cm.origin_x) / res).astype(np.int64)
        cy = np.floor((self.plan[:, 1] - cm.origin_y) / res).astype(np.int64)
        inside = (cx >= 0) & (cx < cm.size_x) & (cy >= 0) & (cy < cm.size_y)
        if not inside.any():
            return np.zeros((0, 2))
        first = int(np.argmax(inside))
        out = np.nonzero(~inside[first:])[0]
        last = first + (int(out[0]) if out.size else len(inside) - first)
        return self.plan[first:last, :2]
