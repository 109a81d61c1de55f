"""``auto`` on a symmetric top that is not fast at the start: Taylor's method in full until braking
brings tau0 |Omega| to secular's bound, then ``secular`` (``taylor -> secular``)."""

import math

import numpy as np
import pytest

from spinviz.driver import simulate
from spinviz.errors import SpecError
from spinviz.integrators import auto as A
from spinviz.integrators import full_to_averaged as FTA
from spinviz.integrators import secular as SC
from spinviz.integrators.scaling import body_spin_problem
from spinviz.physics import bodies as B
from spinviz.physics import closed_forms as CF
from spinviz.physics import models as M

W0 = np.array([0.0, 0.006, 0.008])          # tau0 |Omega0| = 1e-2: ten times secular's bound
TOP = B.symmetric_top(0.3, 0.7)
T_LONG = 1.3e17                              # ~1e8 turns (estimated with braking)


def slow_variables(tr) -> np.ndarray:
    """(|Omega|, omega_perp, omega3, |L|/I1) at each instant, body frame: what the hand-over keeps."""
    w = tr.omega_body
    J3 = tr.body.I3 / tr.body.I1
    wp = np.hypot(w[:, 0], w[:, 1])
    return np.stack([np.linalg.norm(w, axis=1), wp, w[:, 2], np.hypot(wp, J3 * w[:, 2])], axis=-1)


def assert_slow_within_bound(hand, full):
    """Each slow variable of ``hand`` within secular's own stated error (``slow_error_estimate``,
    relative to |Omega| in secular's spin units) of ``full``, plus the reference's tolerance."""
    a, r = slow_variables(hand), slow_variables(full)
    bound = (hand.stats["slow_error_estimate"] + 1e-8) * r[:, :1]
    err = np.abs(a - r)
    assert np.all(err <= bound), (err / r[:, :1]).max(axis=0)
    return err / r[:, :1]


def test_long_run_of_a_slow_top_is_handed_over_and_says_so():
    """1e8 turns: refused before (5e7 resolved turns at most), now the composite in about a
    second; the stats say where it handed over and why, and that phases are unresolved."""
    tr = simulate(TOP, "reduced", W0, t_end=T_LONG, samples=101)
    s = tr.stats
    assert s["method"] == "taylor -> secular"
    assert "not fast at the start" in s["method_reason"] and "then secular" in s["method_reason"]
    turns = float(s["method_reason"].split("~", 1)[1].split(" ", 1)[0])
    assert turns > 1e8
    assert 0.0 < s["handover_at"] < T_LONG
    # handed over where secular's own test passes, and no later than one chunk past the prediction
    assert 0.9 * SC.EPS_MAX <= s["handover_eps_rad"] <= SC.EPS_MAX
    assert s["full_stage"]["chunks"] == 1 and s["full_stage"]["method"] == "taylor"
    assert s["phases_resolved"] is False and not tr.phase_resolved
    # tau0 |Omega| at the hand-over is what the samples say (dimensionless body: tau0 = 1)
    i = np.searchsorted(tr.t, s["handover_at"])
    assert tr.omega_magnitude[i - 1] >= s["handover_eps_rad"] >= tr.omega_magnitude[i]
    # the slow geometry covers the whole grid, as for a secular run, and reproduces q
    from spinviz.physics.free_top import pose_about_L

    for k in ("phi_L", "theta_L", "psi_L"):
        assert tr.slow[k].shape == tr.t.shape and np.all(np.isfinite(tr.slow[k]))
    w = tr.omega_body
    _, q = pose_about_L(tr.slow["q_L"], tr.slow["phi_L"], tr.slow["theta_L"], tr.slow["psi_L"],
                        np.hypot(w[:, 0], w[:, 1]), w[:, 2], tr.slow["q_frame"])
    assert np.all(np.abs(np.abs(np.sum(q * tr.q, axis=1)) - 1.0) < 1e-9)
    # resampling at the stored instants keeps them (the renderer's case), elsewhere interpolates the series
    assert tr.sample(tr.t) is tr
    mid = tr.sample(0.5 * (tr.t[:-1] + tr.t[1:]))
    assert np.all(np.diff(mid.slow["phi_L"]) * np.sign(tr.slow["phi_L"][-1] - tr.slow["phi_L"][0]) >= 0.0)
    # the energy only falls
    assert np.all(np.diff(slow_variables(tr)[:, 3]) < 0.0)


