"""Each closed form of the paper against the differential equation it solves.

These tests need no integrator: they differentiate the closed form (central
differences, step chosen so truncation and round-off are both ~1e-10 relative) and
compare with the model's right-hand side, or take the stated limit.
"""

import math

import numpy as np
import pytest

from spinviz.physics import closed_forms as CF
from spinviz.physics import equations as E
from spinviz.physics import models as M

TOL = 1e-8   # central differences with h ~ 1e-4 of the time scale: truncation ~ 1e-9


def ddt(f, t, h):
    """Central difference of f (t -> (N, k)) at times t."""
    return (f(t + h) - f(t - h)) / (2.0 * h)


def rate(model, omega, delta, chi):
    return M.omega_dot(model, omega, (1.0, 1.0, 1.0 - delta), (math.sin(chi), 0.0, math.cos(chi)))


@pytest.mark.parametrize("model", ["reduced", "truncated"])
@pytest.mark.parametrize("delta,chi", [(-0.6, math.radians(55)), (0.3, 0.7), (0.9, 1.2)])
def test_3_9_solves_both_models_for_askew_tops(model, delta, chi):
    """(3.9): Omega1 = Omega3 = 0, Omega2 = Omega20/F(t) solves (3.3)-(3.5) and (2.5)."""
    w20 = 0.3
    t = np.linspace(0.0, 40.0, 9)[1:]
    f = lambda s: CF.omega_eq3_9(s, 1.0, w20)  # noqa: E731
    np.testing.assert_allclose(ddt(f, t, 1e-4), rate(model, f(t), delta, chi), atol=TOL * w20**3)


@pytest.mark.parametrize("delta", [-1.0, -0.4, 0.0, 0.3, 0.985])
def test_5_2_solves_reduced_chi_0(delta):
    """(5.2) solves (5.1) (the reduced equation at chi = 0) for any delta, the sphere included."""
    w20, w30 = 0.2, 0.5
    t = np.linspace(0.0, 30.0, 7)[1:]
    f = lambda s: CF.omega_eq5_2(s, delta, w20, w30)  # noqa: E731
    np.testing.assert_allclose(ddt(f, t, 1e-4), rate("reduced", f(t), delta, 0.0), atol=TOL * 0.5**3)
    np.testing.assert_allclose(f(np.array([0.0]))[0], [0.0, w20, w30], atol=1e-15)


@pytest.mark.parametrize("delta", [-1.0, 0.0, 0.3, 0.985])
def test_5_4_solves_truncated_chi_0(delta):
    """(5.4) solves (5.3)."""
    w20, w30 = 0.2, 0.5
    t = np.linspace(0.0, 30.0, 7)[1:]
    f = lambda s: CF.omega_eq5_4(s, delta, w20, w30)  # noqa: E731
    np.testing.assert_allclose(ddt(f, t, 1e-4), rate("truncated", f(t), delta, 0.0), atol=TOL * 0.5**3)


def test_5_7_solves_the_linearized_system_5_6():
    """(5.7) solves (5.6), the linearization of (5.5) about omega_inf e1."""
    delta, wi, w20, w30 = 0.3, 0.5, 1e-3, 2e-3
    t = np.linspace(0.0, 10.0, 6)[1:]
    f = lambda s: CF.omega_eq5_7(s, delta, wi, w20, w30)  # noqa: E731
    w = f(t)
    lin = np.stack([np.zeros_like(t), -wi**2 * w[:, 1] - delta * wi * w[:, 2],
                    -(1 + 2 * delta) / (1 - delta) * wi**2 * w[:, 2]], axis=-1)
    np.testing.assert_allclose(ddt(f, t, 1e-4), lin, atol=1e-12)


def test_5_7_is_the_linearization_of_the_reduced_equation_at_chi_pi_2():
    """The residual of (5.5) along (5.7) is quadratic in the perturbation: halving it quarters the residual."""
    delta, wi = 0.3, 0.5
    t = np.linspace(0.5, 10.0, 8)
    res = []
    for a in (1e-2, 5e-3):
        f = lambda s, a=a: CF.omega_eq5_7(s, delta, wi, a, 2 * a)  # noqa: E731
        res.append(np.max(np.abs(ddt(f, t, 1e-4) - rate("reduced", f(t), delta, 0.5 * math.pi))))
    assert 3.6 < res[0] / res[1] < 4.4


