"""The PuzzleBot simulation itself: robots in a world, stepped in simulated time. No ROS in here.

:class:`Simulation` owns the world, the robots and simulated time. :meth:`Simulation.step` advances
one physics step (``dt``): wheel speeds move toward the commanded ones within the acceleration
limit, the body moves along the exact arc those speeds give, and a swept collision check stops it
at first contact (the move is split into pieces shorter than half the body radius, so nothing
thinner than that is ever jumped over, then the contact point is found by bisection). Odometry
follows the true motion with amcl's diff-drive noise model (α1-α4) applied per odometry period.

The ROS node (:mod:`ninjemys.sim.puzzlebot_node`) turns commands into :meth:`Robot.command` calls
and publishes what the sensors here compute.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ninjemys.errors import NinjemysError
from ninjemys.sim.camera import Camera
from ninjemys.sim.raycast import grid_edges
from ninjemys.sim.robot_model import CameraSpec, LaserSpec, RobotModel
from ninjemys.sim.sensors import FloorPaint, LidarCache, Scene, imu_reading, lidar_ranges
from ninjemys.sim.world2d import MovingObstacle, Obstacle, World, box_outline, circle_outline

TRAIL_LENGTH = 2000
#: m: a piece whose top is at most this far above a robot's feet is under it (what it stands on)
STANDS_ON = 1e-3
PERSONAL_SPACE = 0.2  # m: the gap a person who gives way keeps from a robot's body
LOOK_AHEAD = 2.0  # m: how far ahead on its route such a person starts to step aside
#: a robot is spawned when its body circle overlaps something by less than this share of its radius
SPAWN_OVERLAP = 0.5
#: the longest physics step set_physics_properties accepts (s): the collision check splits a move
#: into short pieces, but sensors fire at most once a step, so a longer one would slow a 10 Hz lidar
MAX_TIME_STEP = 0.1

#: shared empty results of the collision broad phase (never written to): a step in open space, or
#: a robot alone in the world, builds no arrays for them
_NONE_BLOCKED = np.zeros(0, dtype=np.intp)
_NO_CENTRES = np.zeros((0, 2))
_NO_RADII = np.zeros(0)
_NO_COLOURS = np.zeros((0, 3), dtype=np.uint8)


class SpawnError(NinjemysError, ValueError):
    """A spawn or delete the simulation refuses; the text says why (shown to the service caller)."""


def scan_angles(spec: LaserSpec) -> tuple[float, float, float]:
    """(angle_min, angle_max, increment) of a laser. ``angle_max`` None is a full turn less one
    increment (our PuzzleBot's 360 beams from the back); otherwise the beams span
    [angle_min, angle_max] inclusive, as Gazebo's ray sensor spreads its samples; one beam: increment 0."""
    if spec.angle_max is None:
        inc = 2.0 * math.pi / spec.beams
        return spec.angle_min, spec.angle_min + inc * (spec.beams - 1), inc
    inc = (spec.angle_max - spec.angle_min) / (spec.beams - 1) if spec.beams > 1 else 0.0
    return spec.angle_min, spec.angle_max, inc


_PI = math.pi
_TWO_PI = 2.0 * math.pi


def wrap_angle(a: float) -> float:
    return (a + _PI) % _TWO_PI - _PI


def point_segment_distance(px: np.ndarray, py: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """(P, N) distances from P points to N segments."""
    ax, ay = segs[:, 0], segs[:, 1]
    ex, ey = segs[:, 2] - ax, segs[:, 3] - ay
    ee = ex * ex + ey * ey
    wx = px[:, None] - ax[None, :]
    wy = py[:, None] - ay[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.clip((wx * ex + wy * ey) / ee, 0.0, 1.0)
    u = np.where(ee > 0, u, 0.0)
    dx = wx - u * ex
    dy = wy - u * ey
    return np.sqrt(dx * dx + dy * dy)


@dataclass
class Robot:
    """One robot's state: true pose, wheels, command, odometry and contact."""

    name: str
    model: RobotModel
    x: float
    y: float
    yaw: float
    start: tuple[float, float, float]
    rng: np.random.Generator
    wl: float = 0.0  # actual wheel speeds (rad/s)
    wr: float = 0.0
    target: tuple[float, float] = (0.0, 0.0)  # commanded (wl, wr): one tuple, so a command is atomic
    left_angle: float = 0.0
    right_angle: float = 0.0
    v: float = 0.0
    w: float = 0.0
    v_prev: float = 0.0
    odom: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    odom_ref: tuple[float, float, float] = (0.0, 0.0, 0.0)  # true pose at the last odometry sample
    contact: bool = False
    contact_with: str = ""
    trail: deque = field(default_factory=lambda: deque(maxlen=TRAIL_LENGTH))
    trail_count: int = 0  # points ever appended (the view sends only the new ones)
    free: tuple[float, float, float] | None = None  # (x, y, r): a disk free of static geometry
    #: spawned with its body overlapping this (name, metres): it may only move away from it
    spawn_overlap: tuple[str, float] | None = None
    camera: Camera | None = None
    extra_cameras: list[Camera] = field(default_factory=list)  # for model.extra_cameras, in order
    #: the height of what it stands on (0: the floor; 0.75: a table top it was spawned over): its
    #: body spans [elevation, elevation + body_height] and its sensors ride that much higher
    elevation: float = 0.0
    start_elevation: float = 0.0  # where reset_world puts it back

    def command(self, linear: float, angular: float) -> None:
        """Set the body velocity to reach (cmd_vel): wheel targets, scaled together to the speed limit."""
        m = self.model
        # the drive's own kinematics (a Gazebo plugin's wheelSeparation/wheelDiameter), the body's otherwise
        sep = m.drive.wheel_separation or m.wheel_separation
        rad = m.drive.wheel_radius or m.wheel_radius
        wr = (linear + angular * sep / 2.0) / rad
        wl = (linear - angular * sep / 2.0) / rad
        peak = max(abs(wl), abs(wr))
        if peak > m.max_wheel_speed:
            wl *= m.max_wheel_speed / peak
            wr *= m.max_wheel_speed / peak
        self.target = (wl, wr)

    def reset(self) -> None:
        self.x, self.y, self.yaw = self.start
        self.wl = self.wr = 0.0
        self.target = (0.0, 0.0)
        self.left_angle = self.right_angle = 0.0
        self.v = self.w = self.v_prev = 0.0
        self.odom = [0.0, 0.0, 0.0]
        self.odom_ref = self.start
        self.contact = False
        self.contact_with = ""
        self.trail.clear()
        self.trail_count = 0
        self.free = None


class Simulation:
    """Robots in a world; ``time`` is simulated seconds. Not thread-safe: the node holds a lock."""

    def __init__(self, world: World, dt: float = 0.01, seed: int = 0) -> None:
        self.world = world
        self.dt = dt
        self.seed = seed
        self.steps = 0
        # the step may change (Gazebo's set_physics_properties): time counts whole steps since then
        self._since = (0, 0)  # (steps, nanoseconds) when the current step began
        self.world_time = 0.0  # moving obstacles' clock (reset_world restarts it, time goes on)
        self.robots: dict[str, Robot] = {}
        self.obstacle_yaw: dict[str, float] = {}  # yaw of spawned or moved obstacles (outlines have none)
        self.obstacle_origin: dict[str, tuple[float, float]] = {}  # spawned models: their pose's x, y
        self._spawned = 0
        self._static: np.ndarray
        self.static_names: list[str] = []
        self._movers_at: tuple[float, tuple] | None = None
        self._mover_fixed: tuple | None = None
        self._mover_joined: tuple[np.ndarray, np.ndarray, list[str]] | None = None
        self._floor = floor_paint(world)
        #: what the lidars' scans reuse from one to the next (the static world prepared per height)
        self._lidar = LidarCache()
        for name, (x, y, yaw) in world.model_poses.items():  # an SDF world's models: their own poses
            self.obstacle_origin[name] = (x, y)
            self.obstacle_yaw[name] = yaw
        self._rebuild_static()

    @property
    def time(self) -> float:
        """Simulated seconds: a whole number of steps, so stamps never drift."""
        steps0, ns0 = self._since
        if not ns0:
            return self.steps * self.dt
        return ns0 / 1e9 + (self.steps - steps0) * self.dt

    @property
    def time_ns(self) -> int:
        """Simulated time in whole nanoseconds (message stamps), exact over any number of steps."""
        steps0, ns0 = self._since
        return ns0 + round((self.steps - steps0) * self.dt * 1e9)

    def clock(self) -> tuple[float, int]:
        """(:attr:`time`, :attr:`time_ns`) in one call (the node reads both every step)."""
        steps0, ns0 = self._since
        if not ns0:
            return self.steps * self.dt, round(self.steps * self.dt * 1e9)
        since = (self.steps - steps0) * self.dt
        return ns0 / 1e9 + since, ns0 + round(since * 1e9)

    def set_time_step(self, dt: float) -> None:
        """Step ``dt`` seconds from now on (Gazebo's ``set_physics_properties`` time_step); time
        goes on from where it is. Refused (SpawnError) unless 0 < dt <= MAX_TIME_STEP."""
        if not (math.isfinite(dt) and 0.0 < dt <= MAX_TIME_STEP):
            raise SpawnError(f"time_step {dt} must be in (0, {MAX_TIME_STEP:g}] s")
        self._since = (self.steps, self.time_ns)
        self.dt = dt

    # -- geometry -------------------------------------------------------------------------------
    def _rebuild_static(self) -> None:
        w = self.world
        w.rebuild()
        segs, heights, colours = [w.segments], [w.seg_height], [w.seg_color]
        facing, bases, owners = [w.seg_facing], [w.seg_base], [w.seg_owner]
        names = [w.obstacles[i].name for i in w.seg_owner]
        if w.grid is not None:
            g = w.grid
            edges = grid_edges(g.occupied, g.resolution, g.origin_x, g.origin_y)
            segs.append(edges)
            facing.append(np.zeros(len(edges), dtype=np.int8))
            heights.append(np.full(len(edges), g.height))
            bases.append(np.zeros(len(edges)))
            owners.append(np.full(len(edges), -1))
            colours.append(np.tile(np.array(g.color, dtype=np.uint8), (len(edges), 1)))
            names += ["map"] * len(edges)
        self._static = np.vstack(segs) if any(len(s) for s in segs) else np.zeros((0, 4))
        self._static_height = np.concatenate(heights)
        self._static_base = np.concatenate(bases)
        #: the static world has something held above the floor (a table top): sensors and robots pass under it
        self._any_base = bool((self._static_base > 0).any())
        self._static_color = np.vstack(colours).astype(np.uint8)
        self._static_facing = np.concatenate(facing).astype(np.int8)
        self._static_owner = np.concatenate(owners).astype(np.intp)
        self.static_names = names
        # visuals without collision (ArUco boards): drawn by the camera, passed through by all else
        solid = np.ones(len(self._static), dtype=bool)
        solid[: len(w.seg_owner)] = [w.obstacles[i].solid for i in w.seg_owner]
        self._static_solid = solid
        self._any_visual = not bool(solid.all())
        for r in self.robots.values():
            r.free = None  # the static world changed
        st = self._static
        self._scene_cache: dict[tuple[bool, int], tuple] = {}  # see _scene_parts
        self._static_lo = np.minimum(st[:, :2], st[:, 2:])  # bounding boxes for the collision broad phase
        self._static_hi = np.maximum(st[:, :2], st[:, 2:])
        self._movers_at = None

    def map_edges(self) -> np.ndarray:
        """The outline of the world's occupancy grid as segments (empty without a map)."""
        return self._static[len(self.world.segments) :]

    def _mover_segments(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
        """Moving obstacles' outlines now (computed once per step: collision and sensors share them)."""
        if self._movers_at is not None and self._movers_at[0] == self.world_time:
            return self._movers_at[1]
        out = self._compute_mover_segments()
        self._movers_at = (self.world_time, out)
        return out

    def _mover_shapes(self) -> tuple:
        """What does not move about the moving obstacles, built once: heights, colours and names per
        outline segment, each mover's outline as segments centred on the origin (boxes are turned to
        their heading at each step), and each mover's bounding radius (for the collision broad phase)."""
        if self._mover_fixed is None:
            heights, colours, names, shapes, bounds = [], [], [], [], []
            for m in self.world.moving:
                if m.kind == "cylinder":
                    outline = circle_outline(0.0, 0.0, m.size[0])
                else:
                    outline = box_outline(0.0, 0.0, m.size[0], m.size[1], 0.0)
                shapes.append(np.hstack([outline, np.roll(outline, -1, axis=0)]))
                bounds.append(float(np.hypot(outline[:, 0], outline[:, 1]).max()))
                heights.append(np.full(len(outline), m.height))
                colours.append(np.tile(np.array(m.color, dtype=np.uint8), (len(outline), 1)))
                names.append([m.name] * len(outline))
            self._mover_fixed = (heights, colours, names, shapes, bounds)
        return self._mover_fixed

    def _mover_outline(self, index: int, x: float, y: float, heading: float) -> np.ndarray:
        """Mover ``index``'s outline segments at pose (x, y, heading)."""
        m = self.world.moving[index]
        segs = self._mover_shapes()[3][index]
        if m.kind != "cylinder":
            c, s = math.cos(heading), math.sin(heading)
            turn = np.array([[c, s, 0.0, 0.0], [-s, c, 0.0, 0.0], [0.0, 0.0, c, s], [0.0, 0.0, -s, c]])
            segs = segs @ turn
        return segs + (x, y, x, y)

    def _compute_mover_segments(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
        movers = self.world.moving
        if not movers:
            return np.zeros((0, 4)), np.zeros(0), np.zeros((0, 3), dtype=np.uint8), []
        if self._mover_joined is None:  # what does not move, joined once
            heights, colours, names, _, _ = self._mover_shapes()
            self._mover_joined = (np.concatenate(heights), np.vstack(colours), [n for g in names for n in g])
        joined_heights, joined_colours, joined_names = self._mover_joined
        segs = [self._mover_outline(i, *m.position(self.world_time)) for i, m in enumerate(movers)]
        return np.vstack(segs), joined_heights, joined_colours, joined_names

    def _movers_near(self, x: float, y: float, reach: float) -> tuple[np.ndarray, list[str]]:
        """Outline segments and names of the moving obstacles that come within ``reach`` of (x, y)
        now; the others are left out without building their outlines (a step's broad phase)."""
        if not self.world.moving:
            return self._static[:0], []
        if self._movers_at is not None and self._movers_at[0] == self.world_time:
            ms, _, _, mnames = self._movers_at[1]  # the sensors built them all this step already
            return ms, mnames
        _, _, names, _, bounds = self._mover_shapes()
        segs, near_names = [], []
        for i, m in enumerate(self.world.moving):
            mx, my, heading = m.position(self.world_time)
            if math.hypot(mx - x, my - y) <= reach + bounds[i]:
                segs.append(self._mover_outline(i, mx, my, heading))
                near_names += names[i]
        return (np.vstack(segs) if segs else self._static[:0]), near_names

    def _any_mover_near(self, x: float, y: float, reach: float) -> bool:
        """Whether some moving obstacle comes within ``reach`` of (x, y) now: the test
        :meth:`_movers_near` makes, without building any outline."""
        moving = self.world.moving
        if not moving:
            return False
        bounds = self._mover_shapes()[4]
        t = self.world_time
        for i, m in enumerate(moving):
            mx, my, _ = m.position(t)
            if math.hypot(mx - x, my - y) <= reach + bounds[i]:
                return True
        return False

    @property
    def has_visuals(self) -> bool:
        """Some static piece is only drawn, not solid (an ArUco board): a lidar's scene then differs
        from a camera's (see :meth:`scene`)."""
        return self._any_visual

    def scene(self, exclude: str | None = None, solid_only: bool = False) -> Scene:
        """Everything seen now by robot ``exclude`` (its own body left out): by a camera, or with
        ``solid_only`` by a lidar (visuals without collision left out)."""
        ms, mh, mc, _ = self._mover_segments()
        static, heights, colours, bases, facing, owners = self._scene_parts(
            solid_only and self._any_visual, mh, mc
        )
        segs = np.concatenate([static, ms]) if len(ms) else static
        others = [r for r in self.robots.values() if r.name != exclude]
        if others:
            circles = (
                np.array([[r.x, r.y] for r in others]),
                np.array([r.model.body_radius for r in others]),
                np.array([r.model.body_height for r in others]),
                np.array([r.model.color for r in others], dtype=np.uint8).reshape(-1, 3),
            )
        else:  # alone in the world: the shared empty arrays (a scene is only read)
            circles = (_NO_CENTRES, _NO_RADII, _NO_RADII, _NO_COLOURS)
        return Scene(
            segs,
            heights,
            colours,
            *circles,
            self._floor,
            facing,
            bases,
            owners,
            self.world.look,
            static,
        )

    def _scene_parts(self, solid: bool, mh: np.ndarray, mc: np.ndarray) -> tuple:
        """What a scene holds besides the moving obstacles' segments, which alone change from step to
        step: the static segments (``solid``: the solid ones only) and every segment's height,
        colour, base, facing and owner, the movers' included. Built once per static world and kind
        of scene (a scene is only read), not at each of the 40 scenes a simulated second."""
        key = (solid, len(mh))
        parts = self._scene_cache.get(key)
        if parts is not None:
            return parts
        static, s_height, s_color = self._static, self._static_height, self._static_color
        s_base, s_facing, s_owner = self._static_base, self._static_facing, self._static_owner
        if solid:
            keep = self._static_solid
            static, s_height, s_color = static[keep], s_height[keep], s_color[keep]
            s_base, s_facing, s_owner = s_base[keep], s_facing[keep], s_owner[keep]
        n = len(mh)
        heights = np.concatenate([s_height, mh]) if n else s_height
        colours = np.vstack([s_color, mc]) if n else s_color
        bases = None
        if self._any_base:
            bases = np.concatenate([s_base, np.zeros(n)]) if n else s_base
        # a moving obstacle may walk over a robot (the camera inside it sees its inside): both sides
        facing = np.concatenate([s_facing, np.zeros(n, dtype=np.int8)]) if n else s_facing
        owners = np.concatenate([s_owner, np.full(n, -1)]) if n else s_owner
        parts = self._scene_cache[key] = (static, heights, colours, bases, facing, owners)
        return parts

    def clearance(
        self, x: float, y: float, exclude: str | None = None, height: float = math.inf, above: float = 0.0
    ) -> tuple[float, str]:
        """Distance from a point to the nearest solid thing lower than ``height`` (what a body that
        tall meets: it passes under a table top held higher) and higher than ``above`` (a body
        standing on a table top is over it), and its name."""
        d, name = self._clearances(
            np.array([x]),
            np.array([y]),
            exclude,
            self._collision_geometry(x, y, 1e9, exclude, height=height, above=above),
        )
        return float(d[0]), name[0]

    def _collision_geometry(
        self,
        x: float,
        y: float,
        reach: float,
        exclude: str | None,
        static: bool = True,
        height: float | None = None,
        above: float | None = None,
    ) -> tuple:
        """Segments (with names) and other robots' circles within ``reach`` of (x, y); ``static=False``
        leaves the static world out (only what moves: moving obstacles and robots). Static pieces
        held at or above ``height`` (default: robot ``exclude``'s body height) are passed under."""
        robot = self.robots.get(exclude) if exclude is not None else None
        if height is None:
            height = robot.elevation + robot.model.body_height if robot is not None else math.inf
        if above is None:
            above = robot.elevation if robot is not None else 0.0
        if static:
            near = self._static_near(x, y, reach, height, above)
            segs = self._static[near]
            names = [self.static_names[i] for i in near]
        else:
            segs, names = self._static[:0], []
        ms, mnames = self._movers_near(x, y, reach)
        if len(ms):
            segs = np.vstack([segs, ms])
            names = names + mnames
        others = [r for r in self.robots.values() if r.name != exclude]
        if not others:  # alone in the world (the usual case): no circles, no arrays to build
            return segs, names, _NO_CENTRES, _NO_RADII, []
        centres = np.array([[r.x, r.y] for r in others]).reshape(-1, 2)
        radii = np.array([r.model.body_radius for r in others])
        return segs, names, centres, radii, [r.name for r in others]

    def _static_near(
        self, x: float, y: float, reach: float, below: float = math.inf, above: float = 0.0
    ) -> np.ndarray:
        """Indices of the static segments whose bounding box comes within ``reach`` of (x, y), of
        the pieces starting lower than ``below`` (a body that tall passes under the others) and
        reaching higher than ``above`` (a body standing on a table top passes over what is lower)."""
        mask = (
            (self._static_lo[:, 0] <= x + reach)
            & (self._static_hi[:, 0] >= x - reach)
            & (self._static_lo[:, 1] <= y + reach)
            & (self._static_hi[:, 1] >= y - reach)
        )
        if self._any_base and below != math.inf:
            mask &= self._static_base < below
        if above > 0.0:
            mask &= self._static_height > above + STANDS_ON
        if self._any_visual:
            mask &= self._static_solid
        return np.flatnonzero(mask)

    def _static_free(self, r: Robot, x: float, y: float) -> bool:
        """True when (x, y) lies in ``r``'s free disk: a disk around a past position holding no static
        geometry closer than the body radius, so moves inside it need no check against the static
        world (only against what moves). The disk is renewed from the current position when left."""
        radius = r.model.body_radius
        free = r.free
        if (
            free is not None
            and math.hypot(x - free[0], y - free[1]) <= free[2] - radius
            and math.hypot(r.x - free[0], r.y - free[1]) <= free[2] - radius
        ):
            return True  # both ends in the disk: so is the straight move between them (a disk is convex)
        reach = 2.0
        segs = self._static[
            self._static_near(r.x, r.y, reach, r.elevation + r.model.body_height, r.elevation)
        ]
        near = point_segment_distance(np.array([r.x]), np.array([r.y]), segs)
        clear = min(float(near.min()) if near.size else reach, reach)
        r.free = (r.x, r.y, clear)
        return math.hypot(x - r.x, y - r.y) <= clear - radius

    @staticmethod
    def _clearances(
        px: np.ndarray, py: np.ndarray, _exclude: str | None, geometry: tuple
    ) -> tuple[np.ndarray, list[str]]:
        segs, names, centres, radii, rnames = geometry
        best = np.full(len(px), np.inf)
        who = [""] * len(px)
        if len(segs):
            d = point_segment_distance(px, py, segs)
            j = np.argmin(d, axis=1)
            best = d[np.arange(len(px)), j]
            who = [names[k] for k in j]
        if len(centres):
            dc = (
                np.hypot(px[:, None] - centres[None, :, 0], py[:, None] - centres[None, :, 1])
                - radii[None, :]
            )
            jc = np.argmin(dc, axis=1)
            bc = dc[np.arange(len(px)), jc]
            closer = bc < best
            best = np.where(closer, bc, best)
            who = [rnames[jc[i]] if closer[i] else who[i] for i in range(len(px))]
        return best, who

    # -- robots and obstacles -------------------------------------------------------------------
    def solid_at(self, x: float, y: float, height: float = math.inf, above: float = 0.0) -> str:
        """The name of the solid thing covering point (x, y), or "" (inside a box, a thick wall, a map
        cell); pieces held at or above ``height`` (a table top over a lower robot) and pieces no
        higher than ``above`` (the table top a robot stands on) do not count."""
        for o in self.world.obstacles:
            if not o.solid or (above > 0.0 and o.height <= above + STANDS_ON):
                continue
            if o.base < height and len(o.outline) > 2 and _inside(x, y, o.outline):
                return o.name
        for m in self.world.moving:
            if _inside(x, y, m.outline_at(self.world_time)):
                return m.name
        g = self.world.grid
        if g is not None:
            col = math.floor((x - g.origin_x) / g.resolution)
            row = math.floor((y - g.origin_y) / g.resolution)
            if 0 <= row < g.occupied.shape[0] and 0 <= col < g.occupied.shape[1] and g.occupied[row, col]:
                return "map"
        return ""

    def add_robot(
        self, name: str, model: RobotModel, x: float, y: float, yaw: float, elevation: float = 0.0
    ) -> Robot:
        """Place a robot (standing ``elevation`` above the floor: on a table top); refused
        (SpawnError) when the name is taken or the body would overlap anything."""
        if name in self.robots:
            raise SpawnError(f"a robot named [{name}] already exists")
        if not all(math.isfinite(v) for v in (x, y, yaw, elevation)):
            raise SpawnError(f"spawn pose of [{name}] is not finite: ({x}, {y}, {yaw})")
        gap, what = self.clearance(x, y, height=elevation + model.body_height, above=elevation)
        solid = self.solid_at(x, y, elevation + model.body_height, elevation)
        if solid:
            gap, what = 0.0, solid
        # Gazebo spawns into an overlap and its physics pushes the body out; here a body whose
        # circle overlaps by less than half its radius (the circle is wider than the real shape)
        # is placed, and moves that bring it closer are refused; deeper than that, it is refused
        if gap < model.body_radius * SPAWN_OVERLAP:
            raise SpawnError(
                f"cannot spawn [{name}] at ({x:.3f}, {y:.3f}): it would be inside '{what}' "
                f"(clearance {max(gap, 0.0):.3f} m, body radius {model.body_radius:.3f} m)"
            )
        rng = np.random.default_rng([self.seed, self._spawned])
        self._spawned += 1
        robot = Robot(name, model, x, y, yaw, (x, y, yaw), rng)
        if gap < model.body_radius:
            robot.spawn_overlap = (what, model.body_radius - gap)
        robot.odom_ref = (x, y, yaw)
        self._mount_cameras(robot, elevation)
        robot.start_elevation = elevation
        self.robots[name] = robot
        return robot

    @staticmethod
    def _mount_cameras(r: Robot, elevation: float) -> None:
        """Stand ``r`` at ``elevation`` and build its cameras' renderers for that height (a camera's
        floor tables depend on its height; a robot changes level only when spawned, moved or falling)."""
        r.elevation = elevation
        m = r.model
        r.camera = camera_for(m.camera, elevation) if m.camera is not None else None
        r.extra_cameras = [camera_for(spec, elevation) for spec in m.extra_cameras]

    def set_elevation(self, r: Robot, elevation: float) -> None:
        """Put ``r`` on another level (landed on a table top, fallen off it, set there)."""
        if elevation != r.elevation:
            self._mount_cameras(r, elevation)
            r.free = None

    def place_robot(self, name: str, x: float, y: float, yaw: float, elevation: float | None = None) -> Robot:
        """Teleport a robot (Gazebo's set_model_state), onto ``elevation`` (None: the level it is on):
        refused (SpawnError) when the pose is not finite or the body would overlap anything; wheels
        and odometry keep running from the new pose."""
        r = self.robots.get(name)
        if r is None:
            raise SpawnError(f"no robot named [{name}]")
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise SpawnError(f"pose of [{name}] is not finite: ({x}, {y}, {yaw})")
        level = r.elevation if elevation is None else elevation
        top = level + r.model.body_height
        gap, what = self.clearance(x, y, exclude=name, height=top, above=level)
        solid = self.solid_at(x, y, top, level)
        if solid:
            gap, what = 0.0, solid
        if gap < r.model.body_radius:
            raise SpawnError(
                f"cannot move [{name}] to ({x:.3f}, {y:.3f}): it would be inside '{what}' "
                f"(clearance {max(gap, 0.0):.3f} m, body radius {r.model.body_radius:.3f} m)"
            )
        r.x, r.y, r.yaw = x, y, wrap_angle(yaw)
        self.set_elevation(r, level)
        r.odom_ref = (r.x, r.y, r.yaw)  # wheel odometry does not see a teleport (the wheels did not turn)
        r.free = None
        r.contact, r.contact_with = False, ""
        return r

    def _pieces(self, name: str) -> list[int]:
        """Indices of the obstacles making up model ``name`` (one, or a model's several pieces)."""
        return [i for i, o in enumerate(self.world.obstacles) if o.model_name == name]

    def obstacle_pose(self, name: str) -> tuple[float, float, float]:
        """A model's (x, y, yaw): where it was spawned or last moved to, else the centre of its
        outline(s), and the yaw it was spawned or moved with (0 for the world's own)."""
        pieces = self._pieces(name)
        if not pieces:
            raise SpawnError(f"no model named [{name}]")
        origin = self.obstacle_origin.get(name)
        if origin is None:
            outlines = np.vstack([self.world.obstacles[i].outline for i in pieces])
            origin = (float(outlines[:, 0].mean()), float(outlines[:, 1].mean()))
        return origin[0], origin[1], self.obstacle_yaw.get(name, 0.0)

    def move_obstacle(
        self,
        name: str,
        x: float,
        y: float,
        yaw: float,
        lift: float = 0.0,
        land: Callable[[list[Obstacle]], float] | None = None,
    ) -> float:
        """Move a model (all its pieces together) so its pose is (x, y), turned by ``yaw`` from its
        first pose and raised by ``lift`` (Gazebo's set_model_state on a model); ``land`` says how
        far the moved pieces then fall (a model with physics). Returns the height change made;
        refused when it would overlap a robot or end under the floor."""
        pieces = self._pieces(name)
        if not pieces:
            raise SpawnError(f"no model named [{name}]")
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise SpawnError(f"pose of [{name}] is not finite: ({x}, {y}, {yaw})")
        cx, cy, cyaw = self.obstacle_pose(name)
        c, s = math.cos(yaw - cyaw), math.sin(yaw - cyaw)
        moved = []
        for i in pieces:
            o = self.world.obstacles[i]
            rel = o.outline - np.array([cx, cy])
            outline = np.column_stack([c * rel[:, 0] - s * rel[:, 1] + x, s * rel[:, 0] + c * rel[:, 1] + y])
            moved.append(replace(o, outline=outline, base=o.base + lift, height=o.height + lift))
        if land is not None:
            drop = land(moved)
            lift -= drop
            moved = [replace(o, base=o.base - drop, height=o.height - drop) for o in moved]
        if all(o.height <= 0.0 for o in moved):
            raise SpawnError(f"cannot move [{name}] {-lift:.3f} m down: it would be under the floor")
        moved = [replace(o, base=max(o.base, 0.0)) for o in moved]
        self._check_clear_of_robots(name, moved, "move")
        for i, o in zip(pieces, moved, strict=True):
            self.world.obstacles[i] = o
        self.obstacle_yaw[name] = yaw
        if name in self.obstacle_origin:
            self.obstacle_origin[name] = (x, y)
        self._rebuild_static()
        return lift

    def remove_robot(self, name: str) -> None:
        if self.robots.pop(name, None) is None:
            raise SpawnError(f"no robot named [{name}]")

    def add_obstacle(
        self,
        name: str,
        kind: str,
        size: tuple[float, float],
        x: float,
        y: float,
        yaw: float,
        height: float,
        color: tuple[int, int, int],
    ) -> None:
        """Add a static box (size = length, width) or cylinder (size[0] = radius); refused on a robot or a name clash."""
        outline = (
            circle_outline(x, y, size[0]) if kind == "cylinder" else box_outline(x, y, size[0], size[1], yaw)
        )
        self.add_outline(name, kind, outline, yaw, height, color)

    def add_outline(
        self,
        name: str,
        kind: str,
        outline: np.ndarray,
        yaw: float,
        height: float,
        color: tuple[int, int, int],
        base: float = 0.0,
        solid: bool = True,
    ) -> None:
        """Add a static obstacle of any outline (world coordinates; an SDF model's footprint, spawned;
        ``solid`` False: a visual only); refused on a robot or a name clash."""
        self.add_model(name, [Obstacle(name, kind, outline, height, color, base, solid=solid)], yaw)

    def add_model(
        self, name: str, pieces: list[Obstacle], yaw: float, origin: tuple[float, float] | None = None
    ) -> None:
        """Add a static model of one or several pieces (outlines in world coordinates; a spawned SDF
        table: top and legs), posed at ``origin`` (None: the centre of its outlines); refused as a
        whole on a robot or a name clash."""
        if name in self.robots or any(o.model_name == name or o.name == name for o in self.world.obstacles):
            raise SpawnError(f"a model named [{name}] already exists")
        self._check_clear_of_robots(name, pieces, "spawn")
        self.world.obstacles.extend(pieces)
        self.obstacle_yaw[name] = yaw
        if origin is not None:
            self.obstacle_origin[name] = origin
        self._rebuild_static()

    def _check_clear_of_robots(self, name: str, pieces: list[Obstacle], verb: str) -> None:
        """SpawnError when a piece would overlap a robot (pieces held above the robot pass over it)."""
        for r in self.robots.values():
            for o in pieces:
                if (
                    not o.solid
                    or o.base >= r.elevation + r.model.body_height
                    or o.height <= r.elevation + STANDS_ON
                ):
                    continue  # held above it, or under its wheels (the table top it stands on)
                outline = o.outline
                d = point_segment_distance(
                    np.array([r.x]), np.array([r.y]), np.hstack([outline, np.roll(outline, -1, axis=0)])
                )
                inside = len(outline) > 2 and _inside(r.x, r.y, outline)
                if inside or float(d.min()) < r.model.body_radius:
                    raise SpawnError(f"cannot {verb} [{name}]: it would overlap robot [{r.name}]")

    def remove_obstacle(self, name: str) -> None:
        """Delete a static model: all its pieces."""
        before = len(self.world.obstacles)
        self.world.obstacles = [o for o in self.world.obstacles if o.model_name != name]
        if len(self.world.obstacles) == before:
            raise SpawnError(f"no model named [{name}]")
        self.obstacle_yaw.pop(name, None)
        self.obstacle_origin.pop(name, None)
        self._rebuild_static()

    # -- time -----------------------------------------------------------------------------------
    def reset_world(self) -> None:
        """Robots back to their start poses, moving obstacles to their start; time goes on (Gazebo's reset_world)."""
        self.world_time = 0.0
        for m in self.world.moving:
            m.walked, m.aside = 0.0, (0.0, 0.0)
        self._movers_at = None
        for r in self.robots.values():
            r.reset()
            self.set_elevation(r, r.start_elevation)

    def reset_simulation(self) -> None:
        """reset_world, and simulated time back to 0 (Gazebo's reset_simulation)."""
        self.reset_world()
        self.steps = 0
        self._since = (0, 0)

    def step(self) -> list[Robot]:
        """Advance one physics step; returns the robots that came into contact during it."""
        dt = self.dt
        self.steps += 1
        self.world_time += dt
        for m in self.world.moving:
            if m.gives_way:
                self._walk(m, dt)
        touched = []
        for r in self.robots.values():
            if self._move(r, dt):
                touched.append(r)
        return touched

    def _move(self, r: Robot, dt: float) -> bool:
        # the state read into locals once (every step of every robot): the same arithmetic, fewer lookups
        m = r.model
        step = m.max_wheel_accel * dt
        target_wl, target_wr = r.target
        wl, wr = r.wl, r.wr
        dl, dr = target_wl - wl, target_wr - wr  # each change clamped to +-step (as min(max(d, -step), step))
        wl += -step if dl < -step else (step if dl > step else dl)
        wr += -step if dr < -step else (step if dr > step else dr)
        r.wl, r.wr = wl, wr
        radius_w = m.wheel_radius
        v = radius_w * (wr + wl) / 2.0
        w = radius_w * (wr - wl) / m.wheel_separation
        r.v_prev = r.v
        r.v, r.w = v, w
        r.left_angle += wl * dt
        r.right_angle += wr * dt
        if v == 0.0 and w == 0.0:
            return False
        th = w * dt
        x, y, yaw = r.x, r.y, r.yaw
        if abs(th) > 1e-9:
            nx = x + v / w * (math.sin(yaw + th) - math.sin(yaw))
            ny = y - v / w * (math.cos(yaw + th) - math.cos(yaw))
        else:
            nx = x + v * dt * math.cos(yaw)
            ny = y + v * dt * math.sin(yaw)
        ddx, ddy = nx - x, ny - y
        travel = math.hypot(ddx, ddy)
        new_contact = False
        if travel > 0:
            radius = m.body_radius
            static = not self._static_free(r, nx, ny)
            reach = travel + radius + 0.05
            geometry: tuple | None
            if not static and len(self.robots) == 1 and not self._any_mover_near(x, y, reach):
                # alone, inside its free disk, no moving obstacle within reach (the common step):
                # what _collision_geometry would find is nothing, so nothing is built
                geometry = None
            else:
                geometry = self._collision_geometry(r.x, r.y, reach, r.name, static)
            if geometry is not None and (len(geometry[0]) or len(geometry[2])):
                pieces = max(1, math.ceil(travel / (radius * 0.5)))
                f = np.arange(0, pieces + 1) / pieces
                dist, who = self._clearances(r.x + f * ddx, r.y + f * ddy, r.name, geometry)
                blocked = np.flatnonzero((dist[1:] < radius) & (dist[1:] < dist[0] - 1e-12))
            else:
                # nothing within reach: the move is free (the common step in open space, and the
                # cheapest: no samples along the move are made at all)
                blocked = _NONE_BLOCKED
            if len(blocked):
                assert geometry is not None  # something was in reach
                k = int(blocked[0]) + 1
                lo, hi = f[k - 1], f[k]
                for _ in range(12):  # contact point to travel/pieces/4096
                    mid = (lo + hi) / 2.0
                    dm, _ = self._clearances(
                        np.array([r.x + mid * ddx]), np.array([r.y + mid * ddy]), r.name, geometry
                    )
                    lo, hi = (mid, hi) if dm[0] >= radius else (lo, mid)
                nx, ny = r.x + lo * ddx, r.y + lo * ddy
                th *= lo
                new_contact = not r.contact
                r.contact, r.contact_with = True, who[k]
                # a kinematic robot stops dead at the wall: wheels and command stop too
                r.wl = r.wr = 0.0
                r.target = (0.0, 0.0)
                r.v = r.w = 0.0
            elif r.contact:
                r.contact, r.contact_with = False, ""
        r.x, r.y = nx, ny
        r.yaw = (yaw + th + _PI) % _TWO_PI - _PI  # wrap_angle inlined (every step)
        if r.elevation > 0.0:
            self._drop_if_unsupported(r)  # a fall changes the level, not x and y
        trail = r.trail
        if not trail or math.hypot(nx - trail[-1][0], ny - trail[-1][1]) > 0.02:
            trail.append((round(nx, 3), round(ny, 3)))
            r.trail_count += 1
        return new_contact

    def ground_under(self, x: float, y: float, at_most: float) -> float:
        """The highest top at (x, y) no higher than ``at_most`` (a table top under a robot standing
        on it, or nothing: the floor, 0): what a body's centre rests on there."""
        best = 0.0
        for o in self.world.obstacles:
            if (
                o.solid
                and best < o.height <= at_most + STANDS_ON
                and len(o.outline) > 2
                and _inside(x, y, o.outline)
            ):
                best = o.height
        return best

    def _drop_if_unsupported(self, r: Robot) -> None:
        """A robot whose centre left the top it stood on falls to what is under it (Gazebo's gravity;
        a robot tipping over an edge is not modelled: its centre decides)."""
        ground = self.ground_under(r.x, r.y, r.elevation)
        if ground < r.elevation:
            self.set_elevation(r, ground)

    def _walk(self, m: MovingObstacle, dt: float) -> None:
        """One step of a moving obstacle that gives way, as a person in a corridor does.

        It walks its route at ``speed``. A robot ahead on the route (within ``LOOK_AHEAD``, closer to
        the route than the two bodies plus ``PERSONAL_SPACE``) makes it step aside to whichever side
        needs the shorter step and has room (no wall or obstacle within its radius); with the robot
        behind it, it drifts back onto the route. It never takes a step that brings it closer to a
        robot than ``PERSONAL_SPACE`` (it waits instead): a robot that stands still is never walked
        into. Deterministic: the step depends only on the state and the robots' poses."""
        radius = m.size[0] if m.kind == "cylinder" else math.hypot(m.size[0], m.size[1]) / 2.0
        x, y, heading = m.position(self.world_time)
        ux, uy = math.cos(heading), math.sin(heading)
        ax, ay = m.aside
        want = (0.0, 0.0)  # back onto the route unless a robot is in the way
        nearest = math.inf
        robots = self.robots.values()
        for r in robots:
            keep = radius + r.model.body_radius + PERSONAL_SPACE + 0.1  # how far across it passes
            dx, dy = r.x - x, r.y - y
            along, lateral = dx * ux + dy * uy, dx * -uy + dy * ux
            # a robot counts as in the way a little beyond ``keep``: once aside, it stays aside
            if not (-0.1 < along < LOOK_AHEAD and abs(lateral) < keep + 0.05) or along >= nearest:
                continue
            nearest = along
            now_lat = ax * -uy + ay * ux  # its own offset from the route, across the route
            robot_lat = now_lat + lateral
            sides = sorted((robot_lat + keep, robot_lat - keep), key=lambda o: abs(o - now_lat))
            want = (ax, ay)  # no room on either side: stay in the lane and wait
            for offset in sides:  # room all the way across, not just a free spot beyond a wall
                tx, ty = x + (offset - now_lat) * -uy, y + (offset - now_lat) * ux
                if self._room_for(np.linspace(x, tx, 12), np.linspace(y, ty, 12), radius):
                    want = (-offset * uy, offset * ux)
                    break
        reach = m.speed * dt
        gx, gy = want[0] - ax, want[1] - ay
        g = math.hypot(gx, gy)
        if g > 1e-9:
            step_aside = (gx * min(1.0, reach / g), gy * min(1.0, reach / g))
            # forward and aside, aside only, forward only: the first that keeps clear of every robot
            candidates: tuple[tuple[float, tuple[float, float]], ...] = (
                (reach, step_aside),
                (0.0, step_aside),
                (reach, (0.0, 0.0)),
            )
        else:  # no step aside (the common step): forward is the one candidate the three come to
            candidates = ((reach, (0.0, 0.0)),)
        for walk, side in candidates:
            if walk == 0.0 and side == (0.0, 0.0):
                continue
            nx, ny, _ = m.route_pose(m.walked + walk)
            nx, ny = nx + ax + side[0], ny + ay + side[1]
            if side != (0.0, 0.0) and not self._room_for(np.array([nx]), np.array([ny]), radius):
                continue
            for r in robots:
                if not self._keeps_clear(r, x, y, nx, ny, radius):
                    break
            else:  # clear of every robot
                m.walked += walk
                m.aside = (ax + side[0], ay + side[1])
                return

    @staticmethod
    def _keeps_clear(r: Robot, x: float, y: float, nx: float, ny: float, radius: float) -> bool:
        """True when moving a body of ``radius`` from (x, y) to (nx, ny) keeps ``PERSONAL_SPACE`` from
        robot ``r``, or at least does not bring it closer."""
        after = math.hypot(r.x - nx, r.y - ny)
        return after - radius - r.model.body_radius >= PERSONAL_SPACE or after >= math.hypot(r.x - x, r.y - y)

    def _room_for(self, xs: np.ndarray, ys: np.ndarray, radius: float) -> bool:
        """True when disks of ``radius`` (plus 2 cm) at every (xs, ys) touch no static geometry."""
        cx, cy = float(xs.mean()), float(ys.mean())
        span = float(np.hypot(xs - cx, ys - cy).max())
        segs = self._static[self._static_near(cx, cy, span + radius + 0.02)]
        if not len(segs):
            return True
        return float(point_segment_distance(xs, ys, segs).min()) >= radius + 0.02

    # -- sensors --------------------------------------------------------------------------------
    def odometry(self, r: Robot) -> tuple[float, float, float]:
        """Advance ``r``'s odometry to its current true pose and return it (odom frame: start = origin).

        The true motion since the last sample is split into amcl's rot1 / trans / rot2 and each
        part gets Gaussian noise with amcl's diff-drive standard deviations
        (√(α1 rot² + α2 trans²) for rotations, √(α3 trans² + α4 (rot1² + rot2²)) for translation).
        """
        a1, a2, a3, a4 = r.model.odom_alpha
        px, py, pyaw = r.odom_ref
        dx, dy = r.x - px, r.y - py
        trans = math.hypot(dx, dy)
        # wrap_angle inlined here and below (every step)
        rot1 = (math.atan2(dy, dx) - pyaw + _PI) % _TWO_PI - _PI if trans > 1e-6 else 0.0
        if abs(rot1) > math.pi / 2 and trans > 1e-6:  # reversing: measure rot1 against the backward heading
            rot1 = wrap_angle(rot1 + math.pi)
            trans = -trans
        rot2 = (r.yaw - pyaw - rot1 + _PI) % _TWO_PI - _PI
        if a1 or a2 or a3 or a4:
            rot1_n = min(abs(rot1), abs(wrap_angle(rot1 - math.pi)))
            rot2_n = min(abs(rot2), abs(wrap_angle(rot2 - math.pi)))
            rot1 -= r.rng.normal(0.0, math.sqrt(a1 * rot1_n**2 + a2 * trans**2))
            trans -= r.rng.normal(0.0, math.sqrt(a3 * trans**2 + a4 * (rot1_n**2 + rot2_n**2)))
            rot2 -= r.rng.normal(0.0, math.sqrt(a1 * rot2_n**2 + a2 * trans**2))
        ox, oy, oyaw = r.odom
        ox += trans * math.cos(oyaw + rot1)
        oy += trans * math.sin(oyaw + rot1)
        oyaw = (oyaw + rot1 + rot2 + _PI) % _TWO_PI - _PI
        r.odom = [ox, oy, oyaw]
        r.odom_ref = (r.x, r.y, r.yaw)
        return ox, oy, oyaw

    @staticmethod
    def sensor_pose(r: Robot, xyz: tuple[float, float, float]) -> tuple[float, float]:
        c, s = math.cos(r.yaw), math.sin(r.yaw)
        return r.x + c * xyz[0] - s * xyz[1], r.y + s * xyz[0] + c * xyz[1]

    def scan(self, r: Robot, scene: Scene | None = None, laser: LaserSpec | None = None) -> np.ndarray:
        """``r``'s lidar ranges (its first lidar's, or ``laser``'s: one of its ``extra_lasers``)."""
        spec = laser or r.model.laser
        assert spec is not None
        lx, ly = self.sensor_pose(r, spec.pose.xyz)
        angle_min, _angle_max, inc = scan_angles(spec)
        return lidar_ranges(
            scene or self.scene(r.name, solid_only=True),
            lx,
            ly,
            spec.pose.xyz[2] + r.elevation,
            r.yaw + spec.pose.rpy[2],
            angle_min,
            inc,
            spec.beams,
            spec.range_min,
            spec.range_max,
            spec.noise,
            r.rng,
            self._lidar,
        )

    def render(
        self,
        r: Robot,
        scene: Scene | None = None,
        colour: bool = True,
        depth: bool = True,
        extra: int | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """``r``'s camera images (colour, depth); one not wanted is left empty (see Camera.render).
        ``extra``: the images of ``r.model.extra_cameras[extra]`` instead of its first camera's."""
        if extra is None:
            spec, camera = r.model.camera, r.camera
        else:
            spec, camera = r.model.extra_cameras[extra], r.extra_cameras[extra]
        assert spec is not None and camera is not None
        cx, cy = self.sensor_pose(r, spec.pose.xyz)
        return camera.render(
            scene or self.scene(r.name), cx, cy, r.yaw + spec.pose.rpy[2], colour=colour, depth=depth
        )

    def imu(self, r: Robot) -> tuple[float, float, float, float]:
        spec = r.model.imu
        assert spec is not None
        return imu_reading(r.yaw, r.v, r.w, r.v_prev, self.dt, spec.gyro_noise, spec.accel_noise, r.rng)


def camera_for(spec: CameraSpec, elevation: float = 0.0) -> Camera:
    """The renderer of a camera description on a robot standing ``elevation`` above the floor (its
    per-row tables are built once, here)."""
    return Camera(spec.width, spec.height, spec.hfov, spec.pose.xyz[2] + elevation, spec.depth_max)


def floor_paint(world: World, resolution: float = 0.01, max_cells: int = 2000) -> FloorPaint | None:
    """The world's floor markings and floor pictures rasterized for the camera (None without any).
    Pictures come first (their colours quantized to a 6x6x6 cube), markings are painted over them."""
    if not world.markings and not world.floor_images:
        return None
    corners = [m.points for m in world.markings]
    for im in world.floor_images:
        c, s = math.cos(im.yaw), math.sin(im.yaw)
        local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [im.width / 2, im.height / 2]
        corners.append(local @ np.array([[c, s], [-s, c]]) + [im.cx, im.cy])
    pts = np.vstack(corners)
    margin = max((m.width for m in world.markings), default=0.0)
    lo = pts.min(axis=0) - margin
    hi = pts.max(axis=0) + margin
    res = max(resolution, float((hi - lo).max()) / max_cells)
    cols, rows = (int(v) + 1 for v in np.ceil((hi - lo) / res))
    cx = lo[0] + (np.arange(cols) + 0.5) * res
    cy = lo[1] + (np.arange(rows) + 0.5) * res
    gx, gy = np.meshgrid(cx, cy)
    texture = np.zeros((rows, cols), dtype=np.uint8)
    palette: list[tuple[int, int, int]] = []
    if world.floor_images:
        levels = np.array([0, 51, 102, 153, 204, 255])
        palette = [(int(r), int(g), int(b)) for r in levels for g in levels for b in levels]
        for im in world.floor_images:
            c, s = math.cos(im.yaw), math.sin(im.yaw)
            lx = c * (gx - im.cx) + s * (gy - im.cy)
            ly = -s * (gx - im.cx) + c * (gy - im.cy)
            h, w = im.rgb.shape[:2]
            u = np.floor((lx / im.width + 0.5) * w).astype(np.int64)
            v = np.floor((0.5 - ly / im.height) * h).astype(np.int64)
            on = (u >= 0) & (u < w) & (v >= 0) & (v < h)
            q = (im.rgb[v[on], u[on]].astype(np.int64) + 25) // 51  # the nearest of the 6 levels
            texture[on] = 1 + q[:, 0] * 36 + q[:, 1] * 6 + q[:, 2]
    for m in world.markings[: 255 - len(palette)]:
        ink = len(palette) + 1
        palette.append(m.color)
        path = np.vstack([m.points, m.points[:1]]) if m.closed else m.points
        for a, b in zip(path[:-1], path[1:], strict=True):
            d = point_segment_distance(gx.ravel(), gy.ravel(), np.array([[a[0], a[1], b[0], b[1]]]))[:, 0]
            texture.ravel()[d <= m.width / 2.0] = ink
    return FloorPaint(texture, np.array(palette, dtype=np.uint8), float(lo[0]), float(lo[1]), res)


def _inside(x: float, y: float, poly: np.ndarray) -> bool:
    inside = False
    n = len(poly)
    for i in range(n):
        ax, ay = poly[i]
        bx, by = poly[(i + 1) % n]
        if (ay > y) != (by > y) and x < ax + (y - ay) * (bx - ax) / (by - ay):
            inside = not inside
    return inside
