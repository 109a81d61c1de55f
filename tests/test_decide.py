"""How long to watch (analysis.decide): the Monte Carlo's model is the closed forms', its fits
recover a noise-free truth exactly, its Z is the likelihood ratio, its answer does not depend on
how the trials are batched or where they run, and the 5 sigma time is stable against the
Monte Carlo's size."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from spinviz.analysis import decide as DC
from spinviz.commands import main
from spinviz.executors.processes import ProcessMapper
from spinviz.inputs.decide import DecideArguments
from spinviz.inputs.scene_spec import load_scene
from spinviz.physics import models as M

ROOT = Path(__file__).resolve().parents[1]
CUBE = ROOT / "scenes" / "dast_cube.toml"


@pytest.fixture(scope="module")
def cube_setup():
    sc = load_scene(CUBE)
    return DC.setup_from_scene(sc, sc.observe.receiver, sc.t_end)


def short(setup, horizon=600.0, **kw):
    """The cube's setup watched for ``horizon`` s only (fewer records: quick trials)."""
    return dataclasses.replace(setup, horizon=horizon, **kw)


class Zeros:
    """A stand-in generator whose normal draws are all zero: noise-free records."""

    def standard_normal(self, shape):
        return np.zeros(shape)


def test_prediction_is_the_closed_forms(cube_setup):
    """The Monte Carlo's model of the line is physics.longitudinal's (5.2), (5.4)."""
    t = np.geomspace(1.0, 1e6, 50)
    w0, share = 3.1e21, 0.37
    for model in M.with_line_law():
        f, y = DC._prediction(model, t, w0, share, cube_setup.tau0)
        f2, shape = M.get(model).line.line(t, share * w0, (1 - share) * w0, cube_setup.tau0)
        assert np.allclose(f, f2, rtol=1e-14) and np.allclose(y, np.log(shape), rtol=1e-13)


@pytest.mark.parametrize("truth", M.with_line_law())
def test_noise_free_records_give_back_the_start(cube_setup, truth):
    """From noise-free records the true model's fit returns the start (omega_L0^2 to 1e-14, the share
    sin^2 theta_L0 to 1e-9) with chi2 ~ 0, and Z is the other model's chi2 to the 1/2 power."""
    setup = short(cube_setup)
    start = DC.Start(u0=0.6 * 2e21, b0=0.4 * 2e21, cos_alpha=0.3, psi0=0.2)
    rec = DC.observe_trial(setup, start, truth, Zeros())
    assert rec.end.size > 10
    chi, x = DC.fit(truth, rec, start, setup.tau0, False, [np.array([1e-9, 0.55, 0.0])])
    assert chi < 1e-6 and abs(x[0]) < 1e-14 and x[1] == pytest.approx(0.6, abs=1e-9)
    other = "truncated" if truth == "reduced" else "reduced"
    chi_other, _ = DC.fit(other, rec, start, setup.tau0, False, [np.array([0.0, 0.6, 0.0]), np.array([0, 1.0, 0])])
    z = DC.z_at(rec, truth, start, setup, {})
    assert z == pytest.approx(math.sqrt(chi_other - chi), rel=1e-6) and z > 5


def test_fitted_tau0_cannot_reject_the_reduced_model_for_a_truncated_truth(cube_setup):
    """With tau0 free the reduced model spun exactly across d (b0 = 0) is the truncated one (3.9)
    with tau0 sin^2 theta_L0: from noise-free truncated records its fit is as good (Z ~ 0), while a
    known tau0 rejects it."""
    start = DC.Start(u0=0.6 * 2e21, b0=0.4 * 2e21, cos_alpha=0.3, psi0=0.2)
    known = short(cube_setup, horizon=3000.0)
    rec = DC.observe_trial(known, start, "truncated", Zeros())
    assert DC.z_at(rec, "truncated", start, known, {}) > 5
    fitted = short(cube_setup, horizon=3000.0, tau0_mode="fitted")
    assert abs(DC.z_at(rec, "truncated", start, fitted, {})) < 1e-2


@pytest.mark.slow
def test_results_do_not_depend_on_batching_or_processes(cube_setup):
    """Each trial has its own seed: in this process in one batch and over two worker processes in
    batches of one, the decision times are the same numbers."""
    setup = short(cube_setup, horizon=300.0)
    a = DC.run(setup, 3, seed=7, batch=3)
    with ProcessMapper(2) as m:
        b = DC.run(setup, 3, seed=7, mapper=m, batch=1)
    for truth in M.with_line_law():
        assert np.array_equal(a.times(truth), b.times(truth))
    assert np.all(np.isfinite(a.times("reduced")))
    import json

    json.dumps(a.record(), allow_nan=False)                # strict JSON: None for never


@pytest.mark.slow
def test_z_stays_above_five_after_the_decision(cube_setup):
    """The bisection takes Z to grow with the observation: at twice each trial's decision time Z is
    still at least 5 (two trials, both truths)."""
    setup = short(cube_setup, horizon=1000.0)
    rows = DC.run_trials(setup, 3, [0, 1])
    seqs = np.random.SeedSequence(3).spawn(2)
    for i, row in enumerate(rows):
        rng = np.random.default_rng(seqs[i])
        start = DC.draw_start(setup, rng)
        for truth in M.with_line_law():
            rec = DC.observe_trial(setup, start, truth, rng)
            t = row[truth]["t"]
            if not math.isfinite(t):
                continue
            n = int(np.searchsorted(rec.end, 2 * t)) + 1
            assert DC.z_at(rec.upto(min(n, rec.end.size)), truth, start, setup, {}) >= DC.DECISION_Z, (i, truth, t)


