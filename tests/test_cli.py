"""The command line: outputs, exit statuses, one-line errors, atomic writes."""

import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from spinviz import rotations as R
from spinviz.commands import main
from spinviz.inputs.scene_spec import load_scene
from spinviz.physics import closed_forms as CF

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "scenes"

GOOD = """
[body]
delta = 0.3
chi = 0.7
[initial]
omega = [0.0, 0.05, 0.3]
euler_zxz = [0.0, 1.5707963267948966, 0.0]
[simulation]
model = "reduced"
t_end = 100.0
samples = 40
"""


def write(tmp_path, text, name="scene.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_simulate_writes_the_documented_arrays(tmp_path, capsys):
    out = tmp_path / "sub" / "traj.npz"
    code, stdout, err = run(["simulate", write(tmp_path, GOOD), "--out", out], capsys)
    assert code == 0, err
    with np.load(out) as z:
        assert z["t"].shape == (40,) and z["omega"].shape == (40, 3) and z["q"].shape == (40, 4)
        assert z["euler_zxz"].shape == (40, 3)
        np.testing.assert_allclose(z["t"], np.linspace(0, 100, 40))
        np.testing.assert_allclose(z["omega"][0], [0.0, 0.05, 0.3])
        np.testing.assert_allclose(z["q"][0], R.quat_from_euler_zxz([0, math.pi / 2, 0]), atol=1e-15)
        np.testing.assert_allclose(z["euler_zxz"][0], [0, math.pi / 2, 0], atol=1e-15)
        assert np.all(np.abs(np.diff(z["euler_zxz"][:, 0])) < np.pi)          # unwrapped
        meta = json.loads(str(z["metadata"]))
    assert meta["units"] == "dimensionless" and meta["model"] == "reduced"
    assert meta["quaternion_order"].startswith("w, x, y, z")
    assert "40 samples" in stdout


def test_simulate_6_10_scene_reproduces_the_closed_form(tmp_path, capsys):
    """The (6.10) check scene, run from the command line, stays on the exact solution."""
    out = tmp_path / "t.npz"
    code, _, err = run(["simulate", SCENES / "check_6_10_cube_truncated.toml", "--out", out], capsys)
    assert code == 0, err
    with np.load(out) as z:
        exact = CF.euler_eq6_10(z["t"], 1.0, 0.1, 0.1)
        assert R.misorientation(z["q"], R.quat_from_euler_zxz(exact)).max() < 1e-8   # default rtol 1e-10


SHIPPED = sorted(p.name for p in SCENES.glob("*.toml") if not p.name.startswith("atlas_"))   # atlas specs: test_atlas.py


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_scene_loads_as_written(name):
    """What a shipped scene loads is what its file says: the initial spin exactly, the
    orientation of its ZXZ angles (rad or deg; none: the identity) to round-off, its models and
    samples, and its horizon in the unit it is given in -- the paper's T = 1/(tau0 Omega_perp^2)
    or Theta = 1/(tau0 Omega3^2 eps^2) of the start, here from their definitions."""
    doc = tomllib.loads((SCENES / name).read_text())
    initial, sim = doc["initial"], doc["simulation"]
    sc = load_scene(SCENES / name)
    assert np.array_equal(sc.omega0, initial["omega"])
    assert sc.models == tuple(sim["models"] if "models" in sim else [sim["model"]])
    assert sc.samples == sim["samples"]
    angles = (np.radians(initial["euler_zxz_deg"]) if "euler_zxz_deg" in initial
              else np.asarray(initial.get("euler_zxz", (0.0, 0.0, 0.0))))
    assert R.misorientation(sc.q0, R.quat_from_euler_zxz(angles)) < 1e-15
    w1, w2, w3 = initial["omega"]
    tau0, eps = sc.body.tau0, sc.body.I3 / sc.body.I1
    if "t_end_T" in sim:
        assert sc.t_end == pytest.approx(sim["t_end_T"] / (tau0 * (w1 * w1 + w2 * w2)), rel=1e-14)
    elif "t_end_Theta" in sim:
        assert sc.t_end == pytest.approx(sim["t_end_Theta"] / (tau0 * w3 * w3 * eps * eps), rel=1e-14)
    else:
        assert sc.t_end == sim["t_end"]


BAD = [
    ("unknown key", GOOD.replace("chi = 0.7", "chi = 0.7\ncolour = 3"), "[body].colour: unknown key"),
    ("missing value", GOOD.replace("samples = 40", ""), "[simulation].samples: missing value"),
    ("missing table", GOOD.replace("[initial]\nomega = [0.0, 0.05, 0.3]\n", ""), "[initial]: missing table"),
    ("negative size", """
[body]
shape = "rod"
length_nm = -315.0
aspect = 10.0
density = 1.6
dipole_debye = 4400.0
[initial]
omega = [0.0, 3e10, 0.0]
[simulation]
model = "reduced"
t_end = 1e-9
samples = 3
""", "[body].length_nm: must lie in [0.1, 1e+09] (from an atom to a metre), got -315"),
    ("I3 > I1 + I2", GOOD.replace("delta = 0.3\nchi = 0.7", "inertia = [1.0, 1.0, 2.5]\ndipole = [0.0, 0.0, 1.0]"),
     "[body].inertia: I3 = 2.5 exceeds I1 + I2 = 2"),
    ("NaN", GOOD.replace("delta = 0.3", "delta = nan"), "[body].delta: must be finite, got nan"),
    ("zero inertia", GOOD.replace("delta = 0.3\nchi = 0.7", "inertia = [0.0, 1.0, 1.0]\ndipole = [0.0, 0.0, 1.0]"),
     "[body].inertia: principal moments must be positive"),
    ("unknown model", GOOD.replace('model = "reduced"', 'model = "schott"'),
     "[simulation].model: unknown value 'schott'; valid: reduced, truncated, free"),
    ("delta out of range", GOOD.replace("delta = 0.3", "delta = 1.5"), "[body].delta: must satisfy -1 <= delta < 1 (3.6)"),
    ("wrong type", GOOD.replace("samples = 40", 'samples = "many"'), "[simulation].samples: must be an integer"),
    ("bad vector", GOOD.replace("omega = [0.0, 0.05, 0.3]", "omega = [0.0, 0.05]"),
     "[initial].omega: must be a list of 3 numbers"),
    ("unknown method", GOOD.replace("samples = 40", 'samples = 40\nmethod = "euler"'),
     "[simulation].method: unknown method 'euler'"),
    ("bad TOML", "[body\n", "(file): invalid TOML"),
]


@pytest.mark.parametrize("name,text,message", BAD, ids=[b[0] for b in BAD])
def test_bad_scene_gets_one_line_exit_2_and_keeps_old_output(tmp_path, capsys, name, text, message):
    scene = write(tmp_path, text)
    out = tmp_path / "old.npz"
    out.write_bytes(b"precious")
    code, stdout, err = run(["simulate", scene, "--out", out], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"spinviz: error: {scene}: ")
    assert message in lines[0]
    assert "Traceback" not in err
    assert out.read_bytes() == b"precious"


def test_missing_scene_file(tmp_path, capsys):
    code, _, err = run(["simulate", tmp_path / "nope.toml", "--out", tmp_path / "x.npz"], capsys)
    assert code == 2 and err.strip().endswith("nope.toml: (file): no such file")


def test_unwritable_output_is_one_line_and_exit_2(tmp_path, capsys):
    target = tmp_path / "adir.npz"
    target.mkdir()
    code, _, err = run(["simulate", write(tmp_path, GOOD), "--out", target], capsys)
    assert code == 2 and "adir.npz: is a directory" in err and len(err.strip().splitlines()) == 1
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".spinviz-")] == []   # no temp left


