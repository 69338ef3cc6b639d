"""The simulation without ROS: lidar against analytic geometry, odometry against closed forms,
no tunnelling, spawning rules, multi-robot visibility, camera depth, robot descriptions."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from ninjemys.sim.raycast import cast_grid, cast_segments, grid_edges
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation, SpawnError
from ninjemys.sim.world2d import load_world, world_from_map
from ninjemys.sim.worlds import ROBOTS_DIR

NOISE = 0.01


def fast_model(tmp_path: Path, **over: object):
    """The PuzzleBot with a high speed limit and (unless given) instantaneous acceleration."""
    lines = ["max_wheel_speed: 1000.0", "max_wheel_accel: 1000000000.0"] + [
        f"{k}: {v}" for k, v in over.items()
    ]
    p = tmp_path / "fast.yaml"
    p.write_text("\n".join(lines) + "\n")
    return load_robot_model(str(p))


def write_wall_map(tmp_path: Path, wall_x: float, res: float = 0.05) -> Path:
    """A 10 x 10 m map (origin -5, -5) whose cells with x >= wall_x (0.2 m thick) are occupied."""
    n = int(10 / res)
    img = np.full((n, n), 254, dtype=np.uint8)
    c0 = round((wall_x + 5) / res)
    img[:, c0 : c0 + 4] = 0
    (tmp_path / "wall.pgm").write_bytes(f"P5\n{n} {n}\n255\n".encode() + img.tobytes())
    y = tmp_path / "wall.yaml"
    y.write_text(
        f"image: wall.pgm\nresolution: {res}\norigin: [-5.0, -5.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return y


def test_scan_matches_a_wall_in_a_generated_map(tmp_path):
    sim = Simulation(world_from_map(write_wall_map(tmp_path, 2.0)), seed=3)
    yaw = 0.3
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, yaw)
    ranges = sim.scan(r).astype(np.float64)
    angles = -math.pi + np.arange(360) * (2 * math.pi / 360)
    world_angles = yaw + angles
    # the wall face x = 2.0 spans y in [-5, 5]: beams that reach it see 2 / cos(world angle)
    with np.errstate(divide="ignore"):
        expected = 2.0 / np.cos(world_angles)
    hits_wall = (np.cos(world_angles) > 0) & (np.abs(np.tan(world_angles) * 2.0) < 4.9)
    assert hits_wall.sum() > 100
    err = ranges[hits_wall] - expected[hits_wall]
    assert np.all(np.abs(err) < 5 * NOISE), np.abs(err).max()
    assert abs(err.mean()) < 0.005 and 0.5 * NOISE < err.std() < 2 * NOISE  # the configured noise
    # beams pointing away see nothing within 12 m (map edge is free): +inf per REP 117
    assert np.all(np.isinf(ranges[np.cos(world_angles) < -0.1]))


def test_scan_matches_a_slanted_wall(tmp_path):
    # thin wall on the line x cos(phi) + y sin(phi) = p, long enough to fill the front half
    phi, p = 0.4, 1.5
    nx, ny = math.cos(phi), math.sin(phi)
    a = (p * nx - 8 * ny, p * ny + 8 * nx)
    b = (p * nx + 8 * ny, p * ny - 8 * nx)
    (tmp_path / "w.yaml").write_text(
        f"walls:\n  - {{from: [{a[0]}, {a[1]}], to: [{b[0]}, {b[1]}], thickness: 0}}\n"
    )
    sim = Simulation(load_world(tmp_path / "w.yaml"))
    model = load_robot_model("puzzlebot")
    model.laser.noise = 0.0
    r = sim.add_robot("pb", model, 0.0, 0.0, 0.0)
    ranges = sim.scan(r).astype(np.float64)
    angles = -math.pi + np.arange(360) * (2 * math.pi / 360)
    facing = np.cos(angles - phi) > 0.3
    assert np.allclose(ranges[facing], p / np.cos(angles[facing] - phi), atol=1e-4)


def test_grid_traversal_and_grid_edges_agree():
    rng = np.random.default_rng(1)
    occ = rng.random((120, 100)) < 0.03
    occ[60, 50] = False
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    a = cast_grid(0.013, 0.021, angles, occ, 0.05, -2.5, -3.0, 12.0)
    b, _ = cast_segments(0.013, 0.021, angles, grid_edges(occ, 0.05, -2.5, -3.0), 12.0)
    both = np.isfinite(a) & np.isfinite(b)
    assert np.array_equal(np.isfinite(a), np.isfinite(b))
    assert np.allclose(a[both], b[both], atol=1e-5)  # traversal works in float32


def test_straight_line_odometry_matches_closed_form(tmp_path):
    (tmp_path / "e.yaml").write_text("bounds: [-5, -5, 5, 5]\n")
    sim = Simulation(load_world(tmp_path / "e.yaml"), dt=0.01)
    r = sim.add_robot("pb", fast_model(tmp_path), 0.0, 0.0, 0.0)
    r.command(0.25, 0.0)
    for _ in range(400):  # 4 s
        sim.step()
    ox, oy, oyaw = sim.odometry(r)
    assert (r.x, r.y, r.yaw) == pytest.approx((1.0, 0.0, 0.0), abs=1e-9)
    assert (ox, oy, oyaw) == pytest.approx((1.0, 0.0, 0.0), abs=1e-9)
    m = r.model
    assert r.wl == pytest.approx(0.25 / m.wheel_radius) and r.wr == pytest.approx(0.25 / m.wheel_radius)


def test_arc_odometry_matches_closed_form(tmp_path):
    (tmp_path / "e.yaml").write_text("bounds: [-5, -5, 5, 5]\n")
    sim = Simulation(load_world(tmp_path / "e.yaml"), dt=0.01)
    r = sim.add_robot("pb", fast_model(tmp_path), 0.5, -0.5, 0.2)
    v, w, t = 0.2, 0.5, 4.0
    r.command(v, w)
    for _ in range(400):
        sim.step()
        sim.odometry(r)  # sampled every step, as the node does at 100 Hz
    radius = v / w
    ex = 0.5 + radius * (math.sin(0.2 + w * t) - math.sin(0.2))
    ey = -0.5 - radius * (math.cos(0.2 + w * t) - math.cos(0.2))
    assert (r.x, r.y, r.yaw) == pytest.approx((ex, ey, 0.2 + w * t), abs=1e-9)
    # odometry starts at the origin of the odom frame: the same arc from (0, 0, 0)
    ox, oy, oyaw = r.odom
    assert (ox, oy, oyaw) == pytest.approx(
        (radius * math.sin(w * t), radius * (1 - math.cos(w * t)), w * t), abs=1e-6
    )
    # the wheels the course reads: wr, wl from v and w with r = 0.05, l = 0.18
    assert r.wr == pytest.approx((v + w * 0.09) / 0.05) and r.wl == pytest.approx((v - w * 0.09) / 0.05)


def test_odometry_noise_is_seeded_and_bounded(tmp_path):
    def run(seed: int) -> tuple[float, float, float]:
        (tmp_path / "e.yaml").write_text("bounds: [-5, -5, 5, 5]\n")
        sim = Simulation(load_world(tmp_path / "e.yaml"), dt=0.01, seed=seed)
        model = fast_model(tmp_path)
        model.odom_alpha = (0.05, 0.05, 0.05, 0.05)
        r = sim.add_robot("pb", model, 0.0, 0.0, 0.0)
        r.command(0.3, 0.2)
        for _ in range(500):
            sim.step()
            sim.odometry(r)
        truth = (r.x, r.y)
        return r.odom[0] - truth[0], r.odom[1] - truth[1], r.odom[2]

    a, b, c = run(1), run(1), run(2)
    assert a == b and a != c
    assert 0 < math.hypot(a[0], a[1]) < 0.2


def test_acceleration_and_wheel_speed_limits():
    sim = Simulation(_empty(), dt=0.01)
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    r.command(5.0, 0.0)  # beyond 16 rad/s * 0.05 m
    sim.step()
    assert r.wl == pytest.approx(0.4) and r.wr == pytest.approx(0.4)  # 40 rad/s^2 * 0.01 s
    for _ in range(100):
        sim.step()
    assert r.v == pytest.approx(16.0 * 0.05)


def _empty():
    from ninjemys.sim.world2d import World

    return World("empty", bounds=(-5, -5, 5, 5))


@pytest.mark.parametrize("speed", [2.0, 20.0, 200.0])
def test_no_tunnelling_through_a_thin_wall(tmp_path, speed):
    (tmp_path / "w.yaml").write_text("walls:\n  - {name: thin, from: [1, -3], to: [1, 3], thickness: 0}\n")
    sim = Simulation(load_world(tmp_path / "w.yaml"), dt=0.01)
    r = sim.add_robot("pb", fast_model(tmp_path), 0.0, 0.0, 0.0)
    r.command(speed, 0.0)
    touched = []
    for _ in range(300):
        touched += sim.step()
    radius = r.model.body_radius
    assert r.x <= 1.0 - radius + 1e-9
    assert r.x > 1.0 - radius - 0.01  # stopped at contact, not before
    assert r.contact and r.contact_with == "thin"
    assert [t.name for t in touched] == ["pb"]  # reported once
    assert r.v == 0.0 and r.wl == 0.0
    r.command(-0.2, 0.0)  # backing away is allowed and clears the contact
    for _ in range(50):
        sim.step()
    assert r.x < 1.0 - radius - 0.05 and not r.contact


def test_robot_does_not_pass_through_a_map_wall(tmp_path):
    sim = Simulation(world_from_map(write_wall_map(tmp_path, 1.0)), dt=0.01)
    r = sim.add_robot("pb", fast_model(tmp_path), 0.0, 0.0, 0.0)
    r.command(3.0, 0.0)
    for _ in range(200):
        sim.step()
    assert 1.0 - r.model.body_radius - 0.01 < r.x <= 1.0 - r.model.body_radius + 1e-9
    assert r.contact_with == "map"


def test_spawn_inside_a_wall_or_robot_is_refused(tmp_path):
    (tmp_path / "w.yaml").write_text(
        "walls:\n  - {name: north, from: [-3, 1], to: [3, 1], thickness: 0.2}\nboxes:\n  - {name: crate, center: [3, 3], size: [2, 2]}\n"
    )
    sim = Simulation(load_world(tmp_path / "w.yaml"))
    model = load_robot_model("puzzlebot")
    with pytest.raises(SpawnError, match=r"inside 'north'"):
        sim.add_robot("a", model, 0.0, 1.0, 0.0)
    with pytest.raises(SpawnError, match=r"inside 'crate'"):
        sim.add_robot("a", model, 3.0, 3.0, 0.0)  # deep inside the box, far from its edges
    sim.add_robot("a", model, 0.0, 0.0, 0.0)
    with pytest.raises(SpawnError, match=r"inside 'a'"):
        sim.add_robot("b", model, 0.1, 0.0, 0.0)
    with pytest.raises(SpawnError, match="already exists"):
        sim.add_robot("a", model, -2.0, -2.0, 0.0)
    with pytest.raises(SpawnError, match="overlap robot"):
        sim.add_obstacle("bin", "cylinder", (0.3, 0.3), 0.2, 0.0, 0.0, 0.5, (1, 2, 3))
    sim.add_obstacle("bin", "cylinder", (0.3, 0.3), -2.0, -2.0, 0.0, 0.5, (1, 2, 3))
    sim.remove_obstacle("bin")
    with pytest.raises(SpawnError, match="no model"):
        sim.remove_obstacle("bin")


def test_two_robots_see_each_other():
    sim = Simulation(_empty())
    model = load_robot_model("puzzlebot")
    model.laser.noise = 0.0
    a = sim.add_robot("a", model, -1.0, 0.0, 0.0)
    b = sim.add_robot("b", model, 1.0, 0.0, math.pi)
    ra, rb = sim.scan(a), sim.scan(b)
    # beam 180 points forward (angle_min = -pi): 2 m between centres minus the other's radius
    assert ra[180] == pytest.approx(2.0 - 0.11, abs=1e-4)
    assert rb[180] == pytest.approx(2.0 - 0.11, abs=1e-4)
    assert np.isinf(ra[0]) and np.isinf(ra[90])


def test_lidar_ignores_obstacles_lower_than_it(tmp_path):
    (tmp_path / "w.yaml").write_text(
        "boxes:\n  - {center: [1, 0], size: [0.2, 2], height: 0.1}\n  - {center: [2, 0], size: [0.2, 2], height: 0.5}\n"
    )
    sim = Simulation(load_world(tmp_path / "w.yaml"))
    model = load_robot_model("puzzlebot")
    model.laser.noise = 0.0
    r = sim.add_robot("pb", model, 0.0, 0.0, 0.0)
    assert sim.scan(r)[180] == pytest.approx(1.9, abs=1e-4)


def test_camera_depth_and_colour(tmp_path):
    (tmp_path / "w.yaml").write_text(
        "walls:\n  - {from: [3, -5], to: [3, 5], thickness: 0, height: 2.0, color: '#ff0000'}\n"
    )
    sim = Simulation(load_world(tmp_path / "w.yaml"))
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    rgb, depth = sim.render(r)
    assert rgb.shape == (240, 320, 3) and depth.shape == (240, 320) and depth.dtype == np.uint16
    cam_x = r.model.camera.pose.xyz[0]
    # every wall pixel reads the optical-axis depth (mm) of the plane x = 3
    assert abs(int(depth[100, 160]) - round((3.0 - cam_x) * 1000)) <= 1
    assert abs(int(depth[100, 10]) - round((3.0 - cam_x) * 1000)) <= 1
    assert rgb[100, 160, 0] > 100 and rgb[100, 160, 1] == 0
    # the bottom row sees the floor in front of the camera: depth = z / tan(elevation)
    cam = r.camera
    expected_floor = cam.cam_z / -cam.row_slope[239]
    assert abs(int(depth[239, 160]) - round(expected_floor * 1000)) <= 1


def test_urdf_and_yaml_descriptions_agree():
    a = load_robot_model("puzzlebot")
    b = load_robot_model(str(ROBOTS_DIR / "puzzlebot.urdf"))
    for field in (
        "wheel_radius",
        "wheel_separation",
        "body_radius",
        "body_height",
        "left_joint",
        "right_joint",
    ):
        assert (
            getattr(a, field) == pytest.approx(getattr(b, field))
            if isinstance(getattr(a, field), float)
            else getattr(a, field) == getattr(b, field)
        )
    assert a.laser.pose.xyz == b.laser.pose.xyz and a.camera.pose.xyz == b.camera.pose.xyz


def test_bad_robot_description_names_field(tmp_path):
    from ninjemys.maps.mapfile import MapFileError

    p = tmp_path / "bad.yaml"
    p.write_text("wheel_radius: 0.05\nsensors:\n  laser:\n    frame: laser\n    range_min: 20\n")
    with pytest.raises(MapFileError, match="sensors.laser.range_min: must be below range_max"):
        load_robot_model(str(p))
    p.write_text("wheel_radius: -1\n")
    with pytest.raises(MapFileError, match=r"bad.yaml:1: wheel_radius: expected a number > 0"):
        load_robot_model(str(p))
    with pytest.raises(MapFileError, match="no such shipped robot"):
        load_robot_model("turtlebot9")


def test_reset_world_and_simulation():
    sim = Simulation(_empty())
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    r.command(0.3, 0.3)
    for _ in range(100):
        sim.step()
    sim.reset_world()
    assert (r.x, r.y, r.yaw, r.wl) == (0.0, 0.0, 0.0, 0.0) and sim.time == pytest.approx(1.0)
    sim.reset_simulation()
    assert sim.time == 0.0


def test_camera_sees_the_square_painted_on_the_floor():
    from ninjemys.sim.worlds import world_path

    sim = Simulation(load_world(world_path("square")))
    r = sim.add_robot(
        "pb", load_robot_model("puzzlebot"), 0.5, -0.6, math.pi / 2
    )  # facing the square's near side
    rgb, depth = sim.render(r)
    # the paint's yellow (230, 200, 60) lit as the floor by the sun: x (0.4 + 0.8 x 0.870) = x 1.096
    yellow = (rgb[:, :, 0] == 252) & (rgb[:, :, 1] == 219) & (rgb[:, :, 2] == 66)
    rows = np.flatnonzero(yellow.any(axis=1))
    assert yellow.sum() > 200 and rows.min() > r.camera.cy  # on the floor, below the horizon
    # the near side (y = 0, 3 cm wide) is 0.6 - 0.08 m ahead of the camera: its rows see the floor there
    near = rows.max()
    assert abs(r.camera.cam_z / -r.camera.row_slope[near] - 0.52) < 0.03
    assert int(depth[near, 160]) == round(r.camera.cam_z / -r.camera.row_slope[near] * 1000)


def test_spawn_model_xml_kinds():
    from ninjemys.maps.mapfile import MapFileError
    from ninjemys.sim.gazebo_api import parse_model_xml

    urdf = (ROBOTS_DIR / "puzzlebot.urdf").read_text()
    kind, model = parse_model_xml(urdf)
    assert kind == "robot" and model.wheel_separation == pytest.approx(0.18)
    assert parse_model_xml("")[0] == "robot" and parse_model_xml("puzzlebot")[1].name == "puzzlebot"
    box = parse_model_xml(
        '<robot name="b"><link name="l"><collision><geometry><box size="0.4 0.6 0.5"/></geometry></collision></link></robot>'
    )
    assert box[0] == "obstacle"
    assert (box[1].kind, box[1].size, box[1].height, box[1].colour) == (
        "box",
        (0.4, 0.6),
        0.5,
        (180, 130, 80),
    )
    assert box[1].bottom == pytest.approx(-0.25) and not box[1].static  # centred on its origin: falls
    # an SDF document goes through the SDF reader: its footprint, standing on the floor (a cylinder
    # centred on the model's origin reaches below it), as spawn_sdf_model places it
    kind, (cyl,) = parse_model_xml(
        "<sdf version='1.6'><model name='c'><link name='l'><collision name='x'><geometry><cylinder><radius>0.2</radius><length>1.0</length></cylinder></geometry></collision></link></model></sdf>"
    )
    assert kind == "sdf" and cyl.kind == "cylinder" and cyl.height == pytest.approx(1.0)
    assert np.abs(cyl.outline).max() == pytest.approx(0.2, abs=1e-9)
    with pytest.raises(MapFileError, match="missing attribute 'version'"):
        parse_model_xml("<sdf><model name='c'/></sdf>")
    with pytest.raises(SpawnError, match="not valid XML"):
        parse_model_xml("<robot")
    with pytest.raises(SpawnError, match="neither a differential-drive robot"):
        parse_model_xml("<robot name='x'><link name='l'/></robot>")


def test_an_obstacle_spawned_ahead_stops_a_moving_robot():
    sim = Simulation(_empty(), dt=0.01)
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    r.command(0.5, 0.0)
    for _ in range(20):
        sim.step()  # cruising in the open: the static world is not even looked at
    assert r.free is not None
    sim.add_obstacle("crate", "box", (0.2, 1.0), r.x + 0.6, 0.0, 0.0, 0.5, (1, 2, 3))
    for _ in range(300):
        sim.step()
    assert r.contact and r.contact_with == "crate"
    assert r.x == pytest.approx(sim.world.obstacles[-1].outline[:, 0].min() - r.model.body_radius, abs=0.005)


def test_time_step_changes_and_time_goes_on():
    """Gazebo's set_physics_properties time_step: later steps are that long, time and stamps go on
    from where they were (no jump), a reset brings time back to 0, bad steps are refused."""
    from ninjemys.sim.simcore import MAX_TIME_STEP

    sim = Simulation(load_world(ROBOTS_DIR.parent / "worlds" / "empty.yaml"), 0.01, 0)
    for _ in range(150):
        sim.step()
    assert sim.time_ns == 1_500_000_000
    sim.set_time_step(0.001)
    assert sim.time_ns == 1_500_000_000 and abs(sim.time - 1.5) < 1e-12
    for _ in range(250):
        sim.step()
    assert sim.time_ns == 1_750_000_000 and abs(sim.time - 1.75) < 1e-9
    for bad in (0.0, -0.01, math.inf, math.nan, MAX_TIME_STEP * 2):
        with pytest.raises(SpawnError, match="time_step"):
            sim.set_time_step(bad)
    assert sim.dt == 0.001
    sim.reset_simulation()
    assert sim.time == 0.0 and sim.time_ns == 0
    sim.step()
    assert sim.time_ns == 1_000_000
