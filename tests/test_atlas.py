"""Regime atlas: the classifier, the runs at the paper's domains, the spec, the formulas.

The cluster, the store's resume and the scheduler are in test_atlas_cluster.py."""

import math
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from spinviz.errors import SceneError
from spinviz.inputs.atlas_spec import Settings, directions, load_spec, log_times, parse_spec
from spinviz.physics import asymptotics as FM
from spinviz.physics import closed_forms as CF
from spinviz.regimes.engine import classify as C
from spinviz.regimes.engine import runs as RN

ROOT = Path(__file__).resolve().parents[1]
TAU = log_times(1e-2, 1e10, 20)[1:]          # the default sampling: 20 a decade, tau = 1e-2 ... 1e10


# --- synthetic series with known exponents -------------------------------------------------
def polar(wp, phi, w3):
    return np.stack([wp * np.cos(phi), wp * np.sin(phi), w3], axis=1)


def type1(d, ch, tau, sign_c=1.0):
    f = FM.type1_eq4_9(d, ch)
    return np.stack([sign_c * f["A_for_C_positive"] * tau**-1.5, f["B"] / tau, sign_c * math.sqrt(f["C2"]) / np.sqrt(tau)], 1)


def type2(d, ch, tau, a=0.3):
    f = FM.type2_eq4_14(d, ch)
    b = math.sqrt(f["B2"])
    return polar(a * tau ** f["alpha"], 0.7 - 2 * d * b * np.sqrt(tau), b / np.sqrt(tau))    # phi_dot = -delta omega3


def type3(d, ch, tau):
    f = FM.type3_eq4_16(d, ch)
    a, b = math.sqrt(f["A2"]), math.sqrt(f["B2"])
    return polar(a / np.sqrt(tau), 0.1 - 2 * d * b * np.sqrt(tau), b / np.sqrt(tau))


def type4(d, ch, tau, b=0.5):
    f = FM.type4_eq4_18(d, ch)
    be = f["beta"]
    return polar(math.sqrt(f["A2"]) / np.sqrt(tau), -d * b * tau ** (be + 1) / (be + 1), b * tau**be)


def type5(d, ch, tau):
    """(4.41)-(4.42) with K = -A^2/(4B) (the sign the full runs show)."""
    f = FM.type5_eq4_42(d, ch)
    n1, n3 = math.sin(ch), math.cos(ch)
    A, B, M = math.sqrt(f["A2"]), f["B"], math.sqrt(f["M2"])
    psi = -4 * d * B / A * M * tau**0.25
    w3 = M * tau**-0.75 * np.sin(psi)
    w2 = (B - f["A2"] / (4 * B) * np.cos(2 * psi)) / np.sqrt(tau)
    return np.stack([A / np.sqrt(tau) * np.cos(psi) - n3 / n1 * (1 - d) * w3, w2, w3], 1)


SYNTHETIC = [
    ("1", type1, -0.6, 0.3, {"slope_perp": -1.0, "slope_3": -0.5}),
    ("1", lambda d, c, t: type1(d, c, t, -1.0), 0.5, 0.2, {"slope_perp": -1.0, "slope_3": -0.5}),
    ("2", type2, 0.5, math.radians(22), {"slope_perp": FM.type2_eq4_14(0.5, math.radians(22))["alpha"], "slope_3": -0.5}),
    ("3", type3, 0.3, 0.72, {"slope_perp": -0.5, "slope_3": -0.5}),
    ("4", type4, 0.5, math.radians(40), {"slope_perp": -0.5, "slope_3": FM.type4_eq4_18(0.5, math.radians(40))["beta"]}),
    ("5", type5, 0.8, 1.2, {"slope_perp": -0.5}),
    ("5", type5, 0.9, 1.3, {"slope_perp": -0.5}),
]


