"""The start-free power-frequency test (analysis.pftest): each model's own synthetic series is
assigned to its own law and the other's is rejected; the exponent and f_inf come with honest
uncertainties; askew tops have no law; measurement files go through the schema."""

import json
import math

import numpy as np
import pytest

from spinviz.analysis import pftest as PF
from spinviz.commands import main
from spinviz.errors import SceneError
from spinviz.inputs.measurements import read_measurements
from spinviz.physics import bodies as B
from spinviz.physics import models as M
from spinviz.physics import presets as P

W = math.pi * 1e10
TAU0 = 3.7e-27                         # the DAST cube's
F_INF = W / (2 * math.pi)              # its reduced line's limit: Omega3 / 2 pi = 5 GHz


def series(model, t, sigma_lnp, sigma_f, seed, u0=W**2, b0=W**2):
    """The line of ``model`` (closed forms) at times t with Gaussian noise: sigma_lnp on ln P,
    sigma_f (Hz) on f."""
    rng = np.random.default_rng(seed)
    f, shape = M.get(model).line.line(t, u0, b0, TAU0)
    p = 1e-19 * shape / shape[0] * np.exp(sigma_lnp * rng.standard_normal(t.size))
    fo = f + sigma_f * rng.standard_normal(t.size)
    return PF.Series(fo, p, np.full(t.size, sigma_f), sigma_lnp * p, t, "W/sr")


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_reduced_series_is_assigned_to_the_reduced_law(seed):
    """Two days of the cube (7.07 -> 5.4 GHz), 3 % in power: the truncated law is rejected far
    beyond 5 sigma, f_inf's interval holds 5 GHz, the exponent is 4 within 3 of its sigmas."""
    t = np.linspace(60.0, 2 * 86400.0, 400)
    r = PF.fit(series("reduced", t, 0.03, 0.01, seed), f_inf_expected=F_INF)
    assert r.verdict == "reduced" and r.z > 20
    lo, hi = r.f_inf_interval
    assert lo - (hi - lo) <= F_INF <= hi + (hi - lo)           # within 2 of its Delta chi2 = 1 half-widths
    assert abs(r.exponent - 4.0) < 3 * r.exponent_sigma
    assert r.z_expected < 3                                      # the start's own f_inf fits
    assert r.reduced.z_fit < 3 and r.truncated.z_fit > 5


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_truncated_series_is_assigned_to_the_truncated_law(seed):
    """The same receiver on the truncated cube: P = A f^4 fits, f_inf is consistent with 0 and
    bounded far below the reduced start's 5 GHz, which the data reject outright."""
    t = np.linspace(60.0, 2 * 86400.0, 400)
    r = PF.fit(series("truncated", t, 0.03, 0.01, seed), f_inf_expected=F_INF)
    assert r.verdict == "truncated" and r.z < 3
    assert r.f_inf_upper95 is not None and r.f_inf_upper95 < 0.5 * F_INF
    assert abs(r.exponent - 4.0) < 3 * r.exponent_sigma
    assert r.z_expected > 5 and r.truncated.z_fit < 3


def test_a_short_series_decides_nothing():
    """Ten minutes of either model (the frequency moves by 1e-4): the laws cannot be told apart
    from the P-f relation alone, and the test says so instead of guessing."""
    t = np.linspace(60.0, 600.0, 50)
    r = PF.fit(series("reduced", t, 0.03, 0.01, 4))
    assert r.verdict in ("truncated", "undecided") and r.z < 5


def test_neither_law_fits_a_wrong_exponent():
    """A line with P ~ f^2 (not a turning dipole) fits neither law."""
    f = np.linspace(5e9, 7e9, 200)
    p = (f / 7e9) ** 2 * 1e-19
    s = PF.Series(f, p, np.full(200, 0.01), 0.01 * p)
    assert PF.fit(s).verdict == "neither"


def test_which_line_and_law_or_none():
    law, _ = PF.line_law(P.dast_cube())
    assert "|L|/(2π I1)" in law and "P ∝ f⁴ (5.4)" in law
    assert PF.line_law(P.cellulose_rod())[0] is not None
    law, reason = PF.line_law(B.symmetric_top(0.3, 0.7))
    assert law is None and "no power-frequency law" in reason and "χ = 0" in reason and "δ = 0" in reason
    assert PF.line_law(P.dast_family1())[0] is None


