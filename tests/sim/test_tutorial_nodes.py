"""square_driver, draw_square and mimic: their control logic against the pure world."""

from __future__ import annotations

import math

import pytest

from geometry_msgs.msg import Twist
from ninjemys.sim.draw_square import SquareController
from ninjemys.sim.mimic import twist_from_pose
from ninjemys.sim.square_driver import DiffDrive, SquarePlan
from ninjemys.sim.world import CENTER, World
from turtlesim.msg import Pose


def test_seed_formulas() -> None:
    d = DiffDrive()
    assert d.distance(10.0, 10.0, 0.5) == pytest.approx(0.05 * 10.0 * 0.5)
    assert d.angle(2.0, -2.0, 1.0) == pytest.approx(0.05 * 4.0 / 0.18)


def test_square_plan_closes_a_1m_square_in_the_world() -> None:
    world = World()
    turtle = world.reset()
    plan = SquarePlan(1.0)
    t, dt = 0.0, 0.02
    world.step(t)
    corners = []
    w_r, w_l = plan.wheels()
    world.command("turtle1", plan.drive.linear(w_r, w_l), 0.0, plan.drive.angular(w_r, w_l), t)
    while plan.legs < 8:
        t += dt
        world.step(t)
        if plan.advance(w_r, w_l, dt) and plan.turning:
            corners.append((turtle.x, turtle.y))
        w_r, w_l = plan.wheels()
        world.command("turtle1", plan.drive.linear(w_r, w_l), 0.0, plan.drive.angular(w_r, w_l), t)
    # open-loop dead reckoning at 50 Hz overshoots each corner by up to one step (0.033 rad)
    expected = [(CENTER + 1, CENTER), (CENTER + 1, CENTER + 1), (CENTER, CENTER + 1), (CENTER, CENTER)]
    for (x, y), (ex, ey) in zip(corners, expected, strict=True):
        assert (x, y) == (pytest.approx(ex, abs=0.1), pytest.approx(ey, abs=0.1))


def test_draw_square_controller_drives_2m_sides() -> None:
    world = World()
    turtle = world.reset()
    ctl = SquareController()
    t = 0.0
    world.step(t)
    for _ in range(3000):
        pose = Pose(turtle.x, turtle.y, turtle.theta, turtle.linear_velocity, turtle.ang_z)
        linear, angular = ctl.step(pose)
        world.command("turtle1", linear, 0.0, angular, t)
        t += 0.016
        world.step(t)
        if len(ctl.goals) >= 3:
            break
    first, turn = ctl.goals[0], ctl.goals[1]
    assert first[:2] == (pytest.approx(CENTER + 2.0, abs=1e-5), pytest.approx(CENTER, abs=1e-5))
    assert turn[2] == pytest.approx(math.pi / 2)
    assert turtle.x == pytest.approx(CENTER + 2.0, abs=0.11)


def test_mimic_copies_velocities() -> None:
    twist = twist_from_pose(Pose(1.0, 2.0, 0.3, 0.7, -0.2), Twist)
    assert (twist.linear.x, twist.angular.z) == (pytest.approx(0.7), pytest.approx(-0.2))