@pytest.mark.parametrize("label, make, delta, chi, slopes", SYNTHETIC)
def test_classifier_synthetic_series_known_exponents(label, make, delta, chi, slopes):
    """Exact power laws (and spirals with the phase law phi_dot = -delta omega3) get their
    type with confidence ~1, and the measured slopes are the exponents to 1e-3."""
    v = C.classify(TAU, make(delta, chi, TAU), delta, chi)
    assert v.label == label and v.confidence > 0.9, (v.label, v.confidence, v.reason)
    for k, expected in slopes.items():
        assert v.evidence[k] == pytest.approx(expected, abs=1e-3), k
    finite = [abs(x) for x in v.deviations.values() if math.isfinite(x)]
    if label in ("1", "2", "3", "4"):             # built from the formulas: the deviations are sampling error only
        assert finite and max(finite) < 5e-3, v.deviations


def test_classifier_synthetic_noise_tolerated_then_refused(rng):
    """1e-3 relative noise keeps the label; 30 % noise makes any label unsafe -> "other"."""
    d, ch = 0.5, math.radians(22)
    w = type2(d, ch, TAU)
    assert C.classify(TAU, w * (1 + 1e-3 * rng.normal(size=w.shape)), d, ch).label == "2"
    w3 = type3(0.3, 0.72, TAU)
    v = C.classify(TAU, w3 * (1 + 0.3 * rng.normal(size=w3.shape)), 0.3, 0.72)
    assert v.label == "other" and v.confidence < C.MIN_CONFIDENCE


def test_classifier_never_forces_a_label():
    """A decay slower than any type (tau^-0.3) and a stopped phase that is not (3.9) are
    "other"; a hand-over from type 2 to type 1 in mid-window (omega_perp from tau^-0.6 to
    tau^-1, the phase stopping) is "approaching" type 1, below the confidence of a label --
    a slow hand-over said as such, neither "other" nor the type it has not reached."""
    slow = C.classify(TAU, polar(0.5 * TAU**-0.3, 3 * np.sqrt(TAU), 0.5 * TAU**-0.3), 0.5, 0.7)
    assert slow.label == "other" and slow.candidate == "none"
    hand = polar(np.where(TAU < 1e9, 0.3 * TAU**-0.6, 0.3 * 1e9**-0.6 * (TAU / 1e9) ** -1.0),
                 3 * np.sqrt(TAU) * (TAU < 1e9) + 1.5 * (TAU >= 1e9), 1.3 / np.sqrt(TAU))
    v = C.classify(TAU, hand, 0.5, 0.38)
    assert v.label == "approaching" and v.candidate == "1" and v.confidence < C.MIN_CONFIDENCE
    frozen = C.classify(TAU, polar(0.7 / np.sqrt(TAU), np.ones_like(TAU), 1e-3 * TAU**-1.5), 0.5, 0.7)
    assert frozen.label == "other" and frozen.candidate == "3.9" and "not (3.9)" in frozen.reason


@pytest.mark.parametrize("w20", [1.0, -0.3])
def test_classifier_exact_3_9(w20):
    """(3.9) itself: omega1 = omega3 = 0 exactly, omega2 sqrt(2 tau) -> 1; both models."""
    w = CF.omega_eq3_9(TAU, 1.0, w20)
    for model in ("reduced", "truncated"):
        v = C.classify(TAU, w, 0.8, 1.2, model)
        assert v.label == "3.9" and v.confidence == 1.0
        assert abs(v.deviations["omega2^2 2 tau (3.9)"]) < 1e-8      # 1/(2 w20^2 tau) ~ 2e-9 at the window


@pytest.mark.parametrize("delta, w20, w30", [(0.5, 0.6, 0.5), (-0.6, 0.9, 0.1)])
def test_classifier_exact_5_2_residual_rotation(delta, w20, w30):
    """(5.2), reduced, chi = 0: omega -> omega30 e3 = along d, no braking: "R"."""
    with np.errstate(over="ignore"):                           # exp(2 eps^2 w3^2 tau) at tau = 1e10
        w = CF.omega_eq5_2(TAU, delta, w20, w30)
    v = C.classify(TAU, w, delta, 0.0)
    assert v.label == "R" and v.confidence > 0.9
    assert abs(v.evidence["slope_norm"]) < 1e-6 and v.evidence["angle_omega_d_deg"] < 1e-6


