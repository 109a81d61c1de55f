"""Hostile scenes, generated from the schema (Hypothesis): every one must end in exit 0 with
finite output, or in one escaped line on stderr naming the file (and the key, for bad input)
with exit 2 -- or exit 1 for a run that cannot be done -- never a traceback, and never a
change to an output that was already there.

Fast and deterministic in CI (a fixed number of derandomized examples); a longer fuzz:
``HYPOTHESIS_PROFILE=fuzz python -m pytest tests/test_fuzz.py`` (see conftest.py).
"""

import contextlib
import io
import math
import re

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

import spinviz
from spinviz.cli import main

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
