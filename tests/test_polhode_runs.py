"""``polhode`` against full Taylor integration, the symmetric limit (``secular``, (5.2), (5.4),
(6.7)-(6.10)), a separatrix crossing, real DAST boxes, and ``auto``'s choice for asymmetric bodies."""

import math

import numpy as np
import pytest

from spinviz import rotations as R
from spinviz.driver import simulate
from spinviz.errors import SpecError
from spinviz.integrators import auto as A
from spinviz.integrators.base import Problem
from spinviz.integrators.polhode import solve_polhode
from spinviz.integrators.secular import solve_secular
from spinviz.integrators.taylor import solve_taylor
from spinviz.physics import bodies as B
from spinviz.physics import closed_forms as CF
from spinviz.physics import presets as P
from spinviz.physics.models import System

BOX = (1.0, 1.36, 1.64)                                   # DAST 100 x 80 x 60 nm, J / I1
D_BOX = np.array([math.cos(math.radians(35.0)), 0.0, math.sin(math.radians(35.0))])
D_SKEW = np.array([0.42, -0.55, 0.72]) / np.linalg.norm([0.42, -0.55, 0.72])   # in no principal plane
Q0 = R.normalize(np.array([0.9, 0.2, -0.3, 0.1]))


def problem(J, d, model, eps, w, n_T, samples=21):
    s = System(model, tuple(J), tuple(math.sqrt(eps) * np.asarray(d)))
    w = np.asarray(w, dtype=float)
    return Problem(s, w / np.linalg.norm(w), np.linspace(0.0, n_T / eps, samples), q0=Q0)


def errors(a, b, J):
    """(|L| and 2E: largest relative error; L_world's direction: largest angle, rad; orientation:
    largest misorientation, rad) of run a against run b."""
    J = np.asarray(J)
    La, Lb = (np.sqrt(np.sum((J * x.omega) ** 2, axis=-1)) for x in (a, b))
    Ea, Eb = (np.sum(J * x.omega**2, axis=-1) for x in (a, b))
    slow = float(max(np.max(np.abs(La / Lb - 1.0)), np.max(np.abs(Ea / Eb - 1.0))))
    Lw = [R.world_from_body(x.q, J * x.omega) for x in (a, b)]
    return slow, float(np.max(R.angle_between(*Lw))), float(np.max(R.misorientation(a.q, b.q)))


@pytest.mark.slow
@pytest.mark.parametrize("model", ["reduced", "truncated"])
@pytest.mark.parametrize("J, d, w", [(BOX, D_BOX, (0.3, 0.5, 0.81)), ((1.0, 0.57, 1.24), D_SKEW, (0.3, 0.4, 0.87))],
                         ids=["dast-box", "skew-dipole"])
def test_errors_within_the_statements_and_falling_as_eps_squared(model, J, d, w):
    """tau0 |Omega0| = 1e-3, 1e-4, 1e-5 over one braking time (up to 1.6e4 turns), far from the
    separatrix, against Taylor at rtol = atol = 1e-13: |L|, 2E, L's direction and the orientation
    within the stated errors; |L| and 2E falling as eps^2 (second-order averaging with the
    first-order transform: fitted exponent >= 1.7, measured 1.8-2.1; the L direction falls as eps
    where no resonance is crossed, as sqrt(eps) through one, both within its statement).  Through
    a separatrix the error is set by the hand-over instead (the crossing test below)."""
    slow = []
    for eps in (1e-3, 1e-4, 1e-5):
        pr = problem(J, d, model, eps, w, 1.0)
        a, b = solve_polhode(pr), solve_taylor(pr, 1e-13, 1e-13)
        assert a.success, a.message
        e_slow, e_L, e_q = errors(a, b, J)
        st = a.stats
        assert e_slow <= st["slow_error_estimate"] + 1e-11
        assert e_L <= st["L_direction_uncertainty_rad"] + 1e-11
        assert e_q <= st["phase_error_rad"]
        slow.append(e_slow)
    assert np.polyfit(np.log([1e-3, 1e-4, 1e-5]), np.log(slow), 1)[0] >= 1.7


