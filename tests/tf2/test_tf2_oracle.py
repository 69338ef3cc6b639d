"""tf numbers against an independent oracle (transforms3d): composition, inverse, interpolation, and the
Euler conventions of tf.transformations."""

from __future__ import annotations

import math

import numpy as np
import pytest

t3d = pytest.importorskip("transforms3d")
from transforms3d import affines, euler, quaternions  # noqa: E402

from ninjemys.tf2 import math as tfm  # noqa: E402
from ninjemys.tf2 import transformations as T  # noqa: E402
from ninjemys.tf2.core import BufferCore  # noqa: E402

rng = np.random.default_rng(20240611)
S = 1_000_000_000


def rand_q() -> tuple[float, float, float, float]:
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return tuple(float(v) for v in q)  # x, y, z, w


def wxyz(q):
    return np.array([q[3], q[0], q[1], q[2]])


def matrix(t):
    """4x4 of a 7-tuple, by the oracle."""
    return affines.compose(t[:3], quaternions.quat2mat(wxyz(t[3:])), [1, 1, 1])


def rand_t():
    return (*(float(v) for v in rng.uniform(-5, 5, 3)), *rand_q())


def same_rotation(q1, q2, tol=1e-9):
    return abs(abs(float(np.dot(q1, q2))) - 1.0) < tol


@pytest.mark.parametrize("axes", sorted(T._AXES2TUPLE))
def test_euler_conventions_match_oracle(axes):
    for _ in range(20):
        a = rng.uniform(-math.pi, math.pi, 3)
        m = T.euler_matrix(*a, axes=axes)
        assert np.allclose(m[:3, :3], euler.euler2mat(*a, axes=axes), atol=1e-12)
        back = T.euler_from_matrix(m, axes)
        assert np.allclose(euler.euler2mat(*back, axes=axes), m[:3, :3], atol=1e-9)
        assert np.allclose(back, euler.mat2euler(m[:3, :3], axes=axes), atol=1e-9)
        q = T.quaternion_from_euler(*a, axes=axes)
        assert same_rotation(wxyz(q), euler.euler2quat(*a, axes=axes))
        assert np.allclose(T.euler_from_quaternion(q, axes), back, atol=1e-9)


def test_quaternion_functions_match_oracle():
    for _ in range(50):
        q0, q1 = rand_q(), rand_q()
        assert np.allclose(
            wxyz(T.quaternion_multiply(q1, q0)), quaternions.qmult(wxyz(q1), wxyz(q0)), atol=1e-12
        )
        assert np.allclose(T.quaternion_matrix(q0)[:3, :3], quaternions.quat2mat(wxyz(q0)), atol=1e-12)
        assert same_rotation(wxyz(T.quaternion_from_matrix(T.quaternion_matrix(q0))), wxyz(q0))
        assert np.allclose(wxyz(T.quaternion_inverse(q0)), quaternions.qinverse(wxyz(q0)), atol=1e-12)
        axis = rng.normal(size=3)
        angle = float(rng.uniform(-3, 3))
        assert same_rotation(
            wxyz(T.quaternion_about_axis(angle, axis)), quaternions.axangle2quat(axis, angle)
        )
        assert np.allclose(
            T.rotation_matrix(angle, axis)[:3, :3],
            quaternions.quat2mat(quaternions.axangle2quat(axis, angle)),
        )


def oracle_slerp(q0, q1, f):
    """q0 * exp(f * log(q0^-1 q1)) along the shorter arc, from the oracle's axis-angle functions."""
    a, b = wxyz(q0), wxyz(q1)
    if np.dot(a, b) < 0:
        b = -b
    axis, angle = quaternions.quat2axangle(quaternions.qmult(quaternions.qinverse(a), b))
    return quaternions.qmult(a, quaternions.axangle2quat(axis, f * angle))


def test_slerp_matches_oracle():
    for _ in range(50):
        q0, q1 = rand_q(), rand_q()
        f = float(rng.uniform(0, 1))
        expected = oracle_slerp(q0, q1, f)
        assert same_rotation(wxyz(tfm.slerp(q0, q1, f)), expected)
        assert same_rotation(wxyz(T.quaternion_slerp(q0, q1, f)), expected)


def test_compose_and_inverse_match_oracle():
    for _ in range(100):
        a, b = rand_t(), rand_t()
        assert np.allclose(matrix(tfm.compose(a, b)), matrix(a) @ matrix(b), atol=1e-12)
        assert np.allclose(matrix(tfm.inverse(a)), np.linalg.inv(matrix(a)), atol=1e-12)
        assert np.allclose(
            matrix(tfm.inverse_compose(a, b)), np.linalg.inv(matrix(a)) @ matrix(b), atol=1e-12
        )


def test_buffer_chain_and_interpolation_match_oracle():
    """A 5-frame tree with two branches; lookups across it at stored and interpolated times."""
    b = BufferCore()
    links = [("w", "a"), ("a", "b"), ("b", "c"), ("a", "d")]
    data = {link: (rand_t(), rand_t()) for link in links}
    for (parent, child), (t1, t2) in data.items():
        b.set_transforms([(parent, child, 1 * S, *t1), (parent, child, 2 * S, *t2)])

    def at(link, f):
        t1, t2 = data[link]
        q = oracle_slerp(t1[3:], t2[3:], f)
        trans = (1 - f) * np.array(t1[:3]) + f * np.array(t2[:3])
        return affines.compose(trans, quaternions.quat2mat(q), [1, 1, 1])

    for f in (0.0, 0.3, 1.0):
        m = {link: at(link, f) for link in links}
        c_in_w = m[("w", "a")] @ m[("a", "b")] @ m[("b", "c")]
        d_in_w = m[("w", "a")] @ m[("a", "d")]
        stamp = S + int(f * S)
        _, got = b.lookup("d", "c", stamp)
        assert np.allclose(matrix(got), np.linalg.inv(d_in_w) @ c_in_w, atol=1e-9)
        _, got = b.lookup("w", "c", stamp)
        assert np.allclose(matrix(got), c_in_w, atol=1e-9)
        _, got = b.lookup("c", "w", stamp)
        assert np.allclose(matrix(got), np.linalg.inv(c_in_w), atol=1e-9)
