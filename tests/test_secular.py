"""The averaged slow flow for real horizons, and the driver's choice of method."""

import math

import numpy as np
import pytest

from spinviz import rotations as R
from spinviz.driver import SimulationError, simulate
from spinviz.integrators import slowflow as SF
from spinviz.integrators.auto import choose_method
from spinviz.physics import bodies as B
from spinviz.physics import closed_forms as CF
from spinviz.physics import models as M
from spinviz.physics import presets as P

W = math.pi * 1e10                      # the spin of section 6, rad/s


NODES = SF.phase_nodes(SF.M_PHASES)


def averaged(delta, chi, wp, w3, scale=1.0):
    """(d w_perp, d w3, d p) of the compiled averaged flow: radiation part plus the free -delta w3."""
    J, g = (1.0, 1.0, 1.0 - delta), tuple(math.sqrt(scale) * np.array([math.sin(chi), 0.0, math.cos(chi)]))
    dwp, dw3, dp, _ = SF.avg_rates(M.get("reduced").kernel_id, J, g, wp, w3, *NODES, False)
    return dwp, dw3, dp - delta * w3


@pytest.mark.parametrize("wp, w3", [(0.2, 0.5), (0.05, -0.3)])
@pytest.mark.parametrize("delta, chi", [(0.3, 0.7), (-0.6, math.radians(55.0)), (0.5, 1.2)])
def test_slow_flow_is_4_12_for_the_reduced_model(delta, chi, wp, w3):
    """The M-point phase average of the model's own rate equals the printed (4.12)."""
    got = averaged(delta, chi, wp, w3)
    np.testing.assert_allclose(got, CF.averaged_rate_eq4_12(wp, w3, delta, chi), rtol=1e-12, atol=1e-16)


@pytest.mark.parametrize("model,form", [("reduced", CF.omega_eq6_7), ("truncated", CF.omega_eq6_9)])
def test_real_dast_cube_over_10_Theta_matches_6_7_6_9_and_6_8(model, form):
    """DAST cube with its real parameters (tau0 = 3.7e-27 s, Omega20 = Omega30 = pi 1e10 /s),
    10 Theta ~ 1.4e16 turns: |Omega_perp|, Omega3 and theta (d from the rotation axis) match
    (6.7)/(6.9) and (6.8)/(6.10) to 1e-6 relative (tolerance set by rtol = 1e-10 on a
    quantity that falls by e^-10)."""
    cube = P.dast_cube()
    Th = 1.0 / (cube.tau0 * W**2)
    tr = simulate(cube, model, (0.0, W, W), t_end=10.0 * Th, samples=201, euler_zxz0=(0.0, 0.5 * math.pi, 0.0))
    assert tr.stats["method"] == "secular"
    assert tr.stats["turns"] > 1e15 and not tr.phase_resolved
    exact = form(tr.t, cube.tau0, W, W)
    wp, wpe = np.hypot(tr.omega[:, 0], tr.omega[:, 1]), np.hypot(exact[:, 0], exact[:, 1])
    np.testing.assert_allclose(wp, wpe, rtol=1e-6)
    np.testing.assert_allclose(tr.omega[:, 2], exact[:, 2], rtol=1e-6)
    # theta: angle between d (= e3) and the fixed rotation axis L_world
    L = np.array(tr.stats["L_axis_world"])
    theta = R.angle_between(tr.dipole_world(), L)
    np.testing.assert_allclose(theta, np.arctan2(wpe, exact[:, 2]), rtol=1e-6, atol=1e-12)
    if model == "reduced":                                  # (6.8): theta ~ exp(-tau0 Omega3^2 t)
        late = tr.t > 3.0 * Th
        rate = -np.polyfit(tr.t[late], np.log(theta[late]), 1)[0]
        assert rate == pytest.approx(cube.tau0 * W**2, rel=1e-4)
    else:                                                   # (6.10): theta stays arctan|Omega20/Omega30|
        np.testing.assert_allclose(theta, math.pi / 4, rtol=1e-9)


