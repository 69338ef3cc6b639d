"""The simulated RGB-D camera: a colour image and a depth image of the world seen from a pinhole camera.

No ROS in here: a :class:`~ninjemys.sim.sensors.Scene` and a pose in, arrays out. The world is 2D with
heights: every obstacle side is a vertical strip standing between its base (0 on the floor, higher for
a table top held in the air) and its top. One vectorised cast (:func:`~ninjemys.sim.raycast.column_pairs`)
gives every crossing of a column's ray with a strip, and a crossing covers the image rows whose rays
meet the strip between its base and its top. Each pixel shows the nearest strip that covers it (or
the lid of a shape lower than the camera, the underside of one held above it, seen through them);
where none does, the background: the floor (shaded with distance, with its markings) below the horizon, the
sky above. The depth image holds the optical-axis depth in millimetres (16UC1, as RealSense's
``depth/image_rect_raw``), 0 where there is no return (sky, beyond the depth range).

Why it is cheap: a crossing can only show in the rows that the nearer strips standing on the floor leave
free, which is above the lowest top among them (their feet are lower in the image than anything farther
away), so each crossing's rows are cut to that before any pixel is touched, and the crossings left with
no rows are dropped. What remains is usually one crossing per column, seldom more than three; the
image is filled with one masked copy (OpenCV) per rank of crossing within its column, farthest first,
so a nearer shape in the air is painted over what it hides and what lies under it stays visible.
A camera that has not moved in an unchanged scene returns the images it drew last.
"""

from __future__ import annotations

import contextlib
import functools
import math
from collections.abc import Iterator
from typing import Any

import numpy as np

from ninjemys.sim.lighting import DEFAULT_LIGHTING, Lighting, SceneLook
from ninjemys.sim.raycast import circle_pairs, column_pairs
from ninjemys.sim.sensors import FloorPaint, Scene

#: reductions called as ufunc methods: ``a.all()`` or ``a.min()`` go through numpy's Python-level
#: wrappers, a few microseconds a call, felt at 30 frames per simulated second
_ALL, _ANY = np.logical_and.reduce, np.logical_or.reduce
_MIN, _MAX = np.minimum.reduce, np.maximum.reduce

#: what :meth:`Camera.render` returns for an image it was asked not to draw
_EMPTY_RGB = np.zeros((0, 0, 3), dtype=np.uint8)
_EMPTY_DEPTH = np.zeros((0, 0), dtype=np.uint16)
#: an RGB pixel as one 3-byte item (see Camera._colour_cells)
_PIXEL = np.dtype("V3")
#: the floor's own colour (lit by the world's lights: see :mod:`ninjemys.sim.lighting`) and the sky's,
#: where the world does not give them (an SDF world gives Gazebo's grey ground and background)
FLOOR_RGB = np.array([176, 170, 160], dtype=np.float32)
SKY_RGB = np.array([206, 220, 235], dtype=np.float32)
#: a scene that says nothing of its lights: Gazebo's default sun, every side flat
_DEFAULT_LOOK = SceneLook()
_UP = (0.0, 0.0, 1.0)
_DOWN = (0.0, 0.0, -1.0)