@pytest.mark.slow
def test_handover_agrees_with_a_full_taylor_run(monkeypatch):
    """~3e4 turns (affordable in full): the composite, made auto's pick below 1e6 turns for the
    test, against Taylor's method at rtol 1e-12 at instants spread over five decades, each slow
    variable within secular's stated error (measured: 5e-8 of |Omega| against a stated 4e-5)."""
    monkeypatch.setattr(A, "MAX_RESOLVED_TURNS", 1e3)
    t = np.concatenate([[0.0], np.geomspace(1e5, 1e10, 6)])
    hand = simulate(TOP, "reduced", W0, t_eval=t)
    assert hand.stats["method"] == "taylor -> secular" and hand.stats["handover_at"] < 1e6
    full = simulate(TOP, "reduced", W0, t_eval=t, method="taylor", rtol=1e-12)
    rel = assert_slow_within_bound(hand, full)
    assert rel[t < hand.stats["handover_at"]].max() < 1e-12          # before the hand-over: the same Taylor run


@pytest.mark.parametrize("model", ["reduced", "truncated"])
def test_dipole_on_the_axis_against_the_closed_forms(model):
    """chi = 0, omega10 = 0: (5.2) (reduced: omega3 stays, omega_perp falls by Phi) and (5.4)
    (truncated: both fall by F) over 8e7 (reduced) and 2e6 (truncated) turns; the torque is equivariant about the axis, so
    secular needs no average and the composite keeps the slow variables to its tolerance."""
    delta, w20, w30 = 0.4, 0.0099, 5e-4 if model == "reduced" else 1.4e-3
    top = B.symmetric_top(delta, 0.0)
    t = np.concatenate([[0.0], np.geomspace(1e3, 1e12 if model == "reduced" else 1e14, 12)])
    tr = simulate(top, model, (0.0, w20, w30), t_eval=t)
    assert tr.stats["method"] == "taylor -> secular" and not tr.phase_resolved
    with np.errstate(over="ignore"):                  # (5.2)'s e^{2 a tau} overflows where Phi is 0 to double precision
        want = (CF.omega_eq5_2 if model == "reduced" else CF.omega_eq5_4)(t, delta, w20, w30)
    w = tr.omega_body
    scale = np.linalg.norm(want, axis=1)                 # errors relative to |Omega| (omega_perp dies away in (5.2))
    err_perp = np.abs(np.hypot(w[:, 0], w[:, 1]) - np.hypot(want[:, 0], want[:, 1])) / scale
    err_3 = np.abs(w[:, 2] - want[:, 2]) / scale
    assert err_perp.max() <= 1e-7 and err_3.max() <= 1e-7, (err_perp.max(), err_3.max())


@pytest.mark.slow
def test_handover_agrees_with_a_full_taylor_run_over_a_million_turns():
    """~1e6 turns, auto's own choice (no patch): as the fast test, a horizon a hundred times longer
    (the full run ~15 s)."""
    t = np.concatenate([[0.0], np.geomspace(1e5, 1.26e13, 9)])
    hand = simulate(TOP, "reduced", W0, t_eval=t)
    assert hand.stats["method"] == "taylor -> secular"
    full = simulate(TOP, "reduced", W0, t_eval=t, method="taylor", rtol=1e-12)
    assert_slow_within_bound(hand, full)
    assert hand.stats["runtime_s"] < 0.1 * full.stats["runtime_s"]


def test_the_predicted_handover_is_where_the_run_hands_over():
    """The averaged flow's prediction of tau0 |Omega| = 0.98e-3 (``handover.plan``) against the
    full stage: one chunk, ending within 1 % of the bound, for both models and three dipole angles
    (including chi = 0.02, where omega3 brakes 1700x slower than omega_perp)."""
    for model in ("reduced", "truncated"):
        for chi in (0.02, 0.7, 1.2):
            top = B.symmetric_top(0.3, chi)
            problem, eps = body_spin_problem(top, model, W0, np.linspace(0.0, 1e9, 3))
            t_h, turns = FTA.plan(problem)
            assert math.isfinite(t_h) and 0 < turns < 3e5
            if chi == 0.02 and model == "reduced":
                continue                                 # 2.5e5 turns in full: ~4 s, the slow test's
            sol = FTA.solve_handover(problem)
            assert sol.success and sol.stats["full_stage"]["chunks"] == 1
            assert sol.stats["handover_eps_rad"] == pytest.approx(FTA.TARGET_MARGIN * SC.EPS_MAX, rel=1e-2)