@pytest.mark.parametrize("delta, w20, w30", [(0.5, 0.6, 0.5), (-0.3, 0.2, 0.9)])
def test_classifier_exact_5_4_truncated_cone(delta, w20, w30):
    """(5.4), truncated, chi = 0: a power-law spiral on a cone, omega3/omega_perp fixed: "Tcone"."""
    v = C.classify(TAU, CF.omega_eq5_4(TAU, delta, w20, w30), delta, 0.0, "truncated")
    assert v.label == "Tcone" and v.confidence > 0.9
    assert v.evidence["Y2"] / v.evidence["X2"] == pytest.approx((w30 / w20) ** 2, rel=1e-6)


def test_classifier_rejects_bad_shapes():
    with pytest.raises(ValueError, match="shape"):
        C.classify(TAU, np.zeros((len(TAU), 2)), 0.5, 0.5)
    assert C.classify(TAU, np.full((len(TAU), 3), np.nan), 0.5, 0.5).label == "failed"


# --- full runs deep inside the paper's domains ---------------------------------------------
MEMBERS = directions(4, 7) * 0.1
SETTINGS = Settings()                         # tau_end = 1e10: the atlas's default


def ensemble(delta, chi, model="reduced", members=MEMBERS, settings=SETTINGS):
    return [RN.run_and_classify(model, delta, chi, w0, settings) for w0 in members]


def _median(recs, key):
    return float(np.median([r.evidence[C.EVIDENCE.index(key)] for r in recs]))


@pytest.mark.slow
def test_domain_2_spiral_alpha_above_minus_one():
    """(0.5, 22 deg): in (4.15), alpha = -0.60 > -1: type 2 for every member; alpha within
    0.03 and B^2 within 3 % of (4.14) (at 1e10 the runs are still converging: -0.608, 1.763)."""
    d, ch = 0.5, math.radians(22)
    f = FM.type2_eq4_14(d, ch)
    assert f["in_domain"] and f["alpha"] > -1
    recs = ensemble(d, ch)
    assert Counter(r.label for r in recs)["2"] == len(recs)
    assert _median(recs, "slope_perp") == pytest.approx(f["alpha"], abs=0.03)
    assert _median(recs, "Y2") == pytest.approx(f["B2"], rel=0.03)


def test_domain_2_with_alpha_far_below_minus_one_is_type_1():
    """(-0.6, 0.3): in (4.15) too, but alpha = -21.7: the spiral dies first and the late state
    is type 1, with (4.9)'s C^2 and B to 1e-3 (the atlas reports it as such)."""
    d, ch = -0.6, 0.3
    assert FM.type2_eq4_14(d, ch)["in_domain"] and FM.type2_eq4_14(d, ch)["alpha"] == pytest.approx(-21.7, abs=0.05)
    recs = ensemble(d, ch)
    assert Counter(r.label for r in recs)["1"] == len(recs)
    f = FM.type1_eq4_9(d, ch)
    assert _median(recs, "Y2") == pytest.approx(f["C2"], rel=1e-3)
    assert _median(recs, "w2_tau") == pytest.approx(f["B"], rel=1e-3)


@pytest.mark.slow
def test_domain_3_deep():
    """(0.8, 11.4 deg): deep in (4.17): type 3, A^2 and B^2 of (4.16) within 1 %."""
    d, ch = 0.8, math.radians(11.4)
    f = FM.type3_eq4_16(d, ch)
    assert f["in_domain"]
    recs = ensemble(d, ch)
    assert Counter(r.label for r in recs)["3"] >= 3
    assert _median(recs, "X2") == pytest.approx(f["A2"], rel=0.01)
    assert _median(recs, "Y2") == pytest.approx(f["B2"], rel=0.01)


