"""Mapping for slam_gmapping: a Rao-Blackwellized particle filter over grid maps, as GMapping.

No ROS in here. Each particle carries a trajectory's last pose, a log weight and its own map (hit and
visit counts per cell, gmapping's ``PointAccumulator``). A scan is processed once the robot has moved
``linearUpdate`` metres or turned ``angularUpdate`` radians since the last processed one (gmapping's
rule), and then, for every particle:

1. prediction: the particle's pose composed with the odometry step, and the step's uncertainty from
   gmapping's motion model (``srr`` translation from translation, ``srt`` translation from rotation,
   ``str`` rotation from translation, ``stt`` rotation from rotation: standard deviations per unit);
2. the improved proposal (Grisetti, Stachniss, Burgard 2007, the paper behind GMapping): the scan is
   scored against the particle's own map, built so far, over a grid of poses around the prediction
   spanning 3 sigma of the motion model (at least ``lstep``/``astep``), refined twice around its
   best pose. A pose's score is the beams' log-likelihood in a likelihood field of the occupied
   cells (``-d^2 / 2 sigma^2``, ``d`` the distance from a beam end to the nearest occupied cell),
   tempered by ``ogain``, plus the motion model's log density. The
   new pose is drawn from the Gaussian fitted to that posterior around its mode, and the particle's
   weight is multiplied by the posterior's mass (``eta``): particles whose maps explain the scan win;
3. the map update, only now, with the corrected pose: the cells a beam crosses count a visit, its end
   cell a visit and a hit; beams end at ``maxUrange`` for mapping (longer readings clear free space
   up to there but mark nothing), readings at or beyond ``maxRange`` carry no hit.

The map grows as gmapping's does: when the cells a scan writes (the sensor and its beam ends, cut at
``maxUrange``) fall outside ``xmin..xmax`` / ``ymin..ymax``, the map is enlarged on that side to 10 m
past them (GMapping's ``enlargeStep``) and the bounds move with it, as slam_gmapping's ``xmin_``.. do;
a launch file's small start map (``xmin -1 .. xmax 1``, turtlebot's and its copies) maps the world.

When the weights degenerate (effective sample size below ``resampleThreshold`` times the particle
count) the particles are resampled (low variance), and a drawn particle takes a copy of its parent's
map. The published map is the best particle's: a cell is occupied (100) when hits / visits >
``occ_thresh``, free (0) when visited, unknown (-1) otherwise; ``map -> odom`` is the best particle's
pose composed with the inverse of the odometry pose.

Speed: a likelihood field is computed only over the window the scan can reach, and each cell counts
at most once per scan (numpy's buffered fancy-index add), so a 360-beam scan costs a few
milliseconds per particle.
"""

from __future__ import annotations

import builtins
import math
from dataclasses import dataclass, fields

import numpy as np

from ninjemys.tf2.math import se2_compose, se2_inverse, wrap_angle


@dataclass
class SlamParams:
    """slam_gmapping's parameters that this mapper uses (same names, same meaning)."""

    delta: float = 0.05
    xmin: float = -15.0
    ymin: float = -15.0
    xmax: float = 15.0
    ymax: float = 15.0
    maxUrange: float = 4.0  # noqa: N815 - gmapping's parameter names
    maxRange: float = 5.0  # noqa: N815
    linearUpdate: float = 0.2  # noqa: N815
    angularUpdate: float = 0.2  # noqa: N815
    occ_thresh: float = 0.25
    sigma: float = 0.05
    lstep: float = 0.05
    astep: float = 0.05
    ogain: float = 3.0
    lskip: int = 0
    srr: float = 0.1
    srt: float = 0.2
    str: float = 0.1
    stt: float = 0.2
    particles: int = 30
    resampleThreshold: float = 0.5  # noqa: N815

    # ``str`` is a field here (gmapping's rotation-from-translation error), so the type is spelled in full
    def update(self, values: dict[builtins.str, object]) -> list[tuple[builtins.str, builtins.str]]:
        """Take ``values`` by name; a value out of its range keeps the current one. Returns (name,
        reason) for each rejected value: the node logs them and goes on."""
        rejected = []
        for f in fields(self):
            if f.name not in values:
                continue
            old = getattr(self, f.name)
            value = type(old)(values[f.name])
            problem = _out_of_range(f.name, value)
            if problem:
                rejected.append((f.name, f"{problem}, got {values[f.name]!r}; using {old!r}"))
            else:
                setattr(self, f.name, value)
        for low, high in (("xmin", "xmax"), ("ymin", "ymax")):
            if not getattr(self, low) < getattr(self, high):
                rejected.append((high, f"must be above {low} ({getattr(self, low)!r}); using both defaults"))
                setattr(self, low, getattr(SlamParams, low))
                setattr(self, high, getattr(SlamParams, high))
        return rejected


