"""Every long command estimates its work before starting and honours ``SPINVIZ_MAX_DAYS``:
``decide`` as its trials times its measured cost per trial (by tau0 mode and the records its
horizon holds), on the workers it will use; the refusal names ``--trials`` (``trials=`` from
Python) and costs nothing of the work it refuses."""

import time
from pathlib import Path

import pytest

from spinviz import experiment
from spinviz.analysis import decide as DC
from spinviz.commands import main
from spinviz.errors import SpecError
from spinviz.inputs import options as O

ROOT = Path(__file__).resolve().parents[1]
CUBE = str(ROOT / "scenes" / "dast_cube.toml")


class Reached(Exception):
    """The trials started."""


@pytest.fixture
def no_work(monkeypatch):
    def reached(*a, **k):
        raise Reached

    monkeypatch.setattr(DC, "run", reached)
    monkeypatch.setattr(DC, "run_trials", reached)
    monkeypatch.setattr(experiment, "_mapper", reached)


def test_decide_is_refused_before_work_above_the_cap(monkeypatch, no_work):
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "1e-9")
    t0 = time.process_time()
    with pytest.raises(SpecError) as e:
        experiment.decide(CUBE, trials=8)
    assert time.process_time() - t0 < 0.5
    assert e.value.key == "trials" and "SPINVIZ_MAX_DAYS" in e.value.reason, e.value
    assert "8 trials" in e.value.reason and "more than the cap of 1e-09 days" in e.value.reason, e.value


def test_the_command_line_names_the_option(monkeypatch, no_work, capsys):
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "1e-9")
    assert main(["decide", CUBE, "--trials", "16", "--tau0", "fitted"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("spinviz: error: --trials: 16 trials"), err


def test_the_estimate_follows_the_trials_the_mode_and_the_workers():
    """Proportional to the trials, ~3x for a fitted tau0 (measured 1.16 s against 0.46 s a trial,
    both models), shared by the workers."""
    from spinviz.inputs.scene_spec import load_scene

    sc = load_scene(CUBE)
    setups = {m: DC.setup_from_scene(sc, sc.observe.receiver, sc.t_end, (0.5, 2.0), m) for m in ("known", "fitted")}
    known = DC.work_seconds(setups["known"], 100, workers=1)
    assert DC.work_seconds(setups["known"], 200, workers=1) == pytest.approx(2 * known)
    assert DC.work_seconds(setups["known"], 200, workers=2) == pytest.approx(known)
    assert 2.5 < DC.work_seconds(setups["fitted"], 100, workers=1) / known < 3.5
    assert 30 < known < 70                                  # ~0.5 s a trial on this machine's core


def test_the_shared_check_for_work_of_alike_pieces(monkeypatch):
    """What other long commands call: units x measured seconds each, over their workers."""
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "1")
    assert O.check_units("runs", 1000, 0.5, "1000 runs", workers=4) == pytest.approx(125.0)
    with pytest.raises(SpecError) as e:
        O.check_units("runs", 1e6, 0.5, "1e6 runs", workers=1)
    assert e.value.key == "runs" and "~5.79 days here, more than the cap of 1 days" in e.value.reason, e.value