def test_domain_4_with_corrected_amplitude():
    """(0.5, 39 deg): in (4.19) and beta = -0.617 > -3/4: type 4; beta within 0.01 and A^2
    within 1 % of (1 + xi)/(2 + xi), far from the printed 1/(2 - xi) = 0.744."""
    d, ch = 0.5, math.radians(39)
    f = FM.type4_eq4_18(d, ch)
    assert f["in_domain"] and f["beta"] > -0.75
    recs = ensemble(d, ch)
    assert Counter(r.label for r in recs)["4"] == len(recs)
    assert _median(recs, "slope_3") == pytest.approx(f["beta"], abs=0.01)
    assert _median(recs, "X2") == pytest.approx(f["A2"], rel=0.01)
    assert abs(_median(recs, "X2") - f["A2_printed"]) > 0.1


def test_domain_4_beyond_beta_three_quarters_locks_into_type_5():
    """(0.5, 45 deg): in (4.19), but beta = -0.833 < -3/4: the phase is captured into the
    libration "5"; omega_perp sqrt(tau) -> 0.882 for every member that is labelled."""
    d, ch = 0.5, math.pi / 4
    assert FM.type4_eq4_18(d, ch)["in_domain"] and FM.type4_eq4_18(d, ch)["beta"] < -0.75
    recs = ensemble(d, ch)
    fives = [r for r in recs if r.label == "5"]
    assert len(fives) >= 3
    assert math.sqrt(_median(fives, "X2")) == pytest.approx(0.8822, abs=2e-3)


def test_residual_rotation_stops_early_where_it_is_exact():
    """chi = 0, reduced: (5.2)'s residual rotation; the run stops once it is reached (its
    cost would otherwise grow like tau) and says so."""
    r = RN.run_and_classify("reduced", 0.5, 0.0, MEMBERS[0], SETTINGS)
    assert r.label == "R" and r.status == RN.STOPPED_RESIDUAL
    assert r.tau_reached < 1e7 and r.nsteps < 50_000


def test_step_budget_gives_other_with_candidate():
    """A run out of steps is never labelled: "other", with what its samples say as candidate."""
    st = Settings(max_steps=3000)
    r = RN.run_and_classify("reduced", 0.5, math.radians(39), MEMBERS[0], st)
    assert r.status == RN.ST.TOO_MANY_STEPS and r.label == "other" and r.tau_reached < st.tau_end
    assert "step" in r.reason


def test_truncated_singular_start_is_failed_with_reason():
    r = RN.run_and_classify("truncated", 0.9, 0.6, np.array([0.0, -0.6, 0.0]), SETTINGS)
    assert r.label == "failed" and r.status == RN.SINGULAR_START and "singular" in r.reason


# --- formulas --------------------------------------------------------------------------------
@pytest.mark.parametrize("delta, chi", [(0.5, 0.7), (-0.3, 1.1), (0.9, 0.2)])
def test_corrected_A2_of_4_18_is_the_averaged_fixed_point(delta, chi):
    """(4.12) with omega3 = 0: d omega_perp/d tau = -a omega_perp^3, so omega_perp^2 tau -> 1/(2a);
    that is (1 + xi)/(2 + xi), not the printed 1/(2 - xi)."""
    dwp = CF.averaged_rate_eq4_12(1.0, 0.0, delta, chi)[0]
    assert FM.type4_eq4_18(delta, chi)["A2"] == pytest.approx(1.0 / (2.0 * -dwp), rel=1e-12)


def test_derived_lines():
    """alpha(4.14) = -1 and beta(4.18) = -3/4 on spinviz's lines; (4.42)'s A^2 = 1 on its line."""
    for d in (-0.6, 0.0, 0.5, 0.9):
        xi = FM.xi_spinviz_alpha_minus_one(d)
        assert FM.type2_eq4_14(d, math.atan(math.sqrt(xi)))["alpha"] == pytest.approx(-1.0, abs=1e-12)
    for d in (0.0, 0.5, 0.9):
        xi = FM.xi_spinviz_beta_minus_three_quarters(d)
        assert FM.type4_eq4_18(d, math.atan(math.sqrt(xi)))["beta"] == pytest.approx(-0.75, abs=1e-12)
    for d in (0.6, 0.8, 0.95):
        xi = FM.xi_spinviz_type5_real(d)
        assert FM.type5_eq4_42(d, math.atan(math.sqrt(xi)))["A2"] == pytest.approx(1.0, abs=1e-12)


