"""Adaptive Monte Carlo localization, as ROS's amcl does it, over numpy arrays of particles.

No ROS in here. The pieces are amcl's:

- the diff-drive odometry model (``odom_alpha1..4``): each odometry step is split into a rotation,
  a translation and a rotation; each is perturbed with a Gaussian whose variance is
  ``a1*rot^2 + a2*trans^2`` (rotations) or ``a3*trans^2 + a4*(rot1^2 + rot2^2)`` (translation),
  rotations measured the short way round whether the robot drove forwards or backwards;
- the likelihood-field laser model: each used beam's endpoint is looked up in a precomputed field of
  distances to the nearest occupied cell (capped at ``laser_likelihood_max_dist``);
  ``pz = z_hit * exp(-d^2 / (2 sigma_hit^2)) + z_rand / range_max`` and a particle's weight is
  multiplied by ``1 + sum(pz^3)`` (amcl's own ad hoc combination); readings at or beyond
  ``range_max``, or NaN, are skipped; ``laser_max_beams`` beams are taken evenly;
- KLD-sampling: after low-variance resampling, the particle count is the smallest n for which the
  number k of occupied histogram bins (0.5 m x 0.5 m x 10 deg) among the first n needs no more than n
  (Fox's bound with ``kld_err`` and ``kld_z``), between ``min_particles`` and ``max_particles``;
- recovery: running averages ``w_slow``/``w_fast`` of the mean weight (``recovery_alpha_slow/fast``)
  inject uniformly drawn particles with probability ``max(0, 1 - w_fast / w_slow)``;
- the estimate is the weighted mean of the heaviest cluster of connected bins, with its covariance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ninjemys.maps.mapfile import GridMap
from ninjemys.nav.costmap import distance_transform

BIN_XY = 0.5
BIN_TH = math.radians(10.0)
SENSOR_BLOCK = 1024  # particles weighed per pass (see ParticleFilter.sensor_update)


@dataclass
class AMCLParams:
    """amcl's main parameters (``~name`` in ROS 1)."""

    min_particles: int = 100
    max_particles: int = 2000
    kld_err: float = 0.01
    kld_z: float = 0.99
    update_min_d: float = 0.2
    update_min_a: float = math.pi / 6.0
    resample_interval: int = 2
    selective_resampling: bool = False
    global_candidates: int = 0
    recovery_alpha_slow: float = 0.0
    recovery_alpha_fast: float = 0.0
    laser_max_beams: int = 30
    laser_min_range: float = -1.0
    laser_max_range: float = -1.0
    laser_z_hit: float = 0.95
    laser_z_rand: float = 0.05
    laser_sigma_hit: float = 0.2
    laser_likelihood_max_dist: float = 2.0
    odom_alpha1: float = 0.2
    odom_alpha2: float = 0.2
    odom_alpha3: float = 0.2
    odom_alpha4: float = 0.2

    def update(self, values: dict[str, object]) -> None:
        """Set the named fields that exist (coerced to each field's type)."""
        for f in fields(self):
            if f.name in values:
                kind = type(getattr(self, f.name))
                setattr(self, f.name, kind(values[f.name]))


def wrap(a: np.ndarray | float) -> np.ndarray | float:
    """Angles wrapped into [-pi, pi)."""
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


def kld_limit(k: np.ndarray | int, err: float, z: float) -> np.ndarray:
    """Fox's KLD bound: particles needed for ``k`` occupied bins (amcl's pf_resample_limit)."""
    k = np.asarray(k, dtype=float)
    km1 = np.maximum(k - 1.0, 1e-9)
    a = 2.0 / (9.0 * km1)
    n = km1 / (2.0 * err) * (1.0 - a + np.sqrt(a) * z) ** 3
    return np.where(k <= 1, 0.0, n)


def bins_of(poses: np.ndarray) -> np.ndarray:
    """Integer histogram bins (n, 3) of poses: 0.5 m x 0.5 m x 10 degrees."""
    return np.column_stack(
        [
            np.floor(poses[:, 0] / BIN_XY),
            np.floor(poses[:, 1] / BIN_XY),
            np.floor(poses[:, 2] / BIN_TH),
        ]
    ).astype(np.int64)