@pytest.mark.parametrize("eq,form,limit", [("6.1", CF.omega_eq6_1, CF.omega_eq5_2), ("6.2", CF.omega_eq6_2, CF.omega_eq5_4)])
def test_6_1_and_6_2_are_the_eps_to_0_limits(eq, form, limit):
    """(6.1) and (6.2) in CGS are the eps -> 0 limits of (5.2) and (5.4) via (4.1): over a
    fixed span (3 T) the difference falls in proportion to eps.  (The limit is pointwise:
    the phase error eps Omega3 t grows with t, so no fixed eps serves all times.)"""
    tau0, W20, W30 = 2.5, 0.08, 0.4                     # tau0 != 1 exercises (4.1)
    T = 1.0 / (tau0 * W20**2)
    t = np.linspace(0.0, 3.0 * T, 31)
    diffs = []
    for eps in (1e-3, 1e-4):
        # (4.1): tau = t/tau0, omega = tau0 Omega; back to CGS by / tau0
        w = limit(t / tau0, 1.0 - eps, tau0 * W20, tau0 * W30) / tau0
        W = form(t, tau0, W20, W30)
        diffs.append(np.max(np.abs(w - W)) / W20)
    assert 8.0 < diffs[0] / diffs[1] < 12.0


@pytest.mark.parametrize("eq", ["6.5", "6.6"])
def test_6_5_and_6_6_solve_the_poisson_equations_6_4(eq):
    """(6.5) with (6.1), and (6.6) with (6.2), satisfy (6.4) exactly (theta = pi/2 throughout)."""
    tau0, W20, W30 = 1.0, 0.2, 1.0
    angles = CF.euler_eq6_5 if eq == "6.5" else CF.euler_eq6_6
    omega = CF.omega_eq6_1 if eq == "6.5" else CF.omega_eq6_2
    t = np.linspace(0.0, 60.0, 7)[1:]
    f = lambda s: angles(s, tau0, W20, W30)  # noqa: E731
    a, w = f(t), omega(t, tau0, W20, W30)
    want = np.stack(E.euler_zxz_rate(a[:, 0], a[:, 1], a[:, 2], w[:, 0], w[:, 1], w[:, 2]), axis=-1)
    np.testing.assert_allclose(ddt(f, t, 1e-4), want, atol=1e-9)


def test_6_7_is_5_2_at_delta_0_and_matches_the_printed_formula():
    """(6.7) = (5.2) at delta = 0 through (4.1), and its stable evaluation equals the paper's
    Omega20 |Omega3| (Omega0^2 exp(2 tau0 Omega3^2 t) - Omega20^2)^(-1/2)."""
    tau0, W20, W30 = 3.4e-27, 2.0e10, -3.0e10
    Th = 1.0 / (tau0 * W30**2)
    t = np.linspace(0.0, 5.0 * Th, 11)
    W = CF.omega_eq6_7(t, tau0, W20, W30)
    printed = W20 * abs(W30) / np.sqrt((W20**2 + W30**2) * np.exp(2 * tau0 * W30**2 * t) - W20**2)
    np.testing.assert_allclose(W[:, 1], printed, rtol=1e-12)
    w = CF.omega_eq5_2(t / tau0, 0.0, tau0 * W20, tau0 * W30) / tau0
    np.testing.assert_allclose(W, w, rtol=1e-12, atol=1e-12 * W20)


def test_6_9_solves_truncated_sphere():
    t = np.linspace(0.0, 40.0, 7)[1:]
    f = lambda s: CF.omega_eq6_9(s, 1.0, 0.2, 0.3)  # noqa: E731
    np.testing.assert_allclose(ddt(f, t, 1e-4), rate("truncated", f(t), 0.0, 0.0), atol=TOL * 0.3**3)