def test_dast_families_from_the_crystal_data():
    """Family 1 (a = b, symmetry axis c): chi = 55 deg, delta of the 100 x 100 x 50 box = -0.6
    as the preset; family 2 (b = c, symmetry axis a): chi = 35 deg, delta = 1 - I_a/I_b."""
    from spinviz.physics.presets import dast_box, dast_families, dast_family1

    f1, f2 = dast_families()
    assert np.degrees(f1["chi"][0]) == pytest.approx(55.0) and np.degrees(f2["chi"][0]) == pytest.approx(35.0)
    body = dast_family1()
    assert body.delta == pytest.approx(FM.box_delta(50.0, 100.0)) and math.degrees(body.chi) == pytest.approx(55.0)
    box = dast_box(300.0, 100.0, 100.0)                        # a != b = c: symmetric about e1 = a
    Ia, Ib, Ic = box.inertia
    assert Ib == pytest.approx(Ic, rel=1e-12, abs=0)        # Ib ~ 3e-25: approx adds abs=1e-12 unless told
    assert 1.0 - Ia / Ib == pytest.approx(FM.box_delta(300.0, 100.0), rel=1e-12)
    n = box.dipole_direction
    assert math.degrees(math.acos(abs(n[0]))) == pytest.approx(35.0, abs=1e-9)


# --- the spec ----------------------------------------------------------------------------------
GOOD = {"models": ["reduced"], "grid": {"delta": {"min": -1.0, "max": 1.0, "cells": 3}, "chi_deg": [10.0, 45.0]},
        "members": {"count": 2, "seed": 1, "omega": 0.1}, "run": {"tau_end": 1e6}}


def test_spec_grid_and_identity():
    s = parse_spec(GOOD, "g.toml")
    assert s.deltas.tolist() == pytest.approx([-2 / 3, 0.0, 2 / 3], abs=1e-15) and s.deltas[1] == 0.0   # exactly 0: (5.2)
    assert np.degrees(s.chis).tolist() == pytest.approx([10.0, 45.0])
    assert s.runs == 3 * 2 * 2 and s.omega0.shape == (2, 3)
    assert np.allclose(np.linalg.norm(s.omega0, axis=1), 0.1)
    from spinviz.regimes.store.levels import identity

    same = parse_spec({**GOOD, "title": "renamed"}, "other.toml")
    assert identity(same) == identity(s)                       # the title does not change the numbers
    other = parse_spec({**GOOD, "members": {"count": 2, "seed": 2, "omega": 0.1}}, "g.toml")
    assert identity(other) != identity(s)


def _with(path, value):
    import copy

    d = copy.deepcopy(GOOD)
    node = d
    for k in path[:-1]:
        node = node[k]
    if value is None:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