def bin_codes(bins: np.ndarray) -> np.ndarray:
    """One int64 per bin row of :func:`bins_of` (equal rows, equal codes): ``np.unique`` over a flat
    array is many times faster than over rows, and KLD sampling and clustering run it every update."""
    lo = bins.min(axis=0)
    span = bins.max(axis=0) - lo + 1
    b = bins - lo
    return (b[:, 0] * span[1] + b[:, 1]) * span[2] + b[:, 2]


def connected_bins(keys: np.ndarray) -> np.ndarray:
    """Cluster labels of occupied histogram bins ``keys`` (k, 3): bins touching in x, y or heading
    (the 26 neighbours, heading wrapping around) share a label (the smallest index in the cluster).

    Neighbour pairs are found by binary search over the encoded keys, then labels spread along them
    with pointer jumping: a few numpy passes instead of a Python walk over thousands of bins (the
    particle cloud right after ``global_localization`` occupies most of the map's bins)."""
    k = len(keys)
    nth = int(round(2 * math.pi / BIN_TH))
    lo = keys.min(axis=0) - 1
    span = keys.max(axis=0) - lo + 2
    x, y, t = keys[:, 0] - lo[0], keys[:, 1] - lo[1], (keys[:, 2] + nth // 2) % nth
    code = (x * span[1] + y) * nth + t
    order = np.argsort(code)
    sorted_code = code[order]
    src: list[np.ndarray] = []
    dst: list[np.ndarray] = []
    for a, b, c in ((a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)):
        if (a, b, c) <= (0, 0, 0):  # each pair once: the 13 offsets after (0, 0, 0)
            continue
        other = ((x + a) * span[1] + (y + b)) * nth + (t + c) % nth
        pos = np.minimum(np.searchsorted(sorted_code, other), k - 1)
        hit = sorted_code[pos] == other
        src.append(np.nonzero(hit)[0])
        dst.append(order[pos[hit]])
    label = np.arange(k)
    if k < 2:
        return label
    i, j = np.concatenate(src), np.concatenate(dst)
    while True:
        low = np.minimum(label[i], label[j])
        new = label.copy()
        np.minimum.at(new, i, low)
        np.minimum.at(new, j, low)
        new = new[new]  # pointer jumping: follow each label to its own label
        if np.array_equal(new, label):
            return label
        label = new


class ParticleFilter:
    """amcl's particle filter over one map. ``poses`` (n, 3) and ``weights`` (n,) are the set."""

    def __init__(self, grid: GridMap, params: AMCLParams | None = None, seed: int | None = None) -> None:
        self.params = params or AMCLParams()
        self.rng = np.random.default_rng(seed)
        self.set_map(grid)
        self.poses = np.zeros((0, 3))
        self.weights = np.zeros(0)
        self.w_slow = 0.0
        self.w_fast = 0.0
        self.spread_pending = False  # the set is a uniform spread no scan has weighed yet

    # -- map --------------------------------------------------------------------------------------

    def set_map(self, grid: GridMap) -> None:
        """Take a new map: rebuild the likelihood field and the free cells for uniform draws.

        The field is padded with one cell of ``laser_likelihood_max_dist`` all round, so an endpoint
        off the map reads the maximum distance (as amcl's) through a clipped index, with no mask."""
        self.grid = grid
        p = self.params
        reach = max(1, int(math.ceil(p.laser_likelihood_max_dist / grid.resolution)))
        dist = distance_transform(grid.data >= 65, reach) * grid.resolution
        self.field = np.minimum(dist, p.laser_likelihood_max_dist)
        self._padded = np.pad(self.field, 1, constant_values=p.laser_likelihood_max_dist)
        self._pz3: tuple[tuple[float, ...], np.ndarray] | None = None
        self.free_cells = np.argwhere(grid.data == 0)  # (row, col)

    def _pz_cubed(self, range_max: float) -> np.ndarray:
        """``pz^3`` of every padded field cell, flattened: pz depends only on the cell's distance and
        the model's constants, so the exponential is taken once per map (and per ``range_max``),
        not once per particle and beam."""
        p = self.params
        key = (p.laser_z_hit, p.laser_z_rand, p.laser_sigma_hit, range_max)
        if self._pz3 is None or self._pz3[0] != key:
            z = self._padded
            pz = p.laser_z_hit * np.exp(-(z * z) / (2.0 * p.laser_sigma_hit**2)) + p.laser_z_rand / range_max
            self._pz3 = (key, (pz * pz * pz).ravel())
        return self._pz3[1]

    # -- initialisation ---------------------------------------------------------------------------

    def init_gaussian(
        self, mean: tuple[float, float, float], cov_xx: float, cov_yy: float, cov_aa: float
    ) -> None:
        """Particles around ``mean`` (x, y, yaw) with the given variances (the initialpose topic)."""
        n = self.params.max_particles
        self.poses = np.column_stack(
            [
                self.rng.normal(mean[0], math.sqrt(max(cov_xx, 0.0)), n),
                self.rng.normal(mean[1], math.sqrt(max(cov_yy, 0.0)), n),
                wrap(self.rng.normal(mean[2], math.sqrt(max(cov_aa, 0.0)), n)),
            ]
        )
        self.weights = np.full(n, 1.0 / n)
        self.w_slow = self.w_fast = 0.0
        self.spread_pending = False

    def uniform_poses(self, n: int) -> np.ndarray:
        """``n`` poses drawn uniformly over the map's free cells (the global_localization service)."""
        g = self.grid
        if len(self.free_cells) == 0:
            return np.zeros((0, 3))
        pick = self.free_cells[self.rng.integers(0, len(self.free_cells), n)]
        x = g.origin[0] + (pick[:, 1] + self.rng.random(n)) * g.resolution
        y = g.origin[1] + (pick[:, 0] + self.rng.random(n)) * g.resolution
        th = self.rng.uniform(-math.pi, math.pi, n)
        return np.column_stack([x, y, th])

    def init_global(self) -> None:
        """``max_particles`` uniform particles; with ``global_candidates`` above that, the first scan
        picks them (see :meth:`sensor_update`)."""
        n = self.params.max_particles
        self.poses = self.uniform_poses(n)
        self.weights = np.full(len(self.poses), 1.0 / max(1, len(self.poses)))
        self.w_slow = self.w_fast = 0.0
        self.spread_pending = True

    # -- motion -----------------------------------------------------------------------------------

    def motion_update(self, old: tuple[float, float, float], new: tuple[float, float, float]) -> None:
        """Move every particle by the odometry step ``old`` -> ``new`` with amcl's diff noise."""
        p = self.params
        n = len(self.poses)
        if n == 0:
            return
        dx, dy = new[0] - old[0], new[1] - old[1]
        trans = math.hypot(dx, dy)
        rot1 = float(wrap(math.atan2(dy, dx) - old[2])) if trans >= 0.01 else 0.0
        rot2 = float(wrap(new[2] - old[2] - rot1))
        r1n = min(abs(float(wrap(rot1))), abs(float(wrap(rot1 - math.pi))))
        r2n = min(abs(float(wrap(rot2))), abs(float(wrap(rot2 - math.pi))))
        rng = self.rng
        s1 = math.sqrt(p.odom_alpha1 * r1n * r1n + p.odom_alpha2 * trans * trans)
        st = math.sqrt(p.odom_alpha3 * trans * trans + p.odom_alpha4 * (r1n * r1n + r2n * r2n))
        s2 = math.sqrt(p.odom_alpha1 * r2n * r2n + p.odom_alpha2 * trans * trans)
        rot1_h = rot1 - rng.normal(0.0, s1, n) if s1 > 0 else np.full(n, rot1)
        trans_h = trans - rng.normal(0.0, st, n) if st > 0 else np.full(n, trans)
        rot2_h = rot2 - rng.normal(0.0, s2, n) if s2 > 0 else np.full(n, rot2)
        th = self.poses[:, 2]
        self.poses[:, 0] += trans_h * np.cos(th + rot1_h)
        self.poses[:, 1] += trans_h * np.sin(th + rot1_h)
        self.poses[:, 2] = wrap(th + rot1_h + rot2_h)

    # -- sensor -----------------------------------------------------------------------------------

    def sensor_update(
        self,
        ranges: np.ndarray,
        angles: np.ndarray,
        range_max: float,
        laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
        range_min: float = 0.0,
    ) -> float:
        """Weigh the particles by one scan (angles in the laser frame); returns the mean weight."""
        p = self.params
        n = len(self.poses)
        if n == 0:
            return 0.0
        ranges = np.asarray(ranges, dtype=float)
        angles = np.asarray(angles, dtype=float)
        if p.laser_max_range > 0:
            range_max = min(range_max, p.laser_max_range)
        if p.laser_min_range > 0:
            range_min = max(range_min, p.laser_min_range)
        count = len(ranges)
        beams = max(2, p.laser_max_beams)
        if count > beams:
            idx = (np.arange(beams) * ((count - 1) / (beams - 1))).astype(np.int64)
            ranges, angles = ranges[idx], angles[idx]
        use = np.isfinite(ranges) & (ranges < range_max) & (ranges >= range_min)
        r, a = ranges[use], angles[use]
        if r.size == 0:
            return float(self.weights.mean()) if n else 0.0
        if self.spread_pending and p.global_candidates > n:
            # global localization: of many uniform candidates, the scan keeps the max_particles that
            # explain it best. A uniform spread of max_particles leaves the true pose's basin (a few
            # centimetres and degrees wide under sigma_hit 0.1) with no particle near its peak, and
            # the partial fits elsewhere outweigh it before it can climb there.
            cand = self.uniform_poses(p.global_candidates)
            like = self._likelihood(cand, r, a, laser_pose, range_max)
            keep = np.argpartition(like, -n)[-n:]
            self.poses, like = cand[keep], like[keep]
            self.weights = np.full(n, 1.0 / n)
        else:
            like = self._likelihood(self.poses, r, a, laser_pose, range_max)
        self.spread_pending = False
        w = self.weights * like
        total = float(w.sum())
        if total <= 0 or not math.isfinite(total):
            self.weights = np.full(n, 1.0 / n)
            return 0.0
        # the mean likelihood of the set (its weights sum to one): amcl divides this by the particle
        # count as well, so its averages jump whenever KLD sampling resizes the set (a shrinking set
        # looks like a better fit and hides a wrong lock; a growing one triggers injections)
        w_avg = total / float(self.weights.sum())
        self.weights = w / total
        if self.w_slow == 0.0:
            self.w_slow = w_avg
        else:
            self.w_slow += p.recovery_alpha_slow * (w_avg - self.w_slow)
        if self.w_fast == 0.0:
            self.w_fast = w_avg
        else:
            self.w_fast += p.recovery_alpha_fast * (w_avg - self.w_fast)
        return w_avg

    def _likelihood(
        self,
        poses: np.ndarray,
        r: np.ndarray,
        a: np.ndarray,
        laser_pose: tuple[float, float, float],
        range_max: float,
    ) -> np.ndarray:
        """amcl's ``1 + sum(pz^3)`` of each pose for the used beams (ranges ``r`` at angles ``a``)."""
        # endpoints in the laser frame, then in the map for every particle (float32: 20 m maps need
        # micrometres, and half the memory traffic makes the update faster)
        lx, ly, lth = laser_pose
        bx = (lx + r * np.cos(lth + a)).astype(np.float32)
        by = (ly + r * np.sin(lth + a)).astype(np.float32)
        g = self.grid
        inv = np.float32(1.0 / g.resolution)
        bx *= inv
        by *= inv
        table = self._pz_cubed(range_max)
        like = np.empty(len(poses))
        # blocks of particles whose (block, beams) index arrays stay in the CPU cache: one pass over
        # 10000 particles at once is several times slower per particle than blocks of 1000
        for lo in range(0, len(poses), SENSOR_BLOCK):
            block = poses[lo : lo + SENSOR_BLOCK].astype(np.float32)
            c, s = np.cos(block[:, 2:3]), np.sin(block[:, 2:3])
            # padded-field cell coordinates: +1 for the border, clipped so an endpoint off the map
            # lands on it
            fx = (block[:, 0:1] - np.float32(g.origin[0])) * inv + np.float32(1.0)
            fy = (block[:, 1:2] - np.float32(g.origin[1])) * inv + np.float32(1.0)
            ix = np.floor(fx + c * bx - s * by).astype(np.int64)
            iy = np.floor(fy + s * bx + c * by).astype(np.int64)
            np.clip(ix, 0, g.width + 1, out=ix)
            np.clip(iy, 0, g.height + 1, out=iy)
            iy *= g.width + 2
            iy += ix
            like[lo : lo + SENSOR_BLOCK] = 1.0 + table[iy].sum(axis=1, dtype=np.float64)
        return like

    # -- resampling -------------------------------------------------------------------------------

    def resample(self) -> int:
        """Low-variance resampling with KLD-adapted size and recovery injection; returns how many
        uniformly drawn (not yet weighed) particles the new set holds."""
        p = self.params
        if len(self.poses) == 0:
            return 0
        if p.selective_resampling and 1.0 / float(self.weights @ self.weights) > 0.5 * len(self.weights):
            return 0
        m = p.max_particles
        w_diff = 0.0
        if self.w_slow > 0:
            w_diff = max(0.0, 1.0 - self.w_fast / self.w_slow)
        cum = np.cumsum(self.weights)
        cum[-1] = 1.0
        u = (self.rng.random() + np.arange(m)) / m
        picked = self.poses[np.searchsorted(cum, u)]
        picked = picked[self.rng.permutation(m)]
        inject = np.zeros(m, dtype=bool)
        if w_diff > 0:
            inject = self.rng.random(m) < w_diff
            k = int(inject.sum())
            if k:
                picked[inject] = self.uniform_poses(k)
        _, first = np.unique(bin_codes(bins_of(picked)), return_index=True)
        is_first = np.zeros(m, dtype=np.int64)
        is_first[first] = 1
        k_of_n = np.cumsum(is_first)  # occupied bins among the first n+1 particles
        needed = kld_limit(k_of_n, p.kld_err, p.kld_z)
        ok = np.nonzero((np.arange(1, m + 1) >= needed) & (np.arange(1, m + 1) >= p.min_particles))[0]
        count = int(ok[0]) + 1 if ok.size else m
        count = max(min(count, m), min(p.min_particles, m))
        self.poses = picked[:count].copy()
        self.weights = np.full(count, 1.0 / count)
        if w_diff > 0:
            self.w_slow = self.w_fast = 0.0  # amcl resets the averages after injecting
        return int(inject[:count].sum())

    # -- estimate ---------------------------------------------------------------------------------

    def estimate(self) -> tuple[np.ndarray, np.ndarray]:
        """(mean (3,), covariance (3, 3)) of the heaviest cluster of connected occupied bins."""
        if len(self.poses) == 0:
            return np.zeros(3), np.eye(3)
        bins = bins_of(self.poses)
        _, first, inverse = np.unique(bin_codes(bins), return_index=True, return_inverse=True)
        keys = bins[first]
        inverse = inverse.ravel()
        bin_w = np.bincount(inverse, weights=self.weights, minlength=len(keys))
        label = connected_bins(keys)
        cluster_w = np.bincount(label, weights=bin_w, minlength=len(keys))
        best = int(np.argmax(cluster_w))
        member = label[inverse] == best
        pts, w = self.poses[member], self.weights[member]
        w = w / w.sum()
        mx, my = float(w @ pts[:, 0]), float(w @ pts[:, 1])
        mth = math.atan2(float(w @ np.sin(pts[:, 2])), float(w @ np.cos(pts[:, 2])))
        d = np.column_stack([pts[:, 0] - mx, pts[:, 1] - my, wrap(pts[:, 2] - mth)])
        cov = (d * w[:, None]).T @ d
        return np.array([mx, my, mth]), cov