@pytest.mark.slow
def test_a_separatrix_crossing_passed_in_full_against_taylor():
    """The DAST box, reduced model, started about the long axis a just inside the separatrix
    (|L|^2/2E = 1.35 against the middle moment 1.36), eps = 1e-4: the averaged flow hands the run to
    Taylor's method near the separatrix, the crossing is recorded with its two lobes about c and
    their probabilities, and the run ends in Taylor's lobe with |L|, 2E and L within the statements."""
    D = 1.35
    r = (1.0 - D) / (D * 1.36 - 1.36**2)
    pr = problem(BOX, D_BOX, "reduced", 1e-4, (1.0, math.sqrt(r), 0.05), 6.0)
    a, b = solve_polhode(pr), solve_taylor(pr, 1e-13, 1e-13)
    st = a.stats
    assert [s[1] for s in st["segments"]] == ["averaged", "full", "averaged"]
    (x,) = st["separatrix_crossings"]
    assert x["from"] == [0, 1.0] and x["to"][0] == 2
    odds = {s: p for _, s, p in x["odds"]["to"]}
    assert sum(odds.values()) == pytest.approx(1.0)
    assert np.sign(b.omega[-1, 2]) == x["to"][1]                # the lobe Taylor's run is in
    e_slow, e_L, _ = errors(a, b, BOX)
    assert e_slow <= st["slow_error_estimate"] and e_L <= st["L_direction_uncertainty_rad"]
    assert 0.0 < st["full_turns"] < 1e4


@pytest.mark.slow
@pytest.mark.parametrize("model", ["reduced", "truncated"])
def test_symmetric_limit_is_secular(model):
    """A symmetric top (delta 0.3, chi 0.7), eps = 1e-4 over 3 braking times: the polhode is the
    precession circle and the method is secular's averaged flow -- omega_perp, omega3 within both
    methods' stated slow errors of each other and of Taylor, L's direction alike; a body asymmetric
    by 1e-6 gives the same slow variables (continuity through k -> 0)."""
    chi, delta = 0.7, 0.3
    d = (math.sin(chi), 0.0, math.cos(chi))
    pr = problem((1.0, 1.0, 1.0 - delta), d, model, 1e-4, (0.5, 0.2, 0.8), 3.0)
    pol, sec, ref = solve_polhode(pr), solve_secular(pr), solve_taylor(pr, 1e-13, 1e-13)

    def slow(x):
        return np.stack([np.hypot(x.omega[:, 0], x.omega[:, 1]), x.omega[:, 2]], axis=-1)

    bound = pol.stats["slow_error_estimate"] + sec.stats["slow_error_estimate"]
    assert np.max(np.abs(slow(pol) - slow(sec))) <= bound
    assert np.max(np.abs(slow(pol) - slow(ref))) <= pol.stats["slow_error_estimate"]
    near = problem((1.0, 1.0 + 1e-6, 1.0 - delta), d, model, 1e-4, (0.5, 0.2, 0.8), 3.0)
    assert np.max(np.abs(slow(solve_polhode(near)) - slow(pol))) < 1e-5


