"""The pure turtlesim world: geometry, kinematics, timeout, walls, pen, spawn/kill/reset."""

from __future__ import annotations

import math
import struct
import zlib

import numpy as np
import pytest

from ninjemys.sim.render import compose_frame, png_bytes
from ninjemys.sim.world import (
    CENTER,
    DEFAULT_BACKGROUND,
    DEFAULT_PEN,
    WORLD_SIZE,
    TurtleError,
    World,
    normalize_angle,
)


@pytest.fixture
def world() -> World:
    w = World()
    w.reset()
    return w


def run(world: World, start: float, seconds: float, period: float = 0.016) -> float:
    t = start
    world.step(t)
    while t < start + seconds:
        t += period
        world.step(t)
    return t


def test_geometry_matches_ros() -> None:
    assert WORLD_SIZE == pytest.approx(11.088889, abs=1e-6)
    assert CENTER == pytest.approx(5.544445, abs=1e-6)


def test_reset_spawns_turtle1_at_center(world: World) -> None:
    assert list(world.turtles) == ["turtle1"]
    t = world.turtles["turtle1"]
    assert (t.x, t.y, t.theta) == (pytest.approx(CENTER), pytest.approx(CENTER), 0.0)
    assert tuple(world.image[0, 0]) == DEFAULT_BACKGROUND


def test_spawn_log_line_matches_seed() -> None:
    lines: list[str] = []
    World(info=lines.append).reset()
    assert lines == ["Spawning turtle [turtle1] at x=[5.544445], y=[5.544445], theta=[0.000000]"]


def test_one_command_moves_one_unit_then_stops(world: World) -> None:
    world.step(0.0)
    world.command("turtle1", 1.0, 0.0, 0.0, now=0.0)
    run(world, 0.0, 3.0)
    t = world.turtles["turtle1"]
    assert t.x - CENTER == pytest.approx(1.0, rel=0.02)
    assert t.y == pytest.approx(CENTER, abs=1e-6)
    assert t.linear_velocity == 0.0  # velocity timed out


def test_jittery_steps_still_move_one_unit(world: World) -> None:
    world.step(10.0)
    world.command("turtle1", 1.0, 0.0, 0.0, now=10.0)
    for t in (10.003, 10.2, 10.21, 10.9, 11.4, 12.5):
        world.step(t)
    assert world.turtles["turtle1"].x - CENTER == pytest.approx(1.0, abs=1e-6)


def test_rotation_and_angle_normalisation(world: World) -> None:
    world.step(0.0)
    world.command("turtle1", 0.0, 0.0, math.pi, now=0.0)
    run(world, 0.0, 2.0, period=0.01)
    t = world.turtles["turtle1"]
    assert -math.pi <= t.theta < math.pi
    assert abs(normalize_angle(t.theta - math.pi)) < 1e-6
    assert normalize_angle(3 * math.pi) == pytest.approx(-math.pi)


def test_wall_clamping_warns() -> None:
    warnings: list[str] = []
    world = World(warn=warnings.append)
    world.reset()
    world.step(0.0)
    world.command("turtle1", 20.0, 0.0, 0.0, now=0.0)
    run(world, 0.0, 1.5)
    assert world.turtles["turtle1"].x == pytest.approx(WORLD_SIZE)
    assert warnings and warnings[0].startswith("Oh no! I hit the wall! (Clamping from [x=")


def test_nan_command_ignored(world: World) -> None:
    world.step(0.0)
    assert world.command("turtle1", float("nan"), 0.0, 0.0, now=0.0) is False
    run(world, 0.0, 0.5)
    t = world.turtles["turtle1"]
    assert (t.x, t.y) == (pytest.approx(CENTER), pytest.approx(CENTER))


def test_spawn_names_and_errors(world: World) -> None:
    assert world.spawn("", 1, 1, 0).name == "turtle2"
    assert world.spawn("leo", 2, 2, 0).name == "leo"
    with pytest.raises(TurtleError, match=r"A turtle named \[leo\] already exists"):
        world.spawn("leo", 3, 3, 0)
    with pytest.raises(TurtleError):
        world.spawn("nanny", float("nan"), 3, 0)
    world.kill("leo")
    assert "leo" not in world.turtles
    with pytest.raises(TurtleError, match=r"Tried to kill turtle \[leo\], which does not exist"):
        world.kill("leo")


def test_teleports(world: World) -> None:
    world.teleport_absolute("turtle1", 2.0, 3.0, 1.0)
    t = world.turtles["turtle1"]
    assert (t.x, t.y, t.theta) == (2.0, 3.0, 1.0)
    world.teleport_absolute("turtle1", 2.0, 2.0, math.pi / 2)
    world.teleport_relative("turtle1", 1.0, 0.0)
    assert (t.x, t.y) == (pytest.approx(2.0), pytest.approx(3.0))


def test_pen_draws_trail_and_off_does_not(world: World) -> None:
    world.teleport_absolute("turtle1", 2.0, CENTER, 0.0)
    row = round((WORLD_SIZE - CENTER) * 45)
    assert tuple(world.image[row, round(2.0 * 45) + 20]) == DEFAULT_PEN
    world.clear()
    world.set_pen("turtle1", 255, 0, 0, 3, off=True)
    world.teleport_absolute("turtle1", 8.0, 2.0, 0.0)
    assert (world.image == np.array(DEFAULT_BACKGROUND, dtype=np.uint8)).all()
    world.set_pen("turtle1", 255, 0, 0, 5, off=False)
    world.teleport_absolute("turtle1", 8.0, 6.0, 0.0)
    assert tuple(world.image[round((WORLD_SIZE - 4.0) * 45), round(8.0 * 45)]) == (255, 0, 0)
    assert world.color_under(world.turtles["turtle1"]) == (255, 0, 0)


def test_reset_restores_single_turtle(world: World) -> None:
    world.spawn("", 1, 1, 0)
    world.teleport_absolute("turtle1", 1, 1, 0)
    world.reset()
    assert list(world.turtles) == ["turtle1"]
    assert world.turtles["turtle1"].x == pytest.approx(CENTER)
    assert not world.segments


def test_png_roundtrip(world: World) -> None:
    data = png_bytes(compose_frame(world))
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    width, height = struct.unpack(">II", data[16:24])
    assert (width, height) == (500, 500)
    idat_len = struct.unpack(">I", data[33:37])[0]
    raw = zlib.decompress(data[41 : 41 + idat_len])
    assert len(raw) == 500 * (500 * 3 + 1)
    # the turtle is drawn at the centre, the corner is background
    assert tuple(raw[1:4]) == DEFAULT_BACKGROUND


def test_commands_between_steps_are_integrated_exactly(world: World) -> None:
    """Commands at 50 Hz, steps at 62.5 Hz: every command counts for exactly its own interval."""
    world.step(0.0)
    t_cmd, t_step, end = 0.0, 0.0, 2.0
    while t_cmd < end - 1e-9:
        world.command("turtle1", 0.5, 0.0, 0.0, now=t_cmd)
        t_cmd += 0.02
        while t_step + 0.016 <= t_cmd:
            t_step += 0.016
            world.step(t_step)
    world.command("turtle1", 0.0, 0.0, 0.0, now=end)
    world.step(end + 1.0)
    assert world.turtles["turtle1"].x - CENTER == pytest.approx(1.0, abs=1e-6)
