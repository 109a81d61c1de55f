"""The one schema (``spinviz.inputs``): every input checked once and named in the caller's
terms, limits checked before any work, typed errors from every public function."""

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spinviz
from spinviz.commands import main
from spinviz.errors import SceneError, SpecError, SpecTypeError, SpinvizError, TrajectoryFileError
from spinviz.inputs.atlas_spec import parse_spec
from spinviz.physics import bodies as B

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "scenes"
BODY = B.symmetric_top(0.3, 0.7)
W0 = (0.0, 0.05, 0.3)

SCENE = """
[body]
delta = 0.3
chi = 0.7
[initial]
omega = [0.0, 0.05, 0.3]
[simulation]
model = "reduced"
t_end = 50.0
samples = 6
{extra}
[render]
duration = 1.0
fps = 8
size = [64, 48]
"""


def write_scene(tmp_path, extra="", name="s.toml"):
    p = tmp_path / name
    p.write_text(SCENE.format(extra=extra))
    return p


def fresh(code: str) -> str:
    """The last line ``code`` prints, run in a fresh interpreter."""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    return r.stdout.strip().splitlines()[-1]


# --- one schema for every input --------------------------------------------------------------
def test_the_atlas_spec_is_read_with_the_shared_schema_not_the_scenes_code():
    """The atlas spec, the scene and the API share ``spinviz.inputs``; reading a spec loads no
    part of the scene's reading."""
    assert fresh("import sys, spinviz.inputs.atlas_spec\nprint(sorted(m for m in sys.modules "
                 "if m.startswith('spinviz.inputs.scene')))") == "[]"


def test_a_scene_is_read_without_the_rendering_package():
    """Data flows from the inputs to the pictures: reading a scene loads no rendering module
    (lint-imports keeps it so: "Inputs above rendering")."""
    code = ("import sys, spinviz\nspinviz.load_scene('scenes/default.toml')\n"
            "print(sorted(m for m in sys.modules if m.startswith('spinviz.rendering') or m == 'spinviz.pipeline'))")
    assert fresh(code) == "[]"


@pytest.mark.parametrize("key, value, argument, reason", [
    ("rtol", "-1.0", {"rtol": -1.0}, "must lie in [1e-19, 0.1] (the long double's precision at the tightest), got -1"),
    ("atol", "1e300", {"atol": 1e300}, "must lie in [1e-300, 1] (units where |omega(0)| = 1), got 1e+300"),
    ("samples", "1000000000000", {"samples": 10**12},
     "must be at most 1000000 (memory: 11 numbers an instant per model), got 1000000000000"),
    ("samples", "1.5", {"samples": 1.5}, "must be an integer, got 1.5"),
    ("method", '"rk99"', {"method": "rk99"}, "unknown method 'rk99'; valid: auto, bdf, dop853, lsoda, polhode, radau, rk45, "
                                           "secular, split2, split4, split6, split8, taylor, taylor-long"),
])
def test_a_file_and_python_get_the_same_check_and_the_same_words(tmp_path, key, value, argument, reason):
    """The scene's [simulation] table and ``simulate``'s arguments are one schema: the same
    value is refused for the same reason, named by the key in the file and by the argument
    in Python (the scene accepted NaN-free negative tolerances differently, Python none)."""
    text = SCENE.format(extra="").replace("samples = 6\n", "" if key == "samples" else "samples = 6\n")
    p = tmp_path / "s.toml"
    p.write_text(text.replace("[render]", f"{key} = {value}\n[render]"))
    with pytest.raises(SceneError) as in_file:
        spinviz.load_scene(p)
    assert str(in_file.value) == f"{p}: [simulation].{key}: {reason}"
    kw = {"t_end": 50.0, "samples": 6, **argument}
    with pytest.raises(SpecError) as in_python:
        spinviz.simulate(BODY, "reduced", W0, **kw)
    assert str(in_python.value) == f"{key}: {reason}"