def _out_of_range(name: str, value: float) -> str:
    if name in ("delta", "maxUrange", "maxRange", "sigma", "lstep", "astep", "ogain") and not value > 0:
        return "must be > 0"
    if name in ("linearUpdate", "angularUpdate", "srr", "srt", "str", "stt", "lskip") and value < 0:
        return "must be >= 0"
    if name == "particles" and value < 1:
        return "must be >= 1"
    if name == "resampleThreshold" and not 0.0 <= value <= 1.0:
        return "must be within 0..1"
    return ""


class _Particle:
    __slots__ = ("pose", "logw", "hits", "visits")

    def __init__(self, pose: tuple[float, float, float], hits: np.ndarray, visits: np.ndarray) -> None:
        self.pose = pose
        self.logw = 0.0
        self.hits = hits
        self.visits = visits


class ParticleMapper:
    """gmapping's filter: feed odometry poses and scans to :meth:`process`, read :meth:`occupancy`."""

    #: beams used for scoring a pose (spread evenly over the scan); the map update uses them all
    MATCH_BEAMS = 90
    #: metres a map grows past the cells that overflowed it (GMapping ScanMatcher's m_enlargeStep)
    ENLARGE_STEP = 10.0

    def __init__(self, params: SlamParams | None = None, seed: int = 0) -> None:
        self.params = p = params or SlamParams()
        self.width = int(round((p.xmax - p.xmin) / p.delta))
        self.height = int(round((p.ymax - p.ymin) / p.delta))
        self.rng = np.random.default_rng(seed)
        self.particles: list[_Particle] = []
        self.odom: tuple[float, float, float] | None = None  # odometry pose of the last processed scan
        self.scans = 0
        self.resamples = 0
        # the likelihood field's kernel: offsets within reach and their log-likelihoods
        reach = max(1, int(math.ceil(2.0 * p.sigma / p.delta)))
        oy, ox = np.mgrid[-reach : reach + 1, -reach : reach + 1]
        d2 = (ox * ox + oy * oy).astype(float)
        keep = d2 <= reach * reach
        order = np.argsort(d2[keep])
        self._kernel = [
            (int(a), int(b), float(-c * p.delta * p.delta / (2 * p.sigma**2)))
            for a, b, c in zip(ox[keep][order], oy[keep][order], d2[keep][order], strict=True)
        ]
        self._reach = reach
        self._null = -(((reach + 1) * p.delta) ** 2) / (2 * p.sigma**2)

    # -- outputs ----------------------------------------------------------------------------------

    def best(self) -> _Particle | None:
        if not self.particles:
            return None
        return max(self.particles, key=lambda q: q.logw)

    def entropy(self) -> float:
        """slam_gmapping's ``~entropy``: -sum(w log w) over the particles' normalized weights (0 when
        one particle holds all the weight, log(particles) when they are all alike)."""
        if not self.particles:
            return 0.0
        lw = np.array([q.logw for q in self.particles])
        w = np.exp(lw - lw.max())
        w /= w.sum()
        w = w[w > 0]
        return float(-(w * np.log(w)).sum())

    def occupancy(self) -> np.ndarray:
        """int8 (height, width) map of the best particle, as slam_gmapping publishes it."""
        b = self.best()
        if b is None:
            return np.full((self.height, self.width), -1, dtype=np.int8)
        return self._occupancy(b.hits, b.visits)

    def _occupancy(self, hits: np.ndarray, visits: np.ndarray) -> np.ndarray:
        out = np.full(hits.shape, -1, dtype=np.int8)
        seen = visits > 0
        out[seen] = 0
        out[seen & (hits > self.params.occ_thresh * visits)] = 100
        return out

    def map_to_odom(self, odom_pose: tuple[float, float, float]) -> tuple[float, float, float]:
        """The correction: map->odom such that map->odom->base is the best particle's pose."""
        b = self.best()
        if b is None or self.odom is None:
            return (0.0, 0.0, 0.0)
        return se2_compose(b.pose, se2_inverse(self.odom))

    # -- processing -------------------------------------------------------------------------------

    def should_process(self, odom_pose: tuple[float, float, float]) -> bool:
        if self.odom is None:
            return True
        step = se2_compose(se2_inverse(self.odom), odom_pose)
        return (
            math.hypot(step[0], step[1]) >= self.params.linearUpdate
            or abs(step[2]) >= self.params.angularUpdate
        )

    def process(
        self,
        odom_pose: tuple[float, float, float],
        ranges: np.ndarray,
        angles: np.ndarray,
        laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
        range_max: float | None = None,
    ) -> tuple[float, float, float]:
        """Filter one scan taken at ``odom_pose`` (laser angles in the laser frame), update the
        particles' maps, and return the best particle's pose of the base in the map frame."""
        p = self.params
        ranges = np.asarray(ranges, dtype=float)
        angles = np.asarray(angles, dtype=float)
        limit = min(p.maxRange, range_max) if range_max else p.maxRange
        ok = ~np.isnan(ranges) & ~np.isneginf(ranges)  # NaN: no reading; -inf: closer than range_min
        ranges, angles = ranges[ok], angles[ok]
        ranges = np.where(np.isfinite(ranges), ranges, limit)  # +inf: no return, free up to maxUrange
        hit = ranges < min(limit, p.maxUrange)
        lx, ly, lth = laser_pose
        # beam ends that score a pose, in the base frame (every lskip+1-th, as gmapping's matcher)
        mr, ma = ranges[hit][:: p.lskip + 1], angles[hit][:: p.lskip + 1]
        if mr.size > self.MATCH_BEAMS:
            take = np.linspace(0, mr.size - 1, self.MATCH_BEAMS).astype(np.int64)
            mr, ma = mr[take], ma[take]
        # scored half a cell past the return, where the map update puts the hit (inside the surface)
        mr = mr + p.delta / 2
        bx = lx + mr * np.cos(lth + ma)
        by = ly + mr * np.sin(lth + ma)
        if not self.particles:
            shape = (self.height, self.width)
            self.particles = [
                _Particle(odom_pose, np.zeros(shape, np.int32), np.zeros(shape, np.int32))
                for _ in range(max(1, p.particles))
            ]
        elif self.odom is not None:
            step = se2_compose(se2_inverse(self.odom), odom_pose)
            for q in self.particles:
                q.pose, log_eta = self._propose(q, step, bx, by)
                q.logw += log_eta
            self._normalize_and_resample()
        self._give_own_maps()
        self._grow_to(laser_pose, ranges, angles)
        for q in self.particles:
            self._integrate(q, se2_compose(q.pose, laser_pose), ranges, angles, hit)
        self.odom = odom_pose
        self.scans += 1
        b = self.best()
        assert b is not None
        return b.pose

    def _propose(
        self, q: _Particle, step: tuple[float, float, float], bx: np.ndarray, by: np.ndarray
    ) -> tuple[tuple[float, float, float], float]:
        """The particle's new pose drawn from the improved proposal, and the log of its mass."""
        p = self.params
        predicted = se2_compose(q.pose, step)
        dist, turn = math.hypot(step[0], step[1]), abs(step[2])
        s_xy = max(p.srr * dist + p.srt * turn, 0.25 * p.lstep)
        s_th = max(p.stt * turn + p.str * dist, 0.25 * p.astep)
        if bx.size < 10:  # nothing to match: the motion model alone
            noise = self.rng.normal(0.0, 1.0, 3) * (s_xy, s_xy, s_th)
            return se2_compose(predicted, (float(noise[0]), float(noise[1]), float(noise[2]))), 0.0
        field, ox, oy = self._field(q, predicted)
        center = np.array(predicted)
        # coarse to fine: a 7x7x7 grid over +-3 sigma of the motion model, then twice around the
        # best pose so far, each grid spanning one step of the one before
        half_xy, half_th = max(3.0 * s_xy, p.lstep), max(3.0 * s_th, p.astep)
        g = np.linspace(-1.0, 1.0, 7)
        best = center
        for _ in range(3):
            axes = (best[0] + g * half_xy, best[1] + g * half_xy, best[2] + g * half_th)
            score = (self._score(field, ox, oy, axes, bx, by) / p.ogain).ravel()
            gx, gy, gt = np.meshgrid(*axes, indexing="ij")
            cands = np.column_stack([gx.ravel(), gy.ravel(), gt.ravel()])
            # the motion model's log density, in the predicted pose's frame
            c, s = math.cos(center[2]), math.sin(center[2])
            ex, ey = cands[:, 0] - center[0], cands[:, 1] - center[1]
            along, across = c * ex + s * ey, -s * ex + c * ey
            eth = _wrap_array(cands[:, 2] - center[2])
            score -= 0.5 * ((along**2 + across**2) / s_xy**2 + eth**2 / s_th**2)
            i = int(np.argmax(score))
            best = cands[i]
            half_xy, half_th = half_xy / 3.0, half_th / 3.0
        w = np.exp(score - score[i])
        total = float(w.sum())
        mean = (w[:, None] * cands).sum(axis=0) / total
        mean[2] = cands[i, 2] + float((w * _wrap_array(cands[:, 2] - cands[i, 2])).sum() / total)
        dev = cands - mean
        dev[:, 2] = _wrap_array(dev[:, 2])
        cov = (w[:, None, None] * dev[:, :, None] * dev[:, None, :]).sum(axis=0) / total
        cov += np.diag([1e-6, 1e-6, 1e-6])
        draw = self.rng.multivariate_normal(mean, cov)
        pose = (float(draw[0]), float(draw[1]), wrap_angle(float(draw[2])))
        return pose, float(score[i]) + math.log(total)

    def _normalize_and_resample(self) -> None:
        ws = np.array([q.logw for q in self.particles])
        ws -= ws.max()
        w = np.exp(ws)
        w /= w.sum()
        for q, lw in zip(self.particles, np.log(np.maximum(w, 1e-300)), strict=True):
            q.logw = float(lw)
        n = len(self.particles)
        if 1.0 / float((w * w).sum()) >= self.params.resampleThreshold * n:
            return
        # low-variance resampling: one random offset, n evenly spaced pointers
        picks = np.searchsorted(np.cumsum(w), (self.rng.random() + np.arange(n)) / n)
        picks = np.minimum(picks, n - 1)
        old = self.particles
        self.particles = []
        for i in picks:
            src = old[int(i)]
            child = _Particle(src.pose, src.hits, src.visits)  # shares the map until it is written
            child.logw = -math.log(n)
            self.particles.append(child)
        self.resamples += 1

    def _give_own_maps(self) -> None:
        """Copy a map shared by several particles (after resampling) before they write to it."""
        seen: set[int] = set()
        for q in self.particles:
            if id(q.hits) in seen:
                q.hits, q.visits = q.hits.copy(), q.visits.copy()
            seen.add(id(q.hits))

    def _field(self, q: _Particle, pose: tuple[float, float, float]) -> tuple[np.ndarray, int, int]:
        """The log-likelihood field of ``q``'s occupied cells over the window a scan from ``pose`` can
        reach, and the window's first column and row."""
        p = self.params
        r = int(math.ceil((p.maxUrange + 0.5) / p.delta)) + self._reach + 2
        cx = int(math.floor((pose[0] - p.xmin) / p.delta))
        cy = int(math.floor((pose[1] - p.ymin) / p.delta))
        x0, x1 = max(0, cx - r), min(self.width, cx + r + 1)
        y0, y1 = max(0, cy - r), min(self.height, cy + r + 1)
        if x1 <= x0 or y1 <= y0:
            return np.full((1, 1), self._null), 0, 0
        hits, visits = q.hits[y0:y1, x0:x1], q.visits[y0:y1, x0:x1]
        occ = (visits > 0) & (hits > p.occ_thresh * visits)
        field = np.full(occ.shape, self._null)
        h, w = occ.shape
        for dx, dy, value in reversed(self._kernel):  # far offsets first, near ones overwrite them
            src = occ[max(0, -dy) : h - max(0, dy), max(0, -dx) : w - max(0, dx)]
            dst = field[max(0, dy) : h - max(0, -dy), max(0, dx) : w - max(0, -dx)]
            dst[src] = value
        field[0, :] = field[-1, :] = field[:, 0] = field[:, -1] = self._null  # what clipped ends read
        return field, x0, y0

    def _score(
        self,
        field: np.ndarray,
        ox: int,
        oy: int,
        axes: tuple[np.ndarray, ...],
        bx: np.ndarray,
        by: np.ndarray,
    ) -> np.ndarray:
        """Summed log-likelihood of the beam ends (base frame) for every pose of the grid ``axes``
        (x values, y values, theta values), as an (x, y, theta) array."""
        p = self.params
        h, w = field.shape
        xs, ys, ts = axes
        c, s = np.cos(ts)[:, None], np.sin(ts)[:, None]
        rx = (c * bx - s * by) / p.delta  # (theta, beam), in cells
        ry = (s * bx + c * by) / p.delta
        fx = (xs - p.xmin) / p.delta - ox
        fy = (ys - p.ymin) / p.delta - oy
        ix = np.clip(np.floor(fx[:, None, None] + rx[None]), 0, w - 1).astype(np.int64)  # (x, theta, beam)
        iy = np.clip(np.floor(fy[:, None, None] + ry[None]), 0, h - 1).astype(np.int64)
        flat = iy[None, :, :, :] * w + ix[:, None, :, :]
        return field.ravel()[flat].sum(axis=3)

    def _integrate(
        self,
        q: _Particle,
        sensor: tuple[float, float, float],
        ranges: np.ndarray,
        angles: np.ndarray,
        hit: np.ndarray,
    ) -> None:
        p = self.params
        world = sensor[2] + angles
        cosw, sinw = np.cos(world), np.sin(world)
        # free cells: samples every half cell from the sensor to half a cell before the beam's end
        step = p.delta / 2
        count = np.ceil(np.maximum(np.minimum(ranges, p.maxUrange) - p.delta * 0.5, 0.0) / step)
        count = count.astype(np.int64)
        beam = np.repeat(np.arange(ranges.size), count)
        t = (np.arange(beam.size) - np.repeat(np.cumsum(count) - count, count)) * step
        flat = self._flat(sensor[0] + cosw[beam] * t, sensor[1] + sinw[beam] * t, sensor)
        q.visits.ravel()[flat] += 1  # buffered: a cell crossed by several beams counts once
        # the hit cell is taken half a cell past the return, inside the surface it came from
        reach = ranges[hit] + p.delta / 2
        flat = self._flat(sensor[0] + cosw[hit] * reach, sensor[1] + sinw[hit] * reach, sensor)
        q.visits.ravel()[flat] += 1
        q.hits.ravel()[flat] += 1

    def _grow_to(
        self, laser_pose: tuple[float, float, float], ranges: np.ndarray, angles: np.ndarray
    ) -> None:
        """Enlarge every particle's map (and move the bounds) so that the cells this scan writes from
        each particle's pose are on it: GMapping's computeActiveArea, which resizes by enlargeStep."""
        p = self.params
        reach = np.minimum(ranges, p.maxUrange)
        lo, hi = [math.inf, math.inf], [-math.inf, -math.inf]
        for q in self.particles:
            sx, sy, sth = se2_compose(q.pose, laser_pose)
            xs = np.append(sx + reach * np.cos(sth + angles), sx)
            ys = np.append(sy + reach * np.sin(sth + angles), sy)
            lo = [min(lo[0], float(xs.min())), min(lo[1], float(ys.min()))]
            hi = [max(hi[0], float(xs.max())), max(hi[1], float(ys.max()))]
        # cells to add on each side (low x, low y, high x, high y); the grid keeps its alignment
        step = self.ENLARGE_STEP
        add = [
            math.ceil((p.xmin - (lo[0] - step)) / p.delta) if lo[0] < p.xmin else 0,
            math.ceil((p.ymin - (lo[1] - step)) / p.delta) if lo[1] < p.ymin else 0,
            math.ceil((hi[0] + step - p.xmax) / p.delta) if hi[0] >= p.xmax else 0,
            math.ceil((hi[1] + step - p.ymax) / p.delta) if hi[1] >= p.ymax else 0,
        ]
        if not any(add):
            return
        pad = ((add[1], add[3]), (add[0], add[2]))
        grown: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        for q in self.particles:
            if id(q.hits) not in grown:  # maps shared after a resample stay shared
                grown[id(q.hits)] = (np.pad(q.hits, pad), np.pad(q.visits, pad))
            q.hits, q.visits = grown[id(q.hits)]
        p.xmin -= add[0] * p.delta
        p.ymin -= add[1] * p.delta
        p.xmax += add[2] * p.delta
        p.ymax += add[3] * p.delta
        self.height, self.width = self.particles[0].hits.shape

    def _flat(self, x: np.ndarray, y: np.ndarray, sensor: tuple[float, float, float]) -> np.ndarray:
        """Flat cell indices of points within ``maxUrange`` of ``sensor``, those off the map left out."""
        p = self.params
        ix = ((x - p.xmin) / p.delta).astype(np.int64)  # truncation is floor for points on the map
        iy = ((y - p.ymin) / p.delta).astype(np.int64)
        margin = p.maxUrange + p.delta
        if not (
            p.xmin + margin <= sensor[0] <= p.xmax - margin
            and p.ymin + margin <= sensor[1] <= p.ymax - margin
        ):
            inside = (x >= p.xmin) & (ix < self.width) & (y >= p.ymin) & (iy < self.height)
            ix, iy = ix[inside], iy[inside]
        return iy * self.width + ix


def _wrap_array(a: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (a + np.pi) % (2 * np.pi) - np.pi
