"""The simulator's fast paths give the same answers as the plain ones: the camera's span masks and
masked paint against ``np.where``, the camera against a per-pixel renderer, the collision broad phase for moving obstacles,
and the simulation lock that the stepping thread hands over only when someone waits."""

from __future__ import annotations

import math
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from camera_reference import assert_matches_reference

from ninjemys.idl.loader import get_message_class
from ninjemys.sim import camera as sim_camera
from ninjemys.sim.puzzlebot_node import keep_freed_memory
from ninjemys.sim.raycast import cast_beams, cast_segments, prepare_segments
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.sensors import LidarCache, Scene, lidar_ranges
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.stepper import StepLock
from ninjemys.sim.world2d import load_world
from ninjemys.sim.worlds import world_path


@pytest.mark.parametrize("height", [1, 7, 240, 255, 256, 300])
def test_span_mask_and_masked_paint_equal_where(height):
    """The wrapping-subtraction span mask is ``top <= v < bottom`` per column (empty spans and spans
    touching the first or last row too, uint8 rows up to 255 and uint16 rows beyond), over the whole
    image and over a band of rows; the masked paint into a band of an image equals ``np.where``."""
    width = 37
    cam = sim_camera.Camera(width, height, 60.0, 0.12, 10.0)
    rng = np.random.default_rng(height)
    rows = np.arange(height)[:, None]
    for _ in range(20):
        top = rng.integers(0, height + 1, width).astype(cam._row_type)
        bottom = rng.integers(0, height + 1, width).astype(cam._row_type)
        top[:3], bottom[:3] = (0, height, 5 % (height + 1)), (height, 0, 5 % (height + 1))
        r0 = int(rng.integers(0, height))
        r1 = int(rng.integers(r0 + 1, height + 1))
        want = (rows >= top) & (rows < bottom)
        assert np.array_equal(cam._span_mask(top, bottom, 0, height).view(bool), want)
        band = cam._span_mask(top, bottom, r0, r1)
        assert band.dtype == np.uint8 and np.array_equal(band.view(bool), want[r0:r1])
        for image, per_column in (
            (rng.integers(0, 256, (height, width, 3), dtype=np.uint8), rng.integers(0, 256, (width, 3))),
            (rng.integers(0, 65536, (height, width), dtype=np.uint16), rng.integers(0, 65536, width)),
        ):
            expect = image.copy()
            expect[r0:r1] = np.where(
                want[r0:r1] if image.ndim == 2 else want[r0:r1, :, None],
                per_column.astype(image.dtype),
                image[r0:r1],
            )
            cam._paint(image[r0:r1], per_column.astype(image.dtype), band)
            assert np.array_equal(image, expect)


def test_camera_matches_a_per_pixel_renderer():
    """Colour and depth of the office seen from three poses, pixel by pixel."""
    sim = Simulation(load_world(world_path("office")), 0.01, 0)
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    for x, y, yaw in ((0.0, 0.0, 0.3), (-3.0, 0.2, 1.4), (2.5, -0.3, -2.0)):
        r.x, r.y, r.yaw = x, y, yaw
        assert_matches_reference(sim, r)


def walker_world(tmp_path: Path, waypoints: str) -> Simulation:
    (tmp_path / "w.yaml").write_text(
        "bounds: [-3, -3, 12, 3]\n"
        "moving:\n"
        f"  - {{name: walker, shape: cylinder, radius: 0.25, height: 1.0, speed: 0.5, waypoints: {waypoints}, loop: false}}\n"
    )
    return Simulation(load_world(tmp_path / "w.yaml"), dt=0.01)


def test_a_moving_obstacle_crossing_the_path_stops_the_robot(tmp_path):
    sim = walker_world(tmp_path, "[[1.5, -2.0], [1.5, 2.0]]")
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    r.command(0.3, 0.0)
    for _ in range(1000):
        sim.step()
        if r.contact:
            break
    assert r.contact and r.contact_with == "walker"
    wx, wy, _ = sim.world.moving[0].position(sim.world_time)
    gap = math.hypot(r.x - wx, r.y - wy) - 0.25 - r.model.body_radius
    assert -0.02 < gap < 0.01  # the walker is a 24-sided polygon inside its circle