def test_quantile_and_fraction():
    t = np.array([1.0, 2.0, 3.0, np.inf] + [0.5] * 16)
    assert DC.quantile_time(t) == 3.0 and DC.quantile_time(t, 0.96) == math.inf


@pytest.mark.slow
def test_the_five_sigma_time_is_stable_against_the_monte_carlo_size(cube_setup):
    """The DAST cube, default receiver, tau0 known, watched for an hour (every decided trial of the
    19-day run is decided within 20 min): 96 trials (seed 1) and 384 (seed 2) give the same time to
    5 sigma in 95 % of trials within their Monte Carlo uncertainty -- their 95 % order-statistic
    intervals overlap (two independent such intervals of one quantity miss each other in well
    under 1 % of cases) -- and the larger run's interval is finite and the narrower (the smaller
    run's may be unbounded above: its upper end falls among the ~2 % of trials never decided)."""
    from spinviz.executors.processes import usable_cores

    setup = short(cube_setup, horizon=3600.0)
    with ProcessMapper(usable_cores()) as m:
        small = DC.run(setup, 96, seed=1, mapper=m)
        large = DC.run(setup, 384, seed=2, mapper=m)
    for truth in M.with_line_law():
        a, b = small.t95[truth], large.t95[truth]
        ia, ib = (DC.quantile_interval(o.times(truth), level=0.95) for o in (small, large))
        assert all(math.isfinite(x) for x in (a, b, ia[0], *ib)), (truth, a, b, ia, ib)
        assert ia[0] <= ib[1] and ib[0] <= ia[1], (truth, a, b, ia, ib)
        assert math.log(ib[1] / ib[0]) < math.log(ia[1] / ia[0])


@pytest.mark.slow
def test_quantile_interval_covers_the_quantile():
    """The order-statistic interval holds the true 95 % quantile of a known distribution in at
    least its level of repeated samples, and not much more once the trials are many (1000 samples
    of exponential times: 0.71 and 0.955 measured at 400 a sample; 0.83 and 0.90 would be at 48
    without the unbounded upper end).  The 1000 samples' own scatter is ~1.5 %."""
    rng = np.random.default_rng(5)
    true = -math.log(0.05)
    for n, level, most in ((48, 0.95, 1.0), (400, 0.68, 0.76), (400, 0.95, 0.99)):
        hits = [lo <= true <= hi for lo, hi in (DC.quantile_interval(rng.exponential(size=n), level=level)
                                                for _ in range(1000))]
        assert level - 0.04 < np.mean(hits) <= most, (n, level, np.mean(hits))


@pytest.mark.parametrize("argv,message", [
    (["--trials", "3"], "--trials: must lie in [8, 100000]"),
    (["--spin-range", "2,1"], "--spin-range: must be LO,HI with 1e-3 <= LO <= HI <= 1e3"),
    (["--spin-range", "2"], "argument --spin-range: expected two numbers LO,HI"),
    (["--tau0", "maybe"], "argument --tau0: invalid choice"),
    (["--distance-cm", "-1"], "--distance-cm: must lie in"),
])
def test_bad_arguments_are_one_line_exit_2(argv, message, capsys):
    try:
        code = main(["decide", str(CUBE), *argv])
    except SystemExit as e:
        code = e.code
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("body,message", [
    ('preset = "dast_family1"', "decide needs a dipole along the symmetry axis (chi = 0) or a spherical top"),
    ("delta = 0.3\nchi = 0.0", "decide needs a body in physical units (CGS)"),
])
def test_scenes_decide_cannot_take(body, message, tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(f'[body]\n{body}\n[initial]\nomega = [0.0, 0.05, 0.3]\n[simulation]\n'
                     f'models = ["reduced", "truncated"]\nt_end = 100.0\nsamples = 10\n')
    code = main(["decide", str(scene), "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not list(tmp_path.glob("x*"))


def test_decide_arguments_schema():
    assert DecideArguments().trials == 200 and DecideArguments(tau0="fitted").tau0 == "fitted"


@pytest.mark.slow
def test_dask_runs_the_same_trials(cube_setup, monkeypatch, capsys, tmp_path):
    """From DASK_TRIALS trials the command runs them on the atlas's Dask cluster (an embedded
    LocalCluster here, one worker): the same decision times as in this process."""
    import json

    from spinviz import experiment

    monkeypatch.setattr(experiment, "DASK_TRIALS", 8)
    code = main(["decide", str(CUBE), "--trials", "8", "--workers", "1", "--json", "--out", str(tmp_path / "c")])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "decide: 8 trials on embedded LocalCluster, 1 worker" in captured.err
    rec = json.loads(captured.out)
    here = DC.run(cube_setup, 8, seed=1)
    for truth in M.with_line_law():
        assert rec["decision_times_s"][truth] == [x if math.isfinite(x) else None for x in here.times(truth)]
    assert (tmp_path / "c_decide.png").stat().st_size > 30_000
