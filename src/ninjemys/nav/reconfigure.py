"""The dynamic_reconfigure configurations move_base serves: ``DWAPlanner`` and ``MoveBase``.

ROS 1 generates these from dwa_local_planner's and move_base's ``.cfg`` files at build time; ours are
built in memory with the same generator, holding the parameters our planners use, with ROS 1's
names, levels (0) and ranges.
"""

from __future__ import annotations

import types
from functools import cache

from ninjemys.dynamic_reconfigure.generator import ParameterGenerator, bool_t, double_t, int_t, render_module
from ninjemys.nav.dwa import DWAParams


def _module(gen: ParameterGenerator, package: str, name: str) -> types.SimpleNamespace:
    gen.pkgname, gen.nodename, gen.name = package, name.lower(), name
    namespace: dict[str, object] = {}
    exec(
        compile(render_module(gen), f"<{package}/{name}Config>", "exec"), namespace
    )  # our generator's output
    return types.SimpleNamespace(**{k: v for k, v in namespace.items() if not k.startswith("__")})


@cache
def dwa_config_type() -> types.SimpleNamespace:
    """dwa_local_planner's DWAPlannerConfig (the parameters this DWA uses)."""
    d = DWAParams()
    gen = ParameterGenerator()
    ranges = {
        "max_vel_x": (0.0, 20.0),
        "min_vel_x": (-20.0, 20.0),
        "max_vel_trans": (0.0, 20.0),
        "min_vel_trans": (0.0, 20.0),
        "max_vel_theta": (0.0, 20.0),
        "min_vel_theta": (0.0, 20.0),
        "acc_lim_x": (0.0, 20.0),
        "acc_lim_theta": (0.0, 20.0),
        "sim_time": (0.0, 10.0),
        "sim_granularity": (0.0, 5.0),
        "path_distance_bias": (0.0, 100.0),
        "goal_distance_bias": (0.0, 100.0),
        "occdist_scale": (0.0, 100.0),
        "forward_point_distance": (-5.0, 5.0),
        "xy_goal_tolerance": (0.0, 10.0),
        "yaw_goal_tolerance": (0.0, 6.3),
    }
    for name, (lo, hi) in ranges.items():
        gen.add(name, double_t, 0, f"dwa_local_planner {name}", float(getattr(d, name)), lo, hi)
    gen.add(
        "vx_samples",
        int_t,
        0,
        "The number of samples to use when exploring the x velocity space",
        d.vx_samples,
        1,
        300,
    )
    gen.add(
        "vth_samples",
        int_t,
        0,
        "The number of samples to use when exploring the theta velocity space",
        d.vth_samples,
        1,
        300,
    )
    gen.add(
        "latch_xy_goal_tolerance",
        bool_t,
        0,
        "Whether to latch the goal position once reached",
        d.latch_xy_goal_tolerance,
    )
    gen.add(
        "prune_plan", bool_t, 0, "Start following closest point of global plan, not first point", d.prune_plan
    )
    return _module(gen, "dwa_local_planner", "DWAPlanner")


@cache
def move_base_config_type() -> types.SimpleNamespace:
    """move_base's MoveBaseConfig (its timing, patience and recovery settings)."""
    gen = ParameterGenerator()
    gen.add("planner_frequency", double_t, 0, "The rate in Hz at which to run the planning loop", 0.0, 0, 100)
    gen.add(
        "controller_frequency", double_t, 0, "The rate in Hz at which to run the control loop", 20.0, 0, 100
    )
    gen.add(
        "planner_patience",
        double_t,
        0,
        "How long the planner will wait in seconds to find a valid plan",
        5.0,
        0,
        100,
    )
    gen.add(
        "controller_patience",
        double_t,
        0,
        "How long the controller will wait in seconds without a valid control",
        15.0,
        0,
        100,
    )
    gen.add(
        "conservative_reset_dist",
        double_t,
        0,
        "The distance away from the robot in meters at which obstacles are cleared",
        3.0,
        0,
        50,
    )
    gen.add(
        "recovery_behavior_enabled",
        bool_t,
        0,
        "Whether or not to enable the move_base recovery behaviors",
        True,
    )
    gen.add(
        "clearing_rotation_allowed",
        bool_t,
        0,
        "Whether the robot will attempt an in-place rotation when clearing",
        True,
    )
    gen.add(
        "oscillation_timeout",
        double_t,
        0,
        "How long in seconds to allow for oscillation before executing recovery behaviors",
        0.0,
        0,
        60,
    )
    gen.add(
        "oscillation_distance",
        double_t,
        0,
        "How far in meters the robot must move to be considered not to be oscillating",
        0.5,
        0,
        10,
    )
    return _module(gen, "move_base", "MoveBase")