def test_asymmetric_body_gets_the_handover_to_polhode():
    """The same slow start on an asymmetric body: below 1e6 turns Taylor's method; past them the
    hand-over to the averaged flow over the polhode (``taylor -> polhode``), where the refusal
    ("resolves each turn") stood before."""
    body = B.custom((1.0, 0.8, 0.5), (0.6, 0.0, 0.8), units="dimensionless")
    assert A.choose_method(body, "reduced", W0, 1e9)[0] == "taylor"
    assert A.choose_method(body, "reduced", W0, T_LONG)[0] == "taylor -> polhode"


def test_a_full_stage_that_cannot_finish_is_refused_in_one_line():
    """chi = 0.001: omega3 brakes as n1^2, so tau0 |Omega| reaches the bound only after ~1e8 turns
    in full: refused before any work, saying so."""
    top = B.symmetric_top(0.3, 0.001)
    assert A.choose_method(top, "reduced", W0, 1e17)[0] == "taylor"
    with pytest.raises(SpecError) as e:
        simulate(top, "reduced", W0, t_end=1e17, samples=11)
    msg = str(e.value)
    assert e.value.key == "t_end" and "\n" not in msg
    assert "the averaged flow predicts it to fall to 0.001 only after ~9.98e+07 turns in full" in msg
    assert msg.endswith("at most 5e+07 can finish")


def test_no_handover_where_braking_never_makes_the_spin_fast():
    """chi = 0 with tau0 omega3 = 5e-3: omega3 is never braked ((5.2)), so tau0 |Omega| stays above
    the bound: no hand-over, resolved in full within the limit, refused beyond it."""
    top = B.symmetric_top(0.3, 0.0)
    w0 = (0.0, 0.006, 0.005)
    problem, _ = body_spin_problem(top, "reduced", w0, np.linspace(0.0, 1e12, 2))
    assert FTA.plan(problem)[0] == math.inf
    assert A.choose_method(top, "reduced", w0, 1e12)[0] == "taylor"
    with pytest.raises(SpecError, match="nor does braking bring it to 0.001 by t_end"):
        simulate(top, "reduced", w0, t_end=1e12, samples=11)


def test_the_kernel_forced_response_is_4_9():
    """secular's kernel carries omega_perp's forced response apart: to second order it is
    (4.9)'s B / tau (omega2 = -n1 n3 w3^2 / delta) and A tau^-3/2, as ``physics.averaged`` has them,
    to the next order mu^2 = (w3 / delta)^2."""
    from spinviz.integrators import slowflow as SF
    from spinviz.physics import averaged as AV

    for delta, chi in ((-0.4, 0.5), (0.3, 0.7)):
        J = np.array([1.0, 1.0, 1.0 - delta])
        g = np.array([math.sin(chi), 0.0, math.cos(chi)])
        for w3 in (1e-2, 1e-3):
            z1, z2 = SF.forced_z(M.get("reduced").kernel_id, J, g, w3)
            zf = complex(AV.flow("reduced", delta, chi).forced_response(w3, order=2))
            mu2 = (w3 / delta) ** 2
            assert z2 == pytest.approx(zf.imag, rel=3.0 * mu2) and z1 == pytest.approx(zf.real, rel=3.0 * mu2)


@pytest.mark.slow
def test_a_type_1_run_keeps_its_forced_response():
    """The oblate type-1 case (delta -0.4, chi 0.5): after the hand-over omega_perp tau follows the full
    integration and (4.9)'s B = -n3 (1 - delta) / (2 n1 delta) = 3.2034 (it fell to 1e-22 when the
    forced response was averaged away with the circle): to 1e-5 of Taylor's at every sample, to 1e-4
    of B from tau = 1e9 on."""
    delta, chi = -0.4, 0.5
    top = B.symmetric_top(delta, chi)
    t = np.concatenate([[0.0], np.geomspace(1e5, 1e11, 7)])
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(A, "MAX_RESOLVED_TURNS", 1e3)
        hand = simulate(top, "reduced", W0, t_eval=t)
    assert hand.stats["method"] == "taylor -> secular"
    full = simulate(top, "reduced", W0, t_eval=t, method="taylor", rtol=1e-12)
    wp_h = np.hypot(hand.omega_body[:, 0], hand.omega_body[:, 1]) * t
    wp_f = np.hypot(full.omega_body[:, 0], full.omega_body[:, 1]) * t
    np.testing.assert_allclose(wp_h[1:], wp_f[1:], rtol=1e-5)
    B49 = -math.cos(chi) * (1.0 - delta) / (2.0 * math.sin(chi) * delta)
    np.testing.assert_allclose(wp_h[t >= 1e9], B49, rtol=1e-4)
