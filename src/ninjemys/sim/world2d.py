"""The PuzzleBot simulator's world: a 2D floor plan with heights, as plain numpy data.

No ROS in here. Everything solid is reduced to what the ray caster and the collision check need:

* ``segments``: an (N, 4) float array of wall faces ``x0 y0 x1 y1`` with a height and an RGB colour
  each (walls are thick rectangles, boxes rectangles, cylinders 24-gons);
* optionally an occupancy ``grid`` (a map_server map used as the world): occupied cells are solid,
  ``grid_height`` tall;
* floor ``markings`` (painted lines, no height: the course's 1 m square) for the camera and the views;
* robots' start poses and moving obstacles that follow waypoints.

Worlds come from our YAML format (:func:`load_world`, described in docs/sim.md) or from a
map_server map (:func:`world_from_map`); :func:`rasterize` turns any world into an
:class:`~ninjemys.maps.mapfile.GridMap` (what the navigation stack uses as its map).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ninjemys.maps.mapfile import Fields, GridMap, MapFileError, load_map, text_byte, yaml_lines
from ninjemys.sim.lighting import DEFAULT_LIGHTING, Lighting, SceneLook, scene_look

CYLINDER_SIDES = 24
DEFAULT_WALL_HEIGHT = 1.0
DEFAULT_WALL_THICKNESS = 0.1

COLOURS: dict[str, tuple[int, int, int]] = {
    "white": (240, 240, 240),
    "grey": (150, 150, 150),
    "gray": (150, 150, 150),
    "darkgrey": (90, 90, 90),
    "black": (20, 20, 20),
    "red": (200, 50, 50),
    "green": (60, 170, 80),
    "blue": (60, 90, 200),
    "yellow": (230, 200, 60),
    "orange": (230, 140, 40),
    "brown": (140, 90, 50),
    "wood": (180, 130, 80),
    "purple": (140, 70, 170),
    "cyan": (60, 190, 200),
}


@dataclass
class Obstacle:
    """A solid shape: its outline polygon (closed, counter-clockwise) or a thin wall (2 points).

    It fills the space from ``base`` (0: it stands on the floor) up to ``height`` above the floor:
    a static SDF table top held at its pose has a base, and what passes under it (a low lidar beam,
    a robot lower than the base) does not meet it. ``model`` names the model the piece belongs to
    when that model has several pieces (a table: top and legs), "" when the piece is the model."""

    name: str
    kind: str  # wall | box | cylinder
    outline: np.ndarray  # (K, 2)
    height: float
    color: tuple[int, int, int]
    base: float = 0.0
    model: str = ""
    #: False for a visual without a collision (an ArUco tag board, a fiducial): the camera sees it,
    #: the lidar, the robots and falling models pass through it, as in Gazebo
    solid: bool = True

    @property
    def model_name(self) -> str:
        """The model this piece belongs to (Gazebo's model name)."""
        return self.model or self.name

    def segments(self) -> np.ndarray:
        pts = self.outline
        if len(pts) == 2:
            return pts.reshape(1, 4).copy()
        return np.hstack([pts, np.roll(pts, -1, axis=0)])

    def facing(self) -> int:
        """+1 for a convex outline going counter-clockwise, -1 clockwise, 0 for anything else (a
        thin wall, a concave or degenerate outline). Ray casts skip the sides of a convex outline
        that face away from the eye: the crossing that enters it is always on a side facing it."""
        pts = self.outline
        if len(pts) < 3:
            return 0
        e = np.roll(pts, -1, axis=0) - pts
        turns = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
        if (turns > 1e-12).all():
            return 1
        if (turns < -1e-12).all():
            return -1
        return 0


@dataclass
class Marking:
    """A line painted on the floor (no height): seen by the camera and the views, not by the lidar."""

    points: np.ndarray  # (K, 2)
    closed: bool
    width: float
    color: tuple[int, int, int]


@dataclass
class FloorImage:
    """A picture on the floor (a Gazebo plane with a textured material: a course's track): its RGB
    pixels (row 0 at the +y edge, column 0 at the -x edge, as seen from above), centre, size and yaw."""

    name: str
    rgb: np.ndarray  # (H, W, 3) uint8
    cx: float
    cy: float
    width: float
    height: float
    yaw: float = 0.0


@dataclass
class RobotStart:
    name: str
    x: float
    y: float
    yaw: float
    model: str = "puzzlebot"


@dataclass
class MovingObstacle:
    """A box or cylinder that moves along waypoints at ``speed`` (back to the first when ``loop``).

    By default it is a pure function of time and goes through whatever stands on its route. One that
    ``gives_way`` walks as people do instead (:meth:`Simulation.step` drives it): it keeps its route
    but steps aside around a robot in its way and waits when there is no room, so it never walks into
    a robot. Its pose is then state (``walked`` along the route, ``aside`` from it), not a function
    of time."""

    name: str
    kind: str  # box | cylinder
    size: tuple[float, float]  # box: (length, width); cylinder: (radius, radius)
    height: float
    color: tuple[int, int, int]
    waypoints: np.ndarray  # (K, 2)
    speed: float
    loop: bool = True
    gives_way: bool = False
    walked: float = 0.0  # metres along the route so far (a mover that gives way)
    aside: tuple[float, float] = (0.0, 0.0)  # its step away from the route (world frame, metres)

    def __post_init__(self) -> None:
        pts = [(float(x), float(y)) for x, y in self.waypoints]
        path = pts + pts[:1] if self.loop else pts + pts[-2::-1]
        #: (x0, y0, x1, y1, length, heading) of each leg of the closed route, in order
        self._legs = [
            (
                a[0],
                a[1],
                b[0],
                b[1],
                math.hypot(b[0] - a[0], b[1] - a[1]),
                math.atan2(b[1] - a[1], b[0] - a[0]),
            )
            for a, b in zip(path[:-1], path[1:], strict=True)
        ]
        self._total = sum(leg[4] for leg in self._legs)
        self._first = pts[0] if pts else (0.0, 0.0)  # the first waypoint, as floats
        #: the last pose :meth:`route_pose` gave and for how far along: the step's collision
        #: checks and the sensors' scenes ask for the same one several times a step
        self._pose_at: tuple[float, tuple[float, float, float]] | None = None

    def position(self, t: float) -> tuple[float, float, float]:
        """Pose (x, y, heading) at time ``t`` seconds after the start; for a mover that gives way,
        where its walk has brought it (``t`` is then not used: its path depends on the robots)."""
        if self.gives_way:
            x, y, heading = self.route_pose(self.walked)
            return x + self.aside[0], y + self.aside[1], heading
        return self.route_pose(t * self.speed)

    def route_pose(self, travelled: float) -> tuple[float, float, float]:
        """Pose (x, y, heading) on the route after ``travelled`` metres from the first waypoint."""
        last = self._pose_at
        if last is not None and last[0] == travelled:
            return last[1]
        pose = self._route_pose(travelled)
        self._pose_at = (travelled, pose)
        return pose

    def _route_pose(self, travelled: float) -> tuple[float, float, float]:
        x0, y0 = self._first
        if self.speed <= 0 or self._total <= 0:
            return x0, y0, 0.0
        s = travelled % self._total
        for i, (ax, ay, bx, by, length, heading) in enumerate(self._legs):
            if s <= length or i == len(self._legs) - 1:
                f = s / length if length > 0 else 0.0
                return ax + f * (bx - ax), ay + f * (by - ay), heading
            s -= length
        return x0, y0, 0.0

    def outline_at(self, t: float) -> np.ndarray:
        x, y, heading = self.position(t)
        if self.kind == "cylinder":
            return circle_outline(x, y, self.size[0])
        return box_outline(x, y, self.size[0], self.size[1], heading)


@dataclass
class Grid:
    """Occupied cells of a map used as world geometry (row 0 at ``origin`` y, like OccupancyGrid)."""

    occupied: np.ndarray  # bool (rows, cols)
    resolution: float
    origin_x: float
    origin_y: float
    height: float = DEFAULT_WALL_HEIGHT
    color: tuple[int, int, int] = COLOURS["grey"]


@dataclass
class World:
    name: str
    obstacles: list[Obstacle] = field(default_factory=list)
    markings: list[Marking] = field(default_factory=list)
    robots: list[RobotStart] = field(default_factory=list)
    moving: list[MovingObstacle] = field(default_factory=list)
    grid: Grid | None = None
    bounds: tuple[float, float, float, float] | None = None  # xmin, ymin, xmax, ymax
    source: str = ""
    #: models' poses (x, y, yaw) where the file gives them (an SDF world's models), by model name
    model_poses: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    #: the heights of those models' poses once Gazebo's physics has settled them (a static shelf at
    #: 1 m stays there; a box with physics rests on the floor or a table), by model name
    model_heights: dict[str, float] = field(default_factory=dict)
    #: an SDF world's models with nothing the floor plan holds (Gazebo's ground_plane): still models
    #: for Gazebo (listed in /gazebo/model_states, in the file's order), by name
    bare_models: list[str] = field(default_factory=list)
    #: an SDF world's models with physics (not ``<static>``): they fall when set in the air
    dynamic_models: list[str] = field(default_factory=list)
    #: the heights the file puts those models at, before they fall (a world loaded paused shows them there)
    placed_heights: dict[str, float] = field(default_factory=dict)
    #: pictures on the floor (an SDF world's textured planes): the camera sees them
    floor_images: list[FloorImage] = field(default_factory=list)
    #: counts the rebuilds: a view that drew the obstacles redraws them when it changes (a model
    #: spawned, moved or deleted)
    revision: int = 0
    #: the lights the camera sees the world by (an SDF world's ``<light>``s and ``<scene>``; Gazebo's
    #: default sun and ambient otherwise): see :mod:`ninjemys.sim.lighting`
    lighting: Lighting = DEFAULT_LIGHTING

    def __post_init__(self) -> None:
        self._look: tuple[int, Lighting, SceneLook] | None = None
        self.rebuild()

    @property
    def look(self) -> SceneLook:
        """The lights and the round obstacles' centres, for the camera (built again after a rebuild
        or a change of lights)."""
        kept = self._look
        if kept is None or kept[0] != self.revision or kept[1] is not self.lighting:
            kept = (self.revision, self.lighting, scene_look(self.lighting, self.obstacles))
            self._look = kept
        return kept[2]

    def rebuild(self) -> None:
        """Recompute the flat segment arrays after obstacles were added or removed."""
        self.revision += 1
        segs, heights, colours, owner, facing, bases = [], [], [], [], [], []
        for i, ob in enumerate(self.obstacles):
            s = ob.segments()
            segs.append(s)
            facing.append(np.full(len(s), ob.facing(), dtype=np.int8))
            heights.append(np.full(len(s), ob.height))
            bases.append(np.full(len(s), ob.base))
            colours.append(np.tile(np.array(ob.color, dtype=np.uint8), (len(s), 1)))
            owner.append(np.full(len(s), i))
        self.segments = np.vstack(segs) if segs else np.zeros((0, 4))
        self.seg_height = np.concatenate(heights) if heights else np.zeros(0)
        #: per segment: the height its obstacle starts at (0 on the floor)
        self.seg_base = np.concatenate(bases) if bases else np.zeros(0)
        self.seg_color = np.vstack(colours) if colours else np.zeros((0, 3), dtype=np.uint8)
        self.seg_owner = np.concatenate(owner) if owner else np.zeros(0, dtype=int)
        #: per segment: its outline's :meth:`Obstacle.facing` (+1, -1, or 0: both sides seen)
        self.seg_facing = np.concatenate(facing) if facing else np.zeros(0, dtype=np.int8)

    def extent(self) -> tuple[float, float, float, float]:
        """The area worth drawing and rasterizing: declared bounds, else everything plus a margin."""
        if self.bounds is not None:
            return self.bounds
        xs: list[float] = []
        ys: list[float] = []
        if len(self.segments):
            xs += [float(self.segments[:, [0, 2]].min()), float(self.segments[:, [0, 2]].max())]
            ys += [float(self.segments[:, [1, 3]].min()), float(self.segments[:, [1, 3]].max())]
        if self.grid is not None:
            g = self.grid
            xs += [g.origin_x, g.origin_x + g.occupied.shape[1] * g.resolution]
            ys += [g.origin_y, g.origin_y + g.occupied.shape[0] * g.resolution]
        for m in self.markings:
            xs += [float(m.points[:, 0].min()), float(m.points[:, 0].max())]
            ys += [float(m.points[:, 1].min()), float(m.points[:, 1].max())]
        for r in self.robots:
            xs.append(r.x)
            ys.append(r.y)
        if not xs:
            return (-5.0, -5.0, 5.0, 5.0)
        margin = 0.0 if self.grid is not None and not len(self.segments) else 0.5
        return (min(xs) - margin, min(ys) - margin, max(xs) + margin, max(ys) + margin)


def box_outline(cx: float, cy: float, length: float, width: float, yaw: float = 0.0) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.array([[-length, -width], [length, -width], [length, width], [-length, width]]) / 2.0
    return local @ np.array([[c, s], [-s, c]]) + np.array([cx, cy])


def circle_outline(cx: float, cy: float, radius: float, sides: int = CYLINDER_SIDES) -> np.ndarray:
    """A regular polygon with its vertices on the circle (faces at most r (1 - cos(pi/n)) inside it)."""
    a = np.arange(sides) * (2 * math.pi / sides)
    return np.column_stack([cx + radius * np.cos(a), cy + radius * np.sin(a)])


def wall_outline(x0: float, y0: float, x1: float, y1: float, thickness: float) -> np.ndarray:
    if thickness <= 0:
        return np.array([[x0, y0], [x1, y1]], dtype=float)
    dx, dy = x1 - x0, y1 - y0
    n = math.hypot(dx, dy)
    nx, ny = -dy / n * thickness / 2, dx / n * thickness / 2
    ex, ey = dx / n * thickness / 2, dy / n * thickness / 2  # square ends: corners meet cleanly
    return np.array(
        [
            [x0 - ex - nx, y0 - ey - ny],
            [x1 + ex - nx, y1 + ey - ny],
            [x1 + ex + nx, y1 + ey + ny],
            [x0 - ex + nx, y0 - ey + ny],
        ]
    )


# -- our YAML world format ----------------------------------------------------------------------


def _colour(f: Fields, value: object, where: str, default: tuple[int, int, int]) -> tuple[int, int, int]:
    if value is None:
        return default
    if isinstance(value, str):
        text = value.strip().lower()
        if text in COLOURS:
            return COLOURS[text]
        if text.startswith("#") and len(text) == 7:
            try:
                return (int(text[1:3], 16), int(text[3:5], 16), int(text[5:7], 16))
            except ValueError:
                pass
        raise f.error(where, f"unknown colour {value!r} (a name like 'red', '#rrggbb' or [r, g, b] 0-255)")
    if isinstance(value, list) and len(value) == 3:
        rgb = [f.number(v, f"{where}[{i}]", minimum=0) for i, v in enumerate(value)]
        if any(v > 255 for v in rgb):
            raise f.error(where, f"colour components are 0-255, got {value!r}")
        return (int(rgb[0]), int(rgb[1]), int(rgb[2]))
    raise f.error(where, f"expected a colour (name, '#rrggbb' or [r, g, b]), got {value!r}")


def _check_keys(f: Fields, item: object, where: str, allowed: set[str], required: set[str]) -> dict:
    if not isinstance(item, dict):
        raise f.error(where, f"expected a mapping, got {item!r}")
    for key in item:
        if key not in allowed:
            raise f.error(f"{where}.{key}", f"unknown field (expected one of {', '.join(sorted(allowed))})")
    for key in sorted(required):
        if key not in item:
            raise f.error(where, f"missing field '{key}'")
    return item


_TOP = {
    "name",
    "bounds",
    "walls",
    "boxes",
    "cylinders",
    "floor",
    "robots",
    "moving",
    "map",
    "map_height",
    "map_color",
}


def load_world(path: str | Path) -> World:
    """Read a world file of ours, or a map_server map (YAML with an ``image`` field)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise MapFileError(f"{p}: cannot read world: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise MapFileError(
            f"{p}: not a text (UTF-8) file: byte {exc.start} is 0x{text_byte(exc):02x}"
        ) from None
    doc, lines = yaml_lines(text, str(p))
    f = Fields(str(p), lines)
    if isinstance(doc, dict) and "image" in doc:
        return world_from_map(p)
    if not isinstance(doc, dict):
        raise f.error(
            "", "a world file is a YAML mapping (walls, boxes, cylinders, floor, robots, moving, ...)"
        )
    return parse_world(doc, f, p)


def parse_world(doc: dict, f: Fields, path: Path) -> World:
    _check_keys(f, doc, "", _TOP, set())
    name = str(doc.get("name", path.stem))
    obstacles: list[Obstacle] = []

    def items(key: str) -> list:
        value = doc.get(key, []) or []
        if not isinstance(value, list):
            raise f.error(key, f"expected a list, got {value!r}")
        return value

    for i, w in enumerate(items("walls")):
        where = f"walls[{i}]"
        _check_keys(f, w, where, {"from", "to", "thickness", "height", "color", "name"}, {"from", "to"})
        a = f.vector(w["from"], f"{where}.from", 2)
        b = f.vector(w["to"], f"{where}.to", 2)
        if a == b:
            raise f.error(where, "a wall needs two different end points")
        t = f.number(w.get("thickness", DEFAULT_WALL_THICKNESS), f"{where}.thickness", minimum=0)
        h = f.number(w.get("height", DEFAULT_WALL_HEIGHT), f"{where}.height", positive=True)
        c = _colour(f, w.get("color"), f"{where}.color", COLOURS["white"])
        obstacles.append(
            Obstacle(str(w.get("name", f"wall_{i}")), "wall", wall_outline(a[0], a[1], b[0], b[1], t), h, c)
        )
    for i, b in enumerate(items("boxes")):
        where = f"boxes[{i}]"
        _check_keys(f, b, where, {"center", "size", "yaw", "height", "color", "name"}, {"center", "size"})
        cx, cy = f.vector(b["center"], f"{where}.center", 2)
        sx, sy = f.vector(b["size"], f"{where}.size", 2)
        if sx <= 0 or sy <= 0:
            raise f.error(f"{where}.size", f"sizes must be > 0, got {b['size']!r}")
        yaw = f.number(b.get("yaw", 0.0), f"{where}.yaw")
        h = f.number(b.get("height", 0.5), f"{where}.height", positive=True)
        c = _colour(f, b.get("color"), f"{where}.color", COLOURS["wood"])
        obstacles.append(
            Obstacle(str(b.get("name", f"box_{i}")), "box", box_outline(cx, cy, sx, sy, yaw), h, c)
        )
    for i, c_ in enumerate(items("cylinders")):
        where = f"cylinders[{i}]"
        _check_keys(f, c_, where, {"center", "radius", "height", "color", "name"}, {"center", "radius"})
        cx, cy = f.vector(c_["center"], f"{where}.center", 2)
        r = f.number(c_["radius"], f"{where}.radius", positive=True)
        h = f.number(c_.get("height", 0.5), f"{where}.height", positive=True)
        col = _colour(f, c_.get("color"), f"{where}.color", COLOURS["blue"])
        obstacles.append(
            Obstacle(str(c_.get("name", f"cylinder_{i}")), "cylinder", circle_outline(cx, cy, r), h, col)
        )
    markings = []
    for i, m in enumerate(items("floor")):
        where = f"floor[{i}]"
        _check_keys(f, m, where, {"points", "closed", "width", "color"}, {"points"})
        pts = m["points"]
        if not isinstance(pts, list) or len(pts) < 2:
            raise f.error(f"{where}.points", "expected a list of at least two [x, y] points")
        arr = np.array([f.vector(p, f"{where}.points[{j}]", 2) for j, p in enumerate(pts)])
        width = f.number(m.get("width", 0.03), f"{where}.width", positive=True)
        markings.append(
            Marking(
                arr,
                bool(m.get("closed", False)),
                width,
                _colour(f, m.get("color"), f"{where}.color", (240, 200, 40)),
            )
        )
    robots = []
    for i, r in enumerate(items("robots")):
        where = f"robots[{i}]"
        _check_keys(f, r, where, {"name", "pose", "model"}, {"name"})
        rname = r["name"]
        if not isinstance(rname, str) or not rname.replace("_", "a").isalnum() or not rname[0].isalpha():
            raise f.error(f"{where}.name", f"expected a ROS name (letters, digits, _), got {rname!r}")
        pose = f.vector(r.get("pose", [0, 0, 0]), f"{where}.pose", 3)
        robots.append(RobotStart(rname, pose[0], pose[1], pose[2], str(r.get("model", "puzzlebot"))))
    moving = []
    for i, m in enumerate(items("moving")):
        where = f"moving[{i}]"
        _check_keys(
            f,
            m,
            where,
            {"name", "shape", "radius", "size", "height", "color", "speed", "waypoints", "loop", "gives_way"},
            {"waypoints"},
        )
        shape = m.get("shape", "cylinder")
        if shape not in ("cylinder", "box"):
            raise f.error(f"{where}.shape", f"expected cylinder or box, got {shape!r}")
        if shape == "cylinder":
            r = f.number(m.get("radius", 0.2), f"{where}.radius", positive=True)
            size = (r, r)
        else:
            sx, sy = f.vector(m.get("size", [0.4, 0.4]), f"{where}.size", 2)
            size = (sx, sy)
        wps = m["waypoints"]
        if not isinstance(wps, list) or not wps:
            raise f.error(f"{where}.waypoints", "expected a list of [x, y] points")
        arr = np.array([f.vector(p, f"{where}.waypoints[{j}]", 2) for j, p in enumerate(wps)])
        gives_way = m.get("gives_way", False)
        if not isinstance(gives_way, bool):
            raise f.error(f"{where}.gives_way", f"expected true or false, got {gives_way!r}")
        moving.append(
            MovingObstacle(
                str(m.get("name", f"mover_{i}")),
                shape,
                size,
                f.number(m.get("height", 0.5), f"{where}.height", positive=True),
                _colour(f, m.get("color"), f"{where}.color", COLOURS["orange"]),
                arr,
                f.number(m.get("speed", 0.3), f"{where}.speed", minimum=0),
                bool(m.get("loop", True)),
                gives_way,
            )
        )
    bounds = None
    if "bounds" in doc:
        b4 = f.vector(doc["bounds"], "bounds", 4)
        if b4[2] <= b4[0] or b4[3] <= b4[1]:
            raise f.error("bounds", "expected [xmin, ymin, xmax, ymax] with xmax > xmin and ymax > ymin")
        bounds = (b4[0], b4[1], b4[2], b4[3])
    grid = None
    if "map" in doc:
        mp = doc["map"]
        if not isinstance(mp, str):
            raise f.error("map", f"expected the path of a map_server YAML, got {mp!r}")
        mpath = Path(mp) if Path(mp).is_absolute() else path.parent / mp
        grid = grid_from_map(load_map(mpath))
        grid.height = f.number(doc.get("map_height", DEFAULT_WALL_HEIGHT), "map_height", positive=True)
        grid.color = _colour(f, doc.get("map_color"), "map_color", COLOURS["grey"])
    return World(name, obstacles, markings, robots, moving, grid, bounds, str(path))


def grid_from_map(m: GridMap) -> Grid:
    """Occupied cells of ``m`` as solid geometry. The origin's yaw is ignored, as amcl and costmap_2d
    ignore it: their cells stay axis-aligned."""
    return Grid(m.occupied(), m.resolution, m.origin[0], m.origin[1])


def world_from_map(yaml_path: str | Path, height: float = DEFAULT_WALL_HEIGHT) -> World:
    """A map_server map as a world: occupied cells are walls ``height`` tall (as users do with Stage)."""
    m = load_map(yaml_path)
    g = grid_from_map(m)
    g.height = height
    p = Path(yaml_path)
    return World(p.stem, grid=g, source=str(p))


# -- rasterizing --------------------------------------------------------------------------------


def _inside_polygon(px: np.ndarray, py: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon test for many points at once."""
    inside = np.zeros(px.shape, dtype=bool)
    x0, y0 = poly[:, 0], poly[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    for a, b, c, d in zip(x0, y0, x1, y1, strict=True):
        crosses = (b > py) != (d > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = a + (py - b) * (c - a) / (d - b)
        inside ^= crosses & (px < xi)
    return inside


def rasterize(
    world: World,
    resolution: float = 0.05,
    extent: tuple[float, float, float, float] | None = None,
    moving_at: float | None = None,
) -> GridMap:
    """The world as an occupancy grid (0 free, 100 occupied), cells ``resolution`` m, row 0 at the bottom.

    A cell is occupied when its centre lies inside a solid shape or a thin wall passes through it, so
    no wall disappears however thin. Moving obstacles are left out (a map for navigation shows the
    static world), unless ``moving_at`` gives the time at which to draw them.
    """
    xmin, ymin, xmax, ymax = extent or world.extent()
    cols = max(1, int(math.ceil((xmax - xmin) / resolution - 1e-9)))
    rows = max(1, int(math.ceil((ymax - ymin) / resolution - 1e-9)))
    occ = np.zeros((rows, cols), dtype=bool)
    outlines = [ob.outline for ob in world.obstacles]
    if moving_at is not None:
        outlines += [m.outline_at(moving_at) for m in world.moving]
    for poly in outlines:
        lo = np.floor((poly.min(axis=0) - [xmin, ymin]) / resolution).astype(int) - 1
        hi = np.ceil((poly.max(axis=0) - [xmin, ymin]) / resolution).astype(int) + 1
        c0, r0 = max(lo[0], 0), max(lo[1], 0)
        c1, r1 = min(hi[0], cols), min(hi[1], rows)
        if c1 <= c0 or r1 <= r0:
            continue
        if len(poly) > 2:
            cx = xmin + (np.arange(c0, c1) + 0.5) * resolution
            cy = ymin + (np.arange(r0, r1) + 0.5) * resolution
            gx, gy = np.meshgrid(cx, cy)
            occ[r0:r1, c0:c1] |= _inside_polygon(gx, gy, poly)
        # the outline itself, sampled finer than a cell: thin walls and slivers stay solid
        closed = np.vstack([poly, poly[:1]]) if len(poly) > 2 else poly
        for a, b in zip(closed[:-1], closed[1:], strict=True):
            n = max(2, int(np.linalg.norm(b - a) / (resolution / 4)) + 2)
            s = np.linspace(0, 1, n)[:, None]
            pts = a + s * (b - a)
            ci = np.floor((pts[:, 0] - xmin) / resolution).astype(int)
            ri = np.floor((pts[:, 1] - ymin) / resolution).astype(int)
            ok = (ci >= 0) & (ci < cols) & (ri >= 0) & (ri < rows)
            occ[ri[ok], ci[ok]] = True
    if world.grid is not None:
        g = world.grid
        col_x = xmin + (np.arange(cols) + 0.5) * resolution
        row_y = ymin + (np.arange(rows) + 0.5) * resolution
        gc = np.floor((col_x - g.origin_x) / g.resolution).astype(int)
        gr = np.floor((row_y - g.origin_y) / g.resolution).astype(int)
        okc = (gc >= 0) & (gc < g.occupied.shape[1])
        okr = (gr >= 0) & (gr < g.occupied.shape[0])
        sub = np.zeros((rows, cols), dtype=bool)
        sub[np.ix_(okr, okc)] = g.occupied[np.ix_(gr[okr], gc[okc])]
        occ |= sub
    data = np.where(occ, 100, 0).astype(np.int8)
    return GridMap(data, resolution, (xmin, ymin, 0.0))
