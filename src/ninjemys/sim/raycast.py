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

import numpy as np

#: reductions called as ufunc methods: ``a.any()`` and ``a.min()`` go through numpy's Python-level
#: wrappers, a few microseconds a call that the camera's per-frame code feels
_ANY = np.logical_or.reduce
_ALL = np.logical_and.reduce
#: the sign of the side an end behind the camera stands for, for the first end and the second
_AWAY = np.array([-1.0, 1.0])


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
    :func:`segment_pairs`; the nearest per ray wins (on an exact tie, the pair listed last).
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
    distance along the ray to the segment, ``inf`` where they do not meet within ``max_range``.

    Each segment is paired only with the rays inside the angle it subtends from the origin (found
    with one ``searchsorted`` over the sorted rays), so the work grows with what is visible, not
    with rays x segments. Every step is done for all segments at once (both end points in one
    ``arctan2``, all span ends in two ``searchsorted``): at a few hundred segments the cost is the
    number of numpy calls. The lidar takes the nearest pair per ray (:func:`nearest_hits`); the
    camera also looks behind it for taller obstacles, from the same pairs.

    ``facing`` (per segment: +1 or -1 for a side of a convex outline going counter-clockwise or
    clockwise, 0 otherwise) leaves out the sides whose outer face looks away from the origin: a
    ray enters a convex outline through a side facing it, so those never give a first crossing,
    into that obstacle or into a taller one behind it (about half of a box's or a cylinder's sides).
    """
    angles = np.asarray(angles, dtype=np.float64)
    n = len(angles)
    none = (np.zeros(0, np.intp), np.zeros(0, np.intp), np.zeros(0))
    if not n or not len(segments):
        return none
    # first end point relative to the origin (p), edge vector (e), second end point (q = p + e)
    px, py = segments[:, 0] - ox, segments[:, 1] - oy
    ex, ey = segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1]
    qx, qy = px + ex, py + ey
    # broad phase: a segment whose middle is farther than max_range plus half its length cannot be
    # hit within range (a superset of the segments that come within range: same answers)
    near = np.hypot(px + qx, py + qy) - np.hypot(ex, ey) <= 2.0 * max_range + 1e-9
    if facing is not None:
        # the origin on a side's outer side: (origin - p) . outward normal >= 0, the outward normal
        # being (ey, -ex) for a counter-clockwise outline and its opposite for a clockwise one
        near &= facing * (py * ex - px * ey) >= 0
    if not near.all():
        keep = np.flatnonzero(near)
        if not len(keep):
            return none
        # gathers by ``take`` (the same elements as fancy indexing, a few times cheaper at this size)
        px, py, ex, ey = px.take(keep), py.take(keep), ex.take(keep), ey.take(keep)
        qx, qy = qx.take(keep), qy.take(keep)
    else:
        keep = None
    k = len(px)
    two_pi = 2.0 * math.pi
    a0 = float(angles.min())
    rel = (angles - a0) % two_pi
    if n < 2 or _ALL(rel[1:] >= rel[:-1]):
        # already in order (a lidar's evenly spaced beams): the stable sort would be the identity
        order, rel_sorted = None, rel
    else:
        order = np.argsort(rel, kind="stable")
        rel_sorted = rel[order]
    ends = (np.arctan2(np.concatenate([py, qy]), np.concatenate([px, qx])) - a0) % two_pi
    r1, r2 = ends[:k], ends[k:]
    lo, hi = np.minimum(r1, r2), np.maximum(r1, r2)
    wrap = (hi - lo) > math.pi
    left = np.searchsorted(rel_sorted, np.concatenate([lo, hi]) - 1e-12, "left")
    right = np.searchsorted(rel_sorted, np.concatenate([hi, lo]) + 1e-12, "right")
    # spans of sorted ray positions: [lo, hi] or, for a segment whose short arc crosses the first
    # ray, [hi, end) and then [0, lo] (the wrapping ones get a second span, after all the first ones)
    w = np.flatnonzero(wrap)
    starts = np.concatenate([np.where(wrap, left[k:], left[:k]), np.zeros(len(w), np.intp)])
    stops = np.concatenate([np.where(wrap, n, right[:k]), right[k:][w]])
    seg_ids = np.concatenate([np.arange(k), w])
    counts = np.maximum(stops - starts, 0)
    total = int(counts.sum())
    if not total:
        return none
    seg_of = np.repeat(seg_ids, counts)
    shift = np.repeat(starts - (np.cumsum(counts) - counts), counts)
    ray_of = np.arange(total) + shift
    if order is not None:
        ray_of = order.take(ray_of)
    dx, dy = np.cos(angles).take(ray_of), np.sin(angles).take(ray_of)
    sx, sy, gx, gy = px.take(seg_of), py.take(seg_of), ex.take(seg_of), ey.take(seg_of)
    denom = dx * gy - dy * gx
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (sx * gy - sy * gx) / denom
        u = (sx * dy - sy * dx) / denom
    t[~((u >= -1e-9) & (u <= 1 + 1e-9) & (t >= 0) & (t <= max_range))] = np.inf  # NaN fails too
    return ray_of, (seg_of if keep is None else keep.take(seg_of)), t


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
    ox: float, oy: float, angles: np.ndarray, centers: np.ndarray, radii: np.ndarray, max_range: float
) -> tuple[np.ndarray, np.ndarray]:
    """Distance to the first circle along each ray (inf if none) and its index (-1); rays starting
    inside a circle do not see it (a robot's own body)."""
    n = len(angles)
    if not len(centers):
        return np.full(n, np.inf), np.full(n, -1, dtype=np.intp)
    dx, dy = np.cos(angles), np.sin(angles)
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
