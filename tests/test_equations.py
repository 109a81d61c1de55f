"""The general equations of motion against the paper's component forms.

(2.2)+(2.3) written for any inertia and dipole must reproduce (3.3)-(3.5) -- with c^3,
not the c^2 the paper prints there (a typo: (3.8) has c^3) -- and
the dimensionless (4.2)-(4.4); (2.5) must reproduce (5.3) at chi = 0.
"""

import math

import numpy as np
import pytest

from spinviz import units as U
from spinviz.physics import equations as E
from spinviz.physics import models as M


def eq_3_3_to_3_5(w, I1, I3, d, chi, c_power=3):
    """(3.3)-(3.5) transcribed from the paper, CGS, with c^c_power in the prefactor; arrays
    broadcast (w: 3 components, each a scalar or an array of draws)."""
    w1, w2, w3 = w
    delta = 1.0 - I3 / I1
    d1, d3 = d * np.sin(chi), d * np.cos(chi)
    W2 = w1 * w1 + w2 * w2 + w3 * w3
    wa = W2 + delta * (delta - 2.0) * w3**2
    wb = W2 + delta * (2.0 * w1**2 - w2**2)
    wc = W2 + delta * (delta + 1.0) * w3**2
    c = U.C_LIGHT**c_power
    r1 = delta * w2 * w3 - 2.0 * d3 / (3.0 * I1 * c) * (d3 * wa * w1 - d1 * wb * w3)
    r2 = -delta * w1 * w3 - 2.0 / (3.0 * I1 * c) * (d1**2 * wc + d3**2 * wa - 3.0 * d1 * d3 * delta * w1 * w3) * w2
    r3 = -2.0 * d1 / (3.0 * I3 * c) * (d1 * wb * w3 - d3 * wa * w1)
    return np.array([r1, r2, r3])


def eq_4_2_to_4_4(w, delta, chi):
    """(4.2)-(4.4), dimensionless, solved for omega_dot; arrays broadcast."""
    w1, w2, w3 = w
    n1, n3 = np.sin(chi), np.cos(chi)
    W2 = w1 * w1 + w2 * w2 + w3 * w3
    wa = W2 + delta * (delta - 2.0) * w3**2
    wb = W2 + delta * (2.0 * w1**2 - w2**2)
    wc = W2 + delta * (delta + 1.0) * w3**2
    r1 = delta * w2 * w3 - n3**2 * wa * w1 + n1 * n3 * wb * w3
    r2 = -delta * w1 * w3 - (n1**2 * wc + n3**2 * wa - 3.0 * n1 * n3 * delta * w1 * w3) * w2
    r3 = (-(n1**2) * wb * w3 + n1 * n3 * wa * w1) / (1.0 - delta)
    return np.array([r1, r2, r3])


# The identities below hold at every state; each is checked at N random draws at once (the
# rate functions are written component-wise and take arrays), seeded by the test's name.
N = 200


def test_reduced_equals_3_3_to_3_5_with_c_cubed(rng):
    """(2.2)+(2.3) in CGS = (3.3)-(3.5) read with c^3, for random parameters.

    Omega is chosen so that tau0 |Omega| ~ 0.1-1: for real particles (1e-16) the
    radiation part would sit below the round-off of the free part and compare nothing.
    Measured: 3.3e-15 of the largest component (round-off: the two codes sum the same terms
    in other orders); bound 5e-14.
    """
    I1 = 10 ** rng.uniform(-27, -25, N)
    I3 = I1 * rng.uniform(0.05, 1.95, N)
    d = 10 ** rng.uniform(-11, -7, N)
    chi = rng.uniform(0.0, 0.5 * math.pi, N)
    tau0 = U.tau0_cgs(d, I1)
    w = rng.normal(size=(3, N)) * rng.uniform(0.1, 1.0, N) / tau0
    g = U.radiation_coupling(np.stack([d * np.sin(chi), 0.0 * d, d * np.cos(chi)], axis=-1)).T
    got = np.array(E.reduced_rate(*w, (I1, I1, I3), tuple(g)))
    want = eq_3_3_to_3_5(w, I1, I3, d, chi, c_power=3)
    assert np.max(np.abs(got - want) / np.abs(want).max(axis=0)) < 5e-14


def test_c_squared_as_printed_disagrees_with_2_2():
    """Read with c^2 as printed, (3.3)-(3.5) are not (2.2): the torque comes out c times too large."""
    I1, I3, d, chi = 2.16e-26, 1.2e-26, 5.7e-11, 0.9
    tau0 = U.tau0_cgs(d, I1)
    w = np.array([0.3, -0.5, 0.4]) / tau0          # tau0 |Omega| ~ 0.7: torque and free part comparable
    g = U.radiation_coupling((d * math.sin(chi), 0.0, d * math.cos(chi)))
    general = np.array(E.reduced_rate(*w, (I1, I1, I3), tuple(g)))
    free = eq_3_3_to_3_5(w, I1, I3, 0.0, chi)
    np.testing.assert_allclose(eq_3_3_to_3_5(w, I1, I3, d, chi, c_power=3), general, rtol=1e-10)
    printed_torque = eq_3_3_to_3_5(w, I1, I3, d, chi, c_power=2) - free
    np.testing.assert_allclose(printed_torque / (general - free), U.C_LIGHT, rtol=1e-8)


