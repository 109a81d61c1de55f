"""Hostile scenes, generated from the schema (Hypothesis): every one must end in exit 0 with
finite output, or in one escaped line on stderr naming the file (and the key, for bad input)
with exit 2 -- or exit 1 for a run that cannot be done -- never a traceback, and never a
change to an output that was already there.

Fast and deterministic in CI (a fixed number of derandomized examples); a longer fuzz:
``HYPOTHESIS_PROFILE=fuzz python -m pytest tests/test_fuzz.py`` (see conftest.py).
"""

import contextlib
import functools
import io
import math
import re

import numpy as np
from hypothesis import event, given
from hypothesis import strategies as st

import spinviz
from spinviz.commands import main
from spinviz.physics.bodies import custom

from tomlgen import dumps

BASE = {
    "title": "fuzz",
    "body": {"delta": 0.3, "chi": 0.7},
    "initial": {"omega": [0.0, 0.05, 0.3], "euler_zxz": [0.0, 1.5707963267948966, 0.0]},
    "simulation": {"model": "reduced", "t_end": 50.0, "samples": 20},
    "render": {"duration": 1.0, "fps": 10, "size": [64, 48]},
}

KEYS = {
    "body": ["delta", "chi", "chi_deg", "inertia", "dipole", "preset", "shape", "length_nm", "aspect", "density",
             "dipole_debye", "a_nm", "b_nm", "c_nm", "name"],
    "initial": ["omega", "euler_zxz", "euler_zxz_deg", "quaternion"],
    "simulation": ["model", "models", "t_end", "t_end_T", "t_end_Theta", "samples", "method", "rtol", "atol", "step",
                   "units"],
    "render": ["duration", "fps", "size", "time_map", "log_knee", "spin", "spin_turns_per_second", "show",
               "trail_seconds", "azimuth_deg", "elevation_deg", "zoom", "background", "title", "poster"],
    "": ["title", "description"],
}

EXTREMES = [0, -0.0, 1, -1, 0.5, 2, 1e-308, 5e-324, 1e-300, 1e300, 1e308, -1e308, 2.0**63, 10**30, -(10**30),
            math.inf, -math.inf, math.nan]
numbers = st.one_of(st.sampled_from(EXTREMES), st.floats(allow_nan=True, allow_infinity=True),
                    st.integers(min_value=-(10**40), max_value=10**40))
texts = st.one_of(st.text(max_size=30),
                  st.sampled_from(["\x1b[31mEVIL\x1b[0m\r\nfake line", "reduced\n", "", "x" * 500, "auto", "dast_cube",
                                   "rod", "box", "log", "true", "black", "dop853", "secular", "cgs"]))
values = st.one_of(numbers, texts, st.booleans(), st.lists(numbers, max_size=5),
                   st.lists(st.lists(numbers, max_size=3), max_size=3), st.lists(texts, max_size=3),
                   st.dictionaries(st.text(max_size=4), numbers, max_size=2))
mutation = st.tuples(st.sampled_from(sorted(KEYS)), st.data())


@st.composite
def scenes(draw):
    doc = {k: (dict(v) if isinstance(v, dict) else v) for k, v in BASE.items()}
    for _ in range(draw(st.integers(1, 3))):
        table = draw(st.sampled_from(sorted(KEYS)))
        key = draw(st.one_of(st.sampled_from(KEYS[table]), st.text(min_size=1, max_size=12)))
        value = draw(values)
        target = doc if table == "" else doc[table]
        if draw(st.integers(0, 9)) == 0 and key in target:
            del target[key]                             # a missing key now and then
        else:
            target[key] = value
    return doc


OLD = b"an output that was there before"
CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def run_cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


@given(doc=scenes())
def test_hostile_scene_gets_a_finite_result_or_one_line(doc, tmp_path_factory):
    d = tmp_path_factory.mktemp("fuzz")
    scene = d / "s.toml"
    scene.write_text(dumps(doc))
    out = d / "out.npz"
    out.write_bytes(OLD)
    code, stdout, stderr = run_cli(["simulate", scene, "--out", out])
    assert "Traceback" not in stderr and not CONTROL.search(stderr.rstrip("\n")), stderr
    assert code in (0, 1, 2), (code, stderr)
    if code == 0:
        assert stderr == "" and len(stdout.strip().splitlines()) == 1
        tr = spinviz.Trajectory.load(out)                       # written completely, readable, finite
        assert all(np.all(np.isfinite(a)) for a in tr.arrays().values())
    else:
        lines = stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("spinviz: ") and len(lines[0]) < 600, stderr
        assert str(scene) in lines[0], lines[0]                 # the file is named ...
        if code == 2:
            assert re.search(r"\(file\)|\[\w+\]|: title|: description|: [a-z_]+:", lines[0]), lines[0]   # ... and the key
        assert out.read_bytes() == OLD                          # nothing replaced
    assert sorted(p.name for p in d.iterdir()) == ["out.npz", "s.toml"]     # nothing left behind


