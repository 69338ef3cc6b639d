"""The simulator's camera draws every shape between its true bottom and top (issue 23, build 4: "the
simulator's camera renders models at their heights and colours"): a box held in the air shows the
floor and what stands behind under it, in colour and in depth; a table shows its legs and the room
under its top; low boxes seen from above show the farther ones over the nearer. The images agree
pixel by pixel with a per-pixel renderer, the per-column cast with a brute-force one, and a camera
that stands still in an unchanged world reuses its last frame."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from camera_reference import assert_matches_reference, ray_hits

from ninjemys.sim.camera import Camera
from ninjemys.sim.raycast import column_pairs
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.sdf import load_sdf_world
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import Obstacle, World, box_outline, circle_outline

NO_ENV = {"HOME": "/nonexistent"}


def sdf_box(name: str, x: float, y: float, z: float, size: str, colour: str) -> str:
    geometry = f"<geometry><box><size>{size}</size></box></geometry>"
    return (
        f'<model name="{name}"><static>true</static><pose>{x} {y} {z} 0 0 0</pose><link name="l">'
        f'<collision name="c">{geometry}</collision><visual name="v">{geometry}'
        f"<material><script><name>{colour}</name></script></material></visual></link></model>"
    )


def test_a_box_held_in_the_air_is_drawn_at_its_height(tmp_path: Path) -> None:
    """A static red box at z = 0.5 (0.3 to 0.7 m) before a green wall: red only between its bottom
    and top rows; under it the wall behind, then the floor, each at its own depth."""
    text = (
        '<sdf version="1.6"><world name="w"><include><uri>model://ground_plane</uri></include>'
        + sdf_box("held", 1.5, 0.0, 0.5, "0.4 0.4 0.4", "Gazebo/Red")
        + sdf_box("wall", 6.0, 0.0, 1.0, "0.2 8 2", "Gazebo/Green")
        + "</world></sdf>"
    )
    path = tmp_path / "held.world"
    path.write_text(text)
    sim = Simulation(load_sdf_world(path, env=NO_ENV))
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    rgb, depth = sim.render(r)
    cam = r.camera
    assert cam is not None and r.model.camera is not None
    u = cam.width // 2
    cam_x = r.model.camera.pose.xyz[0]
    near, far = 1.3 - cam_x, 5.9 - cam_x  # the box's front face and the wall's, ahead of the camera

    def row_at(z: float, d: float) -> int:  # the image row whose ray is at height z at depth d
        return int(round(cam.cy - (z - cam.cam_z) / d * cam.fy))

    def colour(v: int) -> str:
        red, green, blue = (int(c) for c in rgb[v, u])
        return "red" if red > 80 > green else "green" if green > 80 > red else "other"

    for z in (0.35, 0.5, 0.65):  # the box: red, at the box's depth
        v = row_at(z, near)
        assert colour(v) == "red" and depth[v, u] == round(near * 1000), (z, v, rgb[v, u], depth[v, u])
    v = row_at(0.2, near)  # just under the box: the ray goes on and meets the wall at 0.2 + ... m
    assert colour(v) == "green" and depth[v, u] == round(far * 1000), (v, rgb[v, u], depth[v, u])
    v = row_at(0.05, near)  # lower still: the floor between the box and the wall, not red
    floor = cam.cam_z / -cam.row_slope[v]
    assert near < floor < far
    assert colour(v) == "other" and depth[v, u] == round(floor * 1000), (v, rgb[v, u], depth[v, u])
    # seen from below, the box's underside shows under its front edge, down to its back edge's row
    # (at the depth where each row's ray meets the plane z = 0.3); nothing red below that anywhere
    v = (row_at(0.3, near) + row_at(0.3, near + 0.4)) // 2
    assert colour(v) == "red" and near < depth[v, u] / 1000 < near + 0.4
    assert abs(depth[v, u] / 1000 - (0.3 - cam.cam_z) / cam.row_slope[v]) < 0.002
    red = (rgb[:, :, 0] > 80) & (rgb[:, :, 1] < 60)
    assert np.flatnonzero(red.any(axis=1)).max() <= row_at(0.3, near + 0.4) + 1
    assert_matches_reference(sim, r)


def held_world() -> World:
    """A table (a top at 0.7-0.75 m on four legs), a shelf in the air, low boxes in a row (seen from
    above, each farther one shows over the nearer), a cylinder and walls around."""
    obstacles = [
        Obstacle(
            "top", "box", box_outline(2.0, 0.0, 1.0, 0.8), 0.75, (150, 100, 50), base=0.7, model="table"
        ),
        Obstacle("shelf", "box", box_outline(-1.0, 2.0, 1.2, 0.3), 1.2, (40, 90, 200), base=0.8),
        Obstacle("drum", "cylinder", circle_outline(-2.0, -1.5, 0.3), 0.5, (200, 200, 40)),
    ]
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        leg = box_outline(2.0 + sx * 0.45, sy * 0.35, 0.05, 0.05)
        obstacles.append(Obstacle(f"leg{i}", "box", leg, 0.7, (120, 80, 40), model="table"))
    for i in range(4):  # 6 cm boxes, below the camera (12 cm): seen from above
        obstacles.append(
            Obstacle(f"low{i}", "box", box_outline(-1.0 - 0.5 * i, -0.2, 0.2, 0.6), 0.06, (30, 160, 60))
        )
    for name, (x0, y0, x1, y1) in {
        "north": (-5, 4, 5, 4),
        "south": (5, -4, -5, -4),
        "east": (5, 4, 5, -4),
        "west": (-5, -4, -5, 4),
    }.items():
        obstacles.append(
            Obstacle(name, "wall", np.array([[x0, y0], [x1, y1]], dtype=float), 2.5, (200, 200, 200))
        )
    return World("held", obstacles)


@pytest.mark.parametrize(
    "pose",
    [
        (0.6, 0.0, 0.0),  # facing the table: legs, the room under the top, the top's edge
        (0.6, 0.5, -0.2),
        (1.0, 0.0, 0.05),  # close: the top above the image, the legs and the wall
        (0.2, -0.2, math.pi),  # along the row of low boxes
        (-1.0, 0.6, 1.5),  # under the shelf's side, looking at the north wall
        (3.5, -2.5, 2.4),  # across the room: table, shelf, drum and low boxes together
    ],
)
def test_held_shapes_match_a_per_pixel_renderer(pose: tuple[float, float, float]) -> None:
    sim = Simulation(held_world())
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    r.x, r.y, r.yaw = pose
    assert_matches_reference(sim, r)


def test_the_room_shows_under_a_table_top() -> None:
    """Straight at the table from 1.2 m: between the legs the far wall and the floor under the top,
    the top above them, and the legs either side at their own depth."""
    sim = Simulation(held_world())
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.4, 0.0, 0.0)
    rgb, depth = sim.render(r)
    cam, spec = r.camera, r.model.camera
    assert cam is not None and spec is not None
    cam_x = 0.4 + spec.pose.xyz[0]
    u = cam.width // 2
    wall = round((5.0 - cam_x) * 1000)
    column = depth[:, u]
    assert (column == wall).sum() > 5  # the east wall seen under the table top
    under = depth[: cam.height // 2, u] / 1000.0  # the table top's underside, from 1.5 to 2.5 m
    assert ((under > 1.5 - cam_x) & (under < 2.5 - cam_x)).sum() > 10
    leg_u = int(round(cam.cx - cam.fx * 0.35 / (2.0 - 0.45 - 0.025 - cam_x)))  # the near left leg
    assert abs(int(depth[cam.height // 2 + 5, leg_u]) - round((1.525 - cam_x) * 1000)) <= 1


def test_a_still_camera_reuses_its_frame_until_the_world_changes() -> None:
    sim = Simulation(held_world())
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.6, 0.0, 0.0)
    first = sim.render(r)
    second = sim.render(r)  # the scene is noted: the next still frame may be reused
    third = sim.render(r)
    assert third[0] is second[0] and third[1] is second[1]
    assert np.array_equal(first[0], third[0]) and np.array_equal(first[1], third[1])
    sim.move_obstacle("drum", 1.5, 0.0, 0.0)  # into view, before the table
    moved = sim.render(r)
    assert moved[0] is not third[0] and not np.array_equal(moved[1], third[1])
    assert_matches_reference(sim, r)
    r.yaw = 0.1  # the camera turns: drawn anew
    assert sim.render(r)[0] is not moved[0]
    colour_only = sim.render(r, depth=False)  # other images asked for: drawn anew
    assert colour_only[1].size == 0


@pytest.mark.parametrize("seed", range(6))
def test_column_pairs_equal_a_brute_force_cast(seed: int) -> None:
    """The nearest crossing per column (depth along the optical axis) from random segments around
    the camera, some behind it or across its back, equals one ray per column against every segment."""
    rng = np.random.default_rng(seed)
    cam = Camera(160, 120, 69.4, 0.12, 6.0)
    segs = rng.uniform(-8, 8, (60, 4))
    x, y, yaw = rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi)
    col, seg, d = column_pairs(x, y, yaw, cam.col_slopes, segs, cam.depth_max)
    nearest = np.full(cam.width, np.inf)
    np.minimum.at(nearest, col, d)
    for u in range(cam.width):
        dists, _ = ray_hits(x, y, yaw + cam.col_angles[u], segs)
        depths = dists * cam.col_cos[u]
        depths = depths[depths <= cam.depth_max]
        want = depths[0] if len(depths) else np.inf
        assert nearest[u] == pytest.approx(want, abs=1e-9), u
    # every crossing listed is a true one: its point lies on its segment, on its column's ray
    ex, ey = segs[seg, 2] - segs[seg, 0], segs[seg, 3] - segs[seg, 1]
    c, s = math.cos(yaw), math.sin(yaw)
    px = x + d * (c - s * cam.col_slopes[col])
    py = y + d * (s + c * cam.col_slopes[col])
    along = ((px - segs[seg, 0]) * ex + (py - segs[seg, 1]) * ey) / (ex * ex + ey * ey)
    off = np.abs((px - segs[seg, 0]) * ey - (py - segs[seg, 1]) * ex) / np.hypot(ex, ey)
    assert (along > -1e-6).all() and (along < 1 + 1e-6).all() and (off < 1e-6).all()


def test_another_robot_in_view_of_a_lid_is_drawn() -> None:
    """A second robot (a round body, listed after the segments) in a view that also shows a lid (the
    low boxes seen from above): the lid's far sides are matched to their shapes' near sides by
    outline, and the robot's crossings belong to no outline (this frame once raised IndexError)."""
    sim = Simulation(held_world())
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.2, -0.2, math.pi)  # along the low boxes
    alone_rgb, alone_depth = sim.render(r)
    other = sim.add_robot("pb2", load_robot_model("puzzlebot"), -0.6, -0.2, 0.0)  # before the first box
    rgb, depth = sim.render(r)
    assert not np.array_equal(rgb, alone_rgb) and not np.array_equal(depth, alone_depth)
    cam = r.camera
    assert cam is not None
    # straight ahead, below the horizon: the other robot's body, nearer than the floor seen there alone
    u, v = cam.width // 2, cam.height // 2 + 30
    assert 0 < depth[v, u] < alone_depth[v, u], (depth[v, u], alone_depth[v, u])
    assert depth[v, u] < 800, depth[v, u]
    del other