def test_a_scene_hands_the_driver_a_typed_frozen_request_with_units():
    """No untyped keyword dictionary travels from a scene to ``simulate``: ``Scene.request``
    is the ``SimulationRequest`` ``simulate`` checks its own arguments with."""
    from spinviz.driver import simulate_request
    from spinviz.inputs.simulation import SimulationRequest

    sc = spinviz.load_scene(SCENES / "askew_example.toml")
    assert not hasattr(sc, "simulation_kwargs")
    req = sc.request("reduced", t_eval=np.linspace(0.0, 100.0, 11))
    assert isinstance(req, SimulationRequest)
    assert (req.units, req.time_unit, req.omega_unit) == ("dimensionless", "tau0", "1/tau0")
    with pytest.raises(dataclasses.FrozenInstanceError):
        req.rtol = 1e-3
    tr = simulate_request(req)
    same = spinviz.simulate(sc.body, "reduced", sc.omega0, t_eval=np.linspace(0.0, 100.0, 11), q0=sc.q0)
    np.testing.assert_array_equal(tr.omega, same.omega)
    with pytest.raises(SpecError, match="model: 'free' is not one of the scene's models"):
        sc.request("free")
    cube = spinviz.load_scene(SCENES / "dast_cube.toml").request()
    assert (cube.units, cube.time_unit, cube.omega_unit) == ("cgs", "s", "rad/s")


