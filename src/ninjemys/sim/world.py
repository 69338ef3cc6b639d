"""The turtlesim world as pure code: turtles, kinematics, pen trails and the path image.

No ROS in here. The node (``turtlesim_node``) feeds commands in and publishes what comes out, the web
view draws the same state, and tests drive it directly with their own clock.

Geometry follows ROS turtlesim: a 500 x 500 pixel canvas at 45 px per unit, so the world spans
``499 / 45 = 11.0888...`` units in x and y, with the origin at the bottom-left corner and the first
turtle at the centre (5.544445, 5.544445). Poses here are in world coordinates (y up); the image is
row-major with row 0 at the top, so a world point maps to pixel ``(x * 45, (H - y) * 45)``.

Kinematics integrate the commanded body velocity over time. ROS advances every turtle by a fixed
16 ms per timer tick; here :meth:`World.step` takes the real elapsed time, and a command stops
exactly one second after it arrived, so a single ``linear.x = 1`` command moves a turtle one unit
however the host schedules the timer.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ninjemys.errors import NinjemysError

#: Canvas size in pixels and the scale ROS derives from its turtle images (45 px tall).
CANVAS_PIXELS = 500
PIXELS_PER_METER = 45.0
WORLD_SIZE = (CANVAS_PIXELS - 1) / PIXELS_PER_METER
#: Spawn point of turtle1 (and of every reset).
CENTER = WORLD_SIZE / 2.0
#: Pen segments kept for viewers (the path image itself is complete); older ones are dropped in bulk.
SEGMENT_HISTORY = 20000
#: ROS turtlesim's timer period: the node steps the world this often.
UPDATE_PERIOD = 0.016
#: A velocity command holds for this long, then the turtle stops.
COMMAND_TIMEOUT = 1.0

DEFAULT_BACKGROUND = (69, 86, 255)
DEFAULT_PEN = (179, 184, 255)
DEFAULT_PEN_WIDTH = 3


class TurtleError(NinjemysError, ValueError):
    """A request the world refuses (taken name, unknown turtle, non-finite number).

    The text is ROS turtlesim's error log line, so the node can log and return it unchanged.
    """


def normalize_angle(angle: float) -> float:
    """Wrap an angle into [-pi, pi) the way turtlesim does after every update."""
    return angle - 2.0 * math.pi * math.floor((angle + math.pi) / (2.0 * math.pi))


@dataclass
class Pen:
    """The pen a turtle draws with: colour, width in pixels, and whether it is lifted."""

    r: int = DEFAULT_PEN[0]
    g: int = DEFAULT_PEN[1]
    b: int = DEFAULT_PEN[2]
    width: int = DEFAULT_PEN_WIDTH
    off: bool = False


@dataclass
class Turtle:
    """One turtle: pose in world units (y up), the current command and its pen."""

    name: str
    x: float
    y: float
    theta: float
    lin_x: float = 0.0
    lin_y: float = 0.0
    ang_z: float = 0.0
    #: when the last velocity command arrived (same clock as World.step)
    command_time: float = -math.inf
    pen: Pen = field(default_factory=Pen)
    #: which turtle image the browser view draws (ROS picks one at random per spawn)
    image_index: int = 0
    #: the time the pose was last integrated to (None until the world's clock first reaches it)
    t_last: float | None = None

    @property
    def linear_velocity(self) -> float:
        """Speed as turtlesim reports it in Pose (norm of the commanded planar velocity)."""
        return math.hypot(self.lin_x, self.lin_y)


@dataclass(frozen=True)
class Segment:
    """A pen stroke in world units, kept so the browser can replay the trail on its canvas."""

    x0: float
    y0: float
    x1: float
    y1: float
    r: int
    g: int
    b: int
    width: int


def _finite(*values: float) -> bool:
    return all(math.isfinite(v) for v in values)


class World:
    """All turtles, the path image their pens draw on, and the trail since the last clear.

    Not thread-safe by itself: the node serialises access with one lock.
    """

    def __init__(
        self,
        background: tuple[int, int, int] = DEFAULT_BACKGROUND,
        warn: Callable[[str], None] | None = None,
        info: Callable[[str], None] | None = None,
    ) -> None:
        self.width = WORLD_SIZE
        self.height = WORLD_SIZE
        self.background = background
        self.image = np.empty((CANVAS_PIXELS, CANVAS_PIXELS, 3), dtype=np.uint8)
        self.turtles: dict[str, Turtle] = {}
        self.segments: list[Segment] = []
        #: segments drawn since the last clear (including ones dropped from ``segments``)
        self.segment_total = 0
        #: bumps on every clear so viewers know to drop their trail
        self.clear_count = 0
        self._id_counter = 0
        self._image_counter = 0
        self._warn = warn or (lambda _m: None)
        self._info = info or (lambda _m: None)
        self.clear(background)

    # -- canvas -------------------------------------------------------------------------------
    def clear(self, background: tuple[int, int, int] | None = None) -> None:
        """Fill the path image with the background colour and forget the trail."""
        if background is not None:
            self.background = tuple(int(c) & 0xFF for c in background)  # type: ignore[assignment]
        self.image[:, :] = self.background
        self.segments.clear()
        self.segment_total = 0
        self.clear_count += 1

    def to_pixel(self, x: float, y: float) -> tuple[float, float]:
        """World point (y up) -> image column and row (row 0 at the top)."""
        return x * PIXELS_PER_METER, (self.height - y) * PIXELS_PER_METER

    def color_under(self, turtle: Turtle) -> tuple[int, int, int]:
        """The path-image pixel under a turtle: what its color_sensor reports."""
        col, row = self.to_pixel(turtle.x, turtle.y)
        col_i = min(max(int(round(col)), 0), CANVAS_PIXELS - 1)
        row_i = min(max(int(round(row)), 0), CANVAS_PIXELS - 1)
        r, g, b = self.image[row_i, col_i]
        return int(r), int(g), int(b)

    def _draw(self, turtle: Turtle, x0: float, y0: float) -> None:
        if turtle.pen.off or (x0 == turtle.x and y0 == turtle.y):
            return
        pen = turtle.pen
        self.segments.append(Segment(x0, y0, turtle.x, turtle.y, pen.r, pen.g, pen.b, pen.width))
        self.segment_total += 1
        if len(self.segments) > SEGMENT_HISTORY:
            del self.segments[: SEGMENT_HISTORY // 2]
        draw_line(self.image, self.to_pixel(x0, y0), self.to_pixel(turtle.x, turtle.y), pen)

    # -- turtles ------------------------------------------------------------------------------
    def spawn(self, name: str, x: float, y: float, theta: float) -> Turtle:
        """Add a turtle; an empty name picks the next free ``turtleN`` as ROS does."""
        if not _finite(x, y, theta):
            raise TurtleError(f"Cannot spawn turtle [{name}] at non-finite x=[{x}], y=[{y}], theta=[{theta}]")
        if not name:
            while True:
                self._id_counter += 1
                name = f"turtle{self._id_counter}"
                if name not in self.turtles:
                    break
        elif name in self.turtles:
            raise TurtleError(f"A turtle named [{name}] already exists")
        # the Spawn service carries float32, and ROS logs and stores those rounded values
        x, y, theta = (float(np.float32(v)) for v in (x, y, theta))
        turtle = Turtle(name, x, y, theta, image_index=self._image_counter)
        self._image_counter += 1
        self.turtles[name] = turtle
        self._info(f"Spawning turtle [{name}] at x=[{x:f}], y=[{y:f}], theta=[{theta:f}]")
        return turtle

    def kill(self, name: str) -> None:
        """Remove a turtle; unknown names are refused with ROS's message."""
        if name not in self.turtles:
            raise TurtleError(f"Tried to kill turtle [{name}], which does not exist")
        del self.turtles[name]

    def reset(self, background: tuple[int, int, int] | None = None) -> Turtle:
        """Back to the start: one turtle1 at the centre, a clean canvas."""
        self.turtles.clear()
        self._id_counter = 0
        turtle = self.spawn("", CENTER, CENTER, 0.0)
        self.clear(background)
        return turtle

    def get(self, name: str) -> Turtle:
        try:
            return self.turtles[name]
        except KeyError:
            raise TurtleError(f"No turtle named [{name}]") from None

    def command(self, name: str, lin_x: float, lin_y: float, ang_z: float, now: float) -> bool:
        """A cmd_vel arrived. Non-finite values are dropped (returns False) instead of poisoning the pose."""
        turtle = self.get(name)
        if not _finite(lin_x, lin_y, ang_z):
            self._warn(
                f"[{name}]: ignoring velocity command with non-finite values "
                f"(linear.x={lin_x}, linear.y={lin_y}, angular.z={ang_z})"
            )
            return False
        # the previous command was in force until now: integrate it before switching
        self._advance_to(turtle, now)
        turtle.lin_x, turtle.lin_y, turtle.ang_z = float(lin_x), float(lin_y), float(ang_z)
        turtle.command_time = now
        return True

    def set_pen(self, name: str, r: int, g: int, b: int, width: int, off: bool) -> None:
        """Change the pen; ``off`` lifts it and leaves colour and width as they were (as ROS)."""
        turtle = self.get(name)
        turtle.pen.off = bool(off)
        if off:
            return
        turtle.pen.r, turtle.pen.g, turtle.pen.b = int(r) & 0xFF, int(g) & 0xFF, int(b) & 0xFF
        if width:
            turtle.pen.width = int(width)

    def teleport_absolute(self, name: str, x: float, y: float, theta: float) -> None:
        """Jump to a pose; the pen draws the jump, as in ROS."""
        turtle = self.get(name)
        if not _finite(x, y, theta):
            raise TurtleError(f"[{name}]: cannot teleport to non-finite x=[{x}], y=[{y}], theta=[{theta}]")
        x0, y0 = turtle.x, turtle.y
        turtle.x, turtle.y, turtle.theta = float(x), min(float(y), self.height), float(theta)
        self._draw(turtle, x0, y0)

    def teleport_relative(self, name: str, linear: float, angular: float) -> None:
        """Turn by ``angular``, then move ``linear`` along the new heading."""
        turtle = self.get(name)
        if not _finite(linear, angular):
            raise TurtleError(
                f"[{name}]: cannot teleport by non-finite linear=[{linear}], angular=[{angular}]"
            )
        x0, y0 = turtle.x, turtle.y
        turtle.theta += float(angular)
        turtle.x += math.cos(turtle.theta) * linear
        turtle.y += math.sin(turtle.theta) * linear
        self._draw(turtle, x0, y0)

    # -- time ---------------------------------------------------------------------------------
    def step(self, now: float) -> None:
        """Advance every turtle to time ``now`` (seconds, any monotonic clock)."""
        for turtle in self.turtles.values():
            self._advance_to(turtle, now)

    def _advance_to(self, turtle: Turtle, now: float) -> None:
        last = turtle.t_last
        if last is None or now > last:
            turtle.t_last = now
        if last is not None and now > last:
            self._advance(turtle, last, now)

    def _advance(self, turtle: Turtle, start: float, end: float) -> None:
        stop = turtle.command_time + COMMAND_TIMEOUT
        # only the part of [start, end] while the command was in force moves the turtle
        dt = min(end, stop) - max(start, turtle.command_time)
        lin_x, lin_y, ang_z = turtle.lin_x, turtle.lin_y, turtle.ang_z
        if end >= stop:
            turtle.lin_x = turtle.lin_y = turtle.ang_z = 0.0
        if dt <= 0.0 or (lin_x == 0.0 and lin_y == 0.0 and ang_z == 0.0):
            return
        x0, y0 = turtle.x, turtle.y
        theta = normalize_angle(turtle.theta + ang_z * dt)
        x = x0 + (math.cos(theta) * lin_x - math.sin(theta) * lin_y) * dt
        y = y0 + (math.sin(theta) * lin_x + math.cos(theta) * lin_y) * dt
        turtle.theta = theta
        if x < 0.0 or x > self.width or y < 0.0 or y > self.height:
            # ROS reports the position in its y-down canvas frame; keep the same numbers
            self._warn(f"Oh no! I hit the wall! (Clamping from [x={x:f}, y={self.height - y:f}])")
        turtle.x = min(max(x, 0.0), self.width)
        turtle.y = min(max(y, 0.0), self.height)
        self._draw(turtle, x0, y0)


