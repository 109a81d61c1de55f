"""Every horizon judged before any work by the method that will run it: a run ``auto`` hands
over (``taylor -> secular``) is estimated through both stages -- the turns of the full stage,
the steps of the slow flow and the range of float64 it stays in -- and so is a ``secular``
run; one that cannot finish is refused at once (``SpecError`` naming the key, exit 2 on the
command line), wherever the horizon comes from: ``simulate``, a scene's ``[simulation]``, its
``[observe]`` horizon.  The refusal costs CPU time, not the run's: it is measured as such.
A run that fails late says the instant at which it failed."""

import math
import time

import numpy as np
import pytest

import spinviz
from spinviz.driver import simulate
from spinviz.errors import SceneError, SimulationError, SpecError
from spinviz.inputs.scene_spec import parse_scene
from spinviz.integrators import secular as SC
from spinviz.physics import bodies as B
from spinviz.physics import presets as P

TOP = B.symmetric_top(0.3, 0.7)
W0 = (0.0, 0.05, 0.3)                  # tau0 |Omega0| = 0.3: not fast, so auto hands the run over
CUBE_W0 = (0.0, math.pi * 1e10, math.pi * 1e10)
REFUSAL_CPU_S = 0.5                    # the refusal's own cost (the runs it spares take 37 s and minutes)

HANDOVER_SCENE = {
    "body": {"delta": 0.3, "chi": 0.7},
    "initial": {"omega": list(W0)},
    "simulation": {"model": "reduced", "t_end": 1e300, "samples": 11},
}
CUBE_SCENE = {
    "body": {"preset": "dast_cube"},
    "initial": {"omega": list(CUBE_W0), "euler_zxz_deg": [0.0, 45.0, 0.0]},
    "simulation": {"models": ["reduced", "truncated"], "t_end_Theta": 1e30, "samples": 50},
}


def refused(fn):
    """The error ``fn()`` raises and the CPU seconds it took to raise it."""
    t0 = time.process_time()
    with pytest.raises((SpecError, SceneError)) as e:
        fn()
    return e.value, time.process_time() - t0


def with_(scene: dict, table: str, **keys) -> dict:
    return {**scene, table: {**scene.get(table, {}), **keys}}


def test_a_handed_over_horizon_beyond_float64_is_refused_at_once():
    """t_end = 1e300 for a top auto hands over to secular: the slow flow's spin would fall below
    what its rates hold in float64 (they overflow after ~37 s of work); refused before it,
    naming t_end and how far the slow flow can go."""
    e, cpu = refused(lambda: simulate(TOP, "reduced", W0, t_end=1e300, samples=11))
    assert e.key == "t_end" and "\n" not in str(e), e
    assert "secular" in e.reason and "float64" in e.reason and "of this horizon" in e.reason, e.reason
    assert cpu < REFUSAL_CPU_S, cpu


def test_a_secular_horizon_beyond_the_step_limit_is_refused_at_once():
    """The DAST cube to 1e30 Theta: at its residual rotation the slow flow's explicit steps are
    held by the decay of omega_perp (~0.16 a Theta, measured), 1e29 steps; refused before the
    minutes it would run, by auto and by method = "secular" alike."""
    cube = P.dast_cube()
    theta = cube.residual_time_Theta(CUBE_W0[2])
    for method in ("auto", "secular"):
        e, cpu = refused(lambda m=method: simulate(cube, "reduced", CUBE_W0, t_end=1e30 * theta, samples=11, method=m))
        assert e.key == "t_end" and "steps" in e.reason and f"at most {SC.MAX_STEPS:g}" in e.reason, e.reason
        assert cpu < REFUSAL_CPU_S, (method, cpu)


@pytest.mark.parametrize("where", ["simulation", "observe"])
def test_a_scene_horizon_that_cannot_finish_is_refused_naming_its_key(where):
    """Through a scene: [simulation]'s horizon and [observe]'s (which observe simulates), each
    named by the key that set it."""
    if where == "simulation":
        cube = CUBE_SCENE
    else:
        cube = with_(with_(CUBE_SCENE, "simulation", t_end_Theta=6.0), "observe", t_end_Theta=1e30)
    e, cpu = refused(lambda: parse_scene(cube, "cube.toml"))
    assert e.key == f"[{where}].t_end_Theta" and "at most" in e.reason, e
    assert cpu < REFUSAL_CPU_S, cpu
    hand = HANDOVER_SCENE if where == "simulation" else with_(
        with_(HANDOVER_SCENE, "simulation", t_end=1e6), "observe", t_end=1e300)
    e, cpu = refused(lambda: parse_scene(hand, "hand.toml"))
    assert e.key == f"[{where}].t_end" and "float64" in e.reason, e
    assert cpu < REFUSAL_CPU_S, cpu


def test_the_command_line_refuses_it_in_one_line(tmp_path, capsys):
    from spinviz.commands import main

    from tomlgen import dumps

    scene = tmp_path / "hand.toml"
    scene.write_text(dumps(HANDOVER_SCENE))
    assert main(["simulate", str(scene), "--out", str(tmp_path / "t.npz")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"spinviz: error: {scene}: [simulation].t_end: "), err
    assert not (tmp_path / "t.npz").exists()


def test_horizons_within_the_limits_are_accepted():
    """The limits are where the runs stop working, not lower: a hand-over to 1e100 (it finishes:
    the slow test) and the cube's requests to 1e6 Theta (1.6e5 steps, 0.3 s, measured) are
    accepted."""
    spinviz.SimulationRequest(body=TOP, model="reduced", omega0=W0, t_end=1e100, samples=5)
    cube = P.dast_cube()
    spinviz.SimulationRequest(body=cube, model="reduced", omega0=CUBE_W0,
                              t_end=1e6 * cube.residual_time_Theta(CUBE_W0[2]), samples=11)


@pytest.mark.slow
def test_a_long_accepted_horizon_finishes():
    tr = simulate(TOP, "reduced", W0, t_end=1e100, samples=5)
    assert tr.stats["method"] == "taylor -> secular" and np.all(np.isfinite(tr.omega_body))


def test_a_run_failing_late_names_the_instant_it_failed(monkeypatch):
    """A hand-over whose slow flow gives up (here: its step limit lowered below what the run
    needs) names when: after the hand-over, inside the horizon -- not the last sample it had
    reached."""
    monkeypatch.setattr(SC, "MAX_STEPS", 9000)             # the secular stage takes ~1e4 steps
    with pytest.raises(SimulationError) as e:
        simulate(TOP, "reduced", W0, t_end=1e20, samples=11)
    msg = str(e.value)
    assert "exceeded the step limit" in msg and "\n" not in msg, msg
    at = float(msg.split("(at t = ", 1)[1].split(";", 1)[0])
    handed = float(msg.split("handed over at t = ", 1)[1].rstrip(")"))
    assert 0.0 < handed < at < 1e20, msg
