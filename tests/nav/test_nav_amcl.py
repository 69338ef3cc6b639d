"""amcl's filter: tracking along a drive with noisy odometry, KLD sizes, global localization."""

from __future__ import annotations

import math

import numpy as np

from ninjemys.nav.amcl import AMCLParams, ParticleFilter, kld_limit, wrap


def lawnmower(steps: int):
    """A drive around the room's free middle: forward runs and turns, 0.05 m / step."""
    pose = np.array([1.0, 1.0, 0.0])
    path = [pose.copy()]
    for i in range(steps):
        phase = (i // 50) % 4
        if phase in (0, 2):
            pose = pose + [0.05 * math.cos(pose[2]), 0.05 * math.sin(pose[2]), 0.0]
        else:
            pose = pose + [0.0, 0.0, math.pi / 2 / 50]
        path.append(pose.copy())
    return path


def run_filter(room, laser, pf, truth, rng, drift=0.02):
    angles, cast = laser
    odom = truth[0].copy()
    errors = []
    for prev_t, t in zip(truth, truth[1:], strict=False):
        step = t - prev_t
        c, s = math.cos(prev_t[2] - odom[2]), math.sin(prev_t[2] - odom[2])
        noisy = step * (1 + rng.normal(0, drift, 3))
        new_odom = odom + [c * noisy[0] + s * noisy[1], -s * noisy[0] + c * noisy[1], noisy[2]]
        moved = math.hypot(*(new_odom[:2] - odom[:2])) > 0 or abs(noisy[2]) > 0
        if moved:
            pf.motion_update(tuple(odom), tuple(new_odom))
        odom = new_odom
        ranges = cast(room, tuple(t), angles, 5.0) + rng.normal(0, 0.01, len(angles))
        pf.sensor_update(ranges, angles, 5.0)
        pf.resample()
        mean, _ = pf.estimate()
        errors.append((math.hypot(mean[0] - t[0], mean[1] - t[1]), abs(float(wrap(mean[2] - t[2])))))
    return np.array(errors)


def test_tracking_stays_within_a_few_centimetres(room, laser):
    rng = np.random.default_rng(1)
    pf = ParticleFilter(room, AMCLParams(max_particles=2000, min_particles=100, laser_max_beams=60), seed=2)
    truth = lawnmower(200)
    pf.init_gaussian(tuple(truth[0]), 0.25**2, 0.25**2, 0.2**2)
    errors = run_filter(room, laser, pf, truth, rng)
    rms = math.sqrt(float(np.mean(errors[20:, 0] ** 2)))
    assert rms < 0.1
    assert errors[20:, 1].max() < 0.2
    assert len(pf.poses) < 1000  # KLD shrank the set once it converged


def test_global_localization_converges(room, laser):
    rng = np.random.default_rng(3)
    params = AMCLParams(max_particles=3000, min_particles=200, laser_max_beams=60)
    pf = ParticleFilter(room, params, seed=4)
    pf.init_global()
    truth = lawnmower(160)
    errors = run_filter(room, laser, pf, truth, rng)
    assert errors[-20:, 0].max() < 0.2


def test_kld_limit_grows_with_bins():
    assert kld_limit(1, 0.01, 0.99) == 0.0
    values = kld_limit(np.array([2, 10, 100]), 0.01, 0.99)
    assert np.all(np.diff(values) > 0)
    assert 100 < values[1] < 1000


def test_motion_model_spread_follows_alphas(room):
    pf = ParticleFilter(
        room,
        AMCLParams(max_particles=4000, odom_alpha3=0.04, odom_alpha1=0.0, odom_alpha2=0.0, odom_alpha4=0.0),
        seed=1,
    )
    pf.init_gaussian((2.0, 2.0, 0.0), 0.0, 0.0, 0.0)
    pf.motion_update((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    assert math.isclose(pf.poses[:, 0].mean(), 3.0, abs_tol=0.02)
    assert math.isclose(pf.poses[:, 0].std(), 0.2, rel_tol=0.1)  # sqrt(alpha3 * 1^2)
    assert np.allclose(pf.poses[:, 1], 2.0) and np.allclose(pf.poses[:, 2], 0.0)


def test_resample_reports_injected_particles(room, laser):
    """Recovery injection (w_fast below w_slow) says how many unweighed uniform particles it added: the
    node weighs them with the next scan even when the robot stands still."""
    angles, cast = laser
    params = AMCLParams(recovery_alpha_slow=0.001, recovery_alpha_fast=0.1, max_particles=500)
    pf = ParticleFilter(room, params, seed=3)
    pf.init_gaussian((1.0, 1.0, 0.0), 0.01, 0.01, 0.01)
    good = cast(room, (1.0, 1.0, 0.0), angles, 5.0)
    pf.sensor_update(good, angles, 5.0)
    assert pf.resample() == 0  # the averages agree: nothing injected
    pf.sensor_update(good + 1.0, angles, 5.0)  # scans that fit badly: w_fast drops below w_slow
    injected = pf.resample()
    assert injected > 0
    spread = np.hypot(pf.poses[:, 0] - 1.0, pf.poses[:, 1] - 1.0) > 1.0
    assert spread.sum() >= injected // 2  # uniform draws land all over the room


def test_global_candidates_put_particles_at_the_true_pose(laser):
    """In the nearly symmetric office, a uniform spread of max_particles leaves the true pose's
    basin without a particle near its peak; weighing many more candidates with the first scan and
    keeping the best max_particles puts particles at the true pose."""
    from .conftest import world_map

    angles, cast = laser
    office = world_map("office")
    truth = (1.5, 0.2, 0.3)
    ranges = cast(office, truth, angles, 5.0)

    def near(pf: ParticleFilter) -> int:
        d = np.hypot(pf.poses[:, 0] - truth[0], pf.poses[:, 1] - truth[1])
        return int(((d < 0.3) & (np.abs(wrap(pf.poses[:, 2] - truth[2])) < 0.15)).sum())

    plain = ParticleFilter(
        office, AMCLParams(max_particles=2000, laser_max_beams=60, laser_sigma_hit=0.1), seed=5
    )
    plain.init_global()
    plain.sensor_update(ranges, angles, 5.0)
    params = AMCLParams(max_particles=2000, laser_max_beams=60, laser_sigma_hit=0.1, global_candidates=60000)
    pf = ParticleFilter(office, params, seed=6)
    pf.init_global()
    pf.sensor_update(ranges, angles, 5.0)
    assert len(pf.poses) == 2000 and math.isclose(float(pf.weights.sum()), 1.0)
    assert near(pf) >= 3 and near(plain) == 0
    # later scans weigh the kept set as usual (no second draw)
    kept = pf.poses.copy()
    pf.sensor_update(ranges, angles, 5.0)
    assert np.array_equal(kept, pf.poses)


def test_selective_resampling_keeps_a_set_whose_weights_are_even(room, laser):
    """amcl's ~selective_resampling: no resampling while N_eff = 1 / sum(w^2) > n / 2."""
    angles, cast = laser
    pf = ParticleFilter(room, AMCLParams(max_particles=500, selective_resampling=True), seed=3)
    pf.init_gaussian((1.0, 1.0, 0.0), 0.0001, 0.0001, 0.0001)
    pf.sensor_update(cast(room, (1.0, 1.0, 0.0), angles, 5.0), angles, 5.0)  # all fit alike
    kept = pf.poses.copy()
    pf.resample()
    assert np.array_equal(kept, pf.poses)
    pf.init_global()
    pf.sensor_update(cast(room, (1.0, 1.0, 0.0), angles, 5.0), angles, 5.0)  # a few fit well
    pf.resample()
    assert len(pf.poses) != 500 or not np.array_equal(kept, pf.poses)


def test_recovery_average_does_not_follow_the_set_size(room, laser):
    """w_avg is the set's mean likelihood: the same particles' scan gives the same w_avg whether KLD
    left 2000 of them or 200 (amcl's divides by the count, so a resize alone moved w_fast)."""
    angles, cast = laser
    ranges = cast(room, (1.0, 1.0, 0.0), angles, 5.0)
    pf = ParticleFilter(room, AMCLParams(max_particles=2000), seed=4)
    pf.init_gaussian((1.0, 1.0, 0.0), 0.01, 0.01, 0.01)
    poses = pf.poses.copy()
    big = pf.sensor_update(ranges, angles, 5.0)
    pf.poses, pf.weights = poses[::10].copy(), np.full(200, 1.0 / 200)
    small = pf.sensor_update(ranges, angles, 5.0)
    assert big > 10 and math.isclose(big, small, rel_tol=0.1)


def shipped_params(**override) -> AMCLParams:
    """The PuzzleBot navigation's amcl parameters (params/amcl_params.yaml), as the launch loads them."""
    import yaml

    from .conftest import SHARE

    values = yaml.safe_load((SHARE / "puzzlebot_navigation" / "params" / "amcl_params.yaml").read_text())
    params = AMCLParams()
    params.update({**values, **override})
    return params


def corridor_drive(params: AMCLParams, seed: int, step: float) -> float:
    """amcl's error at office goal (2.98, 0.23) after the drive west along the corridor from x = 9.5,
    one filter update every ``step`` metres (the node's order: motion, scan, estimate, resampling every
    ``resample_interval`` updates), with the simulator's perfect odometry and 360-beam 12 m laser."""
    from .conftest import cast, world_map

    grid = world_map("office")
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    rng = np.random.default_rng(seed)
    pf = ParticleFilter(grid, params, seed=seed)
    y, heading = 0.23, math.pi
    pf.init_gaussian((9.5, y, heading), 0.0004, 0.0004, 0.0001)
    last = None
    mean = np.zeros(3)
    for i, x in enumerate([*np.arange(9.5, 2.98, -step), 2.98]):
        pose = (float(x), y, heading)
        if last is not None:
            pf.motion_update(last, pose)
        last = pose
        ranges = cast(grid, pose, angles, 12.0) + rng.normal(0.0, 0.01, len(angles))
        pf.sensor_update(ranges, angles, 12.0, (0.0, 0.0, 0.0), 0.15)
        mean, _ = pf.estimate()
        if (i + 1) % max(1, params.resample_interval) == 0:
            pf.resample()
    return math.hypot(mean[0] - 2.98, mean[1] - y)


def test_shipped_params_keep_the_office_corridor_goal_within_tolerance():
    """Issue 22: under load the office run missed goal (2.98, 0.23, 3.11) at the end of the long corridor,
    amcl 0.11-0.13 m off along it. Offline, with updates 0.3 m apart (scans dropped under load), the
    earlier parameters (min_particles 100, resample_interval 1, odom_alpha 0.1) ended 0.08 m off on
    average and up to 0.135 m over 12 seeds: 100 particles resampled at every update, each spread with
    twice the robot's odometry noise, random-walk along the corridor where the laser holds x loosely.
    The shipped ones (500, 2, 0.05) end 0.04 m off on average, at most 0.06 m."""
    errors = [corridor_drive(shipped_params(), seed, step=0.3) for seed in range(6)]
    rms = math.sqrt(float(np.mean(np.square(errors))))
    assert rms < 0.06 and max(errors) < 0.1, [round(e, 3) for e in errors]
