"""Taylor's method (heyoka): its right-hand sides, the closed forms, batches and events, and
what a run says when it cannot meet the tolerance asked of it."""

import math

import numpy as np
import pytest

from spinviz import rotations as R
from spinviz.driver import accuracy_notes, simulate, solve_many
from spinviz.integrators import status as ST
from spinviz.integrators import taylor as TY
from spinviz.integrators.scaling import spin_problem
from spinviz.physics import bodies as B
from spinviz.physics import cases
from spinviz.physics import equations as E
from spinviz.physics import models as M

hy = pytest.importorskip("heyoka")


def _state(rng):
    w = rng.normal(size=3) * 10 ** rng.uniform(-2, 0.5)
    q = R.normalize(rng.normal(size=4))
    return w, q


@pytest.mark.parametrize("model", ["free", "reduced", "truncated"])
def test_taylor_right_hand_sides_are_the_rates_of_physics_equations(model, rng):
    """The compiled system (scaled variables u = omega sqrt(1 + c t)) at random states, bodies,
    times and braking scales c, against the NumPy rates and q_dot = 1/2 q (x) (0, omega):
    du/dt = sigma f(u / sigma) + u c / (2 sigma^2); agreement to 1e-14 relative (the two
    evaluate the same formulas in different orders).  Relative to the size of the terms
    summed -- (|u|^2 / sigma + |g|^2 |u|^3 / sigma^2 + c |u|) / J_min for the Euler part, |u| /
    sigma for q_dot -- since the free part cancels to zero on a principal axis: below 1e-14
    (measured 1.3e-16 free, 1.6e-16 reduced, 5.3e-15 truncated over 2000 states)."""
    sys_ = TY.equations(model, "quaternion")
    cf = hy.cfunc([e for _, e in sys_], [v for v, _ in sys_])
    worst = 0.0
    for _ in range(200):
        J = np.sort(rng.uniform(0.3, 1.0, 3))[::-1]
        J = J / J[0]
        g = rng.normal(size=3) * 10 ** rng.uniform(-4, 0)
        c = float(g @ g) if model != "free" else 0.0
        t = 10 ** rng.uniform(-2, 3)
        u, q = _state(rng)
        got = cf(np.concatenate([u, q]), pars=np.array([*J, *g, c]), time=t)
        sigma = math.sqrt(1.0 + c * t)
        w = u / sigma
        a = np.array(M.rate_function(model)(*w, tuple(J), tuple(g)))
        want = np.concatenate([sigma * a + u * c / (2.0 * sigma**2), E.quat_rate(*q, *w)])
        uu, gg = float(u @ u), float(g @ g)
        euler = (uu / sigma + gg * uu**1.5 / sigma**2 + c * math.sqrt(uu)) / J.min()
        scale = np.concatenate([np.full(3, euler), np.full(4, math.sqrt(uu) / sigma)])
        worst = max(worst, float(np.max(np.abs(got - want) / scale)))
    assert worst < 1e-14, worst


@pytest.mark.parametrize("model", ["reduced", "truncated"])
def test_symmetric_form_is_the_general_rate(model, rng):
    """(4.2)-(4.4) and spinviz's truncated analogue, as compiled for the atlas, against the
    general rate with J = (1, 1, 1 - delta), g = (n1, 0, n3); relative to the size of the
    terms summed, (|w|^2 + |g|^2 |w|^3) / (1 - delta): below 1e-14 (measured 4.7e-16 reduced,
    1.8e-15 truncated over 3000 states)."""
    sys_ = TY.equations(model, "none", symmetric=True)
    cf = hy.cfunc([e for _, e in sys_], [v for v, _ in sys_])
    worst = 0.0
    for _ in range(300):
        delta = rng.uniform(-0.99, 0.95)
        chi = rng.uniform(0.0, 0.5 * math.pi)
        k = 10 ** rng.uniform(-3, 0)
        n1, n3 = k * math.sin(chi), k * math.cos(chi)
        u = rng.normal(size=3) * 10 ** rng.uniform(-2, 0)
        got = cf(u, pars=np.array([delta, n1, n3, 0.0]), time=0.0)
        want = np.array(M.rate_function(model)(*u, (1.0, 1.0, 1.0 - delta), (n1, 0.0, n3)))
        terms = ((u @ u) + k * k * (u @ u) ** 1.5) / (1.0 - delta)
        worst = max(worst, float(np.max(np.abs(got - want))) / terms)
    assert worst < 1e-14, worst