def test_a_far_moving_obstacle_is_left_out_of_the_step(tmp_path):
    """The walker paces 8 m away: steps never build its outline, the sensors still see it."""
    sim = walker_world(tmp_path, "[[8.0, -1.0], [8.0, 1.0]]")
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    built = []
    outline = sim._mover_outline
    sim._mover_outline = lambda *a: built.append(a) or outline(*a)  # type: ignore[method-assign]
    r.command(0.2, 0.0)
    for _ in range(100):
        sim.step()
    assert not built and not r.contact
    ranges = sim.scan(r)
    assert built  # the scan builds it
    wx, wy, _ = sim.world.moving[0].position(sim.world_time)
    nearest = math.hypot(wx - r.x, wy - r.y) - 0.25
    assert float(np.min(ranges)) == pytest.approx(nearest, abs=0.06)


def test_step_lock_gives_way_only_to_waiters():
    lock = StepLock()
    t = time.monotonic()
    lock.give_way(2.0)
    assert time.monotonic() - t < 0.5  # nobody waits: no pause at all
    got = threading.Event()

    def service() -> None:
        with lock:
            time.sleep(0.05)
            got.set()

    lock.stepping.acquire()
    worker = threading.Thread(target=service)
    worker.start()
    time.sleep(0.05)  # the service now waits for the lock
    lock.stepping.release()
    lock.give_way(5.0)  # returns once the service has had the lock and let it go
    assert got.is_set()
    worker.join(5)
    with lock, lock:  # reentrant
        pass
    t = time.monotonic()
    lock.give_way(2.0)
    assert time.monotonic() - t < 0.5


def test_keep_freed_memory_is_harmless():
    assert keep_freed_memory() in (True, False)
    a = np.ones(1 << 20)
    assert float(a.sum()) == 1 << 20


def brute_force_cast(ox, oy, angles, segments, max_range):  # type: ignore[no-untyped-def]
    """Every ray against every segment."""
    dx, dy = np.cos(angles)[:, None], np.sin(angles)[:, None]
    px, py = segments[None, :, 0] - ox, segments[None, :, 1] - oy
    ex, ey = segments[None, :, 2] - segments[None, :, 0], segments[None, :, 3] - segments[None, :, 1]
    denom = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (px * ey - py * ex) / denom
        u = (px * dy - py * dx) / denom
    t = np.where((u >= -1e-9) & (u <= 1 + 1e-9) & (t >= 0) & np.isfinite(t), t, np.inf)
    dist = t.min(axis=1)
    return np.where(dist <= max_range, dist, np.inf)


@pytest.mark.parametrize("seed", range(6))
def test_cast_segments_equals_brute_force(seed):
    """Random segments (some out of range, some crossing the rays' first angle), lidar-like and
    camera-like fans and scattered rays."""
    rng = np.random.default_rng(seed)
    start = rng.uniform(-15, 15, (300, 2))
    segments = np.hstack([start, start + rng.uniform(-3, 3, (300, 2))])
    for angles in (
        np.linspace(-math.pi, math.pi, 360, endpoint=False) + rng.uniform(-3, 3),
        rng.uniform(-3, 3) + np.arctan((159.5 - np.arange(320)) / 233.0),
        rng.uniform(-10, 10, 40),
    ):
        ox, oy = rng.uniform(-5, 5, 2)
        for max_range in (12.0, 2.0):
            dist, hit = cast_segments(ox, oy, angles, segments, max_range)
            expected = brute_force_cast(ox, oy, angles, segments, max_range)
            assert np.array_equal(np.isinf(dist), np.isinf(expected))
            seen = np.isfinite(dist)
            assert np.allclose(dist[seen], expected[seen], rtol=0, atol=1e-9)
            assert (hit[seen] >= 0).all() and (hit[~seen] == -1).all()


