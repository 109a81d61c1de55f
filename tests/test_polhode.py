"""The torque-free asymmetric top (``physics.polhode``, ``physics.elliptic``) and the torque averaged
over its polhode (``integrators.polhode_flow``): closed forms, the symmetric limit (4.12), the
forced response (4.9), the separatrix odds."""

import math

import numpy as np
import pytest
import scipy.special as S
from scipy.integrate import solve_ivp

from spinviz import rotations as R
from spinviz.integrators import polhode_flow as PFL
from spinviz.physics import averaged as AV
from spinviz.physics import elliptic as EL
from spinviz.physics import models as M
from spinviz.physics import polhode as PH
from spinviz.physics.equations import free_rate, quat_rate
from spinviz.physics.models import System

BOX = (1.0, 1.36, 1.64)                        # the DAST 100 x 80 x 60 nm box, J / I1
D_BOX = (math.cos(math.radians(35.0)), 0.0, math.sin(math.radians(35.0)))


def test_elliptic_functions_match_scipy(rng):
    m = np.concatenate([[0.0, 1e-12, 0.5, 1.0 - 1e-9], rng.random(40)])
    u = rng.uniform(-8.0, 8.0, m.size)
    for mine, ref in zip(EL.ellipj(u, m), S.ellipj(u, m)):
        np.testing.assert_allclose(mine, ref, rtol=0, atol=3e-13)
    np.testing.assert_allclose(EL.ellipk(m), S.ellipk(m), rtol=3e-16)
    m1 = np.array([1e-3, 1e-9, 1e-15])
    np.testing.assert_allclose(EL.ellipk(1.0 - m1, m1), S.ellipkm1(m1), rtol=3e-16)
    phi = rng.uniform(-7.0, 7.0, m.size)
    np.testing.assert_allclose(EL.ellipkinc(phi, m), S.ellipkinc(phi, m), rtol=1e-14)
    # one parameter for many arguments (a polhode's nodes), where sn = 1 exactly: dn = sqrt(1 - m)
    K = float(S.ellipk(0.3))
    sn, cn, dn, _ = EL.ellipj(K * np.arange(5), 0.3)
    np.testing.assert_allclose(dn, S.ellipj(K * np.arange(5), 0.3)[2], atol=1e-15)


@pytest.mark.parametrize("J, w0", [(BOX, (0.3, 0.2, 0.9)), (BOX, (0.9, 0.2, 0.3)), ((1.3, 1.0, 0.7), (0.2, -0.9, 0.4)),
                                   ((1.0, 1.0, 0.6), (0.5, 0.3, 0.7))], ids=["about-c", "about-a", "mixed", "symmetric"])
def test_free_motion_is_the_elliptic_solution_and_its_pose(J, w0):
    """Landau & Lifshitz section 37: omega from the polhode's elliptic functions at u0 + omega_p t,
    and q from the ZXZ angles about L with Sigma integrated, against a direct integration of the
    free Euler equation and q_dot = q (x) (0, Omega) / 2 over ~10 periods."""
    w0 = np.array(w0)
    q0 = R.normalize(np.array([0.9, 0.1, -0.3, 0.2]))
    T = 60.0
    ts = np.linspace(0.0, T, 61)
    sol = solve_ivp(lambda t, y: np.r_[free_rate(*y[:3], J, None), quat_rate(*y[3:], *y[:3])], (0.0, T),
                    np.r_[w0, q0], method="DOP853", rtol=1e-12, atol=1e-14, t_eval=ts)
    pol = PH.polhode_of(J, w0)
    u0, wp = pol.phase(w0), pol.frequency
    np.testing.assert_allclose(pol.omega(u0 + wp * ts), sol.y[:3].T, atol=1e-11)
    q_L = R.quat_between((0.0, 0.0, 1.0), R.world_from_body(q0, np.asarray(J) * w0))
    om_p, nu, c = PH.angle_variables(pol, 128)
    sig_bar = PH.sigma_of(pol, q_L, q0) - PH.sigma_periodic(c, om_p, u0)
    u = u0 + wp * ts
    _, q = pol.pose(q_L, sig_bar + nu * ts + PH.sigma_periodic(c, om_p, u), u)
    assert np.max(R.misorientation(q, sol.y[3:].T)) < 1e-9


def test_polhode_invariants_and_separatrix():
    """X, p from the state keep their digits onto the axis; the separatrix distance is 0 on the
    polhode through the middle axis and 1 on the axis; the period diverges like ln(1/(1 - m))."""
    w = np.array([1e-9, 2e-9, 1.0])
    pol = PH.polhode_of(BOX, w)
    J = np.asarray(BOX)
    assert pol.c == 2 and pol.p == pytest.approx(np.sum(J * (J[2] - J) * w * w), rel=1e-15)
    assert pol.separatrix_distance == pytest.approx(1.0, abs=1e-15)
    sep = []
    for h in (1e-3, 1e-6, 1e-9):
        D = J[1] * (1.0 + h)                     # |L|^2 / 2E just above the middle moment: about c
        r = (J[2] ** 2 - D * J[2]) / (D * J[1] - J[1] ** 2)
        w = np.array([0.0, math.sqrt(r), 1.0])
        pol = PH.polhode_of(BOX, w / np.linalg.norm(J * w))      # |L| = 1
        sep.append((pol.separatrix_distance, 2.0 * math.pi / pol.frequency))
    assert all(0.0 < d < 1e-2 for d, _ in sep)
    # each factor 1000 nearer adds ln(1000) x the same amount to the period
    assert (sep[2][1] - sep[1][1]) == pytest.approx(sep[1][1] - sep[0][1], rel=1e-3)
    with pytest.raises(PH.NoPolhode, match="sphere"):
        PH.extreme_axes((2.0, 2.0, 2.0))