CLOSED_FORMS = {
    "6.10": lambda: cases.eq6_10(0.1),                         # truncated sphere: Omega (6.9), q (6.10)
    "3.9 reduced": lambda: cases.eq3_9("reduced"),             # rotation about e2 of an askew top
    "3.9 truncated": lambda: cases.eq3_9("truncated"),
    "5.2": lambda: cases.longitudinal("reduced"),              # residual rotation about d: Omega exact
    "5.4": lambda: cases.longitudinal("truncated"),            # power-law spin-down: Omega exact
}


@pytest.mark.parametrize("name", sorted(CLOSED_FORMS))
def test_taylor_reproduces_the_closed_forms_to_1e_12(name):
    """(3.9), (5.2), (5.4), (6.10) at rtol 1e-13: |dOmega|/|Omega0| and, where the paper gives
    the orientation, the misorientation, both <= 1e-12 (measured 1e-16 .. 4e-14)."""
    case = CLOSED_FORMS[name]()
    tr = simulate(case.body, case.model, method="taylor", rtol=1e-13, atol=1e-15, **case.run_kwargs(41))
    w_err = np.max(np.abs(tr.omega - case.omega_exact(tr.t))) / np.linalg.norm(case.omega0)
    assert w_err <= 1e-12, w_err
    exact_q = case.orientation_exact(tr.t)
    if exact_q is not None:
        assert R.misorientation(tr.q, exact_q).max() <= 1e-12


def test_3_9_radiates_on_as_the_exact_solution_says_for_both_models():
    """(3.9) is the same exact solution for both models (Omega1 = Omega3 = 0): their Taylor
    runs agree to 1e-13."""
    a = _run(cases.eq3_9("reduced"), method="taylor", rtol=1e-13, atol=1e-15)
    b = _run(cases.eq3_9("truncated"), method="taylor", rtol=1e-13, atol=1e-15)
    assert np.max(np.abs(a.omega - b.omega)) < 1e-13 * 0.1


def _run(case, **kw):
    args = case.run_kwargs(21)
    return simulate(case.body, case.model, args.pop("omega0"), **args, **kw)


def test_long_double_reference_agrees_with_double_to_its_tolerance():
    """taylor-long at 1e-18 and taylor at 1e-13 on the askew family-1 top over 100 turns: the
    double run is within 1e-11 rad and 1e-12 in Omega of the reference (measured ~1e-13)."""
    body = B.symmetric_top(-0.6, math.radians(55.0))
    kw = dict(t_end=2 * math.pi * 100 / 0.1, samples=21, euler_zxz0=(0.3, 1.0, -0.2))
    ref = simulate(body, "reduced", (0.03, 0.05, 0.08), method="taylor-long", rtol=1e-18, atol=1e-18, **kw)
    tr = simulate(body, "reduced", (0.03, 0.05, 0.08), method="taylor", rtol=1e-13, atol=1e-15, **kw)
    assert ref.stats["precision"] == "long double" and ref.stats["order"] > tr.stats["order"]
    assert R.misorientation(tr.q, ref.q).max() < 1e-11
    assert np.max(np.abs(tr.omega - ref.omega)) < 1e-12 * np.linalg.norm(tr.omega[0])


# --- what a run says about the tolerance ------------------------------------------------------
def test_a_tolerance_below_what_a_method_holds_is_said_not_hidden():
    """rtol 1e-17 from taylor (double): the run says it stops following the tolerance, and
    names taylor-long; atol > rtol is said too; a well-posed request says nothing."""
    body = B.symmetric_top(0.3, 0.7)
    tr = simulate(body, "reduced", (0.0, 0.05, 0.3), t_end=10.0, samples=3, method="taylor", rtol=1e-17, atol=1e-19)
    assert tr.stats["tolerance_met"] is False
    assert any("taylor-long" in n for n in tr.stats["accuracy_notes"])
    notes = accuracy_notes("taylor", 1e-13, 1e-12)
    assert len(notes) == 1 and "atol = 1e-12 exceeds rtol = 1e-13" in notes[0]
    assert accuracy_notes("taylor", 1e-10, 1e-12) == []
    assert accuracy_notes("radau", 1e-13, 1e-15) and "radau" in accuracy_notes("radau", 1e-13, 1e-15)[0]