# --- the atlas spec: generated from its schema -------------------------------------
ATLAS_BASE = {
    "title": "fuzz", "models": ["reduced"],
    "grid": {"delta": [0.3], "chi_deg": [30.0]},
    "members": {"count": 2, "seed": 1, "omega": 0.1},
    "run": {"tau_end": 1e6}, "classify": {"window_decades": 2.0},
}
ATLAS_KEYS = {
    "": ["title", "description", "model", "models"],
    "grid": ["delta", "chi", "chi_deg"],
    "members": ["count", "seed", "omega", "list"],
    "run": ["tau_end", "tau_start", "samples_per_decade", "rtol", "max_steps", "atol"],
    "classify": ["window_decades"],
}
axis_tables = st.fixed_dictionaries({"min": numbers, "max": numbers, "cells": numbers})


@st.composite
def atlas_specs(draw):
    doc = {k: (dict(v) if isinstance(v, dict) else v) for k, v in ATLAS_BASE.items()}
    for _ in range(draw(st.integers(1, 3))):
        table = draw(st.sampled_from(sorted(ATLAS_KEYS)))
        key = draw(st.one_of(st.sampled_from(ATLAS_KEYS[table]), st.text(min_size=1, max_size=12)))
        value = draw(st.one_of(values, axis_tables) if key in ("delta", "chi", "chi_deg") else values)
        target = doc if table == "" else doc[table]
        if draw(st.integers(0, 9)) == 0 and key in target:
            del target[key]
        else:
            target[key] = value
    return doc


@given(doc=atlas_specs())
def test_hostile_atlas_spec_gets_a_spec_or_one_line(doc, tmp_path_factory):
    """A generated spec is either an ``AtlasSpec`` whose cost can be judged (finite cells,
    starts and settings) or one ``SceneError`` line naming the file and the key."""
    from spinviz.errors import SceneError
    from spinviz.inputs.atlas import AtlasArguments
    from spinviz.inputs.atlas_spec import load_spec
    from spinviz.regimes.engine.cost import check_feasible

    path = tmp_path_factory.mktemp("atlas") / "a.toml"
    path.write_text(dumps(doc))
    try:
        spec = load_spec(path)
    except SceneError as e:
        line = str(e)
        assert line.startswith(f"{path}: ") and "\n" not in printable_line(line) and len(line) < 600, line
        assert ": " in line[len(str(path)) + 2:], line              # file: key: reason
        return
    assert spec.runs >= 1 and np.all(np.isfinite(spec.omega0)) and np.all(np.isfinite(spec.deltas))
    from spinviz.inputs.atlas import TAU_END_MAX

    assert 0.0 < spec.settings.tau_start < spec.settings.tau_end <= TAU_END_MAX[spec.settings.engine]
    try:
        check_feasible(spec, AtlasArguments(workers=1))
    except SceneError as e:
        assert str(e).startswith(f"{path}: [grid]: "), str(e)


def printable_line(text: str) -> str:
    from spinviz.errors import printable

    return printable(text, 10_000)


# --- the Python API: every public signature, hostile arguments ------------------------
def _tiny_body():
    return spinviz.symmetric_top(0.3, 0.7)


ASYMMETRIC = custom((1.0, 1.36, 1.64), (0.57, 0.0, 0.82), units="dimensionless", name="box")   # the DAST box's shape


api_values = st.one_of(
    values, st.none(), st.just(np.array([0.0, 0.05, 0.3])), st.just(np.array([[1.0, 2.0]])), st.just(np.float32(2.0)),
    st.just(np.int64(5)), st.just("scenes/askew_example.toml"), st.just(object()), st.builds(_tiny_body))
