"""decide with what must be known and what the trap does (analysis.nuisance, analysis.decide_env,
analysis.requirements): the records' likelihood is the Kalman filter's, the perfect experiment
is the vacuum's bit for bit, the decision time grows with the pressure until the gas decides
nothing, the requirements' search finds the edge, the answers are stable against the trials'
number, and a stop signal ends a requirements run clean."""

import dataclasses
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from spinviz import experiment
from spinviz.analysis import decide as DC
from spinviz.analysis import nuisance as NU
from spinviz.analysis import requirements as RQ
from spinviz.errors import SpecError
from spinviz.inputs.decide import DecideArguments
from spinviz.inputs.scene_spec import load_scene

ROOT = Path(__file__).resolve().parents[1]
CUBE = ROOT / "scenes" / "dast_cube.toml"


@pytest.fixture(scope="module")
def cube():
    return load_scene(CUBE)


def test_the_records_likelihood_is_the_kalman_filters():
    """The records' covariance (random walk of intensity q, white noise) factored once gives the
    same -2 ln L as the scalar Kalman filter run over the records one by one."""
    rng = np.random.default_rng(1)
    t = np.sort(rng.uniform(1.0, 100.0, 30))
    sigma = rng.uniform(0.5, 2.0, 30)
    q = 0.7
    y = np.cumsum(rng.standard_normal(30)) + sigma * rng.standard_normal(30)
    Q = q * t                                   # the walk's variance at the nodes
    C = np.minimum.outer(Q, Q) + np.diag(sigma**2)
    L = np.linalg.cholesky(C)
    z = np.linalg.solve(L, y)
    chol = float(z @ z + 2.0 * np.sum(np.log(np.diag(L))))
    assert chol == pytest.approx(NU.kalman_loglike(y, t, sigma, q), rel=1e-12)
    # and covariance() builds that matrix from one node per record of weight 1
    nu = NU.Nuisances()
    C2 = NU.covariance(t[:, None], np.ones((30, 1)), np.full(30, 1e9), sigma, sigma, nu, Q, 0.0)
    assert np.allclose(C2[0::2, 0::2], C, rtol=1e-14)


def test_the_perfect_experiment_is_the_vacuums_bit_for_bit(cube, monkeypatch):
    """No gas, no field, every prior zero: decide's trials are the vacuum's, the same numbers."""
    from spinviz.analysis import decide_env

    setup = dataclasses.replace(DC.setup_from_scene(cube, cube.observe.receiver, cube.t_end), horizon=6.0)
    a = DC.run_trials(setup, 5, [0])
    monkeypatch.setattr(decide_env, "run_trials", None)          # never reached: the vacuum's own code runs
    b = DC.run_trials(dataclasses.replace(setup, nuisance=NU.Nuisances()), 5, [0])
    assert a == b and math.isfinite(a[0]["reduced"]["t"])
    spec = DecideArguments(trials=8)
    s2 = experiment._decide_setup(cube.with_environment(pressure_mbar=0.0), cube.observe.receiver, spec)
    assert s2.nuisance is None


def test_requirement_search_finds_the_edge(monkeypatch):
    """The search steps up by decades until a value fails and bisects the last decade: on a share
    that falls below 95 % at 3e-11, it answers within 10^(1/16) of it, from below."""
    edge = 3e-11
    calls = []

    class Probe:
        stated = {k: 0.0 for k in RQ.KEYS}

        def __call__(self, key, value, horizon_only):
            calls.append((value, horizon_only))
            return (1.0 if value <= edge else 0.5), (None if horizon_only else {"reduced": 10.0, "truncated": 12.0})

    r = RQ.search(Probe(), "pressure_mbar")
    assert r.value <= edge and r.value > edge / 10 ** (1 / 16) and not r.at_least
    assert not calls[0][1] and calls[-1][1]         # the decades keep their decision times, the bisection does not
    assert [p[0] for p in r.probes] == sorted(p[0] for p in r.probes)


def test_requirements_refuse_work_beyond_the_cap(monkeypatch, cube):
    """The requirements' Monte Carlo is estimated before it starts and refused above SPINVIZ_MAX_DAYS."""
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "0.001")
    with pytest.raises(SpecError, match="SPINVIZ_MAX_DAYS") as e:
        experiment.requirements(cube, trials=400, workers=1)
    assert e.value.key == "trials"


def test_decide_arguments_for_the_priors():
    """The priors' ranges, and tau0 given two ways at once, are refused naming the argument."""
    for key, bad in (("tau0_prior", -0.1), ("gain_slope", 50.0), ("clock_stability", 1.0), ("pressure_prior", math.inf)):
        with pytest.raises(SpecError) as e:
            DecideArguments(**{key: bad})
        assert e.value.key == key
    with pytest.raises(SpecError) as e:
        DecideArguments(tau0="fitted", tau0_prior=0.01)
    assert e.value.key == "tau0_prior"


def test_environment_options_are_the_tables_keys(cube):
    """decide's environment keywords are [environment]'s, checked by its schema and against the body."""
    with pytest.raises(SpecError) as e:
        experiment.decide(cube, trials=8, pressure_mbar=-1.0)
    assert e.value.key == "pressure_mbar"
    with pytest.raises(SpecError, match="mean free path") as e:
        experiment.decide(cube, trials=8, pressure_mbar=500.0)
    assert e.value.key == "pressure_mbar"