@pytest.mark.parametrize("W20,W30", [(0.2, 0.3), (0.2, -0.3), (-0.2, 0.3), (-0.2, -0.3)])
def test_6_10_solves_6_4_with_6_9(W20, W30):
    """(6.10) with (6.9) satisfies (6.4); for Omega20 Omega30 < 0 the same motion has psi = pi."""
    t = np.linspace(0.0, 40.0, 7)[1:]
    f = lambda s: CF.euler_eq6_10(s, 1.0, W20, W30)  # noqa: E731
    a, w = f(t), CF.omega_eq6_9(t, 1.0, W20, W30)
    want = np.stack(E.euler_zxz_rate(a[:, 0], a[:, 1], a[:, 2], w[:, 0], w[:, 1], w[:, 2]), axis=-1)
    np.testing.assert_allclose(ddt(f, t, 1e-4), want, atol=1e-10)


def test_vartheta_has_no_cancellation_at_physical_scales():
    """(6.3) at tau0 Omega20^2 t = 1e-20: vartheta = t to 1e-15, where (F - 1)/(...) as printed gives 0."""
    t = np.array([1.0])
    v = CF.vartheta_eq6_3(t, 1.4e-35, 1.0e7)
    np.testing.assert_allclose(v, t, rtol=1e-15)


@pytest.mark.parametrize("delta, chi, wp, w3", [(0.3, 0.7, 0.2, 0.5), (-0.6, math.radians(55), 0.3, -0.2), (0.0, 0.5, 0.1, 0.4)])
def test_4_12_is_the_phase_average_of_the_reduced_equation(delta, chi, wp, w3):
    """(4.12) = the average over the precession phase of (4.11), i.e. of the general reduced
    equation written in (omega_perp, omega3, phi): 64 phases average a trigonometric
    polynomial of low degree exactly, so to round-off (measured 5.6e-17; bound 1e-15)."""
    phi = np.linspace(0.0, 2 * np.pi, 64, endpoint=False)
    w = np.stack([wp * np.cos(phi), wp * np.sin(phi), np.full_like(phi, w3)], -1)
    wd = rate("reduced", w, delta, chi)
    avg = [((w[:, 0] * wd[:, 0] + w[:, 1] * wd[:, 1]) / wp).mean(), wd[:, 2].mean(),
           ((w[:, 0] * wd[:, 1] - w[:, 1] * wd[:, 0]) / wp**2).mean()]
    np.testing.assert_allclose(avg, CF.averaged_rate_eq4_12(wp, w3, delta, chi), atol=1e-15)


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["Omega3>0", "Omega3<0"])      # phi_dot -> |Omega3| whatever the sign
def test_6_8_decay_rate_is_the_late_law_of_6_7(sign):
    """(6.8) theta ~ exp(-tau0 Omega3^2 t) must be what the exact (6.7) does at t >> Theta:
    for the sphere L is along Omega, so tan theta = Omega2 / Omega3 from (6.7); its log-slope
    over [5 Theta, 10 Theta] is the rate asymptotics_eq6_8 states (measured 2.6e-7 relative,
    what the corrections ~ e^-10 leave in the fit; bound 2e-6), and |Omega| at 10 Theta is the
    |Omega3| it gives phi_dot (they differ by Omega2^2 / 2 Omega3^2 = 3.4e-10; bound 1e-8)."""
    tau0, w = 3.4e-27, math.pi * 1e10
    omega3 = sign * w
    theta_scale = 1.0 / (tau0 * omega3**2)
    t = np.linspace(5.0 * theta_scale, 10.0 * theta_scale, 40)
    omega = CF.omega_eq6_7(t, tau0, 0.7 * w, omega3)
    theta = np.arctan2(omega[:, 1], np.abs(omega[:, 2]))
    rate = -np.polyfit(t, np.log(theta), 1)[0]
    a = CF.asymptotics_eq6_8(tau0, omega3)
    assert rate == pytest.approx(a["theta_decay_rate"], rel=2e-6, abs=0)
    assert a["phi_rate"] == pytest.approx(np.linalg.norm(omega[-1]), rel=1e-8, abs=0)   # the spin left: |Omega3|