def random_lidar_scene(rng: np.random.Generator, moving: int, facing: bool) -> Scene:
    """300 random segments (some lower than a lidar, some held above it, with ``facing`` some
    said to face a way, as if sides of outlines), the last ``moving`` of them after the scene's
    static prefix, as a moving obstacle's are."""
    k = 300
    start = rng.uniform(-15, 15, (k, 2))
    segments = np.hstack([start, start + rng.uniform(-3, 3, (k, 2))])
    heights = rng.choice([0.1, 0.5, 1.2], k)
    bases = np.where(rng.random(k) < 0.1, 0.3, 0.0)
    facing = rng.choice(np.array([-1, 0, 1], dtype=np.int8), k) * np.int8(facing)
    facing[k - moving :] = 0
    empty = np.zeros((0, 2))
    return Scene(
        segments, heights, np.zeros((k, 3), np.uint8), empty, np.zeros(0), np.zeros(0),
        np.zeros((0, 3), np.uint8), facing=facing, bases=bases, prefix=segments[: k - moving],
    )  # fmt: skip


@pytest.mark.parametrize("seed", range(4))
def test_lidar_ranges_equal_brute_force(seed):
    """A lidar's scan (its static segments prepared once and kept in a cache, the moving ones cast
    with them) against every beam x every segment it can see: a full turn from the back, a full
    turn whose last beam is its first again (Gazebo's -pi..pi), a narrow fan; then the same scans
    from a fresh cache, bit for bit."""
    rng = np.random.default_rng(seed)
    scene = random_lidar_scene(rng, moving=24, facing=False)
    seen = (scene.heights >= 0.17) & (scene.bases <= 0.17)
    cache = LidarCache()
    fans = ((-math.pi, 2 * math.pi / 360, 360), (-math.pi, 2 * math.pi / 359, 360), (-0.4, 0.01, 81))
    scans = []
    for _ in range(3):
        x, y, yaw = *rng.uniform(-5, 5, 2), rng.uniform(-10, 10)
        for angle_min, inc, beams in fans:
            for max_range in (12.0, 3.0):
                ranges = lidar_ranges(
                    scene, x, y, 0.17, yaw, angle_min, inc, beams, 0.0, max_range, 0.0, rng, cache
                )
                angles = yaw + angle_min + inc * np.arange(beams)
                expected = brute_force_cast(x, y, angles, scene.segments[seen], max_range).astype(np.float32)
                assert np.array_equal(np.isinf(ranges), np.isinf(expected))
                assert np.allclose(ranges[np.isfinite(ranges)], expected[np.isfinite(expected)], rtol=1e-6)
                scans.append((x, y, yaw, angle_min, inc, beams, max_range, ranges))
    for x, y, yaw, angle_min, inc, beams, max_range, ranges in scans:
        again = lidar_ranges(scene, x, y, 0.17, yaw, angle_min, inc, beams, 0.0, max_range, 0.0, rng)
        assert np.array_equal(again, ranges)


@pytest.mark.parametrize("seed", range(4))
def test_cast_beams_equals_cast_segments(seed):
    """The lidar's cast (prepared segments, beams in order, moving segments apart) meets what
    cast_segments meets from the same segments, bit for bit: the same pairs, the same sums."""
    rng = np.random.default_rng(seed)
    scene = random_lidar_scene(rng, moving=24, facing=True)
    k = len(scene.prefix)
    prepared = prepare_segments(scene.prefix, scene.facing[:k])
    for _ in range(5):
        x, y = rng.uniform(-5, 5, 2)
        angles = rng.uniform(-10, 10) + (2 * math.pi / 360) * np.arange(360)
        for max_range in (12.0, 3.0):
            dist = cast_beams(x, y, angles, prepared, max_range, extra=scene.segments[k:], in_order=True)
            expected, _ = cast_segments(x, y, angles, scene.segments, max_range, scene.facing)
            assert np.array_equal(dist, expected)