BAD = [
    (_with(("grid", "colour"), 1), "[grid].colour: unknown key"),
    (_with(("grid", "delta"), []), "[grid].delta: is empty"),
    (_with(("grid", "delta"), {"min": 0.5, "max": -0.5, "cells": 4}), "[grid.delta].max: must exceed min"),
    (_with(("grid", "delta"), {"min": -1.5, "max": 0.5, "cells": 4}), "[grid.delta].min: the range must lie within (-1, 1)"),
    (_with(("grid", "delta"), [1.0]), "[grid].delta: 1 is outside (-1, 1)"),
    (_with(("grid", "delta"), {"min": -1.0, "max": 1.0, "cells": 0}), "[grid.delta].cells: must lie in [1, 4096], got 0"),
    (_with(("grid", "chi_deg"), [10.0, 95.0]), "[grid].chi_deg: 95 is outside [0, 90] deg"),
    (_with(("grid", "chi_deg"), [45.0, 10.0]), "[grid].chi_deg: values must increase"),
    (_with(("members", "count"), 0), "[members].count: must lie in [1, 100000], got 0"),
    (_with(("members", "count"), -3), "[members].count: must lie in [1, 100000], got -3"),
    (_with(("members", "omega"), 50.0), "[members].omega: must lie in [1e-07, 10] (tau0 |Omega| << 1 above"),
    (_with(("members", "list"), [[0.0, 0.1, 0.0]]), "[members].count: give list (explicit starts) or count"),
    (_with(("run", "tau_end"), 10.0), "[run].tau_end: tau_end/tau_start spans 3 decades"),
    (_with(("run", "rtol"), 0.5), "[run].rtol: must lie in"),
    (_with(("models",), ["reduced", "free"]), "models: unknown model 'free'"),
    (_with(("grid",), None), "[grid]: missing table"),
]


@pytest.mark.parametrize("data, message", BAD)
def test_spec_bad_input_one_line(data, message):
    with pytest.raises(SceneError) as e:
        parse_spec(data, "bad.toml")
    text = str(e.value)
    assert text.startswith("bad.toml: ") and message in text and "\n" not in text


def test_shipped_specs_are_valid():
    specs = sorted((ROOT / "scenes").glob("atlas_*.toml"))
    assert specs
    for p in specs:
        s = load_spec(p)
        assert s.runs > 0 and s.settings.tau_end >= 1e8