def draw_line(image: np.ndarray, p0: tuple[float, float], p1: tuple[float, float], pen: Pen) -> None:
    """Stroke a segment of ``pen.width`` pixels onto an (H, W, 3) image, vectorised over its bounding box.

    A pixel is painted when its centre lies within half the pen width of the segment (round caps),
    which is close to what Qt's antialiasing-free QPainter produces for turtlesim's thin pens.
    """
    half = max(pen.width, 1) / 2.0
    rows, cols = image.shape[:2]
    (c0, r0), (c1, r1) = p0, p1
    cmin = max(int(math.floor(min(c0, c1) - half)), 0)
    cmax = min(int(math.ceil(max(c0, c1) + half)), cols - 1)
    rmin = max(int(math.floor(min(r0, r1) - half)), 0)
    rmax = min(int(math.ceil(max(r0, r1) + half)), rows - 1)
    if cmin > cmax or rmin > rmax:
        return
    cc, rr = np.meshgrid(np.arange(cmin, cmax + 1) + 0.0, np.arange(rmin, rmax + 1) + 0.0)
    dc, dr = c1 - c0, r1 - r0
    length2 = dc * dc + dr * dr
    if length2 == 0.0:
        t = np.zeros_like(cc)
    else:
        t = np.clip(((cc - c0) * dc + (rr - r0) * dr) / length2, 0.0, 1.0)
    dist2 = (cc - (c0 + t * dc)) ** 2 + (rr - (r0 + t * dr)) ** 2
    mask = dist2 <= half * half
    image[rmin : rmax + 1, cmin : cmax + 1][mask] = (pen.r, pen.g, pen.b)