def valid_poses(sim: Simulation, count: int, seed: int) -> list[tuple[float, float, float]]:
    """Poses a robot can stand at (its body clear of everything), spread over the world."""
    rng = np.random.default_rng(seed)
    lo, hi = sim._static.min(axis=0)[:2], sim._static.max(axis=0)[:2]
    out: list[tuple[float, float, float]] = []
    while len(out) < count:
        x, y = rng.uniform(lo[0], hi[0]), rng.uniform(lo[1], hi[1])
        if not sim.solid_at(x, y) and sim.clearance(x, y)[0] >= 0.11:
            out.append((x, y, rng.uniform(-math.pi, math.pi)))
    return out


@pytest.mark.parametrize("world", ["office", "maze"])
def test_casts_that_skip_back_faces_see_the_same(world):
    """Leaving out the sides of convex outlines that face away from the eye changes no scan and no
    camera image, from anywhere a robot can stand (the eye is then outside every obstacle)."""
    sim = Simulation(load_world(world_path(world)), 0.01, 0)
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    assert (sim._static_facing != 0).sum() > len(sim._static_facing) // 2  # most sides are culled
    for x, y, yaw in valid_poses(sim, 25, 3):
        r.x, r.y, r.yaw = x, y, yaw
        scene = sim.scene(r.name)
        plain = Scene(**{**scene.__dict__, "facing": None})
        angles = yaw + np.linspace(-math.pi, math.pi, 360, endpoint=False)
        culled, _ = cast_segments(x, y, angles, scene.segments, 12.0, scene.facing)
        full, _ = cast_segments(x, y, angles, scene.segments, 12.0)
        assert np.array_equal(culled, full)
        for a, b in zip(sim.render(r, scene), sim.render(r, plain), strict=True):
            assert np.array_equal(a, b)


def test_obstacle_facing():
    """+1 for convex counter-clockwise outlines, -1 clockwise, 0 for thin walls and concave ones."""
    from ninjemys.sim.world2d import Obstacle, box_outline, circle_outline

    box = box_outline(1.0, 2.0, 1.0, 0.5, 0.7)
    assert Obstacle("b", "box", box, 1.0, (0, 0, 0)).facing() == 1
    assert Obstacle("b", "box", box[::-1], 1.0, (0, 0, 0)).facing() == -1
    assert Obstacle("c", "cylinder", circle_outline(0, 0, 0.3), 1.0, (0, 0, 0)).facing() == 1
    thin = np.array([[0.0, 0.0], [1.0, 0.0]])
    assert Obstacle("w", "wall", thin, 1.0, (0, 0, 0)).facing() == 0
    ell = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=float)  # an L: concave
    assert Obstacle("l", "wall", ell, 1.0, (0, 0, 0)).facing() == 0


@pytest.mark.parametrize("world", ["office", "square"])
def test_camera_draws_only_the_images_asked_for(world):
    """Colour alone and depth alone are the same images as both together (the other one empty)."""
    sim = Simulation(load_world(world_path(world)), 0.01, 0)
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    for x, y, yaw in valid_poses(sim, 6, 5):
        r.x, r.y, r.yaw = x, y, yaw
        rgb, depth = sim.render(r)
        rgb_only, no_depth = sim.render(r, depth=False)
        no_rgb, depth_only = sim.render(r, colour=False)
        assert np.array_equal(rgb, rgb_only) and np.array_equal(depth, depth_only)
        assert no_depth.size == 0 and no_rgb.size == 0
        assert rgb.shape == (240, 320, 3) and depth.shape == (240, 320)