@pytest.mark.slow
def test_the_decision_time_grows_with_pressure_until_the_gas_decides_nothing(cube):
    """The cube's decision, eight trials (seed 3) at each pressure: at 1e-14 mbar (a collision every
    ~2 min, each located) the decision times are the vacuum's within a factor 2; at 1e-12 mbar (one
    every 1.5 s: a random walk of the line, ~500 Hz a second) the median is a hundred times longer;
    at 1e-7 mbar (6e4 a second) no trial decides."""
    times = {}
    for p in (0.0, 1e-14, 1e-12, 1e-7):
        out = experiment.decide(cube, trials=8, seed=3, workers=2, pressure_mbar=p)
        times[p] = {m: out.times(m) for m in out.setup.models}
    for m in cube.models:
        vac, located, walk = (np.median(times[p][m]) for p in (0.0, 1e-14, 1e-12))
        assert located < 2.0 * vac and walk > 100.0 * vac, (m, vac, located, walk)
        assert not np.any(np.isfinite(times[1e-7][m]))


@pytest.mark.slow
def test_the_answer_is_stable_against_the_number_of_trials(cube):
    """At 1e-13 mbar, 16 trials (seed 1) and 48 (seed 2): the 95 % times' Monte Carlo intervals
    overlap, and the larger run's interval is no wider."""
    a = experiment.decide(cube, trials=16, seed=1, workers=2, pressure_mbar=1e-13)
    b = experiment.decide(cube, trials=48, seed=2, workers=2, pressure_mbar=1e-13)
    for m in cube.models:
        (lo1, hi1), (lo2, hi2) = a.interval[m], b.interval[m]
        assert lo1 <= hi2 and lo2 <= hi1, (m, a.interval[m], b.interval[m])
        assert math.isfinite(b.t95[m])


@pytest.mark.slow
def test_a_stop_signal_ends_a_requirements_run_clean(tmp_path):
    """SIGTERM during the requirements' Monte Carlo (worker processes running): one line, exit 143,
    nothing written, no process of the command left.  40 trials: with 16 one dark start (spun
    nearly along d) leaves the vacuum's share below 95 %, and the command answers at once."""
    from procs import gone

    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "spinviz", "decide", str(CUBE), "--requirements", "--trials", "40",
                             "--workers", "2", "--out", str(tmp_path / "r")], cwd=tmp_path, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    seen, end = [], time.monotonic() + 120
    while time.monotonic() < end:
        line = proc.stderr.readline()
        seen.append(line)
        if "requirements: at most" in line:
            break
    time.sleep(3.0)                                 # into the vacuum's trials, on the workers
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    lines = [x for x in err.splitlines() if not x.startswith("  ")]
    assert proc.returncode == 143, err
    assert lines == ["spinviz: interrupted by SIGTERM; nothing was written"], err
    assert list(tmp_path.iterdir()) == []
    assert gone(proc.pid) == []


def _requirements(probed: bool):
    """A Requirements answer drawn by hand: every key probed at three values, or none probed."""
    results = {}
    for key in RQ.KEYS:
        probes = [(1e-13, 1.0, {"reduced": 30.0, "truncated": 40.0}), (1e-12, 0.97, {"reduced": 60.0, "truncated": 90.0}),
                  (1e-11, 0.4, {"reduced": math.inf, "truncated": 300.0})] if probed else []
        results[key] = RQ.Requirement(key, 1e-12 if probed else None, False, probes,
                                      "" if probed else "not decided within the horizon even in a perfect vacuum")
    return RQ.Requirements(title="a crystal", stated={k: 0.0 for k in RQ.KEYS}, trials=10, seed=1, horizon=3600.0,
                           vacuum_t95={"reduced": 25.0, "truncated": 35.0}, results=results,
                           models=("reduced", "truncated"))


@pytest.mark.parametrize("probed", [True, False])
def test_the_requirements_figure_says_what_was_probed(tmp_path, probed):
    """The figure: six panels when the keys were probed; one panel saying why when even the
    vacuum does not decide (no empty axes); written whole (a PNG of the stated size)."""
    pytest.importorskip("matplotlib")
    from PIL import Image

    from spinviz.analysis.requirement_plots import plot_requirements

    path = tmp_path / "r.png"
    plot_requirements(_requirements(probed), str(path))
    with Image.open(path) as im:
        w, h = im.size
    assert (w / h < 2.0) == probed                   # the six-panel grid is 17 x 10, the message 9 x 3.6


def test_decide_in_a_gas_is_estimated_at_a_trial_in_gas(monkeypatch, cube):
    """The work cap prices a trial in a gas (collisions located and fitted) at its own measured
    cost, not the vacuum's: a cap that lets the vacuum's 8 trials through refuses the same 8 in
    a gas, before any trial."""
    from spinviz.analysis import decide as DC

    spec = DecideArguments(trials=8, workers=1)
    vacuum = experiment._decide_setup(cube, cube.observe.receiver, spec)
    gas = experiment._decide_setup(cube.with_environment(pressure_mbar=1e-13), cube.observe.receiver, spec)
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", str(2.0 * DC.work_seconds(vacuum, 8) / 86400.0))
    DC.check_work(vacuum, 8, 1)
    with pytest.raises(SpecError, match="SPINVIZ_MAX_DAYS") as e:
        DC.check_work(gas, 8, 1)
    assert e.value.key == "trials"