def test_library_errors_name_the_argument_the_command_line_its_option(tmp_path, capsys):
    """``spinviz.atlas(workers=0)`` names the argument ``workers``, never a flag a Python caller
    did not give; the command line maps it to its option, ``--workers``."""
    out = tmp_path / "a.zarr"
    with pytest.raises(SpecError) as e:
        spinviz.atlas(SCENES / "atlas_quick.toml", out=out, workers=0)
    assert str(e.value) == "workers: must be at least 1, got 0"
    with pytest.raises(SpecError) as e:
        spinviz.atlas(SCENES / "atlas_quick.toml", out=out, scheduler="tcp://127.0.0.1:1", workers=1)
    assert str(e.value).startswith("workers: applies to the embedded cluster only") and "--" not in str(e.value)
    code = main(["atlas", str(SCENES / "atlas_quick.toml"), "--out", str(out), "--workers", "4096"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.startswith("spinviz: error: --workers: must be at most "), err
    assert not out.exists()


def test_trajectory_omega_body_is_the_documented_name():
    """``Trajectory.omega`` is the body-frame angular velocity; ``omega_body`` says so (the frame in
    the name) and is the same array (``omega`` stays: the field, the keyword and the saved name)."""
    tr = spinviz.simulate(BODY, "reduced", W0, t_end=10.0, samples=3)
    assert tr.omega_body is tr.omega and tr.omega_body.shape == (3, 3)
    np.testing.assert_array_equal(tr.omega_body[0], W0)


# --- limits before work -------------------------------------------------------------------------
ATLAS = """
models = ["reduced"]
[grid]
delta = {{ min = -1.0, max = 1.0, cells = {cells} }}
chi_deg = {{ min = 0.0, max = 90.0, cells = {cells} }}
[members]
count = {members}
seed = 1
omega = 0.1
[run]
tau_end = 1e20
"""


@pytest.mark.parametrize("cells, members", [(4096, 1), (100, 10000)], ids=["4096x4096 cells", "1e8 runs"])
def test_an_atlas_that_cannot_finish_is_refused_before_any_work(tmp_path, monkeypatch, cells, members):
    """4096 x 4096 cells, or 1e8 runs to tau = 1e20, would grow memory until MemoryError or
    take months (the runs the averaged flow cannot carry are integrated in full: ~0.5 s each
    at 1e20).  The memory of this process and the time on its workers are estimated from the
    spec and the machine (here a 16 GB machine, one worker), and refused in one line naming the key."""
    from spinviz.regimes import compute
    from spinviz.regimes.engine import cost as SP

    def work(*a, **k):
        raise AssertionError("the atlas started working")

    monkeypatch.setattr(compute, "compute", work)
    monkeypatch.setattr(SP, "physical_memory", lambda: 16e9)
    spec = tmp_path / "big.toml"
    spec.write_text(ATLAS.format(cells=cells, members=members))
    out = tmp_path / "big.zarr"
    with pytest.raises(SceneError) as e:
        spinviz.atlas(spec, out=out, workers=1, progress=False)
    msg = str(e.value)
    assert msg.startswith(f"{spec}: [grid]: ") and "\n" not in msg
    assert ("GB in this process" in msg) if cells == 4096 else ("days on 1 workers" in msg), msg
    assert not out.exists()


def test_atlas_horizon_cap_is_the_engines():
    """The brute-force engine stops at tau_end = 1e16 (its cost grows as sqrt(tau_end)); the
    hand-over engine, the default, reaches 1e20; the refusal names the key and the other engine."""
    data = json.loads(json.dumps(GOOD_SPEC))
    data["run"].update(tau_end=1e17, engine="taylor")
    with pytest.raises(SceneError) as e:
        parse_spec(data, "s.toml")
    assert str(e.value) == ("s.toml: [run].tau_end: must be at most 1e+16 with engine = 'taylor', got 1e+17; "
                            "engine = \"handover\" reaches 1e20")
    data["run"]["engine"] = "handover"
    assert parse_spec(data, "s.toml").settings.tau_end == 1e17
    del data["run"]["engine"]
    assert parse_spec(data, "s.toml").settings.engine == "handover"


GOOD_SPEC = {"models": ["reduced"], "grid": {"delta": [0.3], "chi_deg": [30.0]},
             "members": {"count": 2, "seed": 1, "omega": 0.1}, "run": {"tau_end": 1e6}}


@pytest.mark.parametrize("table, key, value, message", [
    ("run", "tau_start", 5e-324, "[run].tau_start: must lie in [1e-12, 1000] (the first sample after 0, tau), got 4.94066e-324"),
    ("members", "omega", 5e-324, "[members].omega: must lie in [1e-07, 10]"),
    ("members", "list", [[0.0, 0.0, 5e-324]], "[members].list: |omega(0)| must lie in [1e-07, 10], got 4.94066e-324"),
    ("run", "max_steps", 10**40, "[run].max_steps: must lie in [1000, 1000000000000], got 1e+40"),
    ("run", "tau_end", 1e21, "[run].tau_end: must lie in (0, 1e+20], got 1e+21"),
    ("members", "omega", 1e-3, "[run].tau_end: tau_end = 1e+06 is 1 braking times T = 1/|omega0|^2 of the slowest start"),
    ("run", "atol", 1e300, "[run].atol: is not used since the atlas integrates with Taylor's method"),
])
def test_atlas_times_tolerances_and_starts_that_cannot_run_are_refused(table, key, value, message):
    """A time, tolerance or start where no run can finish (``tau_start = 5e-324``, ``omega =
    5e-324``) is refused before any work; each value must lie where a run can finish, said
    with the key."""
    data = json.loads(json.dumps(GOOD_SPEC))
    if key == "list":
        data["members"] = {"list": value}
    else:
        data[table][key] = value
    with pytest.raises(SceneError) as e:
        parse_spec(data, "s.toml")
    assert str(e.value).startswith(f"s.toml: {message}"), str(e.value)


@pytest.mark.parametrize("command, ext", [("simulate", ".npz"), ("render", ".gif")])
def test_an_output_name_the_file_system_cannot_hold_is_refused_before_the_run(tmp_path, monkeypatch, capsys, command, ext):
    """An output name over 255 bytes is refused before the run, not by the write after it."""
    from spinviz import driver, pipeline

    def run(*a, **k):
        raise AssertionError("the run started")

    for module in (driver, pipeline):                 # where simulate and render reach the driver
        monkeypatch.setattr(module, "simulate_request", run)
    p = write_scene(tmp_path)
    out = tmp_path / ("x" * 300 + ext)
    code = main([command, str(p), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and err.startswith("spinviz: error: ") and len(err) < 300, err
    assert err.endswith(f"xxx{ext}: a name of 304 bytes; the file system takes at most 255"), err
    assert sorted(q.name for q in tmp_path.iterdir()) == ["s.toml"]


@pytest.mark.parametrize("method", ["auto", "rk45", "dop853"])
def test_a_nan_in_t_eval_is_refused_not_integrated(method):
    """A NaN in t_eval is refused, naming t_eval, not integrated into a trajectory of NaN."""
    with pytest.raises(SpecError) as e:
        spinviz.simulate(BODY, "reduced", W0, t_eval=[0.0, math.nan, 5.0], method=method)
    assert str(e.value) == "t_eval: must be finite, got [0.0, nan, 5.0]"


# --- every public function raises spinviz's errors, naming the argument ------------------------------
def sim(**kw):
    args = {"t_end": 10.0, "samples": 5, **kw}
    body = args.pop("body", BODY)
    omega0 = args.pop("omega0", W0)
    return lambda: spinviz.simulate(body, "reduced", omega0, **args)


def atlas(tmp, **kw):
    return lambda: spinviz.atlas(SCENES / "atlas_quick.toml", out=tmp / "never.zarr", **{"progress": False, **kw})


API = [
    ("step = 0", sim(method="split4", step=0), SpecError, "step: must be positive, got 0"),
    ("q0 of 3", sim(q0=[1.0, 0.0, 0.0]), SpecTypeError, "q0: must be a list of 4 numbers (w, x, y, z), got [1.0, 0.0, 0.0]"),
    ("q0 zero", sim(q0=[0.0, 0.0, 0.0, 0.0]), SpecError, "q0: must not be zero (a rotation is a unit quaternion; it is "
                                                         "normalized here)"),
    ("rtol nan", sim(rtol=math.nan), SpecError, "rtol: must be finite, got nan"),
    ("rtol < 0", sim(rtol=-1e-8), SpecError, "rtol: must lie in [1e-19, 0.1] (the long double's precision at the "
                                             "tightest), got -1e-08"),
    ("atol nan", sim(atol=math.nan), SpecError, "atol: must be finite, got nan"),
    ("atol < 0", sim(atol=-1.0), SpecError, "atol: must lie in [1e-300, 1] (units where |omega(0)| = 1), got -1"),
    ("samples 1e12", sim(samples=10**12), SpecError, "samples: must be at most 1000000 (memory: 11 numbers an instant "
                                                     "per model), got 1000000000000"),
    ("samples float", sim(samples=1e12), SpecTypeError, "samples: must be an integer, got 1000000000000.0"),
    ("path as body", sim(body="scenes/askew_example.toml"), SpecTypeError,
     "body: must be a Body (spinviz.symmetric_top(...), spinviz.PRESETS[name]() or spinviz.Body(...)), got str "
     "'scenes/askew_example.toml' (a scene's body is spinviz.load_scene(path).body)"),
    ("omega nan", sim(omega0=[math.nan, 0.0, 0.3]), SpecError, "omega0: must be finite, got [nan, 0.0, 0.3]"),
    ("omega 2", sim(omega0=[0.1, 0.2]), SpecTypeError, "omega0: must be a list of 3 numbers, got [0.1, 0.2]"),
    ("model", lambda: spinviz.simulate(BODY, "schott", W0, t_end=1.0, samples=2), SpecError,
     "model: unknown value 'schott'; valid: reduced, truncated, free"),
    ("unknown", lambda: spinviz.render_frame(SCENES / "askew_example.toml", colour=3), SpecTypeError,
     "colour: unknown argument"),
    ("load None", lambda: spinviz.load_scene(None), SpecTypeError,
     "path: must be the path of a scene file (str or os.PathLike), got NoneType"),
    ("render_frame None", lambda: spinviz.render_frame(None), SpecTypeError,
     "source: must be a Scene, the path of a scene file, a Trajectory or a list of one or two Trajectories, got NoneType"),
    ("render_frame t < 0", lambda: spinviz.render_frame(SCENES / "askew_example.toml", t=-1.0), SpecError,
     "t: must not be negative, got -1"),
    ("render_frame t > end", lambda: spinviz.render_frame(SCENES / "askew_example.toml", t=1e4), SpecError,
     "t: must lie in [0, 1200] (the run's time, in its unit), got 10000"),
    ("render fps", lambda: spinviz.render(SCENES / "askew_example.toml", out="x.gif", fps=1.5), SpecTypeError,
     "fps: must be an integer, got 1.5"),
    ("Trajectory.load None", lambda: spinviz.Trajectory.load(None), SpecTypeError,
     "path: must be the path of a .npz trajectory, got NoneType"),
]
ATLAS_API = [
    ("workers 1.5", {"workers": 1.5}, SpecTypeError, "workers: must be an integer, got 1.5"),
    ("workers '2'", {"workers": "2"}, SpecTypeError, "workers: must be an integer, got '2'"),
    ("runs_per_task 0", {"runs_per_task": 0}, SpecError, "runs_per_task: must lie in [1, 1000000], got 0"),
    ("runs_per_task -3", {"runs_per_task": -3}, SpecError, "runs_per_task: must lie in [1, 1000000], got -3"),
    ("progress 'no'", {"progress": "no"}, SpecTypeError, "progress: must be True or False, got 'no'"),
]


@pytest.mark.parametrize("call, kind, message", [c[1:] for c in API], ids=[c[0] for c in API])
def test_python_api_raises_spinviz_errors_naming_the_argument(call, kind, message):
    """Hostile arguments (step=0, a 3-element q0, NaN tolerances, samples=1e12, a path for a
    body, NaN omega, render_frame(None)) get spinviz's typed error naming the argument as the
    caller wrote it, never ZeroDivisionError, IndexError, MemoryError or AttributeError."""
    with pytest.raises(SpinvizError) as e:
        call()
    assert type(e.value) is kind and isinstance(e.value, ValueError | TypeError)
    assert str(e.value) == message


@pytest.mark.parametrize("kw, kind, message", [c[1:] for c in ATLAS_API], ids=[c[0] for c in ATLAS_API])
def test_atlas_arguments_raise_spinviz_errors_before_any_work(tmp_path, kw, kind, message):
    """``atlas(workers=1.5)`` or ``"2"`` and ``runs_per_task <= 0`` are refused by the schema,
    naming the argument, before any work."""
    with pytest.raises(SpinvizError) as e:
        atlas(tmp_path, **kw)()
    assert type(e.value) is kind and str(e.value) == message
    assert list(tmp_path.iterdir()) == []


def test_workers_are_bounded_by_the_cores(tmp_path):
    """More render processes or atlas workers than cores only share them: refused, saying how many."""
    from spinviz.executors.processes import usable_cores

    n = usable_cores()
    with pytest.raises(SpecError) as e:
        spinviz.render(write_scene(tmp_path), out=str(tmp_path / "v.mp4"), workers=n + 1)
    assert str(e.value) == (f"workers: must be at most {n}, the cores this process may use (more render processes "
                            f"than cores only share them), got {n + 1}")
    with pytest.raises(SpecError, match=f"workers: must be at most {n}, the cores"):
        atlas(tmp_path, workers=n + 1)()
    assert sorted(q.name for q in tmp_path.iterdir()) == ["s.toml"]


def _npz(path, **arrays):
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)


@pytest.mark.parametrize("damage, reason", [
    ("empty", "damaged or not a spinviz trajectory (.npz): EOFError"),
    ("truncated", "damaged or not a spinviz trajectory (.npz): BadZipFile"),
    ("no metadata", "not a spinviz trajectory (no metadata entry)"),
    ("metadata not JSON", "damaged or not a spinviz trajectory (.npz): JSONDecodeError"),
    ("no omega", "damaged: the array 'omega' is missing"),
    ("nan in omega", "damaged: the array 'omega' is not finite numbers"),
    ("body missing", "damaged metadata: KeyError 'body_description'"),
    ("missing", "no such file"),
    ("directory", "is a directory, not a regular file"),
])
def test_a_damaged_trajectory_file_is_one_typed_error(tmp_path, damage, reason):
    """``Trajectory.load`` of a damaged file raised BadZipFile, EOFError, KeyError or
    JSONDecodeError; now ``TrajectoryFileError`` (a ValueError) naming the file."""
    good = tmp_path / "good.npz"
    tr = spinviz.simulate(BODY, "reduced", W0, t_end=10.0, samples=3)
    tr.save(good)
    p = tmp_path / "bad.npz"
    meta = json.dumps(tr.metadata())
    if damage == "empty":
        p.write_bytes(b"")
    elif damage == "truncated":
        p.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    elif damage == "no metadata":
        _npz(p, t=tr.t, omega=tr.omega)
    elif damage == "metadata not JSON":
        _npz(p, metadata=np.array("{not json"), t=tr.t, omega=tr.omega)
    elif damage == "no omega":
        _npz(p, metadata=np.array(meta), t=tr.t)
    elif damage == "nan in omega":
        _npz(p, metadata=np.array(meta), t=tr.t, omega=np.full((3, 3), np.nan))
    elif damage == "body missing":
        m = tr.metadata()
        del m["body_description"]
        _npz(p, metadata=np.array(json.dumps(m)), t=tr.t, omega=tr.omega)
    elif damage == "directory":
        p.mkdir()
    with pytest.raises(TrajectoryFileError) as e:
        spinviz.Trajectory.load(p)
    assert isinstance(e.value, ValueError) and str(e.value) == f"{p}: {reason}"


@pytest.mark.slow
def test_render_frame_is_the_videos_frame_that_shows_t():
    """``render_frame(scene, t)`` is the frame of the scene's own video that shows t: the first
    at t = 0, the last at the run's end, frame f at its time, and between two frames the one
    nearer on the time map (t is the trajectory's time); the frames differ, so each check
    could fail.  A shorter video's last frame is ``Renderer(t_end=...)``'s."""
    sc = spinviz.load_scene(SCENES / "askew_example.toml")
    look = {"size": (64, 48), "duration": 1.0, "fps": 8}
    with spinviz.Renderer(sc, **look) as r:
        frames = [r.frame(f) for f in range(r.frames)]
        sim_t = r.plan.sim_t
    assert not np.array_equal(frames[3], frames[4]) and not np.array_equal(frames[0], frames[-1])
    assert np.array_equal(spinviz.render_frame(sc, t=0.0, **look), frames[0])
    assert np.array_equal(spinviz.render_frame(sc, t=sc.t_end, **look), frames[-1])
    assert np.array_equal(spinviz.render_frame(sc, t=0.6 * sim_t[3] + 0.4 * sim_t[4], **look), frames[3])
    assert np.array_equal(spinviz.render_frame(sc, t=0.4 * sim_t[3] + 0.6 * sim_t[4], **look), frames[4])
    with spinviz.Renderer(sc, t_end=600.0, **look) as r:            # the video of [0, 600]: its last frame shows t = 600
        assert r.plan.sim_t[-1] == 600.0


def test_adding_an_atlas_key_is_one_field_and_keeps_old_identities():
    """The recipe of ``spinviz.inputs.atlas``: a key is one annotated field; marked ``Added()``
    it enters the spec's identity only when it differs from its default, so a store made
    before the key existed keeps its identity.  A store's canonical spec gives back the
    Settings it was made with."""
    from types import SimpleNamespace
    from typing import Annotated

    from pydantic import Field

    from spinviz.inputs.atlas import Added, RunTable
    from spinviz.inputs.atlas_spec import _identity_values, load_spec, settings_from_canonical
    from spinviz.inputs.base import Int, request

    @request
    class RunWithRefinement:
        tau_end: float = 1e10
        refine_levels: Annotated[Int, Field(ge=0, le=8), Added()] = 0

    old = SimpleNamespace(tau_end=1e10, refine_levels=0)
    assert _identity_values(RunWithRefinement, old) == {"tau_end": 1e10}
    assert _identity_values(RunWithRefinement, SimpleNamespace(tau_end=1e10, refine_levels=2)) == {
        "tau_end": 1e10, "refine_levels": 2}
    with pytest.raises(SpecError, match=r"refine_levels: must lie in \[0, 8\], got 9"):
        RunWithRefinement(refine_levels=9)
    spec = load_spec(SCENES / "atlas_quick.toml")
    assert settings_from_canonical(json.loads(spec.canonical_json())) == spec.settings
    # engine is not Added: its default ("handover") gives other numbers than the stores made
    # before it (brute force), so it always enters the identity
    assert set(_identity_values(RunTable, spec.settings)) == {"tau_end", "tau_start", "samples_per_decade", "rtol",
                                                              "max_steps", "engine"}