@pytest.mark.parametrize("model", ["reduced", "truncated"])
@pytest.mark.parametrize("delta, chi", [(0.3, 0.7), (-0.4, 0.5), (0.8, 1.2)])
def test_averaged_rates_of_a_symmetric_top_are_4_12(model, delta, chi):
    """On a symmetric top the polhode is the precession circle: d ln X/dt and d ln p/dt
    (p = |delta| omega_perp^2) averaged over it are (4.12) (the reduced model, a cubic: to
    round-off; spinviz's derived truncated flow for the other, its cubic part: to O(tau0 |Omega|),
    the Sherman-Morrison denominator's share)."""
    eps = 1e-4
    g = math.sqrt(eps) * np.array([math.sin(chi), 0.0, math.cos(chi)])
    flow = PFL.Flow(System(model, (1.0, 1.0, 1.0 - delta), tuple(g)), 2, 1.0)
    P_, Q, R_, S_ = M.get(model).averaged.coefficients(delta, chi)
    for wp, w3 in ((0.6, 0.8), (0.2, 0.98), (0.9, 0.3)):
        av = flow.averages(flow.x_of(np.array([wp, 0.0, w3])), phases=False)
        dlnwp, dlnw3 = -eps * (P_ * wp**2 + Q * w3**2), -eps * (R_ * wp**2 + S_ * w3**2)
        J3 = 1.0 - delta
        X = wp**2 + J3**2 * w3**2
        np.testing.assert_allclose(av.rates, [(2 * wp**2 * dlnwp + 2 * J3**2 * w3**2 * dlnw3) / X, 2 * dlnwp],
                                   rtol=1e-12 if model == "reduced" else 5.0 * eps)
        assert av.omega_p == pytest.approx(abs(delta * w3), rel=1e-13)


def test_rates_keep_their_digits_however_far_the_spin_has_braked():
    """The rates at |L| = 1e-100 are 1e-200 x those at |L| = 1 -- the torque is cubic in Omega, the
    rates of ln X and ln p go as |Omega|^2 (a(lam w; g) = lam^2 a(w; sqrt(lam) g) for both models)
    -- and near the axis the transverse damping is not round-off: p / X = 1e-30."""
    for model in ("reduced", "truncated"):
        flow = PFL.Flow(System(model, BOX, tuple(1e-8 * np.asarray(D_BOX))), 2, 1.0)
        x = np.array([0.0, math.log(0.05)])
        base = flow.averages(x, phases=False).rates
        far = flow.averages(x + math.log(1e-200), phases=False).rates
        np.testing.assert_allclose(far, 1e-200 * base, rtol=1e-9)
        near = [flow.averages(np.array([0.0, math.log(r)]), phases=False).rates[1] for r in (1e-20, 1e-25, 1e-30)]
        # d ln p / dt tends to the axis' own rate: smooth, not noise
        assert abs(near[2] - near[1]) < 1e-3 * abs(near[1]) and abs(near[1] - near[0]) < 1e-3 * abs(near[0])


@pytest.mark.parametrize("delta, chi", [(-0.4, 0.5), (0.3, 0.7)])
def test_forced_offset_is_4_9(delta, chi):
    """The forced tilt of the axis under the reduced model's transverse forcing, to second order,
    is ``physics.averaged``'s z_f: omega2 = -n1 n3 w3^2 / delta (B / tau of (4.9) on type 1) and
    omega1 its second order (A tau^-3/2) -- both to the next order, mu^2 = (w3 / delta)^2
    (measured: 1.3 mu^2 at most, falling as w3^2 over 1.5 decades)."""
    g = np.array([math.sin(chi), 0.0, math.cos(chi)])
    flow = PFL.Flow(System("reduced", (1.0, 1.0, 1.0 - delta), tuple(g)), 2, 1.0)
    for w3 in (1e-2, 1e-3, 1e-4):
        xf = flow.forced_offset(w3)
        zf = complex(AV.flow("reduced", delta, chi).forced_response(w3, order=2))
        assert xf[2] == 0.0
        mu2 = (w3 / delta) ** 2
        assert xf[1] == pytest.approx(zf.imag, rel=3.0 * mu2)
        assert xf[0] == pytest.approx(zf.real, rel=3.0 * mu2)


def test_separatrix_odds_are_probabilities_that_follow_the_flux():
    """Leaving the lobe about c through the separatrix: two lobes about the other extreme axis,
    probabilities that sum to 1, proportional to the flux through the branch each shares with
    the lobe; a dipole in the a-c plane (the DAST box) makes the two branches' fluxes differ."""
    s = System("reduced", BOX, tuple(1e-3 * np.asarray(D_BOX)))
    w = np.array([0.2, 0.9, 0.3])
    odds = PFL.separatrix_odds(s, w, (0, 1.0))
    (o1, s1, p1), (o2, s2, p2) = odds["to"]
    assert o1 == o2 == 2 and {s1, s2} == {1.0, -1.0}
    assert p1 + p2 == pytest.approx(1.0) and 0.0 <= p1 <= 1.0
    f = odds["flux"]
    if min(f) > 0.0:
        assert p1 / p2 == pytest.approx(f[0] / f[1])
    assert abs(p1 - p2) > 0.1
