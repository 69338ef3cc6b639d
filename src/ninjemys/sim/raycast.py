"""Ray casting in numpy: many rays from one origin against segments, circles and occupancy grids.

No ROS in here. The lidar, the camera's per-column rays and the depth image all come from these
functions; each returns the distance along every ray to the first hit (``inf`` when nothing is
hit within ``max_range``) and, for segments and circles, which one was hit.

* Segments: ray/segment intersections from 2D cross products, then a min per ray. Segments out of
  reach of ``max_range`` are culled first, and each remaining segment is paired only with the rays
  inside the angle it subtends (one ``searchsorted`` over the sorted rays), so the work follows what
  is visible (a few thousand pairs) instead of the full rays x segments product.
* Circles: the closed-form ray/circle intersection (robots and round obstacles seen by others).
* Grids: exact cell traversal, vectorised: every crossing of a vertical grid line and every
  crossing of a horizontal one along every ray, the cell entered at each crossing looked up at
  once, and the first occupied one taken (what a DDA finds, without a per-step Python loop). The
  simulator itself casts maps against their outline (:func:`grid_edges`), cheaper still.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: reductions called as ufunc methods: ``a.any()`` and ``a.min()`` go through numpy's Python-level
#: wrappers, a few microseconds a call that the camera's per-frame code feels
_ANY = np.logical_or.reduce
_ALL = np.logical_and.reduce
#: the sign of the side an end behind the camera stands for, for the first end and the second
_AWAY = np.array([-1.0, 1.0])


@dataclass(frozen=True, eq=False)
class SegmentSet:
    """Segments as the casts use them, with what depends on the segments alone worked out once
    (:func:`prepare_segments`): a lidar keeps the static world's between scans, which then differ
    only in where the eye stands and which way it looks."""

    #: (6, k): x0, y0, ex, ey, x0, y0 (e = second end - first): less the eye's (x, y, 0, 0, x, y)
    #: they are p, e, p (p: the first end seen from the eye), and one add makes the second p into q
    rows: np.ndarray
    #: (2, k): facing * ex and -(facing * ey), or None when no side is known to face a way: the
    #: sides whose outer face looks at the eye are those with py face[0] + px face[1] >= 0
    face: np.ndarray | None
    #: (2, k): x0 + x1, y0 + y1 (twice the middle); (k,): the lengths (the broad phase by range)
    middle: np.ndarray
    length: np.ndarray
    #: (x_lo, y_lo, x_hi, y_hi) of every end point: an eye whose farthest corner is within range
    #: reaches all of them, and the broad phase by range is skipped
    box: tuple[float, float, float, float]


def prepare_segments(segments: np.ndarray, facing: np.ndarray | None = None) -> SegmentSet:
    """``segments`` (k, 4) and their ``facing`` (see :func:`segment_pairs`) made ready to cast against."""
    k = len(segments)
    ends = np.asarray(segments, dtype=np.float64).T  # x0, y0, x1, y1
    rows = np.empty((6, k))
    rows[0:2] = ends[0:2]
    np.subtract(ends[2:4], ends[0:2], out=rows[2:4])
    rows[4:6] = ends[0:2]
    face = None
    if facing is not None and _ANY(facing != 0):
        face = rows[2:4] * np.asarray(facing, dtype=np.float64)
        np.negative(face[1], out=face[1])  # multiplying by +-1 and negating are exact: same signs
    box = (0.0, 0.0, 0.0, 0.0)
    if k:
        lo, hi = np.minimum(ends[0:2], ends[2:4]).min(axis=1), np.maximum(ends[0:2], ends[2:4]).max(axis=1)
        box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    return SegmentSet(rows, face, ends[0:2] + ends[2:4], np.hypot(rows[2], rows[3]), box)


#: the lower bounds of a crossing's (t, u): ahead of the eye, on the segment (ends included, and
#: a hair beyond them, so that a ray through a shared corner meets one side or the other)
_LOW = np.array([[0.0], [-1e-9]])


def cast_segments(
    ox: float,
    oy: float,
    angles: np.ndarray,
    segments: np.ndarray,
    max_range: float,
    facing: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Distance to the first segment along each ray (inf if none within ``max_range``) and its index (-1).

    ``angles`` are the rays' world angles in any order. The candidate pairs come from
    :func:`segment_pairs`; the nearest per ray wins (on an exact tie, the segment listed last).
    """
    n = len(angles)
    ray_of, seg_of, t = segment_pairs(ox, oy, angles, segments, max_range, facing)
    return nearest_hits(n, ray_of, seg_of, t)