PLAUSIBLE = {              # values a caller might mean: the fuzz reaches runs as well as refusals
    "model": st.sampled_from(["reduced", "truncated", "free"]),
    "omega0": st.lists(st.floats(-0.5, 0.5), min_size=3, max_size=3),
    "t_end": st.one_of(st.floats(1e-3, 200.0), st.none()), "samples": st.one_of(st.integers(2, 60), st.none()),
    "t_eval": st.one_of(st.none(), st.lists(st.floats(0.01, 100.0), min_size=1, max_size=20).map(
        lambda v: [0.0, *sorted(set(v))])),
    "q0": st.one_of(st.none(), st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4)),
    "euler_zxz0": st.one_of(st.none(), st.lists(st.floats(-7.0, 7.0), min_size=3, max_size=3)),
    "method": st.sampled_from(["auto", "taylor", "rk45", "dop853", "radau", "split4", "secular", "polhode",
                               "taylor -> polhode", "TAYLOR"]),
    "rtol": st.floats(1e-12, 1e-3), "atol": st.one_of(st.none(), st.floats(1e-14, 1e-6)),
    "step": st.one_of(st.none(), st.floats(0.01, 5.0)),
    "kinematics": st.sampled_from(["quaternion", "euler_zxz", "none"]),
    # render keywords
    "duration": st.floats(0.05, 2.0), "fps": st.integers(1, 30), "size": st.tuples(st.integers(16, 96), st.integers(16, 96)),
    "time_map": st.sampled_from(["linear", "log"]), "spin": st.sampled_from(["auto", "true", "slowed"]),
    "show": st.lists(st.sampled_from(["body", "dipole", "omega", "L", "trail", "hud", "hodograph", "inset"]), min_size=1,
                     max_size=4),
    "zoom": st.floats(0.05, 20.0), "poster": st.floats(0.0, 1.0), "captions": st.sampled_from(["outreach", "physics"]),
}
SIMULATE_ARGS = {"body": None, "model": "reduced", "omega0": [0.0, 0.05, 0.3], "t_end": 50.0, "samples": 20,
                 "t_eval": None, "q0": None, "euler_zxz0": None, "method": "auto", "rtol": 1e-10, "atol": None,
                 "step": None, "kinematics": "quaternion"}


def _spinviz_error(e, names) -> None:
    """A library error from hostile arguments: spinviz's, a ValueError or TypeError, one line,
    naming one of the function's arguments."""
    from spinviz.errors import SpinvizError

    assert isinstance(e, SpinvizError) and isinstance(e, ValueError | TypeError), repr(e)
    text = str(e)
    assert "\n" not in printable_line(text) and len(text) < 600, text
    assert text.split(":")[0] in names, text


@given(data=st.data())
def test_hostile_simulate_arguments_get_a_trajectory_or_a_typed_error(data):
    """``spinviz.simulate`` with one to three arguments replaced by anything: a finite
    ``Trajectory`` (or a ``SimulationError`` for a run that cannot be done), else one
    ``SpecError``/``SpecTypeError`` naming the argument -- never a raw NumPy or Python error."""
    from spinviz.errors import SimulationError, SpecError
    from spinviz.inputs.simulation import SimulationRequest

    kw = dict(SIMULATE_ARGS, body=data.draw(st.sampled_from([_tiny_body(), ASYMMETRIC])))
    hostile = data.draw(st.integers(0, 2)) == 0          # a third hostile, the rest what a caller might mean
    for _ in range(data.draw(st.integers(1, 3))):
        name = data.draw(st.sampled_from(sorted(SIMULATE_ARGS)))
        kw[name] = data.draw(api_values if hostile or name not in PLAUSIBLE else PLAUSIBLE[name])
    body, model, omega0 = kw.pop("body"), kw.pop("model"), kw.pop("omega0")
    try:
        req = SimulationRequest(body=body, model=model, omega0=omega0, **kw)
    except SpecError as e:
        event(f"refused: {e.key}")
        _spinviz_error(e, set(SIMULATE_ARGS))
        try:                                           # and simulate says exactly the same
            spinviz.simulate(body, model, omega0, **kw)
        except SpecError as again:
            assert str(again) == str(e)
        return
    if req.horizon * float(np.linalg.norm(req.omega0)) > 1e3 or req.rtol < 1e-12 or req.times().size > 5000:
        event("accepted, not run (long)")
        return                                         # valid, but too long for a quick test
    event("run")
    try:
        tr = spinviz.simulate(body, model, omega0, **kw)
    except SimulationError as e:
        assert "\n" not in str(e)
        return
    assert all(np.all(np.isfinite(a)) for a in tr.arrays().values())


RENDER_FIELDS = ["duration", "fps", "size", "time_map", "log_knee", "spin", "spin_turns_per_second", "show",
                 "trail_seconds", "azimuth_deg", "elevation_deg", "zoom", "background", "title", "poster", "captions",
                 "subtitles", "colour"]