def _drive(sim: Simulation, name: str, steps: int) -> list[tuple[float, float, float, bool, str]]:
    """Poses and contacts of robot ``name`` driving a fixed sequence of commands (into a wall too)."""
    r = sim.robots[name]
    out = []
    for i in range(steps):
        if i % 300 == 0:
            r.command((0.4, 0.2, 0.0)[(i // 300) % 3], (0.0, 0.9, -0.6)[(i // 300) % 3])
        sim.step()
        out.append((r.x, r.y, r.yaw, r.contact, r.contact_with))
    return out


def test_a_step_alone_in_open_space_moves_as_the_checked_step():
    """A robot alone in the world, in open space, skips the collision samples along its move (no
    arrays built): it drives, turns and stops at the wall exactly as when a second robot elsewhere
    in the world makes every step go through the full check."""
    world = world_path("square")
    alone = Simulation(load_world(world), 0.01, 3)
    alone.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.3)
    checked = Simulation(load_world(world), 0.01, 3)
    checked.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.3)
    checked.add_robot("far", load_robot_model("puzzlebot"), -1.2, -1.2, 0.0)  # never in reach
    calls = {"full": 0}
    real = checked._clearances

    def counted(*args):
        calls["full"] += 1
        return real(*args)

    checked._clearances = counted  # type: ignore[method-assign]
    a, b = _drive(alone, "pb", 2400), _drive(checked, "pb", 2400)
    assert a == b
    assert any(c for *_, c, _w in a), "the drive must reach a wall"
    assert calls["full"] >= 1000  # the checked run did check its moving steps


@pytest.mark.parametrize("world", ["office", "walker"])
def test_a_step_with_movers_out_of_reach_moves_as_the_checked_step(world, tmp_path):
    """A robot alone, in its free disk, with no moving obstacle within reach, builds no collision
    geometry at all; it moves, meets the walker crossing its path (or the office's person and walls)
    exactly as when every step goes through the full broad phase."""

    def build(fast: bool) -> tuple[Simulation, list[int]]:
        if world == "office":
            sim = Simulation(load_world(world_path("office")), 0.01, 3)
            sim.add_robot("pb", load_robot_model("puzzlebot"), 3.0, 0.0, 0.0)  # in the person's way
        else:  # the walker paces across the robot's path, back and forth
            sim = walker_world(tmp_path, "[[1.2, -2.5], [1.2, 2.5], [1.2, -2.5], [1.2, 2.5]]")
            sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
        built: list[int] = []
        geometry = sim._collision_geometry

        def counted(*args, **kwargs):
            built.append(1)
            return geometry(*args, **kwargs)

        sim._collision_geometry = counted  # type: ignore[method-assign]
        if not fast:
            sim._any_mover_near = lambda *_a: True  # type: ignore[method-assign]
        return sim, built

    (fast, fast_built), (checked, checked_built) = build(True), build(False)
    a, b = _drive(fast, "pb", 3000), _drive(checked, "pb", 3000)
    assert a == b
    person = [m.position(s.world_time) for s in (fast, checked) for m in s.world.moving]
    assert person[0] == person[1]
    met = {w for *_, c, w in a if c}
    assert met, "the drive must meet the person, the walker or a wall"
    if world == "walker":
        assert met == {"walker"}
    assert len(checked_built) >= 1000 and len(fast_built) < len(checked_built) // 2


def test_rays_in_order_and_shuffled_meet_the_same():
    """segment_pairs skips its sort when the rays come in order (a lidar's beams): each ray's hit is
    bit for bit the one it gets from the same rays shuffled (which are sorted first)."""
    sim = Simulation(load_world(world_path("office")), 0.01, 0)
    scene = sim.scene()
    rng = np.random.default_rng(5)
    for x, y, yaw in valid_poses(sim, 10, 7):
        angles = yaw - math.pi + (2.0 * math.pi / 360) * np.arange(360)
        perm = rng.permutation(360)
        in_order = cast_segments(x, y, angles, scene.segments, 12.0, scene.facing)
        shuffled = cast_segments(x, y, angles[perm], scene.segments, 12.0, scene.facing)
        for ordered, mixed in zip(in_order, shuffled, strict=True):
            assert np.array_equal(ordered[perm], mixed)


#: a red board 1.5 m ahead with no collision (an ArUco tag): the camera sees it, the lidar does not
VISUAL_BOARD_WORLD = (
    '<sdf version="1.6"><world name="w"><model name="aruco"><static>true</static>'
    '<pose>1.5 0 0.2 0 0 0</pose><link name="tag"><visual name="face"><geometry><box>'
    "<size>0.02 0.4 0.4</size></box></geometry></visual></link></model></world></sdf>"
)


@pytest.mark.parametrize("visual", [False, True], ids=["office", "visual-only board"])
def test_sensors_firing_in_one_step_share_its_scene(visual: bool) -> None:
    """The lidar and the camera firing in the same step see one scene, built once for that step
    and dropped after it (the next step's world has moved); in a world with a visual-only piece
    the lidar gets its own scene without it (it must not see the board the camera sees)."""
    from ninjemys.node import Node
    from ninjemys.node.log import NodeLog
    from ninjemys.sim.puzzlebot_node import SimNode
    from ninjemys.sim.sdf import parse_sdf_world
    from ninjemys.testing import run_master, wait_until

    world = (
        parse_sdf_world(VISUAL_BOARD_WORLD, "w.world", {"HOME": "/nonexistent"})
        if visual
        else load_world(world_path("office"))
    )
    with run_master() as master:
        node = Node("scene_share_sim", master_uri=master)
        client = Node("scene_share_client", master_uri=master)
        try:
            sn = SimNode(node, NodeLog(node.name), Simulation(world, 0.01), 0.0, None)
            io = sn.add_robot("puzzlebot", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0, False)
            built: list[tuple[str | None, bool]] = []
            scans: list[tuple[object, np.ndarray]] = []
            renders: list[object] = []
            real_scene, real_scan, real_render = sn.sim.scene, sn.sim.scan, sn.sim.render

            def scene(exclude=None, solid_only=False):
                built.append((exclude, solid_only))
                return real_scene(exclude, solid_only)

            def scan(r, scene=None, laser=None):
                ranges = real_scan(r, scene, laser)
                scans.append((scene, ranges))
                return ranges

            def render(r, scene=None, **kw):
                renders.append(scene)
                return real_render(r, scene, **kw)

            sn.sim.scene, sn.sim.scan, sn.sim.render = scene, scan, render  # type: ignore[method-assign]
            model = io.robot.model
            assert model.laser is not None and model.camera is not None
            subs = [
                client.subscriber(
                    "/" + model.laser.topic, get_message_class("sensor_msgs/LaserScan"), lambda _m: None
                ),
                client.subscriber(
                    "/" + model.camera.image_topic, get_message_class("sensor_msgs/Image"), lambda _m: None
                ),
            ]
            wait_until(
                lambda: io.pubs["scan"].get_num_connections() and io.pubs["image"].get_num_connections(),
                10,
                "the subscribers",
            )
            io.scan_due.next = io.camera_due.next = sn.sim.time + sn.sim.dt  # both fire next step
            sn._step_and_publish()
            assert len(scans) == 1 and len(renders) == 1
            (scan_scene, ranges), (render_scene,) = scans[0], renders
            assert scan_scene is not None and render_scene is not None
            if visual:
                assert built == [("puzzlebot", True), ("puzzlebot", False)]
                assert len(scan_scene.segments) < len(render_scene.segments)
                assert float(np.min(ranges[np.isfinite(ranges)], initial=np.inf)) > 1.6  # not the board
            else:
                assert built == [("puzzlebot", True)] and scan_scene is render_scene
            assert sn._scenes == {}
            for sub in subs:
                sub.unregister()
        finally:
            client.shutdown("test over")
            node.shutdown("test over")
