"""Quaternion and Euler-angle conventions (docs/design.md, "Conventions")."""

import math

import numpy as np
import pytest

from spinviz import rotations as R


def Rz(a):
    """Rotations about z by the angles a, shape a.shape + (3, 3)."""
    c, s, o, i = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, -s, o], -1), np.stack([s, c, o], -1), np.stack([o, o, i], -1)], -2)


def Rx(a):
    """Rotations about x by the angles a, shape a.shape + (3, 3)."""
    c, s, o, i = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([i, o, o], -1), np.stack([o, c, -s], -1), np.stack([o, s, c], -1)], -2)


def test_zxz_quaternion_is_Rz_Rx_Rz(rng):
    """O = Rz(phi) Rx(theta) Rz(psi) is the matrix of quat_from_euler_zxz (the convention of
    (6.4)), at 200 random angle triples (measured 5.6e-16, round-off; bound 1e-14)."""
    phi, theta, psi = rng.uniform(-np.pi, np.pi, 200), rng.uniform(0, np.pi, 200), rng.uniform(-np.pi, np.pi, 200)
    m = R.matrix_from_quat(R.quat_from_euler_zxz(np.stack([phi, theta, psi], -1)))
    np.testing.assert_allclose(m, Rz(phi) @ Rx(theta) @ Rz(psi), atol=1e-14)


def test_quaternion_is_scalar_first():
    q = R.quat_from_axis_angle((0.0, 0.0, 1.0), 0.5 * np.pi)
    np.testing.assert_allclose(q, [math.cos(np.pi / 4), 0, 0, math.sin(np.pi / 4)], atol=1e-15)
    # and maps body x to world y
    np.testing.assert_allclose(R.world_from_body(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-15)


def test_euler_round_trip_generic(rng):
    a = np.stack([rng.uniform(-np.pi, np.pi, 200), rng.uniform(1e-3, np.pi - 1e-3, 200), rng.uniform(-np.pi, np.pi, 200)], -1)
    back = R.euler_zxz_from_quat(R.quat_from_euler_zxz(a))
    np.testing.assert_allclose(back, a, atol=1e-12)


@pytest.mark.parametrize("phi, psi", [(0.3, 0.5), (-2.0, 1.0), (3.0, 3.0)])
@pytest.mark.parametrize("theta", [0.0, np.pi], ids=["0", "pi"])
def test_euler_round_trip_at_the_singularities(theta, phi, psi):
    """At theta = 0 only phi + psi is defined, at theta = pi only phi - psi: the angles come
    back with psi = 0, theta exact, and the *rotation* is the same."""
    q = R.quat_from_euler_zxz([phi, theta, psi])
    back = R.euler_zxz_from_quat(q)
    assert back[1] == pytest.approx(theta, abs=1e-15)
    assert back[2] == 0.0
    assert R.misorientation(R.quat_from_euler_zxz(back), q) < 1e-14
    want = phi + psi if theta == 0.0 else phi - psi
    assert abs(np.angle(np.exp(1j * (back[0] - want)))) < 1e-14


@pytest.mark.parametrize("th", [1e-6, 1e-10, 1e-14])
def test_theta_keeps_precision_near_zero(th):
    """theta from atan2 (not arccos, which would give 0 below ~1e-8) is exact to round-off
    even at 1e-14 rad (bound 1e-9 relative: arccos is off by 100 % there)."""
    back = R.euler_zxz_from_quat(R.quat_from_euler_zxz([0.4, th, -0.3]))
    assert back[1] == pytest.approx(th, rel=1e-9, abs=0)


def test_round_trip_is_sign_blind():
    q = R.quat_from_euler_zxz([0.4, 1.0, -2.0])
    np.testing.assert_allclose(R.euler_zxz_from_quat(-q), R.euler_zxz_from_quat(q), atol=1e-14)


@pytest.mark.parametrize("ang", [1e-12, 1e-6, 0.5, 3.0])
def test_misorientation_tiny_and_large_angles_and_sign(ang, rng):
    """The angle between q and q (x) (rotation by ang), either sign, to round-off.  The product
    r is itself rounded (~1e-16 in each component), so the angle it holds is ang to a few
    1e-16 absolute (measured at most 2.7e-16 over 2000 random q at 1e-12): abs 1e-15, where an
    arccos of the scalar part would give 0 or ~1e-8."""
    q = R.normalize(rng.normal(size=4))
    r = R.multiply(q, R.quat_from_axis_angle((0.6, 0.0, 0.8), ang))
    assert R.misorientation(q, r) == pytest.approx(ang, rel=1e-9, abs=1e-15)
    assert R.misorientation(q, -r) == pytest.approx(ang, rel=1e-9, abs=1e-15)


def test_exp_rotvec_and_matrix_round_trip():
    v = np.array([0.3, -1.2, 2.0])
    q = R.exp_rotvec(v)
    np.testing.assert_allclose(R.world_from_body(q, v), v, atol=1e-14)   # the axis is fixed
    assert R.misorientation(q, np.array([1.0, 0, 0, 0])) == pytest.approx(np.linalg.norm(v), rel=1e-14, abs=0)
    assert R.allclose_up_to_sign(R.quat_from_matrix(R.matrix_from_quat(q)), q)


def test_world_and_body_are_inverse_pairwise(rng):
    q = R.normalize(rng.normal(size=(5, 4)))
    v = rng.normal(size=(5, 3))
    np.testing.assert_allclose(R.body_from_world(q, R.world_from_body(q, v)), v, atol=1e-14)


def test_slerp_series_follows_uniform_rotation():
    """Sampled from a uniform rotation (0.4 rad between samples), slerp reproduces it exactly in between."""
    t = np.linspace(0.0, 10.0, 26)
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    q = R.quat_from_axis_angle(axis, 1.0 * t)
    q[1::2] *= -1.0                                   # sign flips must not matter
    t2 = np.linspace(0.0, 10.0, 97)
    np.testing.assert_array_less(R.misorientation(R.slerp_series(t, q, t2), R.quat_from_axis_angle(axis, 1.0 * t2)), 1e-13)


def test_unwrap_euler_removes_jumps():
    phi = np.linspace(0.0, 20.0, 200)
    a = np.stack([phi, np.full_like(phi, 1.0), -phi], -1)
    wrapped = R.euler_zxz_from_quat(R.quat_from_euler_zxz(a))
    np.testing.assert_allclose(R.unwrap_euler_zxz(wrapped), a, atol=1e-12)


def test_bad_shapes_say_what_was_expected():
    with pytest.raises(ValueError, match=r"last axis of length 3 \(phi, theta, psi\); got shape \(4,\)"):
        R.quat_from_euler_zxz([1.0, 2.0, 3.0, 4.0])
    with pytest.raises(ValueError, match=r"last axis of length 4 \(w, x, y, z\); got shape \(3,\)"):
        R.as_quaternion_array([1.0, 0.0, 0.0])