def test_reduced_equals_4_2_to_4_4(rng):
    """Dimensionless general reduced equation = (4.2)-(4.4) for random delta, chi, omega
    (measured 4.9e-15 of the largest component, round-off; bound 5e-14)."""
    delta = rng.uniform(-1.0, 0.95, N)
    chi = rng.uniform(0.0, 0.5 * math.pi, N)
    w = rng.normal(size=(3, N))
    got = np.array(E.reduced_rate(*w, (1.0, 1.0, 1.0 - delta), (np.sin(chi), 0.0, np.cos(chi))))
    want = eq_4_2_to_4_4(w, delta, chi)
    assert np.max(np.abs(got - want) / np.abs(want).max(axis=0)) < 5e-14


def test_truncated_equals_5_3_at_chi_0(rng):
    """(2.5) at chi = 0 = (5.3): omega_dot_perp = free - omega_perp^2 omega_perp, omega3_dot =
    -omega_perp^2 omega3 (measured 2.1e-15 of the largest component, round-off; bound 5e-14)."""
    delta = rng.uniform(-1.0, 0.95, N)
    w1, w2, w3 = rng.normal(size=(3, N))
    wp2 = w1 * w1 + w2 * w2
    want = np.array([delta * w2 * w3 - wp2 * w1, -delta * w1 * w3 - wp2 * w2, -wp2 * w3])
    got = np.array(E.truncated_rate(w1, w2, w3, (1.0, 1.0, 1.0 - delta), (0.0, 0.0, 1.0)))
    assert np.max(np.abs(got - want) / np.abs(want).max(axis=0)) < 5e-14


def test_truncated_solves_2_5_exactly_for_asymmetric_bodies(rng):
    """The Sherman-Morrison solution makes the residual of (2.5) vanish, any inertia and
    dipole (measured 2.7e-15 absolute, terms up to 7; bound 1e-14)."""
    J = np.sort(rng.uniform(0.3, 1.0, size=(N, 3)), axis=1)
    J[:, 2] = np.minimum(J[:, 2], J[:, 0] + J[:, 1])
    g = rng.normal(size=(N, 3)) * 0.4
    w = rng.normal(size=(N, 3)) * 0.5
    wd = np.array(E.truncated_rate(*w.T, tuple(J.T), tuple(g.T))).T
    v = np.cross(g, w)
    lhs = J * wd + np.cross(w, J * w)
    rhs = -(np.sum(v * v, axis=1, keepdims=True) * w + np.sum(g * np.cross(w, wd), axis=1, keepdims=True) * g)
    assert np.max(np.abs(lhs - rhs)) < 1e-14


@pytest.mark.parametrize("symmetric, general", [(E.symmetric_reduced_rate, E.reduced_rate),
                                                 (E.symmetric_truncated_rate, E.truncated_rate)], ids=["reduced", "truncated"])
def test_symmetric_top_rates_equal_the_general_ones(symmetric, general, rng):
    """The written-out symmetric-top rates the atlas integrates ((4.2)-(4.4), and spinviz's own
    truncated analogue) equal the general rates with J = (1, 1, 1 - delta), g = (sin chi, 0,
    cos chi), at random bodies and states (measured 2.2e-15 and 3.7e-15 of the largest
    component, round-off; bound 5e-14)."""
    delta = rng.uniform(-1.0, 0.95, N)
    chi = rng.uniform(0.0, 0.5 * math.pi, N)
    w = rng.normal(size=(3, N)) * rng.uniform(0.01, 1.0, N)
    got = np.array(symmetric(*w, delta, np.sin(chi), np.cos(chi)))
    want = np.array(general(*w, (1.0, 1.0, 1.0 - delta), (np.sin(chi), 0.0, np.cos(chi))))
    assert np.max(np.abs(got - want) / np.abs(want).max(axis=0)) < 5e-14


def test_2_3b_both_printed_forms_are_the_free_flow_derivative():
    """Both lines of (2.3b) equal d/dt of (2.3a) along the free flow (the reduction's input)."""
    J = (1.0, 0.7, 0.4)
    w = np.array([0.3, -0.5, 0.8])
    h = 1e-6
    a = lambda x: np.array(E.free_rate(*x, J, None))  # noqa: E731
    ddot_fd = (a(w + h * a(w)) - a(w - h * a(w))) / (2 * h)
    Jv = np.array(J)
    ad = a(w)
    ddot_23b = (np.cross(w, np.cross(w, Jv * w)) - np.cross(Jv * w, (np.cross(w, Jv * w)) / Jv)) / Jv
    ddot_first = -(np.cross(ad, Jv * w) + np.cross(w, Jv * ad)) / Jv
    np.testing.assert_allclose(ddot_23b, ddot_first, rtol=1e-12)
    np.testing.assert_allclose(ddot_first, ddot_fd, rtol=1e-7)