def test_command_bad_spec_exit_2_nothing_written(tmp_path):
    """As a command: one line on stderr, exit status 2, no store."""
    bad = tmp_path / "bad.toml"
    bad.write_text('models = ["reduced"]\n[grid]\ndelta = [0.5]\nchi_deg = [30.0]\n[members]\ncount = 0\nseed = 1\n')
    out = tmp_path / "a.zarr"
    r = subprocess.run([sys.executable, "-m", "spinviz", "atlas", str(bad), "--out", str(out)], capture_output=True,
                       text=True, cwd=ROOT)
    assert r.returncode == 2
    assert r.stderr.strip() == f"spinviz: error: {bad}: [members].count: must lie in [1, 100000], got 0"
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_import_is_light():
    """``import spinviz.regimes`` loads neither numba nor dask nor matplotlib."""
    code = ("import sys, spinviz.regimes\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'numba', 'dask', 'distributed', 'matplotlib', 'zarr'}))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0 and r.stdout.strip() == "[]", r.stderr


def test_plan_covers_exactly_the_missing_runs():
    """Batches tile the missing runs exactly (never a done one), inside one storage chunk each."""
    from spinviz.regimes.engine.runs import plan
    from spinviz.regimes.store.levels import chunk_shape

    s = parse_spec({**GOOD, "members": {"count": 5, "seed": 1, "omega": 0.1}}, "g.toml")
    chunks = chunk_shape(s)
    done = np.zeros((1, 3, 2, 5), dtype=bool)
    done[0, 1, 0, 1:4] = True
    done[0, 2] = True
    batches, keys, expected = plan(s, chunks, done, runs_per_task=4)
    cover = np.zeros_like(done, dtype=int)
    for b in batches:
        m, (d0, d1), (c0, c1), (m0, m1) = b.region
        cover[m, d0:d1, c0:c1, m0:m1] += 1
        assert b.runs == (d1 - d0) * (c1 - c0) * (m1 - m0) and b.runs <= 5
        assert c0 // chunks[2] == (c1 - 1) // chunks[2]                        # inside one chunk
    assert np.array_equal(cover, (~done).astype(int))
    assert sum(expected.values()) == len(batches) == len(keys)


@pytest.mark.parametrize("delta, chi, slow", [(0.3, 0.72, -0.0396), (0.8, math.radians(11.4), -0.4598),
                                              (-0.6, math.radians(77), -0.1049)])
def test_type_3_is_the_fixed_point_of_4_12_and_how_fast_it_attracts(delta, chi, slow):
    """(4.12) for x = omega_perp^2 tau, y = omega3^2 tau against ln tau: dx/ds = x (1 - 2 (a x + b y)),
    dy/ds = y (1 - 2 (c x + e y)).  Its interior fixed point is (4.16)'s (A^2, B^2), also at
    delta < -1/2; the slow eigenvalue there says why type 3's amplitudes settle so slowly."""
    a_, b_ = (-np.array(CF.averaged_rate_eq4_12(1.0, y, delta, chi)[0]) for y in (0.0, 1.0))
    a, b = a_, b_ - a_
    e = -CF.averaged_rate_eq4_12(0.0, 1.0, delta, chi)[1]
    c = -CF.averaged_rate_eq4_12(1.0, 1.0, delta, chi)[1] - e
    x, y = np.linalg.solve(2.0 * np.array([[a, b], [c, e]]), [1.0, 1.0])
    f = FM.type3_eq4_16(delta, chi)
    assert x == pytest.approx(f["A2"], rel=1e-12) and y == pytest.approx(f["B2"], rel=1e-12)
    jac = np.array([[-2 * a * x, -2 * b * x], [-2 * c * y, -2 * e * y]])
    assert sorted(np.linalg.eigvals(jac).real) == pytest.approx([-1.0, slow], abs=1e-4)


PHYSICAL_POINTS = [  # one point per domain of figure 2 (reduced) and per truncated type
    ("1", "reduced", -0.6, 17.2), ("2", "reduced", 0.5, 22.0), ("3", "reduced", 0.8, 11.4), ("4", "reduced", 0.5, 39.0),
    ("5", "reduced", 0.8, 68.8), ("T2", "truncated", -0.6, 60.0), ("T4", "truncated", 0.5, 22.0),
    ("Tcone", "truncated", -0.3, 20.0), ("TF", "truncated", 0.8, 68.8),
]


@pytest.mark.parametrize("name,model,delta,chi_deg", PHYSICAL_POINTS, ids=[p[0] for p in PHYSICAL_POINTS])
def test_dimensionless_atlas_runs_match_physical_unit_simulate(name, model, delta, chi_deg):
    """The atlas's (4.2)-(4.4) (or the truncated analogue), dimensionless, in
    heyoka's batch mode, against spinviz.simulate on a CGS body with the same delta, chi and
    tau0 = 1e-20 s (Omega0 ~ 1e19 rad/s), the general (2.2)+(2.3) or (2.5), mapped through
    (4.1): every sample within 1e-7 relative to tau = 1e6 (both at rtol 1e-10; measured <= 3e-9
    to tau = 1e8, spinviz atlas evidence physical)."""
    from spinviz.validation.atlas import physical as PC

    rows = PC.compare([(name, model, delta, chi_deg)], members=2, tau_end=1e6)
    for r in rows:
        assert r["end_rel_diff"] < 1e-7, r
        assert r["label_atlas"] == r["label_physical"], r


def test_the_diagrams_delta_axis_names_each_side_by_its_bodies():
    """delta = 1 - I3/I1 > 0 is prolate (the cellulose rod, I3 < I1), delta < 0 oblate (the
    DAST family-1 plate, I3 > I1): the axis label puts "oblate" left of 0 and "prolate" right."""
    from spinviz.physics.presets import PRESETS
    from spinviz.regimes.figures.style import DELTA_AXIS

    rod, plate = PRESETS["cellulose_rod"](), PRESETS["dast_family1"]()
    assert rod.inertia[2] < rod.inertia[0] and 1 - rod.inertia[2] / rod.inertia[0] > 0.9
    assert 1 - plate.inertia[2] / plate.inertia[0] == pytest.approx(-0.6, abs=0.01)
    left, right = DELTA_AXIS.split("\u2190 0 \u2192")
    assert left.rstrip().endswith("oblate") and right.lstrip().startswith("prolate")