def test_auto_takes_long_double_below_what_double_holds():
    body = B.symmetric_top(0.3, 0.7)
    tr = simulate(body, "reduced", (0.0, 0.05, 0.3), t_end=10.0, samples=3, rtol=1e-17, atol=1e-18)
    assert tr.stats["method"] == "taylor-long" and tr.stats["tolerance_met"]


def test_the_command_line_says_when_the_tolerance_is_not_met(tmp_path, capsys):
    from spinviz.commands import main

    sc = tmp_path / "s.toml"
    sc.write_text('[body]\ndelta = 0.3\nchi = 0.7\n[initial]\nomega = [0.0, 0.05, 0.3]\n'
                  '[simulation]\nmodel = "reduced"\nt_end = 10.0\nsamples = 3\nrtol = 1e-13\natol = 1e-12\n')
    assert main(["simulate", str(sc), "--out", str(tmp_path / "t.npz"), "--method", "taylor"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "note:" in err and "atol = 1e-12 exceeds rtol = 1e-13" in err


# --- batches and events (the atlas's path) ------------------------------------------------------
def _atlas_runs(model, cells, starts, tau, **kw):
    inertia = [(1.0, 1.0, 1.0 - d) for d, _ in cells]
    coupling = [(math.sin(c), 0.0, math.cos(c)) for _, c in cells]
    return solve_many(model, inertia, coupling, starts, tau, **kw)


def test_batch_lanes_are_independent_and_match_single_runs(rng):
    """Eleven runs (a full SIMD batch and a partial one) of different cells: each lane's result
    is the same whatever its neighbours (bit for bit: heyoka's lanes do not mix), and within
    1e-7 of a scalar run of the general equation at the same tolerance."""
    cells = [(rng.uniform(-0.8, 0.8), rng.uniform(0.1, 1.4)) for _ in range(11)]
    starts = [rng.normal(size=3) * 0.03 for _ in range(11)]
    tau = np.concatenate([[0.0], np.logspace(-1, 5, 25)])
    runs = _atlas_runs("reduced", cells, starts, tau, rtol=1e-10)
    alone = _atlas_runs("reduced", cells[3:4], starts[3:4], tau, rtol=1e-10)[0]
    assert np.array_equal(runs[3].omega, alone.omega)
    for k in (0, 10):
        d, c = cells[k]
        tr = simulate(B.symmetric_top(d, c), "reduced", starts[k], t_eval=tau, kinematics="none", method="taylor",
                      rtol=1e-10, atol=1e-10)
        assert np.max(np.abs(tr.omega - runs[k].omega)) < 1e-7 * np.linalg.norm(starts[k])


def test_residual_rotation_event_stops_an_exact_cell_early():
    """chi = 0 (reduced): the residual rotation (5.2) is the exact end state; with eta = 1e-9 the
    run stops once |d x omega| < eta |d| |omega|, long before tau_end, status STOPPED_RESIDUAL,
    and the state there is along d = e3 with omega3 = its initial value ((5.1): omega3 conserved)."""
    tau = np.concatenate([[0.0], np.logspace(-2, 10, 241)])
    w0 = np.array([0.02, -0.03, 0.03])
    r = _atlas_runs("reduced", [(0.4, 0.0)], [w0], tau, rtol=1e-8, residual_eta=[1e-9])[0]
    assert r.status == ST.STOPPED_RESIDUAL and r.t_stop < 1e7 and r.reached < len(tau)
    w = r.omega[r.reached - 1]
    assert math.hypot(w[0], w[1]) < 1e-8 * abs(w[2]) and w[2] == pytest.approx(w0[2], rel=1e-9)
    assert "residual rotation about d reached" in r.reason


def test_runaway_event_keeps_the_samples_before_it():
    """tau0 |Omega0| = 10, an asymmetric body: the reduced solution blows up (|omega| ~ 1/(t* - t),
    t* = 21.93).  The terminal event stops it where |omega| passes 10 x its start (status
    RUNAWAY, at tau = 21.2) and the samples before are kept, NaN after."""
    tau = np.linspace(0.0, 25.0, 101)
    d = np.array([0.042, 0.938, -0.344])
    r = solve_many("reduced", [(1.0, 0.8, 0.5)], [d / np.linalg.norm(d)], [(-7.154, 5.648, 4.115)], tau,
                   rtol=1e-10)[0]
    assert r.status == ST.RUNAWAY and r.t_stop == pytest.approx(21.2, abs=0.05)
    assert r.reached == int(np.searchsorted(tau, r.t_stop))
    assert np.all(np.isfinite(r.omega[:r.reached])) and np.all(np.isnan(r.omega[r.reached:]))


def test_step_budget_ends_a_batch_with_partial_series():
    tau = np.concatenate([[0.0], np.logspace(-2, 10, 241)])
    runs = _atlas_runs("reduced", [(0.3, 0.7)] * 3, [np.array([0.02, 0.03, 0.01])] * 3, tau, rtol=1e-8, max_steps=500)
    for r in runs:
        assert r.status == ST.TOO_MANY_STEPS and 1 < r.reached < len(tau)
        assert np.all(np.isfinite(r.omega[:r.reached]))


def test_truncated_start_near_its_singular_surface_is_not_run():
    tau = np.linspace(0.0, 1.0, 5)
    r = solve_many("truncated", [(1.0, 1.0, 0.3)], [(0.6, 0.0, 0.8)], [(0.3, -0.99 / 1.12, 0.2)], tau,
                   singular_margin=0.5)[0]
    assert r.status == ST.SINGULAR_START and r.reached == 1 and "near-singular" in r.reason


def test_solve_many_spin_units_round_trip():
    """solve_many works in spin units inside; what it returns is dimensionless (4.1): a run
    with |omega0| = 1e-3 gives the same omega/|omega0| as one with 1e-1 at tau scaled by
    1e4, to the tolerance (the free top is scale-free exactly)."""
    tau = np.linspace(0.0, 50.0, 11)
    a = solve_many("free", [(1.0, 0.8, 0.5)], [(0.0, 0.0, 1.0)], [(0.1, 0.05, 0.02)], tau, rtol=1e-13)[0]
    b = solve_many("free", [(1.0, 0.8, 0.5)], [(0.0, 0.0, 1.0)], [(1e-3, 5e-4, 2e-4)], tau * 100.0, rtol=1e-13)[0]
    assert np.max(np.abs(a.omega / 0.1 - b.omega / 1e-3)) < 1e-11


def test_spin_problem_coupling_and_time_scale():
    """The spin-unit problem of the atlas's runs: |omega(0)| = 1, |g|^2 = eps, t scaled by eps."""
    s = M.System("reduced", (1.0, 1.0, 0.7), (0.6, 0.0, 0.8))
    p, eps = spin_problem(s, (0.03, 0.0, 0.04), np.array([0.0, 10.0]), kinematics="none")
    assert eps == pytest.approx(0.05) and np.linalg.norm(p.omega0) == pytest.approx(1.0)
    assert float(np.dot(p.system.coupling, p.system.coupling)) == pytest.approx(0.05)
    assert p.t_eval[-1] == pytest.approx(0.5)


def test_built_integrators_are_cached_and_a_damaged_cache_is_rebuilt(tmp_path, monkeypatch):
    """The pickled integrator gives the very numbers of a fresh build; a damaged file is
    replaced, never loaded."""
    monkeypatch.setenv("SPINVIZ_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(TY, "_templates", {})
    body = B.symmetric_top(0.3, 0.7)
    kw = dict(t_end=50.0, samples=5, method="taylor", rtol=1e-9)
    a = simulate(body, "reduced", (0.0, 0.05, 0.3), **kw)
    files = list((tmp_path / "taylor").glob("*.pickle"))
    assert len(files) == 1
    monkeypatch.setattr(TY, "_templates", {})
    b = simulate(body, "reduced", (0.0, 0.05, 0.3), **kw)              # from the pickle
    assert np.array_equal(a.q, b.q) and np.array_equal(a.omega, b.omega)
    files[0].write_bytes(b"not a pickle")
    monkeypatch.setattr(TY, "_templates", {})
    c = simulate(body, "reduced", (0.0, 0.05, 0.3), **kw)
    assert np.array_equal(a.q, c.q) and files[0].read_bytes()[:1] != b"n"