@pytest.mark.parametrize("model", ["reduced", "truncated", "free"])
def test_jacobian_matches_finite_differences(model):
    J, g = (1.0, 0.8, 0.45), (0.3, -0.2, 0.9)
    w = np.array([0.4, -0.7, 0.5])
    jac = M.jacobian(model, w, J, g)
    h = 1e-6
    fd = np.empty((3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd[:, k] = (M.omega_dot(model, w + e, J, g) - M.omega_dot(model, w - e, J, g)) / (2 * h)
    np.testing.assert_allclose(jac, fd, rtol=1e-7, atol=1e-9)


def test_free_rate_conserves_energy_and_body_momentum_magnitude(rng):
    """d/dt (1/2 W.JW) = 0 and d/dt |JW|^2 = 0 along (2.3a), exactly (not just numerically):
    measured 4.4e-16 (rates up to 4), round-off; bound 1e-14."""
    J = np.array([1.0, 0.6, 0.5])
    w = rng.normal(size=(N, 3))
    wd = np.array(E.free_rate(*w.T, tuple(J), None)).T
    assert np.max(np.abs(np.sum(J * w * wd, axis=1))) < 1e-14
    assert np.max(np.abs(np.sum(J * w * J * wd, axis=1))) < 1e-14


@pytest.mark.parametrize("model", ["reduced", "truncated"])
@pytest.mark.parametrize("J, chi", [((1.0, 1.0, 0.6), 0.0), ((1.0, 1.0, 1.6), 0.0), ((1.0, 1.0, 1.0), 0.9)],
                         ids=["prolate-longitudinal", "oblate-longitudinal", "sphere-askew"])
def test_radiation_torque_dissipates_energy_where_the_torque_is_axial(J, chi, model):
    """dE/dt = W . J W_dot < 0 at every state for a longitudinal dipole (chi = 0, the case of
    (5.2)/(5.4)) and for a spherical top, in both models: the braking of the title (2000
    random states).  For an askew symmetric top it is not so pointwise (next test, and
    test_integration's test_askew_energy_is_not_monotonic_but_falls)."""
    rng = np.random.default_rng(7)
    g = (math.sin(chi), 0.0, math.cos(chi))
    w = rng.normal(size=(2000, 3)) * rng.uniform(1e-3, 0.1, size=(2000, 1))
    assert np.max(np.sum(np.array(J) * w * M.omega_dot(model, w, J, g), axis=1)) < 0


@pytest.mark.parametrize("model, fraction", [("reduced", 0.011465), ("truncated", 0.00404)])
def test_askew_top_gains_energy_at_some_states(model, fraction):
    """The counterpart: for delta = 0.4, chi = 0.9, random states (isotropic, |omega| ~ 0.1)
    have dE/dt > 0 with probability 1.15 % (reduced) and 0.40 % (truncated), measured with
    2e6 draws (to +- 8e-5 and 5e-5); 2e4 draws here find it within 4 sampling deviations
    sqrt(p/2e4) (7.6e-4, 4.5e-4)."""
    rng = np.random.default_rng(7)
    J, g = (1.0, 1.0, 0.6), (math.sin(0.9), 0.0, math.cos(0.9))
    w = rng.normal(size=(20_000, 3)) * 0.1
    rising = np.mean(np.sum(np.array(J) * w * M.omega_dot(model, w, J, g), axis=1) > 0)
    assert abs(rising - fraction) < 4 * math.sqrt(fraction / 20_000), rising


def test_quat_rate_matches_quaternion_product(rng):
    from spinviz import rotations as R

    q = R.normalize(rng.normal(size=4))
    w = rng.normal(size=3)
    want = 0.5 * R.multiply(q, np.concatenate([[0.0], w]))
    np.testing.assert_allclose(E.quat_rate(*q, *w), want, atol=1e-15)


def test_euler_rate_6_4_matches_quaternion_kinematics():
    """(6.4) and q_dot = 1/2 q (x) (0, W) describe the same motion (away from theta = 0)."""
    from spinviz import rotations as R

    ang = np.array([0.4, 1.1, -0.7])
    w = np.array([0.3, -0.2, 0.5])
    rates = np.array(E.euler_zxz_rate(*ang, *w))
    h = 1e-6
    q_plus = R.quat_from_euler_zxz(ang + h * rates)
    q_minus = R.quat_from_euler_zxz(ang - h * rates)
    q_dot_fd = (q_plus - q_minus) / (2 * h)
    q = R.quat_from_euler_zxz(ang)
    np.testing.assert_allclose(q_dot_fd, E.quat_rate(*q, *w), atol=1e-9)


def test_unknown_model_is_refused():
    with pytest.raises(ValueError, match="unknown model 'schott'; valid: reduced, truncated, free"):
        M.rate_function("schott")