def nearest_hits(
    n: int, ray_of: np.ndarray, seg_of: np.ndarray, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Per ray of ``n``: the smallest finite ``t`` among its pairs (inf if none) and the pair's
    ``seg_of`` (-1 if none); on an exact tie the pair listed last wins."""
    dist = np.full(n, np.inf)
    hit = np.full(n, -1, dtype=np.intp)
    if not len(t):
        return dist, hit
    np.minimum.at(dist, ray_of, t)
    won = t == dist[ray_of]
    won &= t != np.inf
    hit[ray_of[won]] = seg_of[won]
    return dist, hit


def segment_pairs(
    ox: float,
    oy: float,
    angles: np.ndarray,
    segments: np.ndarray,
    max_range: float,
    facing: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every (ray, segment) pair that can meet, and where: ``(ray_of, seg_of, t)`` with ``t`` the
    distance along the ray to the segment, ``inf`` where they do not meet within ``max_range``;
    by segment (ascending), then by ray position from the rays' smallest angle on.

    Each segment is paired only with the rays inside the angle it subtends from the origin (found
    with one ``searchsorted`` over the sorted rays), so the work grows with what is visible, not
    with rays x segments. Every step is done for all segments at once: at a few hundred segments
    the cost is the number of numpy calls. The lidar takes the nearest pair per ray
    (:func:`cast_beams`, its segments prepared once); :func:`cast_segments` also says which one.

    ``facing`` (per segment: +1 or -1 for a side of a convex outline going counter-clockwise or
    clockwise, 0 otherwise) leaves out the sides whose outer face looks away from the origin: a
    ray enters a convex outline through a side facing it, so those never give a first crossing,
    into that obstacle or into a taller one behind it (about half of a box's or a cylinder's sides).
    """
    angles = np.asarray(angles, dtype=np.float64)
    n = len(angles)
    if not n or not len(segments):
        return _NO_PAIRS
    a0, rel, order = _sorted_rays(angles, False)
    near, keep = _near(ox, oy, prepare_segments(segments, facing), max_range)
    if near is None:
        return _NO_PAIRS
    ray_of, seg_of = _spans(near, rel, a0)
    if not len(ray_of):
        return _NO_PAIRS
    if order is not None:
        ray_of = order.take(ray_of)
    t = _meet(near, ray_directions(angles), ray_of, seg_of, max_range)
    return ray_of, (seg_of if keep is None else keep.take(seg_of)), t


def cast_beams(
    ox: float,
    oy: float,
    angles: np.ndarray,
    segments: SegmentSet,
    max_range: float,
    directions: np.ndarray | None = None,
    extra: np.ndarray | None = None,
    in_order: bool = False,
) -> np.ndarray:
    """A lidar's :func:`cast_segments` distances, bit for bit (from the same pairs): its
    ``segments`` prepared once (:func:`prepare_segments`) and ``extra`` ones (k, 4), which move,
    cast with them; ``directions``: the beams' (cos, sin) (:func:`ray_directions`) if known;
    ``in_order``: the angles increase (a lidar's evenly spaced beams), not checked.
    """
    n = len(angles)
    dist = np.full(n, np.inf)
    if not n:
        return dist
    near, _ = _near(ox, oy, segments, max_range, extra)
    if near is None:
        return dist
    a0, rel, order = _sorted_rays(angles, in_order)
    ray_of, seg_of = _spans(near, rel, a0)
    if len(ray_of):
        if order is not None:
            ray_of = order.take(ray_of)
        dirs = ray_directions(angles) if directions is None else directions
        np.minimum.at(dist, ray_of, _meet(near, dirs, ray_of, seg_of, max_range))
    return dist


def _sorted_rays(angles: np.ndarray, in_order: bool) -> tuple[float, np.ndarray, np.ndarray | None]:
    """The rays' smallest angle a0, their angles from it in [0, 2 pi) sorted, and the sort's order
    (None: they came in order). ``in_order``: they increase, from a0 = the first, and when they
    span less than a turn nothing else is done."""
    two_pi = 2.0 * math.pi
    if in_order:
        a0 = float(angles[0])
        rel = angles - a0
        if rel[-1] < two_pi:
            return a0, rel, None
    else:
        a0 = float(angles.min())
        rel = angles - a0
    rel %= two_pi
    if len(rel) < 2 or _ALL(rel[1:] >= rel[:-1]):
        # already in order (a lidar's evenly spaced beams): the stable sort would be the identity
        return a0, rel, None
    order = np.argsort(rel, kind="stable")
    return a0, rel.take(order), order


def ray_directions(angles: np.ndarray) -> np.ndarray:
    """(2, n): the rays' cos and sin (a lidar's circles and segments cast along the same)."""
    dirs = np.empty((2, len(angles)))
    np.cos(angles, out=dirs[0])
    np.sin(angles, out=dirs[1])
    return dirs


def _near(
    ox: float, oy: float, segs: SegmentSet, max_range: float, extra: np.ndarray | None = None
) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The segments seen from (ox, oy) that can be met within ``max_range`` (a superset of them):
    their (6, k) p, e, q (rows as in :attr:`SegmentSet.rows`), and their indices (None: all of
    them; ``extra``'s numbered after ``segs``' and never left out); (None, None) if none.

    Two broad phases, both answer-neutral: the sides facing away (see :func:`segment_pairs`), and
    the segments out of range, the latter only when the world reaches beyond twice the range (an
    office's few far segments cost less to cast than to cull)."""
    k = segs.rows.shape[1]
    m = 0 if extra is None else len(extra)
    eye = np.array([[ox], [oy], [0.0], [0.0], [ox], [oy]])
    if not m:
        near = segs.rows - eye
    else:
        assert extra is not None
        near = np.empty((6, k + m))
        np.subtract(segs.rows, eye, out=near[:, :k])
        ends = extra.T
        np.subtract(ends[0:2], eye[0:2], out=near[0:2, k:])
        np.subtract(ends[2:4], ends[0:2], out=near[2:4, k:])
        near[4:6, k:] = near[0:2, k:]
    near[4:6] += near[2:4]
    x_lo, y_lo, x_hi, y_hi = segs.box
    ranged = math.hypot(max(ox - x_lo, x_hi - ox), max(oy - y_lo, y_hi - oy)) > 2.0 * max_range
    if not k or (segs.face is None and not ranged):
        return (near if k + m else None), None
    if segs.face is not None:
        # the eye on a side's outer side: (eye - p) . outward normal >= 0, the outward normal being
        # (ey, -ex) for a counter-clockwise outline and its opposite for a clockwise one
        turned = near[1::-1, :k] * segs.face
        keep = turned[0] + turned[1] >= 0.0
    else:
        keep = np.ones(k, dtype=bool)
    if ranged:
        # a segment whose middle is farther than max_range plus half its length cannot be met
        # within range (with a hair of slack for rounding: a superset, the same answers)
        away = np.hypot(segs.middle[0] - 2.0 * ox, segs.middle[1] - 2.0 * oy)
        away -= segs.length
        keep &= away <= 2.0 * max_range + 1e-9
    idx = keep.nonzero()[0]
    if m:
        idx = np.concatenate([idx, np.arange(k, k + m)])
    if len(idx) == k + m:
        return near, None
    if not len(idx):
        return None, None
    return near.take(idx, axis=1), idx


def _spans(near: np.ndarray, rel: np.ndarray, a0: float) -> tuple[np.ndarray, np.ndarray]:
    """(ray position, segment) of every ray inside the angle a segment subtends, rays given by
    their angles from ``a0`` (``rel``: sorted, in [0, 2 pi)): by segment, then by ray.

    A segment's end points' angles from ``a0`` bound its rays, found by ``searchsorted`` (with
    1e-12 rad of slack); one whose short arc crosses ``a0`` takes the rays from its larger angle
    to the last and on from the first to its smaller one, as positions past n brought back."""
    n = len(rel)
    two_pi = 2.0 * math.pi
    at = np.arctan2(near[1::4], near[0::4])  # rows: the first end's angle, the second's
    at -= a0
    at %= two_pi
    ends = np.empty_like(at)  # rows: the smaller, the larger (a sort along axis 0 costs more)
    np.minimum(at[0], at[1], out=ends[0])
    np.maximum(at[0], at[1], out=ends[1])
    wrap = ends[1] - ends[0] > math.pi
    ends = np.where(wrap, ends[::-1], ends)  # rows: where the rays start, where they stop
    start = rel.searchsorted(ends[0] - 1e-12, "left")
    stop = rel.searchsorted(ends[1] + 1e-12, "right")
    np.add(stop, n, out=stop, where=wrap)
    counts = stop - start
    total = int(np.add.reduce(counts))
    if not total:
        return _NO_PAIRS[0], _NO_PAIRS[1]
    seg_of = np.arange(len(counts)).repeat(counts)
    ray_of = np.arange(total)
    ray_of += (stop - counts.cumsum()).repeat(counts)
    np.subtract(ray_of, n, out=ray_of, where=ray_of >= n)
    return ray_of, seg_of


def _meet(
    near: np.ndarray, dirs: np.ndarray, ray_of: np.ndarray, seg_of: np.ndarray, max_range: float
) -> np.ndarray:
    """Distance along each ray ``ray_of`` (``dirs``: (2, n) cos, sin) to segment ``seg_of`` (of
    ``near``, as :func:`_near` gives it), inf where they do not meet within ``max_range``.

    The crossing p + u e = t d: t = cross(p, e) / cross(d, e), u = cross(p, d) / cross(d, e),
    each product made for two rows at once."""
    d = dirs.take(ray_of, axis=1)  # dx, dy
    s = near[:4].take(seg_of, axis=1)  # px, py, ex, ey
    p, e_swapped = s[0:2], s[3:1:-1]
    pe = p * e_swapped  # px ey, py ex
    de = d * e_swapped  # dx ey, dy ex
    pd = p * d[::-1]  # px dy, py dx
    num = np.empty_like(pd)
    np.subtract(pe[0], pe[1], out=num[0])
    np.subtract(pd[0], pd[1], out=num[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        tu = num / (de[0] - de[1])  # rows t, u
    ok = tu >= _LOW
    ok &= tu <= np.array([[max_range], [1 + 1e-9]])  # NaN (parallel) fails both
    return np.where(ok[0] & ok[1], tu[0], np.inf)


#: the answer when no pair can meet (shared, never written to)
_NO_PAIRS = (np.zeros(0, np.intp), np.zeros(0, np.intp), np.zeros(0))


def grid_edges(occupied: np.ndarray, resolution: float, origin_x: float, origin_y: float) -> np.ndarray:
    """The boundary between occupied and free cells as merged straight segments (N, 4).

    A map used as a world is cast against these: the same answer as walking the cells, at the cost
    of its outline rather than of its area.
    """
    occ = np.pad(occupied.astype(bool), 1)
    out = []
    for axis in (0, 1):
        # boundaries between consecutive rows (axis 0: horizontal edges) or columns (axis 1)
        change = occ[1:, :] != occ[:-1, :] if axis == 0 else (occ[:, 1:] != occ[:, :-1]).T
        side = occ[1:, :] if axis == 0 else occ[:, 1:].T  # which side is solid: runs must not merge across
        for line in np.flatnonzero(change.any(axis=1)):
            row = change[line]
            solid = side[line]
            key = np.where(row, np.where(solid, 1, 2), 0)
            change_at = np.flatnonzero(np.diff(np.concatenate([[0], key, [0]])) != 0)
            for start, stop in zip(change_at[:-1], change_at[1:], strict=True):
                if key[start] == 0:
                    continue
                # padded line k lies between padded cells k and k+1: coordinate k (cells), same for runs
                c = line * resolution
                x0, x1 = (start - 1) * resolution, (stop - 1) * resolution
                if axis == 0:
                    out.append((origin_x + x0, origin_y + c, origin_x + x1, origin_y + c))
                else:
                    out.append((origin_x + c, origin_y + x0, origin_x + c, origin_y + x1))
    return np.array(out, dtype=np.float64).reshape(-1, 4)


def cast_circles(
    ox: float,
    oy: float,
    angles: np.ndarray,
    centers: np.ndarray,
    radii: np.ndarray,
    max_range: float,
    directions: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Distance to the first circle along each ray (inf if none) and its index (-1); rays starting
    inside a circle do not see it (a robot's own body). ``directions``: the rays' (cos, sin) if
    known (:func:`ray_directions`)."""
    n = len(angles)
    if not len(centers):
        return np.full(n, np.inf), np.full(n, -1, dtype=np.intp)
    dx, dy = ray_directions(angles) if directions is None else directions
    cx = centers[:, 0] - ox
    cy = centers[:, 1] - oy
    b = dx[:, None] * cx + dy[:, None] * cy  # projection of the centre on the ray
    c = cx * cx + cy * cy - radii * radii
    disc = b * b - c
    with np.errstate(invalid="ignore"):
        t = b - np.sqrt(disc)
    t = np.where((disc >= 0) & (c > 0) & (t >= 0), t, np.inf)
    j = np.argmin(t, axis=1)
    dist = t[np.arange(n), j]
    hit = np.where(dist <= max_range, j, -1)
    dist = np.where(hit >= 0, dist, np.inf)
    return dist, hit


def circle_pairs(
    ox: float, oy: float, angles: np.ndarray, centers: np.ndarray, radii: np.ndarray, max_range: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every (ray, circle) pair that meets within ``max_range``: ``(ray_of, circle_of, t)``, by ray
    and, within a ray, by circle index *descending* (so that, as in :func:`nearest_hits`, the
    lowest index wins an exact tie, as :func:`cast_circles`' argmin does)."""
    if not len(centers) or not len(angles):
        return np.zeros(0, np.intp), np.zeros(0, np.intp), np.zeros(0)
    dx, dy = np.cos(angles), np.sin(angles)
    cx = centers[:, 0] - ox
    cy = centers[:, 1] - oy
    b = dx[:, None] * cx + dy[:, None] * cy
    c = cx * cx + cy * cy - radii * radii
    disc = b * b - c
    with np.errstate(invalid="ignore"):
        t = b - np.sqrt(disc)
    meets = (disc >= 0) & (c > 0) & (t >= 0) & (t <= max_range)
    ray_of, circle_of = np.nonzero(meets[:, ::-1])
    circle_of = len(centers) - 1 - circle_of
    return ray_of, circle_of, t[ray_of, circle_of]


def cast_grid(
    ox: float,
    oy: float,
    angles: np.ndarray,
    occupied: np.ndarray,
    resolution: float,
    origin_x: float,
    origin_y: float,
    max_range: float,
) -> np.ndarray:
    """Exact distance to the first occupied cell along each ray (inf if none within ``max_range``).

    ``occupied[row, col]`` with row 0 at ``origin_y`` (OccupancyGrid layout); outside the grid is
    free. For each axis, every ray's crossings of that axis' grid lines (at most the range or the
    grid's size) are computed at once in float32, the cell entered at each crossing is looked up in
    a grid padded with one free cell all round (so out-of-grid indices need no mask), and the first
    occupied one wins; the nearer of the two axes' answers is the hit.
    """
    rows, cols = occupied.shape
    angles = np.asarray(angles, dtype=np.float64)
    n = len(angles)
    dx, dy = np.cos(angles), np.sin(angles)
    gx = (ox - origin_x) / resolution  # the origin in cell units
    gy = (oy - origin_y) / resolution
    reach = max_range / resolution
    c0, r0 = math.floor(gx), math.floor(gy)
    if 0 <= r0 < rows and 0 <= c0 < cols and occupied[r0, c0]:
        return np.zeros(n)
    padded = np.zeros((rows + 2, cols + 2), dtype=bool)
    padded[1:-1, 1:-1] = occupied
    flat = padded.ravel()
    stride = cols + 2
    result = np.full(n, np.inf)
    for axis in (0, 1):
        d_main, d_other = (dx, dy) if axis == 0 else (dy, dx)
        g_main, g_other = (gx, gy) if axis == 0 else (gy, gx)
        size_main, size_other = (cols, rows) if axis == 0 else (rows, cols)
        idx = np.flatnonzero(np.abs(d_main) > 1e-12)  # rays parallel to these lines never cross one
        dm, do = d_main[idx], d_other[idx].astype(np.float32)
        forward = dm > 0
        sign = np.where(forward, 1.0, -1.0).astype(np.float32)
        first = np.where(forward, math.floor(g_main) + 1, math.ceil(g_main) - 1).astype(np.float32)
        steps = int(min(math.ceil(reach) + 1, size_main + 1))
        lines = first[:, None] + sign[:, None] * np.arange(steps, dtype=np.float32)[None, :]
        t = (lines - np.float32(g_main)) * (1.0 / dm).astype(np.float32)[:, None]  # in cells
        other = np.float32(g_other) + t * do[:, None]
        cell_main = lines.astype(np.int32) - (~forward)[:, None].astype(np.int32)
        cell_other = np.floor(other).astype(np.int32)
        np.clip(cell_main, -1, size_main, out=cell_main)
        np.clip(cell_other, -1, size_other, out=cell_other)
        if axis == 0:
            hit = flat[(cell_other + 1) * stride + (cell_main + 1)]
        else:
            hit = flat[(cell_main + 1) * stride + (cell_other + 1)]
        j = np.argmax(hit, axis=1)
        rows_i = np.arange(len(idx))
        found = np.where(hit[rows_i, j], t[rows_i, j], np.inf)
        result[idx] = np.minimum(result[idx], found)
    result = result * resolution
    result[result > max_range] = np.inf
    return result


def column_pairs(
    ox: float,
    oy: float,
    yaw: float,
    slopes: np.ndarray,
    segments: np.ndarray,
    depth_max: float,
    facing: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every crossing of a pinhole camera's column rays with the segments, within ``depth_max``:
    ``(col_of, seg_of, depth)`` with ``depth`` along the optical axis (the camera-frame x of the point
    hit), in no particular order.

    The camera stands at (ox, oy) looking along ``yaw``; column u's ray is (1, ``slopes[u]``) in the
    camera frame (x ahead, y to the left, ``slopes`` decreasing from the first column to the last,
    all within +-90 degrees). Why not :func:`segment_pairs`: a camera's rays are sorted already and its
    field of view is a wedge, so each segment's columns follow in closed form from the angles of its
    end points (no sort, no search), and the depth a camera needs is one division per crossing,
    ``cross(p, e) / (e_y - k e_x)`` (the point p + s e on the ray (d, d k)). Segments behind the
    camera, beyond ``depth_max`` or facing away (``facing``, as in :func:`segment_pairs`) are dropped
    before any crossing is made, so the work follows what the camera can see.
    """
    none = (np.zeros(0, np.intp), np.zeros(0, np.intp), np.zeros(0))
    n = len(slopes)
    if not n or not len(segments):
        return none
    c, s = math.cos(yaw), math.sin(yaw)
    # per segment, one row each: both end points in the camera frame (x0, y0, x1, y1, from one
    # product), the edge (ex, ey) and cross(p, e) (the same in any frame), so that culling and the
    # gathers per crossing below are one call each for all of them
    turn = np.array([[c, -s, 0.0, 0.0], [s, c, 0.0, 0.0], [0.0, 0.0, c, -s], [0.0, 0.0, s, c]])
    rows = np.empty((7, len(segments)))
    np.matmul(turn.T, (segments - (ox, oy, ox, oy)).T, out=rows[:4])
    x0, y0, x1, y1, ex, ey, num = rows
    np.subtract(x1, x0, out=ex)
    np.subtract(y1, y0, out=ey)
    np.multiply(x0, ey, out=num)
    num -= y0 * ex
    # some point ahead of the camera and some point within the depth range (a point's depth is its x)
    keep = np.maximum(x0, x1) > 0.0
    keep &= np.minimum(x0, x1) <= depth_max
    if facing is not None:
        keep &= facing * num <= 0.0  # the outer face looks at the camera (see segment_pairs)
    idx = keep.nonzero()[0]
    m = len(idx)
    if not m:
        return none
    if m < len(num):
        rows = rows.take(idx, axis=1)
    ends, num = rows[:4], rows[6]
    # each end point's slope (lateral over ahead, left positive), in two rows: the smaller, the
    # larger; the columns follow from slopes (a pinhole camera's columns are evenly spaced in
    # slope), so no angle is computed. An end behind the camera (or beside it) is replaced by the
    # side the segment leaves the view by: the side its short arc turns to from its end ahead,
    # left (+inf) when counterclockwise, that is when cross(end ahead, end behind) > 0, which is
    # ``num`` for the second end behind and ``-num`` for the first
    xs = ends[0::2]
    ahead = xs > 0.0
    at = np.multiply.outer(_AWAY, np.copysign(np.inf, num))
    np.divide(ends[1::2], xs, out=at, where=ahead)
    at.sort(axis=0)
    k0 = float(slopes[0])
    lim = math.tan(math.atan(k0) + 1e-9)
    np.maximum(at, -lim, out=at)
    np.minimum(at, lim, out=at)
    # column u looks along slopes[u], slopes evenly spaced (a pinhole camera's): the columns
    # within [lo, hi] run from u(hi) to u(lo), u(k) = (slopes[0] - k) / (slopes[0] - slopes[1])
    scale = (n - 1) / (k0 - float(slopes[-1])) if n > 1 else 0.0
    np.subtract(k0, at, out=at)
    at *= scale
    first = np.ceil(at[1] - 1e-9)
    counts = np.floor(at[0] + 1e-9)
    counts -= first
    counts += 1.0
    np.maximum(first, 0.0, out=first)  # never needed but for rounding: an index stays an index
    np.minimum(counts, n - first, out=counts)
    np.maximum(counts, 0.0, out=counts)
    counts = counts.astype(np.intp)
    total = int(np.add.reduce(counts))
    if not total:
        return none
    seg_of = np.arange(m).repeat(counts)
    col_of = np.arange(total)
    col_of += (first.astype(np.intp) - (counts.cumsum() - counts)).repeat(counts)
    with np.errstate(divide="ignore", invalid="ignore"):
        # gathers by ``take``: a few times cheaper than fancy indexing at a thousand crossings
        ex, ey, num = rows[4:].take(seg_of, axis=1)
        depth = num / (ey - slopes.take(col_of) * ex)
    ok = depth > 1e-9  # NaN (seen edge-on) fails too
    ok &= depth <= depth_max
    ok = ok.nonzero()[0]
    if len(ok) < total:
        col_of, seg_of, depth = col_of.take(ok), seg_of.take(ok), depth.take(ok)
    return col_of, (seg_of if m == len(keep) else idx.take(seg_of)), depth
