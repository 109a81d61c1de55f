"""Hostile [environment] tables and environment= arguments, generated from the schema
(Hypothesis): each is accepted or refused in one line naming its key; through the command
line, a scene with one ends in exit 0 with a finite trajectory or in one escaped line naming the
file and the key (exit 2), or the run's reason (exit 1) -- never a traceback, nothing replaced."""

import contextlib
import io
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import spinviz
from spinviz.commands import main
from spinviz.errors import SpecError
from spinviz.inputs.environment import EnvironmentSpec

from tomlgen import dumps

FIELDS = tuple(EnvironmentSpec.__pydantic_fields__)
EXTREMES = [0, -0.0, 1, -1, 0.5, 1e-308, 5e-324, 1e-300, 1e-12, 1e3, 1e4, 1e10, 1e11, 1e300, 2.0**63, 10**30,
            math.inf, -math.inf, math.nan]
numbers = st.one_of(st.sampled_from(EXTREMES), st.floats(allow_nan=True, allow_infinity=True),
                    st.integers(min_value=-(10**40), max_value=10**40))
texts = st.one_of(st.text(max_size=20), st.sampled_from(["N2", "He", "Kr", "n2", "", "\x1b[31mEVIL\n", "x" * 300]))
values = st.one_of(numbers, texts, st.booleans(), st.lists(numbers, max_size=4), st.lists(texts, max_size=3),
                   st.dictionaries(st.text(max_size=4), numbers, max_size=2))


@st.composite
def tables(draw):
    out = {}
    for _ in range(draw(st.integers(1, 4))):
        key = draw(st.one_of(st.sampled_from(FIELDS), st.text(min_size=1, max_size=10)))
        out[key] = draw(values)
    return out


@settings(max_examples=30)
@given(table=tables())
def test_a_hostile_environment_is_accepted_or_refused_by_its_key(table):
    try:
        env = EnvironmentSpec(**{str(k): v for k, v in table.items()})
    except SpecError as e:
        assert e.key in FIELDS or e.key in table, e
        assert "\n" not in str(e)
        return
    assert 0.0 <= env.pressure_mbar <= 1e3 and all(math.isfinite(x) for x in env.field_v_per_m)
    gas = env.gas_model()
    assert gas is None or (math.isfinite(gas.density) and gas.density >= 0.0)


BASE = {
    "title": "fuzz",
    "body": {"preset": "dast_cube"},
    "initial": {"omega": [0.0, 3.141592653589793e10, 3.141592653589793e10]},
    "simulation": {"model": "reduced", "t_end": 1e-9, "samples": 3},
}
OLD = b"an output that was there before"
CONTROL = re.compile(r"[\x00-\x1f\x7f]")


@pytest.mark.slow
@settings(max_examples=40)
@given(table=tables())
def test_a_hostile_environment_table_through_the_command_line(table, tmp_path_factory):
    d = tmp_path_factory.mktemp("envfuzz")
    scene = d / "s.toml"
    doc = {**BASE, "environment": {str(k): v for k, v in table.items()}}
    try:
        scene.write_text(dumps(doc))
    except (ValueError, TypeError):
        return                                              # not expressible in TOML (NaN keys and the like)
    out = d / "out.npz"
    out.write_bytes(OLD)
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(["simulate", str(scene), "--out", str(out)])
    stderr = e.getvalue()
    assert "Traceback" not in stderr and not CONTROL.search(stderr.rstrip("\n")), stderr
    assert code in (0, 1, 2), (code, stderr)
    if code == 0:
        tr = spinviz.Trajectory.load(out)
        assert all(np.all(np.isfinite(a)) for a in tr.arrays().values())
    else:
        lines = stderr.strip().splitlines()
        assert len(lines) == 1 and str(scene) in lines[0], stderr
        if code == 2:
            assert "[environment]" in lines[0] or "(file)" in lines[0] or "[simulation]" in lines[0], lines[0]
        assert out.read_bytes() == OLD