def write_csv(path, s, header="t_s,f_hz,power,sigma_f_hz,sigma_power"):
    rows = [",".join(repr(float(x)) for x in row) for row in zip(s.t_s, s.f_hz, s.power, s.sigma_f_hz, s.sigma_power)]
    path.write_text("# the cube's reduced line, synthetic\n" + header + "\n" + "\n".join(rows) + "\n")


def test_measurement_files_give_the_same_test(tmp_path, capsys):
    """A series written as CSV and as JSON reads back exactly and gives the same test as the series
    itself; ``spinviz decide SCENE --measurements FILE`` prints it."""
    s = series("reduced", np.linspace(60.0, 86400.0, 120), 0.03, 0.01, 5)
    csv = tmp_path / "m.csv"
    write_csv(csv, s)
    js = tmp_path / "m.json"
    js.write_text(json.dumps({"f_hz": s.f_hz.tolist(), "power": s.power.tolist(), "sigma_f_hz": s.sigma_f_hz.tolist(),
                              "sigma_power": s.sigma_power.tolist(), "power_unit": "W/sr"}))
    direct = PF.fit(s)
    for path in (csv, js):
        data, unit = read_measurements(path)
        assert np.array_equal(data["f_hz"], s.f_hz) and np.array_equal(data["power"], s.power)
        assert PF.fit(PF.from_measurements(data, unit, str(path))).z == pytest.approx(direct.z, rel=1e-12)
    assert "t_s" in read_measurements(csv)[0] and "t_s" not in read_measurements(js)[0]
    code = main(["decide", "scenes/dast_cube.toml", "--measurements", str(csv)])
    out = capsys.readouterr().out
    assert code == 0 and "verdict: reduced" in out and "the rotation line" in out


BAD = [
    ("m.csv", "f_hz,power,sigma_f_hz\n1,2,3\n", "missing column 'sigma_power'"),
    ("m.csv", "f_hz,power,sigma_f_hz,sigma_power,colour\n", "unknown column 'colour'"),
    ("m.csv", "f_hz,power,sigma_f_hz,sigma_power\n" + "1e9,1,0.1,0.1\n" * 3 + "1e9,-1,0.1,0.1\n",
     "row 4 (line 5), power: must be positive, got -1"),
    ("m.csv", "f_hz,power,sigma_f_hz,sigma_power\n1e9,x,0.1,0.1\n", "row 1 (line 2), power: expected a number, got 'x'"),
    ("m.csv", "f_hz,power,sigma_f_hz,sigma_power\n1e9,1,0.1\n", "row 1 (line 2): 3 values for 4 columns"),
    ("m.csv", "f_hz,power,sigma_f_hz,sigma_power\n1e9,1,0.1,0.1\n", "1 measurements; the test needs 4"),
    ("m.json", '{"f_hz": [1, 2], "power": [1], "sigma_f_hz": [1, 1], "sigma_power": [1, 1]}', "differ in length"),
    ("m.json", '{"f_hz": [1, 2, 3, 4], "power": [1, 1, 1, "a"], "sigma_f_hz": [1, 1, 1, 1], "sigma_power": [1, 1, 1, 1]}',
     "row 4, power: must be a number, got 'a'"),
    ("m.json", "[1, 2]", "must be a JSON object of arrays"),
    ("m.txt", "f_hz\n", "ends in .csv or .json"),
]


@pytest.mark.parametrize("name,text,message", BAD)
def test_bad_measurements_are_one_line_exit_2(name, text, message, tmp_path, capsys):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(SceneError, match=None) as e:
        read_measurements(path)
    assert message in str(e.value) and str(path) in str(e.value)
    code = main(["decide", "scenes/dast_cube.toml", "--measurements", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1


def test_askew_scene_says_it_has_no_law(tmp_path, capsys):
    scene = tmp_path / "askew.toml"
    scene.write_text('[body]\npreset = "dast_family1"\n[initial]\nomega = [0.0, 3e10, 3e10]\n'
                     '[simulation]\nmodels = ["reduced", "truncated"]\nt_end = 100.0\nsamples = 10\n')
    m = tmp_path / "m.csv"
    write_csv(m, series("reduced", np.linspace(60.0, 600.0, 10), 0.03, 0.01, 6))
    assert main(["decide", str(scene), "--measurements", str(m)]) == 0
    assert "no test: a symmetric top with δ = -0.6" in capsys.readouterr().out
