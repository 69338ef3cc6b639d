"""tf.transformations beyond Euler angles and quaternions: each matrix builder against its inverse
function, and the module's public surface."""

from __future__ import annotations

import math

import numpy as np
import pytest

import tf.transformations as tft

rng = np.random.default_rng(7)


def test_public_names_of_ros1_module():
    for name in (
        "identity_matrix translation_matrix translation_from_matrix reflection_matrix reflection_from_matrix "
        "rotation_matrix rotation_from_matrix scale_matrix scale_from_matrix projection_matrix "
        "projection_from_matrix clip_matrix shear_matrix shear_from_matrix decompose_matrix compose_matrix "
        "orthogonalization_matrix superimposition_matrix euler_matrix euler_from_matrix euler_from_quaternion "
        "quaternion_from_euler quaternion_about_axis quaternion_matrix quaternion_from_matrix quaternion_multiply "
        "quaternion_conjugate quaternion_inverse quaternion_slerp random_quaternion random_rotation_matrix "
        "random_vector vector_norm unit_vector inverse_matrix concatenate_matrices is_same_transform Arcball "
        "arcball_map_to_sphere arcball_constrain_to_axis arcball_nearest_axis"
    ).split():
        assert callable(getattr(tft, name)), name
    assert tft._AXES2TUPLE["sxyz"] == (0, 0, 0, 0) and tft._NEXT_AXIS == [1, 2, 0, 1]


def test_rotation_round_trip_and_fixed_point():
    angle, axis, point = 0.8, np.array([1.0, -1.0, 2.0]), np.array([1.0, 2.0, 3.0])
    m = tft.rotation_matrix(angle, axis, point)
    a, d, p = tft.rotation_from_matrix(m)
    assert np.allclose(tft.rotation_matrix(a, d, p[:3]), m)
    assert np.allclose(m @ p, p)  # the returned point lies on the axis


def test_scale_reflection_shear_projection_round_trips():
    s = tft.scale_matrix(1.5, [1, 2, 3], [0, 0, 1])
    f, o, d = tft.scale_from_matrix(s)
    assert np.allclose(tft.scale_matrix(f, o, d), s)
    f, o, d = tft.scale_from_matrix(tft.scale_matrix(0.5, [1, 2, 3]))
    assert d is None and f == pytest.approx(0.5)
    r = tft.reflection_matrix([1, 2, 3], [0, 1, 1])
    p, n = tft.reflection_from_matrix(r)
    assert tft.is_same_transform(tft.reflection_matrix(p, n), r)
    sh = tft.shear_matrix(0.4, [1, 0, 0], [1, 2, 3], [0, 1, 0])
    a, d, p, n = tft.shear_from_matrix(sh)
    assert tft.is_same_transform(tft.shear_matrix(a, d, p, n), sh)
    for kwargs in ({}, {"direction": [1, 1, 0]}, {"perspective": [2, 3, 4]}):
        pm = tft.projection_matrix([0.5, 0, 0], [1, 0, 0], **kwargs)
        pt = rng.uniform(-1, 1, 3)
        out = pm @ np.append(pt, 1.0)
        assert out[0] / out[3] == pytest.approx(0.5)  # lands on the plane x = 0.5
    with pytest.raises(ValueError, match="not orthogonal"):
        tft.shear_matrix(0.4, [1, 0, 0], [0, 0, 0], [1, 0, 0])
    with pytest.raises(ValueError, match="invalid frustrum"):
        tft.clip_matrix(1, 0, 0, 1, 1, 2)


def test_compose_decompose_round_trip():
    m = tft.compose_matrix([1, 2, 3], [0.1, 0.2, 0.3], [0.4, 0.5, 0.6], [1, 2, 3], [0, 0, 0, 1])
    scale, shear, angles, trans, persp = tft.decompose_matrix(m)
    assert np.allclose(scale, [1, 2, 3]) and np.allclose(shear, [0.1, 0.2, 0.3])
    assert np.allclose(angles, [0.4, 0.5, 0.6]) and np.allclose(trans, [1, 2, 3])
    assert tft.is_same_transform(tft.compose_matrix(scale, shear, angles, trans, persp), m)


@pytest.mark.parametrize("usesvd", [True, False])
def test_superimposition_recovers_a_rigid_transform(usesvd):
    m = tft.concatenate_matrices(
        tft.translation_matrix([1, -2, 3]), tft.random_rotation_matrix([0.1, 0.2, 0.3])
    )
    v0 = rng.uniform(-5, 5, (3, 20))
    v1 = (m @ np.vstack([v0, np.ones(20)]))[:3]
    assert np.allclose(tft.superimposition_matrix(v0, v1, usesvd=usesvd), m)
    scaled = tft.superimposition_matrix(v0, v1 * 2.0, scaling=True, usesvd=usesvd)
    assert np.allclose(scaled[:3, :3] / 2.0, m[:3, :3])


def test_vectors_random_and_arcball():
    assert tft.vector_norm([3, 4]) == 5.0
    assert np.allclose(tft.vector_norm([[3, 4], [6, 8]], axis=1), [5, 10])
    assert np.allclose(tft.unit_vector([[3, 4], [6, 8]], axis=1), [[0.6, 0.8], [0.6, 0.8]])
    q = tft.random_quaternion()
    assert tft.vector_norm(q) == pytest.approx(1.0)
    r = tft.random_rotation_matrix()
    assert np.allclose(r[:3, :3] @ r[:3, :3].T, np.eye(3))
    assert np.allclose(tft.inverse_matrix(r) @ r, np.eye(4))
    ball = tft.Arcball()
    ball.place([320, 320], 320)
    ball.down([500, 250])
    ball.drag([475, 275])
    m = ball.matrix()
    assert np.allclose(m[:3, :3] @ m[:3, :3].T, np.eye(3)) and not np.allclose(m, np.eye(4))
    assert tft.orthogonalization_matrix([10, 10, 10], [90, 90, 90]) == pytest.approx(np.diag([10, 10, 10, 1]))
    assert tft.quaternion_slerp([0, 0, 0, 1], [0, 0, math.sin(0.5), math.cos(0.5)], 0.5) == pytest.approx(
        [0, 0, math.sin(0.25), math.cos(0.25)]
    )
