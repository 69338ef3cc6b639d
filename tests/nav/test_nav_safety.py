"""The safety monitor's decisions: twist_mux priorities with timeouts, and the swept stop zone."""

from __future__ import annotations

import numpy as np

from ninjemys.nav.safety import MuxInput, TwistMux, blocked, stop_distance
from ninjemys.nav.safety_node import parse_topics


def test_mux_priority_and_watchdog():
    teleop = MuxInput("teleop", "teleop/cmd_vel", 100, 0.5)
    nav = MuxInput("navigation", "nav/cmd_vel", 10, 0.5)
    mux = TwistMux([nav, teleop])
    assert mux.select(0.0) is None
    nav.last_time = 1.0
    assert mux.select(1.2) is nav
    teleop.last_time = 1.3
    assert mux.select(1.4) is teleop  # teleop overrides navigation
    nav.last_time = 1.7
    assert mux.select(1.9) is nav  # teleop went stale after 0.5 s
    assert mux.select(2.0, allowed={"teleop"}) is None  # localization lost: navigation not allowed
    assert mux.select(2.6) is None  # everything stale: stop


def test_stop_zone_follows_the_arc_and_lets_the_robot_back_away():
    assert stop_distance(0.3, 1.5, 0.1) == 0.3 * 0.1 + 0.09 / 3.0
    wall_ahead = np.array([[0.28, y] for y in np.linspace(-0.3, 0.3, 13)])
    assert blocked(wall_ahead, 0.3, 0.0, 0.11, 0.05, 1.5, 0.3)
    assert not blocked(wall_ahead, -0.2, 0.0, 0.11, 0.05, 1.5, 0.3)  # backing away
    assert not blocked(wall_ahead, 0.0, 1.0, 0.11, 0.05, 1.5, 0.3)  # turning in place
    far = wall_ahead + [1.0, 0.0]
    assert not blocked(far, 0.3, 0.0, 0.11, 0.05, 1.5, 0.3)
    assert blocked(far, 0.3, 0.0, 0.11, 0.05, 1.5, 0.3, obstacle_speed=2.0)  # someone running at us
    side_wall = np.array([[x, 0.2] for x in np.linspace(-0.5, 1.5, 41)])
    assert not blocked(side_wall, 0.3, 0.0, 0.11, 0.05, 1.5, 0.3)  # driving along a wall
    assert blocked(side_wall, 0.3, 2.5, 0.11, 0.05, 1.5, 0.3)  # arcing into it


def test_topics_parameter_errors_are_one_line_each():
    inputs, errors = parse_topics(
        [{"name": "a", "topic": "x", "priority": 5, "timeout": 0.2}, {"name": "b"}, 7]
    )
    assert [i.name for i in inputs] == ["a"]
    assert len(errors) == 2 and all("\n" not in e and e.startswith("~topics[") for e in errors)