@pytest.mark.slow
@pytest.mark.parametrize("model, form", [("reduced", CF.omega_eq5_2), ("truncated", CF.omega_eq5_4)])
def test_dipole_on_the_axis_is_5_2_and_5_4(model, form):
    """chi = 0 (delta = 0.4): the reduced omega3 stays and omega_perp falls by Phi (5.2), the
    truncated both fall by F (5.4); eps = 1e-3 over three decades of |omega_perp|'s fall."""
    delta, w20, w30 = 0.4, 0.6, 0.8
    s = System(model, (1.0, 1.0, 1.0 - delta), (0.0, 0.0, math.sqrt(1e-3)))
    t = np.concatenate([[0.0], np.geomspace(10.0, 3e4, 12)])
    sol = solve_polhode(Problem(s, np.array([0.0, w20, w30]), t, q0=Q0))
    exact = form(t / 1e-3, delta, w20 * 1e-3, w30 * 1e-3) / 1e-3      # spin units: tau = t / eps, omega = eps w
    np.testing.assert_allclose(np.hypot(sol.omega[:, 0], sol.omega[:, 1]), np.hypot(exact[:, 0], exact[:, 1]),
                               rtol=1e-7)
    np.testing.assert_allclose(sol.omega[:, 2], exact[:, 2], rtol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("model, form", [("reduced", CF.omega_eq6_7), ("truncated", CF.omega_eq6_9)])
def test_a_sphere_is_secular_and_6_7_6_9(model, form):
    """The DAST cube has no polhode (every axis is fixed): ``polhode`` hands it to secular (e3 along
    d) and says so; (6.7) and (6.9) over 10 Theta (~1.4e16 turns) to 1e-6."""
    cube = P.dast_cube()
    W = math.pi * 1e10
    Th = 1.0 / (cube.tau0 * W**2)
    tr = simulate(cube, model, (0.0, W, W), t_end=10.0 * Th, samples=51, method="polhode")
    assert "sphere" in tr.stats["polhode_note"]
    exact = form(tr.t, cube.tau0, W, W)
    np.testing.assert_allclose(np.hypot(tr.omega[:, 0], tr.omega[:, 1]), np.hypot(exact[:, 0], exact[:, 1]), rtol=1e-6)
    np.testing.assert_allclose(tr.omega[:, 2], exact[:, 2], rtol=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("model", ["reduced", "truncated"])
def test_real_dast_box_over_6_Theta_in_seconds(model):
    """The 100 x 80 x 60 nm box spun as the cube is, 6 Theta (7.3 days, ~4e15 turns): auto picks
    polhode, the run ends about the largest axis e3 with |L| and 2E only falling, the stated
    errors tiny (eps = 1.6e-16) and the phase beyond float64."""
    box = P.dast_box(100.0, 80.0, 60.0)
    W = math.pi * 1e10
    w0 = (0.0, W, W)
    Th = box.residual_time_Theta(W)
    tr = simulate(box, model, w0, t_end=6.0 * Th, samples=101, euler_zxz0=(0.0, 0.5, 0.0))
    st = tr.stats
    assert st["method"] == "polhode" and not tr.phase_resolved
    assert st["end_axis"] == [2, 1.0] and st["slow_error_estimate"] < 1e-8
    J = np.asarray(box.inertia)
    L = np.sqrt(np.sum((J * tr.omega) ** 2, axis=-1))
    assert np.all(np.diff(L) < 0.0)


def test_auto_picks_polhode_for_a_long_run_of_an_asymmetric_body():
    """An asymmetric body past 1e6 turns at tau0 |Omega0| <= 1e-3: polhode, and why."""
    body = B.custom(BOX, tuple(D_BOX), units="dimensionless")
    w0 = np.array([0.0, 3e-5, 4e-5])                    # tau0 |Omega0| = 5e-5
    method, why = A.choose_method(body, "reduced", w0, 1e15)
    assert method == "polhode" and "averaged over the Euler-Poinsot polhode" in why


def test_auto_hands_an_asymmetric_body_over_when_it_starts_too_fast():
    """tau0 |Omega0| = 1e-2 (not fast enough to average at the start), 1e8 turns: the hand-over
    taylor -> polhode, the full stage's turns predicted and affordable."""
    body = B.custom((1.0, 0.8, 0.5), (0.6, 0.0, 0.8), units="dimensionless")
    method, why = A.choose_method(body, "reduced", np.array([0.0, 0.006, 0.008]), 1.3e17)
    assert method == "taylor -> polhode"
    assert "then polhode to t_end" in why


def test_refusals_name_what_neither_method_can_do():
    """A horizon float64 cannot hold in spin units is refused at once, in one line, naming t_end;
    where braking never makes the spin fast (chi = 0-like: d along the axis the body spins about,
    reduced model), the refusal says why the hand-over cannot come."""
    box = P.dast_box(100.0, 80.0, 60.0)
    W = math.pi * 1e10
    with pytest.raises(SpecError) as e:
        simulate(box, "reduced", (0.0, W, W), t_end=1e300, samples=11)
    assert e.value.key == "t_end" and "beyond float64" in e.value.reason and "\n" not in e.value.reason
    body = B.custom((1.0, 0.8, 0.5), (0.0, 0.0, 1.0), units="dimensionless")
    with pytest.raises(SpecError) as e:
        simulate(body, "reduced", (0.0, 0.0, 5e-3), t_end=1e12, samples=11)
    assert e.value.key == "t_end" and "nor does braking bring it to 0.001 by t_end" in e.value.reason


@pytest.mark.slow
def test_handover_to_polhode_agrees_with_a_full_taylor_run(monkeypatch):
    """An asymmetric body started too fast to average (tau0 |Omega0| = 1e-2), made auto's pick below
    1e6 turns for the test: Taylor's method in full until tau0 |Omega| = 1e-3, then polhode; |L| and
    the energy at instants over four decades within polhode's stated error of a Taylor run at
    rtol 1e-12 (and the same Taylor run before the hand-over)."""
    monkeypatch.setattr(A, "MAX_RESOLVED_TURNS", 1e3)
    body = B.custom((1.0, 0.8, 0.5), (0.6, 0.0, 0.8), units="dimensionless")
    w0 = np.array([0.0, 0.006, 0.008])
    t = np.concatenate([[0.0], np.geomspace(1e5, 1e9, 5)])
    hand = simulate(body, "reduced", w0, t_eval=t)
    assert hand.stats["method"] == "taylor -> polhode" and hand.stats["handover_at"] < 1e6
    full = simulate(body, "reduced", w0, t_eval=t, method="taylor", rtol=1e-12)
    J = np.asarray(body.inertia)
    rel = [np.abs(np.sqrt(np.sum((J * h) ** 2, -1)) / np.sqrt(np.sum((J * f) ** 2, -1)) - 1.0)
           for h, f in zip(hand.omega_body, full.omega_body)]
    assert max(rel) <= hand.stats["slow_error_estimate"] + 1e-9
    assert max(rel[: int(np.searchsorted(t, hand.stats["handover_at"]))]) < 1e-10