def test_secular_is_exact_for_free_symmetric_motion():
    """No torque: the secular reconstruction is the exact free symmetric top."""
    body = B.symmetric_top(0.4, 0.3)
    kw = dict(t_end=200.0, samples=50, q0=R.quat_from_euler_zxz((0.3, 1.1, -0.2)), rtol=1e-12, atol=1e-14)
    a = simulate(body, "free", (0.2, -0.1, 0.5), method="secular", **kw)
    b = simulate(body, "free", (0.2, -0.1, 0.5), method="taylor", **kw)
    np.testing.assert_allclose(a.omega, b.omega, atol=1e-11)
    assert R.misorientation(a.q, b.q).max() < 1e-10


def test_secular_is_exact_for_6_10():
    """(6.10): the torque is along L, so L stays fixed exactly and secular is exact
    (tau0 |Omega0| = 7e-4, ~1000 turns)."""
    w = 5e-4
    tr = simulate(B.symmetric_top(0.0, 0.0), "truncated", (0.0, w, w), t_end=3.0 / w**2, samples=51,
                  euler_zxz0=(0.0, math.pi / 4, 0.0), method="secular", rtol=1e-12, atol=1e-14)
    exact = R.quat_from_euler_zxz(CF.euler_eq6_10(tr.t, 1.0, w, w))
    assert R.misorientation(tr.q, exact).max() < 1e-8
    assert tr.phase_resolved and tr.stats["resonances"] == []


def test_secular_slow_variables_are_second_order_in_tau0_omega_for_an_askew_top():
    """Askew top (delta = -0.6, chi = 55 deg) over 2 T against a resolved run: with the
    near-identity transform the slow variables are off by O(eps^2) (first-order averaging
    without it is O(eps)); measured here ~2-5 eps^2, bound 20 eps^2, and the order in eps ~2."""
    body = B.symmetric_top(-0.6, math.radians(55.0))
    errs = []
    for eps_rad in (3e-4, 1e-4):
        w0 = np.array([0.0, 0.6, 0.8]) * eps_rad
        t_end = 2.0 / (0.6 * eps_rad) ** 2
        a = simulate(body, "reduced", w0, t_end=t_end, samples=41, method="secular")
        b = simulate(body, "reduced", w0, t_end=t_end, samples=41, method="taylor", rtol=1e-12, atol=1e-14)
        err = max(np.max(np.abs(np.hypot(a.omega[:, 0], a.omega[:, 1]) - np.hypot(b.omega[:, 0], b.omega[:, 1]))),
                  np.max(np.abs(a.omega[:, 2] - b.omega[:, 2]))) / eps_rad
        assert err < 20 * eps_rad**2, (eps_rad, err)
        errs.append(err)
    assert math.log(errs[0] / errs[1]) / math.log(3.0) == pytest.approx(2.0, abs=0.5)


def test_secular_follows_3_9_where_nothing_precesses():
    """Rotation about e2 of an askew top (3.9): no precession at all, so the hybrid integrates
    the body-frame equation in full -- at the braking time scale -- and follows (3.9) exactly."""
    w = 1e-4
    tr = simulate(B.symmetric_top(-0.6, 1.0), "reduced", (0.0, w, 0.0), t_end=3.0 / w**2, samples=21, method="secular")
    np.testing.assert_allclose(tr.omega, CF.omega_eq3_9(tr.t, 1.0, w), rtol=1e-9, atol=1e-12 * w)
    assert tr.stats["nsteps_averaged"] == 0 and tr.stats["nsteps"] < 1000


def test_secular_refuses_a_strongly_braked_spin():
    """tau0 |Omega0| = 0.1: the radiation changes the spin within a few turns, nothing is fast."""
    with pytest.raises(SimulationError, match=r"tau0 \|Omega0\| = 0.1 > 0.001"):
        simulate(B.symmetric_top(-0.6, 1.0), "reduced", (0.0, 0.1, 0.0), t_end=10.0, samples=3, method="secular")


def test_secular_needs_a_symmetric_top():
    body = B.custom((1.0, 0.8, 0.5), (0.0, 0.0, 1.0), units="dimensionless")
    with pytest.raises(ValueError, match="symmetric top"):
        simulate(body, "reduced", (0.0, 0.1, 0.1), t_end=10.0, samples=3, method="secular")