class Camera:
    """A pinhole RGB-D camera rendered by column ray casting; the per-row tables are built once."""

    def __init__(self, width: int, height: int, hfov_deg: float, cam_z: float, depth_max: float) -> None:
        self.width = width
        self.height = height
        self.fx = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
        self.fy = self.fx  # square pixels
        self.cx = (width - 1) / 2.0
        self.cy = (height - 1) / 2.0
        self.cam_z = cam_z
        self.depth_max = depth_max
        u = np.arange(width)
        #: each column's ray, lateral over forward (left of the image is +y, counter-clockwise)
        self.col_slopes = (self.cx - u) / self.fx
        self.col_angles = np.arctan(self.col_slopes)
        self.col_cos = np.cos(self.col_angles)
        v = np.arange(height)
        self.row_slope = (self.cy - v) / self.fy  # tan of the elevation of each row's ray
        below = self.row_slope < -1e-9
        floor_depth = np.zeros(height)
        floor_depth[below] = cam_z / -self.row_slope[below]
        floor_depth[floor_depth > depth_max] = 0.0
        self.floor_depth_mm = np.rint(floor_depth * 1000).astype(np.uint16)
        self._below = below
        # the rows that see the floor within range: the last ones, from the first such row down
        # (the floor's depth shrinks row by row below the horizon)
        self._floor_first = int(np.flatnonzero(floor_depth > 0)[0]) if (floor_depth > 0).any() else height
        forward = floor_depth[self._floor_first :][:, None]
        #: where each floor pixel meets the floor, in the camera's horizontal frame (x ahead, y left):
        #: how far ahead (one value per row) and how far to the left
        self._floor_points = (
            forward.astype(np.float32),
            (forward * self.col_slopes[None, :]).astype(np.float32),
        )
        # a column's rows are top <= v < bottom, with top and bottom in [0, height]: held in the
        # narrowest unsigned type that holds them (uint8 up to 255 rows), and tested as one wrapping
        # subtraction and one comparison per pixel, (v - top) mod 2^bits < bottom - top
        self._row_type = np.uint8 if height <= 255 else np.uint16
        self._rows = np.arange(height, dtype=self._row_type)[:, None]
        #: the floor (one colour: a directional light does not fade with distance) below the horizon
        #: and the sky above, for the lights of :attr:`_lit_by` (see :meth:`_light`)
        self._lit_by: Lighting | None = None
        self._background = np.zeros((height, width, 3), dtype=np.uint8)
        self._lit_palette: tuple[np.ndarray, Lighting, np.ndarray] | None = None
        #: the segments' colours lit on each side, for the last scene seen (see _Palette), and the
        #: arrays of the last scene drawn without one
        self._palette: _Palette | None = None
        self._last_scene: tuple[Any, ...] | None = None
        self._floor_depth_image = np.ascontiguousarray(
            np.broadcast_to(self.floor_depth_mm[:, None], (height, width))
        )
        # scratch, reused by every frame (render runs on one thread at a time: the node's lock)
        self._offset = np.empty((height, width), dtype=self._row_type)
        self._mask = np.empty((height, width), dtype=bool)
        self._span_row = np.zeros(width, dtype=self._row_type)
        self._top_row = np.zeros(width, dtype=self._row_type)
        self._colour_row = np.zeros((width, 3), dtype=np.uint8)
        #: the same row as one 3-byte cell per column: set by column with a 1-D index, several
        #: times cheaper than the rows of a 2-D array
        self._colour_cells = self._colour_row.view(_PIXEL).reshape(width)
        self._depth_row = np.zeros(width, dtype=np.uint16)
        #: the last frame's pose and images, and a copy of its scene once the camera stood still
        self._last: tuple[tuple[float, float, float, bool, bool], tuple[np.ndarray, np.ndarray]] | None = None
        #: what row bounds are made of (see _rises) for the last heights and bases seen, and the
        #: offsets of the two bounds (cy for a top row, cy + 1 for the row past a base)
        self._rise: tuple[np.ndarray, np.ndarray | None, np.ndarray] | None = None
        self._row_offsets = np.array([[self.cy], [self.cy + 1.0]])
        #: the sides to cast and the planes seen through them for the last arrays seen (_cast_sides)
        self._sides: tuple[Any, ...] | None = None
        self._still: _SceneCopy | None = None
        #: the arrays the next frames are drawn into (see drawing_into)
        self._into: tuple[np.ndarray | None, np.ndarray | None] = (None, None)

    def render(
        self,
        scene: Scene,
        x: float,
        y: float,
        yaw: float,
        colour: bool = True,
        depth: bool = True,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(rgb8 image (H, W, 3), depth in mm uint16 (H, W)) from a camera at (x, y, cam_z) facing ``yaw``.

        ``colour=False`` or ``depth=False`` leaves that image out (an empty array in its place):
        a camera whose depth stream nobody reads (or that has none) does not draw it. The arrays
        returned are not changed afterwards (a camera that stood still returns the same ones again).
        Inside :meth:`drawing_into` the images are drawn into (and returned as) the arrays given there.
        """
        key = (x, y, yaw, colour, depth)
        into = self._into
        out = (into[0] if colour else None, into[1] if depth else None)
        last = self._last
        if last is not None and last[0] == key:
            # the camera stood still: the scene is compared with a copy taken at the previous frame
            if self._still is not None and self._still.same(scene):
                if out[0] is None and out[1] is None:
                    return last[1]
                images = _copied_into(last[1], out)
                self._last = (key, images)
                return images
            self._still = _SceneCopy(scene)
        else:
            self._still = None
        images = self._render(scene, x, y, yaw, colour, depth, out)
        self._last = (key, images)
        return images

    @contextlib.contextmanager
    def drawing_into(self, rgb: np.ndarray | None, depth: np.ndarray | None) -> Iterator[None]:
        """Draw the frames rendered inside the block into ``rgb`` (C-contiguous (H, W, 3) uint8) and
        ``depth`` ((H, W) uint16); None: into new arrays, as outside. Why: a publisher's loan is a
        shared-memory slot that its subscriber reads, so an image drawn there is never copied. The
        arrays are kept as the frame's images (a camera that stands still copies them into the next
        frame's), so the caller must not change them afterwards either. A wrong array raises
        ValueError naming it."""
        for name, array, shape, dtype in (
            ("colour", rgb, (self.height, self.width, 3), np.uint8),
            ("depth", depth, (self.height, self.width), np.uint16),
        ):
            if array is not None and not _fits(array, shape, dtype):
                raise ValueError(
                    f"camera {self.width}x{self.height}: the {name} image must be drawn into a "
                    f"writable C-contiguous {np.dtype(dtype).name} array of shape {shape}, got "
                    f"{array.dtype} {array.shape}{'' if array.flags.writeable else ' read-only'}"
                )
        self._into = (rgb, depth)
        try:
            yield
        finally:
            self._into = (None, None)

    def _render(
        self,
        scene: Scene,
        x: float,
        y: float,
        yaw: float,
        want_rgb: bool,
        want_depth: bool,
        out: tuple[np.ndarray | None, np.ndarray | None] = (None, None),
    ) -> tuple[np.ndarray, np.ndarray]:
        if not (want_rgb or want_depth):
            return _EMPTY_RGB, _EMPTY_DEPTH
        look = scene.look or _DEFAULT_LOOK
        if want_rgb:
            self._light(look.lighting)
        seen = self._crossings(scene, x, y, yaw)
        wall = (
            np.zeros((self.height, self.width), dtype=bool) if want_rgb and scene.floor is not None else None
        )
        ranks = seen.ranks() if seen is not None else None
        if seen is not None and want_rgb:
            self._shade(seen, scene, look, x, y, yaw)
        if seen is not None and seen.plane is None and ranks == [None]:
            rgb, depth_mm = self._paint_one_layer(seen, want_rgb, want_depth, wall, out)
            if seen.round_pixels is not None:
                _, rows, cols, colours = seen.round_pixels
                rgb[rows, cols] = colours
        elif seen is None:
            rgb = _filled(out[0], self._background) if want_rgb else _EMPTY_RGB
            depth_mm = _filled(out[1], self._floor_depth_image) if want_depth else _EMPTY_DEPTH
        else:  # the background drawn by the first pass, around and under its crossings
            assert ranks is not None
            rgb = _new_image(out[0], self._background) if want_rgb else _EMPTY_RGB
            depth_mm = _new_image(out[1], self._floor_depth_image) if want_depth else _EMPTY_DEPTH
            self._paint_crossings(seen, ranks, rgb, depth_mm, wall)
        if wall is not None:
            assert scene.floor is not None
            self._paint_floor(rgb, wall, scene.floor, x, y, yaw, look.lighting)
        return rgb, depth_mm

    def _light(self, lighting: Lighting) -> None:
        """Draw the background for ``lighting`` (when it changed): the floor lit as a surface facing
        up (the same colour at every distance), the sky above the horizon."""
        if lighting is self._lit_by:
            return
        floor = np.asarray(lighting.floor if lighting.floor is not None else FLOOR_RGB, dtype=np.float32)
        sky = np.asarray(lighting.sky if lighting.sky is not None else SKY_RGB, dtype=np.float32)
        row = np.where(self._below[:, None], lighting.shade_flat(floor, _UP)[None, :], sky.astype(np.uint8))
        self._background[...] = row[:, None, :]
        self._lit_by = lighting

    def _shade(self, seen: _Seen, scene: Scene, look: SceneLook, x: float, y: float, yaw: float) -> None:
        """Each crossing's colour (``seen.rgb``), lit by the world's lights on its face's normal: a
        side's horizontal normal on the camera's side of it (one of the two colours of each segment,
        lit once per world: :class:`_Palette`), a round shape's from its axis to where the ray meets
        it, a lid's up, an underside's down; and the pixels of the sides of spheres, lit row by row
        on the sphere's normal at that height (``seen.round_pixels``)."""
        pal = self._palette_for(scene, look)
        item = seen.item
        n = pal.n
        seen.round_pixels = None
        if n == len(scene.segments) + len(scene.circles) or _ALL(item < n):
            rgb = pal.seen_from(x, y).take(item, axis=0)
            if pal.any_round:
                round_ = pal.is_round.take(item).nonzero()[0]
                if len(round_):
                    self._shade_round(
                        seen, look, rgb, round_, pal.centres.take(item.take(round_), axis=0), pal, x, y, yaw
                    )
        else:  # crossings of moving obstacles' sides and of other robots' round bodies
            rgb = np.empty((len(item), 3), dtype=np.uint8)
            known = (item < n).nonzero()[0]
            rgb[known] = pal.seen_from(x, y).take(item.take(known), axis=0)
            n_seg = len(scene.segments)
            moved = ((item >= n) & (item < n_seg)).nonzero()[0]
            if len(moved):
                rgb[moved] = _flat_colours(scene, look.lighting, item.take(moved), x, y)
            round_ = (item >= n_seg).nonzero()[0]
            centres = scene.circles[item.take(round_) - n_seg]
            if pal.any_round:
                also = known[pal.is_round.take(item.take(known))]
                round_ = np.concatenate([also, round_])
                centres = np.concatenate([pal.centres.take(item.take(also), axis=0), centres])
            if len(round_):
                self._shade_round(seen, look, rgb, round_, centres, pal, x, y, yaw)
        if seen.plane is not None:
            flat = (~np.isnan(seen.plane)).nonzero()[0]
            lid = (seen.plane.take(flat) < self.cam_z)[:, None]
            under = item.take(flat)
            if _ALL(under < n):
                rgb[flat] = np.where(lid, pal.lid.take(under, axis=0), pal.under.take(under, axis=0))
            else:  # a moving obstacle's lid
                colours = seen.colors.take(under, axis=0)
                lighting = look.lighting
                rgb[flat] = np.where(
                    lid, lighting.shade_flat(colours, _UP), lighting.shade_flat(colours, _DOWN)
                )
        seen.rgb = rgb

    def _palette_for(self, scene: Scene, look: SceneLook) -> _Palette:
        """The palette of the scene's segments: the last one if the scene has the same arrays, or
        starts with the same segments (the world's, before the moving obstacles' that change every
        step); else a new one over the segments the scene shares with the last scene drawn."""
        pal = self._palette
        if pal is not None and (pal.fits(scene, look) or pal.prefix_of(scene, look)):
            return pal
        n = len(scene.segments)
        last = self._last_scene
        if last is not None and last[3] is look:
            n = _common_rows(n, (last[0], scene.segments), (last[1], scene.colors), (last[2], scene.owners))
        self._last_scene = _arrays_of(scene, look)
        pal = self._palette = _Palette(scene, look, n)
        return pal

    def _shade_round(
        self,
        seen: _Seen,
        look: SceneLook,
        rgb: np.ndarray,
        k: np.ndarray,
        centres: np.ndarray,
        pal: _Palette,
        x: float,
        y: float,
        yaw: float,
    ) -> None:
        """The colours (into ``rgb``) of crossings ``k``, sides of round shapes (the world's
        cylinders and spheres, other robots' bodies) with axes at ``centres``: lit on the normal from
        the axis to where the ray meets the side; spheres' pixels row by row (``_sphere_pixels``)."""
        d = seen.depth.take(k)
        slope = self.col_slopes.take(seen.col.take(k))
        c, s = math.cos(yaw), math.sin(yaw)
        nx = x + d * (c - s * slope) - centres[:, 0]
        ny = y + d * (s + c * slope) - centres[:, 1]
        length = np.hypot(nx, ny)
        length[length == 0.0] = 1.0
        normals = np.zeros((len(k), 3))
        normals[:, 0], normals[:, 1] = nx / length, ny / length
        colours = seen.colors.take(seen.item.take(k), axis=0)
        rgb[k] = look.lighting.shade(colours, normals)
        if pal.any_sphere:
            self._sphere_pixels(seen, look, pal, k, normals, colours)

    def _sphere_pixels(
        self,
        seen: _Seen,
        look: SceneLook,
        pal: _Palette,
        k: np.ndarray,
        normals: np.ndarray,
        colours: np.ndarray,
    ) -> None:
        """The pixels of the sides of spheres (seen directly, not through a lid), each lit on the
        sphere's normal at the height its ray meets the side: tilted up toward the top (a white
        ball's upper part saturates, as in Gazebo), down toward the bottom. ``k``: the crossings of
        round shapes, with their horizontal ``normals`` and ``colours``."""
        item = seen.item.take(k)
        ball = item < pal.n
        ball[ball] = ~np.isnan(pal.sphere_r.take(item[ball]))
        if seen.plane is not None:
            ball &= np.isnan(seen.plane.take(k))
        if not _ANY(ball):
            return
        pick = ball.nonzero()[0]
        kk, ball_item = k[pick], item[pick]
        r, cz = pal.sphere_r.take(ball_item), pal.sphere_z.take(ball_item)
        top, bottom = seen.top.take(kk).astype(np.intp), seen.bottom.take(kk).astype(np.intp)
        lengths = bottom - top
        keep = lengths > 0
        if not _ALL(keep):
            pick, kk, r, cz, top, lengths = (a[keep] for a in (pick, kk, r, cz, top, lengths))
        if not len(kk):
            return
        which = np.repeat(np.arange(len(kk)), lengths)
        starts = np.repeat(np.cumsum(lengths) - lengths, lengths)
        rows = np.arange(len(which)) - starts + top[which]
        height = self.cam_z + self.row_slope[rows] * seen.depth[kk][which]
        t = np.clip((height - cz[which]) / r[which], -1.0, 1.0)
        across = np.sqrt(1.0 - t * t)
        n = np.empty((len(which), 3))
        n[:, 0] = normals[pick[which], 0] * across
        n[:, 1] = normals[pick[which], 1] * across
        n[:, 2] = t
        seen.round_pixels = (
            kk[which],
            rows,
            seen.col[kk][which],
            look.lighting.shade(colours[pick[which]], n),
        )

    def _crossings(self, scene: Scene, x: float, y: float, yaw: float) -> _Seen | None:
        """The crossings that show in the image, each with its rows cut to what the nearer strips
        standing on the floor leave free; None when nothing shows.

        The far side of a convex shape (``scene.facing``) shows only through the shape's lid (a shape
        lower than the camera, seen from above) or its underside (a shape held above the camera): it
        is cast only for those shapes, and its visible rows are the lid's or the underside's, drawn
        at the depth where each row's ray meets that plane (see :meth:`_paint_crossings`)."""
        heights, bases, colors = scene.heights, scene.bases, scene.colors
        segments = scene.segments
        facing, inner_plane = self._cast_sides(heights, bases, scene.facing)
        col, item, d = column_pairs(x, y, yaw, self.col_slopes, segments, self.depth_max, facing)
        plane_of: np.ndarray | None = None
        if inner_plane is not None and len(item):
            assert scene.facing is not None
            seg = segments[item]
            # the side faces away from the camera: (p - o) x e has the sign of the outline's turning
            away = scene.facing[item] * (
                (seg[:, 0] - x) * (seg[:, 3] - seg[:, 1]) - (seg[:, 1] - y) * (seg[:, 2] - seg[:, 0])
            )
            plane_of = np.where(away > 0.0, inner_plane[item], np.nan)
        if len(scene.circles):  # other robots: round bodies standing on the floor, listed after the segments
            ray_c, circle_c, t_c = circle_pairs(
                x,
                y,
                yaw + self.col_angles,
                scene.circles,
                scene.radii,
                self.depth_max / float(self.col_cos.min()),
            )
            d_c = t_c * self.col_cos[ray_c]
            near = d_c <= self.depth_max
            n = len(segments)
            col = np.concatenate([col, ray_c[near]])
            item = np.concatenate([item, circle_c[near] + n])
            d = np.concatenate([d, d_c[near]])
            if plane_of is not None:
                plane_of = np.concatenate([plane_of, np.full(int(near.sum()), np.nan)])
            heights = np.concatenate([heights, scene.circle_heights])
            colors = np.concatenate([colors, scene.circle_colors])
            if bases is not None:
                bases = np.concatenate([bases, np.zeros(len(scene.circles))])
        if not len(d):
            return None
        # by column, nearest first
        key = col * (2.0 * self.depth_max + 2.0)
        key += d
        order = key.argsort(kind="stable")  # on a tie (two sides flush) the first listed wins
        col, item, d = col.take(order), item.take(order), d.take(order)
        h = self.height
        # rows v whose ray meets the strip between its base and its top: base <= cam_z + slope_v d <= top,
        # slope_v = (cy - v) / fy; the bound is one row past the base's row (exclusive)
        # (both bounds at once: cy + (cam_z - top) fy / d and cy + 1 + (cam_z - base) fy / d)
        rows = self._rises(heights, bases).take(item, axis=1)
        rows *= self.fy / d
        rows += self._row_offsets
        top, bottom = rows
        np.ceil(top, out=top)
        np.floor(bottom, out=bottom)
        plane: np.ndarray | None = None
        if plane_of is not None:
            plane = plane_of[order]
            if np.isnan(plane).all():
                plane = None
            else:
                self._through_planes(scene, col, item, d, plane, top, bottom)
        np.maximum(top, 0.0, out=top)
        np.minimum(bottom, float(h), out=bottom)
        # a strip standing on the floor hides every row of a farther one from its own top down: the
        # farther one's lowest row is above its foot. The lowest top among the nearer ones in the same
        # column, from one running minimum (each column shifted below all earlier ones, so a column
        # starts afresh; a value carried over from an earlier column comes back above ``h``)
        stride = float(h + 1)
        shift = col * stride
        grounded = top - shift if bases is None else np.where(bases[item] <= 0.0, top, float(h)) - shift
        running = np.minimum.accumulate(grounded)
        shift[1:] += running[:-1]
        shift[0] = stride
        np.minimum(bottom, shift, out=bottom)
        shows = top < bottom
        if not _ALL(shows):
            pick = shows.nonzero()[0]
            if not len(pick):
                return None
            col, item, d = col.take(pick), item.take(pick), d.take(pick)
            rows = rows.take(pick, axis=1)
            if plane is not None:
                plane = plane.take(pick)
        if plane is not None and np.isnan(plane).all():
            plane = None
        return _Seen(
            col,
            item,
            d,
            rows,
            colors,
            plane,
            self.width,
            self._row_type,
        )

    def _cast_sides(
        self, heights: np.ndarray, bases: np.ndarray | None, facing: np.ndarray | None
    ) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Which sides to cast (``facing`` for the cast: the far sides of the shapes the camera sees
        from above or below are cast too, as 0) and per segment the height of the lid or underside
        they are seen through (NaN: none; None: no segment is); kept for the last arrays seen, as a
        world's scenes share them from step to step."""
        kept = self._sides
        if kept is not None and kept[0] is heights and kept[1] is bases and kept[2] is facing:
            return kept[3]
        inner_plane: np.ndarray | None = None
        cast = facing
        if facing is not None and len(heights):
            straddles = heights >= self.cam_z
            if bases is not None:
                straddles &= bases <= self.cam_z
            if not _ALL(straddles):
                # sides facing away are cast for shapes the camera sees from above or below
                level = np.where(heights < self.cam_z, heights, bases if bases is not None else 0.0)
                inner_plane = np.where(straddles | (facing == 0), np.nan, level)
                cast = np.where(straddles, facing, 0).astype(np.int8)
        self._sides = (heights, bases, facing, (cast, inner_plane))
        return cast, inner_plane

    def _rises(self, heights: np.ndarray, bases: np.ndarray | None) -> np.ndarray:
        """(2, N): per segment, the camera's height less its top and less its base (0: on the floor),
        what the image rows of its crossings follow from; kept for the last arrays seen (a world's
        scenes share them from step to step)."""
        kept = self._rise
        if kept is not None and kept[0] is heights and kept[1] is bases:
            return kept[2]
        rise = np.empty((2, len(heights)))
        np.subtract(self.cam_z, heights, out=rise[0])
        np.subtract(self.cam_z, 0.0 if bases is None else bases, out=rise[1])
        self._rise = (heights, bases, rise)
        return rise

    def _through_planes(
        self,
        scene: Scene,
        col: np.ndarray,
        item: np.ndarray,
        d: np.ndarray,
        plane: np.ndarray,
        top: np.ndarray,
        bottom: np.ndarray,
    ) -> None:
        """Turn the rows of each far side seen through a lid or an underside (``plane`` not NaN) into
        that plane's rows: a ray meets the lid (or the underside) at height ``plane`` between the
        side it enters the shape by (at depth ``d_in``) and the side it leaves by (``d``). So a lid's
        rows run from its far edge's row down to its near edge's (the near side's top row, where the
        near side's own rows begin); an underside's from its near edge's row (below the near side's
        rows) down to its far edge's. The side it enters by is the nearest one of the same shape in
        the same column (a camera inside the shape's outline, under a table top, has none: d_in 0).
        Arrays by crossing, sorted by column and depth; ``top`` and ``bottom`` changed in place."""
        n = len(scene.segments)
        if scene.owners is not None:
            # crossings of other robots (items from n on, round bodies) belong to no outline
            shape = (item < n).nonzero()[0]
            shape = shape[scene.owners.take(item.take(shape)) >= 0]
        else:
            shape = (~np.isnan(plane)).nonzero()[0]
            shape = shape[item[shape] < n]
        owner = scene.owners[item[shape]] if scene.owners is not None else np.zeros(len(shape), np.intp)
        by_shape = shape[np.lexsort((d[shape], owner, col[shape]))]
        # consecutive crossings of one shape in one column: the first enters, the next leaves by
        prev, cur = by_shape[:-1], by_shape[1:]
        same = (col[prev] == col[cur]) & (np.isnan(plane[prev])) & (~np.isnan(plane[cur]))
        if scene.owners is not None:
            same &= scene.owners[item[prev]] == scene.owners[item[cur]]
        inner = (~np.isnan(plane)).nonzero()[0]
        d_in = np.zeros(len(d))
        d_in[cur[same]] = d[prev[same]]
        rise = plane[inner] - self.cam_z
        with np.errstate(divide="ignore", invalid="ignore"):
            edge = -self.fy * rise / d_in[inner]  # the near edge's row, less cy (+-inf at d_in 0)
        lid = rise < 0.0
        bottom[inner] = np.where(lid, np.ceil(self.cy + edge), bottom[inner])
        top[inner] = np.where(lid, top[inner], np.floor(self.cy + edge) + 1.0)

    def _paint_one_layer(
        self,
        seen: _Seen,
        want_rgb: bool,
        want_depth: bool,
        wall: np.ndarray | None,
        out: tuple[np.ndarray | None, np.ndarray | None],
    ) -> tuple[np.ndarray, np.ndarray]:
        """The images when each column shows at most one crossing and no lid or underside (the common
        case), the same pixels as :meth:`_paint_crossings` in fewer passes: each output pixel is
        written about once. The rows above and below every crossing are the background's, copied;
        when every column has a crossing, the rows all of them cover (the core) are their colours
        and depths repeated down, with no mask; only the fringes between the highest and lowest
        top (and bottom) are masked copies over the background."""
        h, w = self.height, self.width
        cols, top, bottom = seen.col, seen.top, seen.bottom
        r0, r1 = int(_MIN(top)), int(_MAX(bottom))
        full = len(cols) == w  # one crossing in every column: cols is 0..w-1, in order
        c0 = c1 = r1  # the core's rows: none unless every column covers them
        if full:
            c0, c1 = int(_MAX(top)), int(_MIN(bottom))
            if c0 >= c1:
                c0 = c1 = r1
        cv2 = _opencv()
        rgb, depth_mm = _EMPTY_RGB, _EMPTY_DEPTH
        if want_rgb:
            shaded = seen.rgb
            if full:
                colour_row = shaded
            else:
                colour_row = self._colour_row
                self._colour_cells[cols] = shaded.view(_PIXEL).reshape(-1)
            rgb = np.empty((h, w, 3), dtype=np.uint8) if out[0] is None else out[0]
            rgb[:r0] = self._background[:r0]
            rgb[r1:] = self._background[r1:]
            if c0 < c1:
                cv2.repeat(colour_row[None], c1 - c0, 1, dst=rgb[c0:c1])
        if want_depth:
            mm = np.rint(seen.depth * 1000.0).astype(np.uint16)
            if full:
                depth_row = mm
            else:
                depth_row = self._depth_row
                depth_row[cols] = mm
            depth_mm = np.empty((h, w), dtype=np.uint16) if out[1] is None else out[1]
            depth_mm[:r0] = self._floor_depth_image[:r0]
            depth_mm[r1:] = self._floor_depth_image[r1:]
            if c0 < c1:
                cv2.repeat(depth_row[None], c1 - c0, 1, dst=depth_mm[c0:c1])
        if wall is not None and c0 < c1:
            wall[c0:c1] = True
        spans: tuple[np.ndarray, np.ndarray] | None = None  # the columns' rows, for both fringes
        for a, b in ((r0, c0), (c1, r1)):
            if a >= b:
                continue
            if spans is None:
                spans = (bottom - top, top) if full else self._column_spans(cols, top, bottom)
            # the band is the columns' values repeated down, then the background copied back where
            # no crossing covers it: each pixel written at most twice and no band-sized temporary
            bare = self._band_mask(*spans, a, b, inside=False)
            if want_rgb:
                _columns_over(rgb[a:b], colour_row, self._background[a:b], bare)
            if want_depth:
                _columns_over(depth_mm[a:b], depth_row, self._floor_depth_image[a:b], bare)
            if wall is not None:
                wall[a:b] |= ~bare.view(bool)
        return rgb, depth_mm

    def _paint_crossings(
        self,
        seen: _Seen,
        ranks: list[np.ndarray | None],
        rgb: np.ndarray,
        depth_mm: np.ndarray,
        wall: np.ndarray | None,
    ) -> None:
        """Fill each crossing's rows with its colour (lit, flat; a sphere's side row by row) and depth:
        one masked copy per rank within the column, the farthest first, over the band of rows that
        rank spans (a nearer strip in the air is painted over what it hides). A lid's or an
        underside's rows (a far side seen through them) get, in the depth image, the depth where each
        row's ray meets that plane: (plane - cam_z) / slope_v. The images come undrawn: the first
        pass draws the background around its band and where its crossings do not cover the band."""
        if rgb.size:
            shaded = seen.rgb
            spheres = seen.round_pixels
            if spheres is not None:
                pass_of = np.zeros(len(seen.col), dtype=np.intp)
                for p, sel in enumerate(ranks):
                    if sel is not None:
                        pass_of[sel] = p
                sphere_pass = pass_of[spheres[0]]
        if depth_mm.size:
            mm = np.rint(seen.depth * 1000.0).astype(np.uint16)
        for p, sel in enumerate(ranks):
            cols = seen.col if sel is None else seen.col.take(sel)
            top = seen.top if sel is None else seen.top.take(sel)
            bottom = seen.bottom if sel is None else seen.bottom.take(sel)
            r0, r1 = int(_MIN(top)), int(_MAX(bottom))
            # the first pass's mask is where its band shows the background, the others' where
            # their crossings cover it
            mask = self._band_mask(*self._column_spans(cols, top, bottom), r0, r1, inside=p > 0)
            if wall is not None:
                wall[r0:r1] |= mask.view(bool) if p else ~mask.view(bool)
            # the values of columns outside the mask do not matter: the scratch rows are not cleared
            if rgb.size:
                cells = shaded.view(_PIXEL).reshape(-1)
                self._colour_cells[cols] = cells if sel is None else cells.take(sel)
                if p:
                    self._paint(rgb[r0:r1], self._colour_row, mask)
                else:
                    _background_around(rgb, self._background, r0, r1)
                    _columns_over(rgb[r0:r1], self._colour_row, self._background[r0:r1], mask)
                if spheres is not None:
                    here = sphere_pass == p
                    rgb[spheres[1][here], spheres[2][here]] = spheres[3][here]
            if depth_mm.size:
                self._depth_row[cols] = mm if sel is None else mm.take(sel)
                if p:
                    self._paint(depth_mm[r0:r1], self._depth_row, mask)
                else:
                    _background_around(depth_mm, self._floor_depth_image, r0, r1)
                    _columns_over(depth_mm[r0:r1], self._depth_row, self._floor_depth_image[r0:r1], mask)
                if seen.plane is not None:
                    self._paint_planes(seen, sel, depth_mm)

    def _column_spans(
        self, cols: np.ndarray, top: np.ndarray, bottom: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Per image column: how many rows columns ``cols`` cover from ``top`` (0 elsewhere), and
        that top row (scratch rows: the values of other columns do not matter)."""
        span, start = self._span_row, self._top_row
        span.fill(0)
        span[cols] = bottom - top
        start[cols] = top
        return span, start

    def _paint_planes(self, seen: _Seen, sel: np.ndarray | None, depth_mm: np.ndarray) -> None:
        """The depth of the lids and undersides among one pass's crossings (their columns' rows, at
        the depth where each row's ray meets the plane), over what the pass painted there."""
        assert seen.plane is not None
        plane = seen.plane if sel is None else seen.plane[sel]
        lid = (~np.isnan(plane)).nonzero()[0]
        if not len(lid):
            return
        pick = lid if sel is None else sel[lid]
        cols, top, bottom = seen.col[pick], seen.top[pick], seen.bottom[pick]
        r0, r1 = int(top.min()), int(bottom.max())
        band_top = np.zeros(self.width, dtype=self._row_type)
        band_bottom = np.zeros(self.width, dtype=self._row_type)
        band_top[cols], band_bottom[cols] = top, bottom
        rise = np.zeros(self.width)
        rise[cols] = plane[lid] - self.cam_z
        with np.errstate(divide="ignore", invalid="ignore"):
            metres = rise[None, :] / self.row_slope[r0:r1, None]
        np.nan_to_num(metres, copy=False, nan=0.0, posinf=0.0, neginf=0.0)
        np.clip(metres, 0.0, self.depth_max, out=metres)
        self._paint(
            depth_mm[r0:r1],
            np.rint(metres * 1000.0).astype(np.uint16),
            self._span_mask(band_top, band_bottom, r0, r1),
            whole=True,
        )

    def _span_mask(self, top: np.ndarray, bottom: np.ndarray, r0: int, r1: int) -> np.ndarray:
        """uint8 (r1 - r0, width): 1 at the rows v in [r0, r1) of each column u with
        top[u] <= v < bottom[u] (none where bottom <= top)."""
        span = np.subtract(bottom, top, dtype=self._row_type)
        span[bottom <= top] = 0
        return self._band_mask(span, top, r0, r1)

    def _band_mask(
        self, span: np.ndarray, top: np.ndarray, r0: int, r1: int, inside: bool = True
    ) -> np.ndarray:
        """uint8 (r1 - r0, width): 1 at the rows v in [r0, r1) of each column u with
        top[u] <= v < top[u] + span[u], as (v - top) mod 2^bits < span: a row above top wraps
        around to at least 2^bits - top, more than any span below ``height``; ``inside=False``:
        1 at the other rows."""
        offset, mask = self._offset[: r1 - r0], self._mask[: r1 - r0]
        np.subtract(self._rows[r0:r1], top, out=offset)
        (np.less if inside else np.greater_equal)(offset, span, out=mask)
        return mask.view(np.uint8)

    def _paint(
        self, image: np.ndarray, per_column: np.ndarray, mask: np.ndarray, whole: bool = False
    ) -> None:
        """Set ``image``'s pixels under ``mask`` (uint8, ``image``'s rows and columns) to their
        column's value (``per_column``: one value or pixel per column; ``whole``: already one per
        pixel), in place (OpenCV's masked copy, a few times faster than numpy's ``where`` or
        ``copyto(where=)`` here; the column values repeated down the rows by OpenCV too, a third
        faster than a contiguous copy of a broadcast)."""
        cv2 = _opencv()
        full = per_column if whole else cv2.repeat(np.ascontiguousarray(per_column)[None], image.shape[0], 1)
        cv2.copyTo(full, mask, image)

    def _paint_floor(
        self,
        rgb: np.ndarray,
        wall: np.ndarray,
        paint: FloorPaint,
        x: float,
        y: float,
        yaw: float,
        lighting: Lighting = DEFAULT_LIGHTING,
    ) -> None:
        """Draw the floor markings (the course's 1 m square) where floor pixels see them, lit as the
        floor. The floor is a plane: the image rows that see it map onto the markings' texture by one
        homography, so the texture is looked up for every floor pixel by one perspective warp
        (OpenCV, nearest texel, 0 outside the texture) rather than a dozen numpy passes over the
        floor's rows; the wall pixels are then cleared of ink."""
        first = self._floor_first
        if first >= self.height:
            return
        res = paint.resolution
        c, s = math.cos(yaw), math.sin(yaw)
        fx, cx = self.fx, self.cx
        # one over the distance ahead of row first + r is g2 r + g3; the floor point seen by pixel
        # (u, first + r) at texel (X, Y) = (a . (u, r, 1), b . (u, r, 1)) / (g2 r + g3), less half a
        # texel so that the warp's rounding to the nearest texel takes the texel the point lies in
        g2 = 1.0 / (self.cam_z * self.fy)
        g3 = (first - self.cy) * g2
        ex, ny = (x - paint.origin_x) / res - 0.5, (y - paint.origin_y) / res - 0.5
        warp = np.array(
            [
                [s / (fx * res), ex * g2, ex * g3 + (c - s * cx / fx) / res],
                [-c / (fx * res), ny * g2, ny * g3 + (s + c * cx / fx) / res],
                [0.0, g2, g3],
            ]
        )
        cv2 = _opencv()
        ink = cv2.warpPerspective(
            paint.texture,
            warp,
            (self.width, self.height - first),
            flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP,
            borderMode=cv2.BORDER_CONSTANT,
            borderValue=0,
        )
        np.copyto(ink, 0, where=wall[first:])  # a wall stands there
        painted = ink.reshape(-1).nonzero()[0]
        if not len(painted):
            return
        cells = rgb.view(_PIXEL).reshape(-1)
        kept = self._lit_palette
        if kept is None or kept[0] is not paint.palette or kept[1] is not lighting:
            kept = (paint.palette, lighting, np.ascontiguousarray(lighting.shade_flat(paint.palette, _UP)))
            self._lit_palette = kept
        cells[painted + first * self.width] = (
            kept[2].view(_PIXEL).reshape(-1).take(ink.reshape(-1).take(painted) - 1)
        )

    def intrinsics(self) -> tuple[float, float, float, float]:
        return self.fx, self.fy, self.cx, self.cy


class _Seen:
    """The crossings that show, sorted by column and, within a column, nearest first: column, obstacle
    (``item``, into ``colors``), optical-axis depth and the rows they may fill (``top <= v < bottom``,
    given as the two rows of ``rows``)."""

    def __init__(
        self,
        col: np.ndarray,
        item: np.ndarray,
        depth: np.ndarray,
        rows: np.ndarray,
        colors: np.ndarray,
        plane: np.ndarray | None,
        width: int,
        row_type: type,
    ) -> None:
        self.col, self.item, self.depth, self.colors, self.width = col, item, depth, colors, width
        self.top, self.bottom = rows.astype(row_type)
        #: per crossing: the height of the lid or underside it is seen through (NaN: a side seen
        #: directly); None when no crossing is
        self.plane = plane
        #: per crossing: its colour as lit (see Camera._shade), set when a colour image is drawn
        self.rgb: np.ndarray = _EMPTY_RGB
        #: the sides of spheres, pixel by pixel: (crossing, row, column, colour) arrays; None: none
        self.round_pixels: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None

    def ranks(self) -> list[np.ndarray | None]:
        """The crossings of each paint pass: each column's crossings from its farthest to its
        nearest, one per pass (pass p holds those with p farther ones in their column); None: every
        crossing, all in one pass (one per column, the common case)."""
        col = self.col
        repeated = col[1:] == col[:-1]
        if not _ANY(repeated):
            return [None]
        n = len(col)
        # where each column's crossings start, and the end of the last column
        bounds = np.ones(n + 1, dtype=bool)
        np.logical_not(repeated, out=bounds[1:n])
        edges = bounds.nonzero()[0]
        ends = edges[1:]
        lengths = ends - edges[:-1]
        from_far = ends.repeat(lengths)  # each crossing's column's end
        from_far -= np.arange(1, n + 1)
        passes = int(_MAX(lengths))
        return [(from_far == p).nonzero()[0] for p in range(passes)]


class _Palette:
    """The first ``n`` segments of a scene (the world's; a scene's moving obstacles' come after
    them) with their colours lit once, each on both of its sides (``front`` seen from the side of
    its normal (``nx``, ``ny``), ``back`` from the other), and per segment the centre of a round
    obstacle and a sphere's centre height and radius (NaN: not round, not a sphere)."""

    def __init__(self, scene: Scene, look: SceneLook, n: int) -> None:
        self.scene_arrays = _arrays_of(scene, look)
        self.look = look
        self.n = n
        #: the scene's static segments when this palette covers no more than them (see prefix_of)
        self.prefix = scene.prefix if scene.prefix is not None and n <= len(scene.prefix) else None
        seg = self.segments = scene.segments[:n]
        self.colors = scene.colors[:n]
        self.owners = None if scene.owners is None else scene.owners[:n]
        self.centres = np.full((n, 2), np.nan)
        self.sphere_z = np.full(n, np.nan)
        self.sphere_r = np.full(n, np.nan)
        self.any_round = self.any_sphere = False
        if self.owners is not None and look.any_round:
            owner = self.owners
            known = (owner >= 0) & (owner < len(look.round_centres))
            self.centres[known] = look.round_centres[owner[known]]
            self.sphere_z[known] = look.sphere_z[owner[known]]
            self.sphere_r[known] = look.sphere_r[owner[known]]
            self.any_round = not bool(np.isnan(self.centres[:, 0]).all())
            self.any_sphere = not bool(np.isnan(self.sphere_r).all())
        #: per segment: a side of a round obstacle
        self.is_round = ~np.isnan(self.centres[:, 0])
        nx = seg[:, 3] - seg[:, 1]
        ny = seg[:, 0] - seg[:, 2]
        length = np.hypot(nx, ny)
        length[length == 0.0] = 1.0
        self.nx, self.ny = nx / length, ny / length
        self.c0 = self.nx * seg[:, 0] + self.ny * seg[:, 1]
        normals = np.zeros((2 * n, 3))
        normals[0::2, 0], normals[0::2, 1] = self.nx, self.ny
        normals[1::2, 0], normals[1::2, 1] = -self.nx, -self.ny
        table = look.lighting.shade(np.repeat(self.colors, 2, axis=0), normals)
        #: each segment's colour seen from the side of its normal, and from the other
        self.front, self.back = table[0::2], table[1::2]
        #: each segment's colour on a lid (seen from above) and on an underside
        self.lid = look.lighting.shade_flat(self.colors, _UP)
        self.under = look.lighting.shade_flat(self.colors, _DOWN)
        self._seen_at: tuple[tuple[float, float], np.ndarray] | None = None

    def seen_from(self, x: float, y: float) -> np.ndarray:
        """(n, 3): each segment's colour on the side a camera at (x, y) is on (n . (camera - p0) < 0:
        its back); a few passes over the segments, cheaper than per crossing for a few hundred."""
        if self._seen_at is not None and self._seen_at[0] == (x, y):
            return self._seen_at[1]
        side = self.nx * x
        side += self.ny * y
        back = np.less(side, self.c0)[:, None]
        colours = np.where(back, self.back, self.front)
        self._seen_at = ((x, y), colours)
        return colours

    def fits(self, scene: Scene, look: SceneLook) -> bool:
        """Built from these very arrays and lights."""
        return all(a is b for a, b in zip(self.scene_arrays, _arrays_of(scene, look), strict=True))

    def prefix_of(self, scene: Scene, look: SceneLook) -> bool:
        """The scene starts with this palette's segments, colours and owners (a scene of the same
        world whose moving obstacles moved)."""
        n = self.n
        if (
            look is not self.look
            or len(scene.segments) < n
            or (scene.owners is None) != (self.owners is None)
        ):
            return False
        if self.prefix is not None and scene.prefix is self.prefix:
            # the same world's static segments (the simulator's one array): only the moving
            # obstacles after them changed; colours and owners are the same arrays too
            _, colors, owners, _ = self.scene_arrays
            if scene.colors is colors and scene.owners is owners:
                return True
        if (
            not np.equal(scene.segments[:n], self.segments).all()
            or not np.equal(scene.colors[:n], self.colors).all()
        ):
            return False
        owners = scene.owners
        return owners is None or self.owners is None or bool(np.equal(owners[:n], self.owners).all())


def _common_rows(n: int, *pairs: tuple[np.ndarray | None, np.ndarray | None]) -> int:
    """How many first rows (at most ``n``) every pair of arrays has equal."""
    for a, b in pairs:
        if a is None or b is None:
            if a is not b:
                return 0
            continue
        m = min(n, len(a), len(b))
        same = np.equal(a[:m], b[:m])
        if same.ndim > 1:
            same = same.all(axis=1)
        n = m if same.all() else int(np.argmin(same))
    return n


def _fits(array: np.ndarray, shape: tuple[int, ...], dtype: type) -> bool:
    flags = array.flags
    return array.shape == shape and array.dtype == dtype and flags.c_contiguous and flags.writeable


def _columns_over(band: np.ndarray, per_column: np.ndarray, background: np.ndarray, bare: np.ndarray) -> None:
    """Draw ``band``: each column's value (``per_column``) repeated down its rows, and ``background``
    copied back where ``bare`` (uint8) is set; each pixel written at most twice (OpenCV), with no
    band-sized temporary."""
    cv2 = _opencv()
    cv2.repeat(per_column[None], band.shape[0], 1, dst=band)
    cv2.copyTo(background, bare, band)


def _background_around(image: np.ndarray, background: np.ndarray, r0: int, r1: int) -> None:
    """``background``'s rows above ``r0`` and from ``r1`` on, copied into ``image``."""
    image[:r0] = background[:r0]
    image[r1:] = background[r1:]


def _new_image(out: np.ndarray | None, like: np.ndarray) -> np.ndarray:
    """``out``, or a new array shaped as ``like``, to be drawn in full."""
    return np.empty_like(like) if out is None else out


def _filled(out: np.ndarray | None, image: np.ndarray) -> np.ndarray:
    """``image`` copied into ``out``, or a new copy of it."""
    if out is None:
        return image.copy()
    np.copyto(out, image)
    return out


def _copied_into(
    images: tuple[np.ndarray, np.ndarray], out: tuple[np.ndarray | None, np.ndarray | None]
) -> tuple[np.ndarray, np.ndarray]:
    """A still camera's last ``images`` again, each copied into its ``out`` array if it has one."""
    return (
        images[0] if out[0] is None else _filled(out[0], images[0]),
        images[1] if out[1] is None else _filled(out[1], images[1]),
    )


def _flat_colours(scene: Scene, lighting: Lighting, it: np.ndarray, x: float, y: float) -> np.ndarray:
    """(len(it), 3): the colours of segments ``it`` lit on the side a camera at (x, y) is on,
    computed for these crossings alone (the moving obstacles' sides)."""
    seg = scene.segments.take(it, axis=0)
    ex = seg[:, 2] - seg[:, 0]
    ey = seg[:, 3] - seg[:, 1]
    toward = ey * (x - seg[:, 0])
    toward -= ex * (y - seg[:, 1])
    length = np.hypot(ex, ey)
    length[length == 0.0] = 1.0
    flip = np.where(toward < 0.0, -1.0, 1.0)
    flip /= length
    normals = np.zeros((len(it), 3))
    normals[:, 0] = ey * flip
    normals[:, 1] = -ex * flip
    return lighting.shade(scene.colors.take(it, axis=0), normals)


def _arrays_of(scene: Scene, look: SceneLook) -> tuple[Any, ...]:
    """What a palette is built from (compared by identity)."""
    return (scene.segments, scene.colors, scene.owners, look)


class _SceneCopy:
    """What a scene held, to tell whether the next one is the same (a still camera's frame is reused)."""

    def __init__(self, scene: Scene) -> None:
        self.arrays = [None if a is None else a.copy() for a in _scene_arrays(scene)]
        self.floor = scene.floor
        self.look = scene.look

    def same(self, scene: Scene) -> bool:
        if scene.floor is not self.floor or scene.look is not self.look:
            return False
        for kept, now in zip(self.arrays, _scene_arrays(scene), strict=True):
            if kept is None or now is None:
                if kept is not now:
                    return False
            elif not np.array_equal(kept, now):
                return False
        return True


def _scene_arrays(scene: Scene) -> list[np.ndarray | None]:
    return [
        scene.segments,
        scene.heights,
        scene.colors,
        scene.circles,
        scene.radii,
        scene.circle_heights,
        scene.circle_colors,
        scene.facing,
        scene.bases,
    ]


@functools.cache
def _opencv() -> Any:
    """OpenCV (a runtime dependency), imported at the first frame drawn: not at import time, nor
    when a robot is spawned (its 25-80 ms would delay the first scan after a spawn)."""
    import cv2

    return cv2
