"""A moving obstacle that ``gives_way`` (the office's person): it steps around a robot in its way,
waits when there is no room, never walks into a robot, and is deterministic."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from ninjemys.maps.mapfile import MapFileError
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import PERSONAL_SPACE, Simulation
from ninjemys.sim.world2d import load_world


def corridor(tmp_path: Path, half_width: float, gives_way: str = "true") -> Simulation:
    """A corridor along x with walls at y = +-half_width and a person pacing y = 0.3 from x 0 to 8."""
    (tmp_path / "w.yaml").write_text(
        "bounds: [-2, -3, 10, 3]\n"
        "walls:\n"
        f"  - {{from: [-2, {half_width}], to: [10, {half_width}], thickness: 0.1}}\n"
        f"  - {{from: [-2, {-half_width}], to: [10, {-half_width}], thickness: 0.1}}\n"
        "moving:\n"
        "  - {name: person, shape: cylinder, radius: 0.25, height: 1.0, speed: 0.4,\n"
        f"     waypoints: [[0, 0.3], [8, 0.3]], loop: false, gives_way: {gives_way}}}\n"
    )
    return Simulation(load_world(tmp_path / "w.yaml"), dt=0.01)


def gap(sim: Simulation) -> float:
    r = sim.robots["pb"]
    px, py, _ = sim.world.moving[0].position(sim.world_time)
    return math.hypot(r.x - px, r.y - py) - 0.25 - r.model.body_radius


def test_the_person_steps_around_a_robot_standing_in_its_lane(tmp_path):
    sim = corridor(tmp_path, 1.0)
    sim.add_robot("pb", load_robot_model("puzzlebot"), 4.0, 0.3, math.pi)
    person = sim.world.moving[0]
    closest, reversals, last_y, last_dir = math.inf, 0, 0.0, 0.0
    for _ in range(3000):  # 30 s: there (4 m), past the robot and on
        sim.step()
        closest = min(closest, gap(sim))
        move = person.aside[1] - last_y
        if abs(move) > 1e-9 and person.walked < 7.5:  # until it turns back at the route's end
            reversals += last_dir * move < 0
            last_dir, last_y = move, person.aside[1]
    assert closest >= PERSONAL_SPACE - 1e-6
    assert reversals == 1  # out, then back onto its route once past: no hunting at the edge
    assert person.walked > 6.0  # it got past the robot, not stuck behind it
    assert not sim.robots["pb"].contact


def test_with_no_room_the_person_waits_and_walks_on_once_the_robot_leaves(tmp_path):
    sim = corridor(tmp_path, 0.6)  # 1.1 m between the walls' faces: no room to pass a robot
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 4.0, 0.0, math.pi / 2)
    for _ in range(2000):
        sim.step()
        assert gap(sim) >= PERSONAL_SPACE - 1e-6
    person = sim.world.moving[0]
    waiting = person.walked
    assert 2.5 < waiting < 4.0  # stopped short of the robot
    r.x = 20.0  # the robot is gone (carried off): the person walks on
    for _ in range(500):
        sim.step()
    assert person.walked > waiting + 1.5


def test_the_walk_is_deterministic_and_reset_world_restarts_it(tmp_path):
    poses = []
    for _ in range(2):
        sim = corridor(tmp_path, 1.0)
        sim.add_robot("pb", load_robot_model("puzzlebot"), 4.0, 0.3, 0.0)
        for _ in range(1500):
            sim.step()
        poses.append(sim.world.moving[0].position(sim.world_time))
    assert poses[0] == poses[1]
    sim.reset_world()
    assert sim.world.moving[0].position(sim.world_time)[:2] == pytest.approx((0.0, 0.3))


def test_a_person_that_does_not_give_way_walks_its_timetable(tmp_path):
    sim = corridor(tmp_path, 1.0, gives_way="false")
    sim.add_robot("pb", load_robot_model("puzzlebot"), 4.0, 0.3, 0.0)
    for _ in range(500):
        sim.step()
    assert sim.world.moving[0].position(sim.world_time)[:2] == pytest.approx((2.0, 0.3))


def test_gives_way_must_be_a_boolean(tmp_path):
    with pytest.raises(MapFileError, match=r"moving\[0\]\.gives_way: expected true or false, got 'yes'"):
        corridor(tmp_path, 1.0, gives_way="'yes'")