def test_auto_picks_secular_radau_or_taylor_and_says_why():
    cube = P.dast_cube()
    m, why = choose_method(cube, "reduced", (0.0, W, W), 10.0 / (cube.tau0 * W**2))
    assert m == "secular" and "turns of a symmetric top" in why and "beyond float64" in why
    thin = B.custom((1.0, 1.0, 1e-6), (math.sin(0.5), 0.0, math.cos(0.5)), units="dimensionless")
    m, why = choose_method(thin, "reduced", (0.0, 3.0, 3.0), 2.0)            # decay/spin 1.6e6
    assert m == "radau" and "stiff" in why
    m, why = choose_method(thin, "reduced", (0.0, 0.1, 0.1), 100.0)          # 5e4: taylor still faster
    assert m == "taylor" and "non-stiff" not in why
    m, why = choose_method(B.symmetric_top(0.3, 0.7), "reduced", (0.0, 0.05, 0.3), 1200.0)
    assert m == "taylor" and "non-stiff" in why
    m, why = choose_method(B.symmetric_top(0.3, 0.7), "reduced", (0.0, 0.05, 0.3), 1200.0, rtol=1e-17)
    assert m == "taylor-long" and "long double" in why


@pytest.mark.slow
def test_driver_switches_to_radau_when_the_explicit_method_detects_stiffness(monkeypatch):
    """If the up-front estimate misses stiffness, taylor's stiffness watch (steps below 1e-5 rad
    of spin over 4 x 512 steps) fires and the driver reruns with radau, saying so.  The body:
    I3/I1 = 1e-6, d at 30 deg, |omega| = 4.2: decay/spin 1.6e6, where radau is 2x faster."""
    import spinviz.driver as DR

    monkeypatch.setattr(DR, "choose_method", lambda *a, **k: ("taylor", "forced for the test"))
    thin = B.custom((1.0, 1.0, 1e-6), (0.5, 0.0, math.sqrt(0.75)), units="dimensionless")
    tr = simulate(thin, "reduced", (0.0, 3.0, 3.0), t_end=2.0, samples=11)
    assert tr.stats["method"] == "radau"
    assert tr.stats["method_reason"].startswith("taylor gave up (stiffness detected at t = ")
    ref = simulate(thin, "reduced", (0.0, 3.0, 3.0), t_end=2.0, samples=11, method="radau")
    np.testing.assert_allclose(tr.omega, ref.omega)


def test_slow_flow_keeps_a_1e_16_torque_above_round_off():
    """At real scale (tau0 Omega ~ 1e-16) the averaged radiation rates are still (4.12),
    to 1e-10 relative: they are computed without the O(1) free part, whose round-off would
    otherwise be as large as the torque (this once hung the askew DAST scene)."""
    eps = 1e-16
    delta, chi = -0.6, math.radians(55.0)
    dwp, dw3, dp = averaged(delta, chi, 0.5, 0.8, scale=eps)
    want = CF.averaged_rate_eq4_12(0.5, 0.8, delta, chi)
    np.testing.assert_allclose([dwp, dw3], eps * np.array(want[:2]), rtol=1e-10)
    assert dp == pytest.approx(-delta * 0.8, rel=1e-12)


@pytest.mark.parametrize("model", ["reduced", "truncated", "free"])
def test_radiation_part_plus_free_rate_is_the_rate(model):
    """At 200 random states (the rate functions take arrays): round-off, measured at most
    3.6e-15 absolute."""
    from spinviz.physics import equations as E
    from spinviz.physics import models as M

    w = np.random.default_rng(3).normal(size=(3, 200))
    J, g = (1.0, 0.8, 0.5), (0.3, -0.2, 0.7)
    total = np.array(M.rate_function(model)(*w, J, g))
    parts = np.array(M.radiation_function(model)(*w, J, g)) + np.array(E.free_rate(*w, J, g))
    np.testing.assert_allclose(parts, total, rtol=1e-13, atol=1e-14)