@given(data=st.data())
def test_hostile_render_arguments_get_a_plan_or_a_typed_error(data, tmp_path_factory):
    """``plan`` / ``Renderer`` / ``render_frame`` / ``render`` take a source, times and
    ``RenderSpec`` keywords: hostile ones give a frame plan (its times finite and within the
    run) or one typed error naming the argument; nothing is drawn or written here."""
    from spinviz import pipeline
    from spinviz.errors import SpecError

    d = tmp_path_factory.mktemp("render")
    path = d / "s.toml"
    path.write_text(dumps({**BASE, "render": {"duration": 0.5, "fps": 8, "size": [64, 48]}}))
    hostile = data.draw(st.integers(0, 2)) == 0          # a third hostile, the rest what a caller might mean
    source = data.draw(api_values if hostile else st.sampled_from([path, str(path)]))
    overrides = {}
    for _ in range(data.draw(st.integers(0, 2))):
        name = data.draw(st.sampled_from(RENDER_FIELDS))
        overrides[name] = data.draw(api_values if hostile or name not in PLAUSIBLE else PLAUSIBLE[name])
    maybe = api_values if hostile else st.sampled_from([None] * 8 + [0.0, 10.0, 50.0, 2, 5, 1e9, -1.0])
    t_end, frames, t = data.draw(maybe), data.draw(maybe), data.draw(maybe)
    names = set(RENDER_FIELDS) | {"source", "t_end", "frames", "t", "path"}
    try:
        scene, trajs, spec = pipeline.resolve_spec(source, **overrides)
        args = pipeline.RenderArguments(t_end=t_end, frames=frames, t=t)
    except SpecError as e:
        event(f"refused: {e.key}")
        _spinviz_error(e, names)
        return
    except spinviz.SceneError as e:                   # a scene-file problem, named in the file's terms
        assert str(e).startswith(str(source)), str(e)
        return
    if spec.frames > 200 or (args.frames or 0) > 200:
        event("accepted, not planned (long)")
        return
    event("planned")
    try:
        plan = pipeline.plan(scene if scene is not None else trajs, t_end=args.t_end, frames=args.frames, **overrides)
    except SpecError as e:
        _spinviz_error(e, names)
        return
    assert np.all(np.isfinite(plan.sim_t)) and plan.sim_t[0] == 0.0 and plan.sim_t[-1] <= scene.t_end
    assert sorted(p.name for p in d.iterdir()) == ["s.toml"]


ATLAS_ARGS = ["out", "scheduler", "workers", "plot", "progress", "runs_per_task", "processes", "flush_s",
              "retry_failed", "on_result"]


@given(data=st.data())
def test_hostile_atlas_arguments_are_checked_before_the_spec_is_read(data, monkeypatch, tmp_path_factory):
    """``spinviz.atlas`` with hostile keyword arguments: one typed error naming the argument,
    before the spec is even read (or, when they are acceptable, the spec is read next)."""
    from spinviz.errors import SpecError
    from spinviz.regimes import api

    class Reached(Exception):
        pass

    def reached(*a, **k):
        raise Reached

    monkeypatch.setattr(api, "load_spec", reached)
    d = tmp_path_factory.mktemp("atlas_args")
    kw = {data.draw(st.sampled_from(ATLAS_ARGS)): data.draw(api_values) for _ in range(data.draw(st.integers(1, 3)))}
    kw.setdefault("out", str(d / "a.zarr"))
    try:
        spinviz.atlas("spec.toml", **kw)
    except SpecError as e:
        _spinviz_error(e, set(ATLAS_ARGS))
    except Reached:
        pass
    assert list(d.iterdir()) == []


@functools.cache
def _saved_trajectory() -> bytes:
    """A saved trajectory's bytes, made once (the same in every example of a run)."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        p = f"{d}/t.npz"
        spinviz.simulate(_tiny_body(), "reduced", (0.0, 0.05, 0.3), t_end=10.0, samples=4).save(p)
        with open(p, "rb") as fh:
            return fh.read()


@given(blob=st.one_of(st.binary(max_size=300), st.data()))
def test_any_bytes_as_a_trajectory_file_load_or_one_typed_error(blob, tmp_path_factory):
    """``Trajectory.load`` of any bytes -- random, or a saved trajectory with bytes changed or
    cut -- gives the trajectory or one ``TrajectoryFileError`` naming the file."""
    from spinviz.errors import TrajectoryFileError

    d = tmp_path_factory.mktemp("npz")
    p = d / "t.npz"
    if isinstance(blob, bytes):
        p.write_bytes(blob)
    else:
        raw = bytearray(_saved_trajectory())
        for _ in range(blob.draw(st.integers(1, 4))):
            i = blob.draw(st.integers(0, len(raw) - 1))
            raw[i] = blob.draw(st.integers(0, 255))
        p.write_bytes(bytes(raw[: blob.draw(st.integers(0, len(raw)))]))
    try:
        tr = spinviz.Trajectory.load(p)
    except TrajectoryFileError as e:
        assert str(e).startswith(f"{p}: ") and "\n" not in str(e)
        return
    assert np.all(np.isfinite(tr.t)) and np.all(np.isfinite(tr.omega))
