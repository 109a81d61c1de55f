"""``spinviz compare``: the angles between the two predictions and the final states."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from spinviz import plotting as PL
from spinviz.analysis import compare as CMP
from spinviz.commands import main
from spinviz.driver import simulate
from spinviz.physics import bodies as B
from spinviz.physics import presets as P

SCENES = Path(__file__).resolve().parents[1] / "scenes"


def test_first_crossing_interpolates():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    a = np.array([0.0, 0.5, 1.5, 20.0])
    assert CMP.first_crossing(t, a, 1.0) == pytest.approx(1.5)
    assert CMP.first_crossing(t, a, 10.0) == pytest.approx(2.0 + 8.5 / 18.5)
    assert CMP.first_crossing(t, a, 50.0) is None


def test_resolved_askew_comparison_grows_from_zero():
    """Same start, two models: the orientations agree at t = 0 and part later, 1 deg before 10 deg."""
    body = B.symmetric_top(-0.6, math.radians(55.0))
    t = CMP.compare_times(200.0, 200)
    trajs = [simulate(body, m, (0.05, 0.1, 0.2), t_eval=t) for m in ("reduced", "truncated")]
    c = CMP.compare(trajs)
    assert c.phase_resolved
    assert c.misorientation_deg[0] == 0.0 and c.dipole_angle_deg[0] == 0.0
    one, ten = c.first_exceed["misorientation"]["1 deg"], c.first_exceed["misorientation"]["10 deg"]
    assert 0.0 < one < ten < 200.0
    # the crossing is where the curve says it is
    assert np.interp(one, c.t, c.misorientation_deg) == pytest.approx(1.0, abs=0.05)


def test_dast_cube_final_states_residual_rotation_vs_rest():
    """Real DAST cube over 6 Theta: reduced ends rotating about d at |Omega3| (5.2)/(6.7);
    truncated spins down by the power law of (6.9), exponent -(tau0 W^2 t)/F^2 -> -6/13 here."""
    cube = P.dast_cube()
    W = math.pi * 1e10
    Th = 1.0 / (cube.tau0 * W**2)
    t = CMP.compare_times(6.0 * Th, 200)
    trajs = [simulate(cube, m, (0.0, W, W), t_eval=t) for m in ("reduced", "truncated")]
    c = CMP.compare(trajs)
    assert not c.phase_resolved and c.misorientation_deg is None       # 1e16 turns: not comparable turn by turn
    red, tru = c.models
    assert red.final_state.startswith("residual rotation about the dipole")
    assert red.omega_ratio == pytest.approx(1 / math.sqrt(2), rel=1e-3)      # |Omega| -> Omega30 = |Omega0|/sqrt(2)
    assert tru.final_state.startswith("spinning down to rest")
    assert tru.spin_exponent == pytest.approx(-0.45, abs=0.03)
    assert tru.angle_d_L_deg[-1] == pytest.approx(45.0, abs=1e-6)              # (6.10)
    assert c.first_exceed["angle(d, L)"]["1 deg"] < c.first_exceed["angle(d, L)"]["10 deg"] < 6.0 * Th


@pytest.mark.slow
def test_compare_command_json_and_plots(tmp_path, capsys):
    code = main(["compare", str(SCENES / "hodograph_askew.toml"), "--out", str(tmp_path / "h"), "--samples", "200", "--json"])
    assert code == 0
    rec = json.loads(capsys.readouterr().out)
    assert rec["phase_resolved"] is True
    assert [m["model"] for m in rec["models"]] == ["reduced", "truncated"]
    from PIL import Image

    for p in rec["plots"]:
        w, h = Image.open(p).size
        assert w > 600 and h > 300


def test_compare_needs_two_models(tmp_path, capsys):
    assert main(["compare", str(SCENES / "check_6_10_cube_truncated.toml"), "--out", str(tmp_path / "x")]) == 2
    assert "compare needs two models" in capsys.readouterr().err


@pytest.mark.slow
def test_compare_plots_units_colours_thresholds_and_shared_hodograph_axes(monkeypatch):
    """The plots as a reader gets them: every axis says its unit, the time axis is logarithmic
    (no symlog "0" over "10⁻³") in τ₀ here, the 1° and 10° lines are labelled, each model has one
    colour on every panel (the videos' colour), and the two hodographs share their axis ranges."""
    figs = []
    monkeypatch.setattr(CMP, "save", lambda fig, path: figs.append(fig))
    body = B.symmetric_top(-0.6, math.radians(55.0))
    t = CMP.compare_times(300.0, 150)
    c = CMP.compare([simulate(body, m, (0.05, 0.1, 0.2), t_eval=t) for m in ("reduced", "truncated")])
    CMP.plot(c, "unused.png", "askew")
    CMP.plot_hodograph(c, "unused.png", "askew")
    fig, hodo = figs
    axes = fig.axes
    for ax in axes:
        assert ax.get_xscale() == "log" and ax.get_xlabel() == "time t (τ₀), log scale"
        assert "(" in ax.get_ylabel() and ")" in ax.get_ylabel(), ax.get_ylabel()
    assert "Ω" in axes[1].get_ylabel() or "ω" in axes[1].get_ylabel()
    notes = {x.get_text() for x in axes[0].texts}
    assert {"1° apart", "10° apart"} <= notes
    for ax in axes[1:]:
        colors = {line.get_label(): line.get_color() for line in ax.get_lines()}
        assert colors == {"reduced": PL.model_color("reduced"), "truncated": PL.model_color("truncated")}
    assert PL.model_color("reduced") != PL.model_color("truncated")
    a, b = hodo.axes[:2]
    assert a.get_xlim() == b.get_xlim() and a.get_ylim() == b.get_ylim() and a.get_zlim() == b.get_zlim()
    assert a.get_xlabel() == "ω₁ / |ω₀|"
    import matplotlib.pyplot as plt

    plt.close("all")


def test_time_unit_for_people():
    year = 365.25 * 86400.0
    assert PL.time_unit(19 * 86400.0, "cgs") == (86400.0, "time t (days)")
    assert PL.time_unit(6.6e6 * year, "cgs") == (1e6 * year, "time t (million years)")
    assert PL.time_unit(1200.0, "dimensionless") == (1.0, "time t (τ₀)")