def test_errors_from_a_real_process_have_no_traceback(tmp_path):
    scene = write(tmp_path, GOOD.replace("chi = 0.7", "chi = 0.7\nspin = 1"))
    r = subprocess.run([sys.executable, "-m", "spinviz", "simulate", str(scene), "--out", str(tmp_path / "o.npz")],
                       capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2
    assert r.stderr.strip() == f"spinviz: error: {scene}: [body].spin: unknown key"


def test_info_flags_printed_figures_that_differ_by_more_than_5_percent(capsys):
    code, out, _ = run(["info", "cellulose_rod"], capsys)
    assert code == 0
    i3 = next(line for line in out.splitlines() if line.strip().startswith("I3 "))
    assert "4.872e-28" in i3 and "4.11e-28" in i3 and "more than 5 %" in i3
    i1 = next(line for line in out.splitlines() if line.strip().startswith("I1 "))
    assert "more than 5 %" not in i1                     # 3.27e-26 vs 3.3e-26: within 1 %
    tau = next(line for line in out.splitlines() if "tau0" in line)
    assert "1.46e-35" in tau and "more than 5 %" not in tau


def test_info_json_for_a_scene(capsys):
    code, out, _ = run(["info", "--json", SCENES / "check_6_10_cube_truncated.toml"], capsys)
    rows = {r["key"]: r for r in json.loads(out)}
    assert code == 0
    assert rows["T_scene"]["value"] == pytest.approx(1.0 / 0.1**2)   # the paper's T = 1/(tau0 Omega20^2)


@pytest.mark.parametrize("name, horizon", [
    ("check_6_5_rod_reduced", 3.0 / 0.2**2),        # checks.check_eps_limit: 3 T, T = 1/Omega20^2
    ("check_6_6_rod_truncated", 3.0 / 0.2**2),
    ("check_6_10_cube_truncated", 3.0 / 0.1**2),    # checks.check_6_10: 3 T
    ("check_5_4_longitudinal_truncated", 5.0 / 0.1**2),   # checks.check_longitudinal: 5 T
    ("check_3_9_askew_both", 3.0 / 0.1**2),
])
def test_check_scenes_run_the_horizons_of_spinviz_check(name, horizon):
    """t_end_T counts the paper's T = 1/(tau0 Omega20^2) (after (3.9), (6.1)), not 1/(tau0 |Omega0|^2)."""
    assert load_scene(SCENES / f"{name}.toml").t_end == pytest.approx(horizon, rel=1e-14)


def test_info_unknown_target(capsys):
    code, _, err = run(["info", "dast_sphere"], capsys)
    assert code == 2 and "not a preset" in err


# the records of `spinviz check --quick`, in the order of checks.ALL_CHECKS
QUICK_EQUATIONS = ["6.5", "6.6", "6.8", "6.10", "3.9", "3.9", "5.2", "5.4", "2.4a", "2.1", "5.4 E"] + ["secular"] * 6


@pytest.mark.slow
def test_check_json_records_and_exit_status(check_quick):
    """``spinviz check --quick --json``, the session's one run of it (conftest.py): exit 0, one
    record per check in order, each passed; --quick keeps tau0 |Omega0| = 1e-4, 1e-5 in every
    secular comparison (the full command adds 1e-6); and the numbers are the library's own
    (the (6.10) check, recomputed here in a few ms, equals the record to the last bit)."""
    from spinviz.validation import checks

    assert check_quick.code == 0, check_quick.stderr
    records = check_quick.records
    assert [r["equation"] for r in records] == QUICK_EQUATIONS
    for r in records:
        assert set(r) >= {"equation", "description", "passed", "max_error", "criterion", "runtime_s"}, r
        assert r["passed"] is True, r
    for r in records[-6:]:
        assert [row["eps"] for row in r["details"]["rows"]] == [1e-4, 1e-5], r["description"]
    assert records[3]["max_error"] == checks.check_6_10().max_error


def test_every_method_is_documented_in_the_readme():
    """Each registered method is named in the README or in the manual's pages (docs/*.md)."""
    from spinviz.integrators import names

    text = (ROOT / "README.md").read_text() + "".join(p.read_text() for p in sorted((ROOT / "docs").glob("*.md")))
    for n in names():
        assert f"`{n}`" in text, n
