"""One set of rules for the Python API: every public callable refuses a bad argument with
``SpecError`` / ``SpecTypeError`` naming it (body constructors included), ``Trajectory.sample``
refuses times it cannot honour, and the line of sight is checked once, by the schema, with
exactly the rule the detector needs."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import spinviz
from spinviz import rotations as R
from spinviz.errors import SpecError, SpecTypeError
from spinviz.physics import presets as P
from spinviz.physics import radiation as RA

BODY = spinviz.symmetric_top(-0.6, 0.9)


@pytest.fixture(scope="module")
def run():
    return spinviz.simulate(BODY, "reduced", (0.02, 0.05, 0.3), t_end=20.0, samples=9)


def refused(call, kind, key):
    """``call()`` raises ``kind`` (a SpecError) whose key is ``key``; returns the reason."""
    with pytest.raises(SpecError) as e:
        call()
    assert isinstance(e.value, kind), type(e.value)
    assert e.value.key == key and str(e.value) == f"{key}: {e.value.reason}"
    return e.value.reason


@pytest.mark.parametrize("times, kind, reason", [
    ([math.nan], SpecError, "must be finite, got [nan]"),
    ([0.0, math.inf], SpecError, "must be finite"),
    ([1e300], SpecError, "must lie in [0, 20] (the run's stored span: sampling interpolates, it never integrates), "
                         "got 1e+300"),
    ([-1.0], SpecError, "must lie in [0, 20]"),
    ("abc", SpecTypeError, "must be a time or a list of times, got 'abc'"),
    (None, SpecTypeError, "must be a time or a list of times, got None"),
    ([[1.0, 2.0]], SpecError, "must be a time or a 1-D list of at least one, got shape (1, 2)"),
    ([], SpecError, "must be a time or a 1-D list of at least one, got shape (0,)"),
])
def test_sample_refuses_times_it_cannot_honour(run, times, kind, reason):
    """NaN, infinite or out-of-span times, and what is not times: a ``SpecError`` naming
    ``times``, never a trajectory of NaN or a plain ValueError."""
    assert reason in refused(lambda: run.sample(times), kind, "times")


def test_sample_inside_the_span_still_interpolates(run):
    s = run.sample([0.0, 10.0, 20.0])
    np.testing.assert_array_equal(s.omega[[0, 2]], run.omega[[0, -1]])
    assert np.all(np.isfinite(s.omega)) and s.t.tolist() == [0.0, 10.0, 20.0]


@pytest.mark.parametrize("los, kind, reason", [
    ((0.0, 0.0, 0.0), SpecError, "must not be zero: a direction needs a length"),
    ("abc", SpecTypeError, "must be a list of 3 numbers, got 'abc'"),
    ((1.0, 2.0), SpecTypeError, "must be a list of 3 numbers"),
    ((math.nan, 0.0, 1.0), SpecError, "must be finite"),
])
def test_radiation_line_of_sight_through_the_schema(run, los, kind, reason):
    """A zero, non-finite or malformed line of sight: the schema's typed error naming it."""
    assert reason in refused(lambda: run.radiation(line_of_sight=los), kind, "line_of_sight")


@pytest.mark.parametrize("scale", [1e308, 1e-320, 5e-324])
def test_a_line_of_sight_of_any_finite_size_is_its_direction(run, scale):
    """1e308 components overflowed |n| and 1e-320 underflowed it: the schema passed them, the
    detector refused them after the simulation.  Normalised safely (by the largest component
    first), the power toward them is the power toward (1, 1, 1) or (1, 0, 0)."""
    for direction in ((1.0, 1.0, 1.0), (1.0, 0.0, 0.0)):
        huge = tuple(scale * x for x in direction)
        a, b = run.radiation(line_of_sight=huge), run.radiation(line_of_sight=direction)
        np.testing.assert_allclose(a["power_per_sr"].values, b["power_per_sr"].values, rtol=1e-14, atol=0)
        n, _, _ = RA.polarization_basis(huge)
        np.testing.assert_allclose(n, np.asarray(direction) / np.linalg.norm(direction), rtol=1e-15)


def test_the_detector_takes_every_line_of_sight_the_schema_takes():
    """The detector on a symmetric top at (1e308, 1e308, 1e308) and (1e-320, 0, 0): the lines it
    reports are those toward (1, 1, 1) and (1, 0, 0)."""
    from spinviz.analysis.detector import detect

    tr = spinviz.simulate(BODY, "reduced", (0.02, 0.05, 0.3), t_end=20.0, samples=9)
    for huge, plain in (((1e308,) * 3, (1.0, 1.0, 1.0)), ((1e-320, 0.0, 0.0), (1.0, 0.0, 0.0))):
        a, b = detect(tr, line_of_sight=huge), detect(tr, line_of_sight=plain)
        np.testing.assert_array_equal(a.line_of_sight, b.line_of_sight)
        np.testing.assert_allclose(a.power, b.power, rtol=1e-14)


component = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([0.0, -0.0, 5e-324, 1e-320,
                                                                                        1e308, -1e308]))


@given(v=st.tuples(component, component, component))
def test_one_rule_for_a_line_of_sight(v):
    """The schema (``[observe].line_of_sight``, ``--los``) accepts exactly the directions the
    detector can normalise, and nothing it then refuses."""
    from spinviz.inputs.scene import ObserveTable

    try:
        ObserveTable(line_of_sight=v)
        accepted = True
    except SpecError as e:
        assert e.key == "line_of_sight"
        accepted = False
    try:
        n = R.unit_vector(v)
        usable = bool(np.all(np.isfinite(n))) and abs(np.linalg.norm(n) - 1.0) < 1e-15
    except ValueError:
        usable = False
    assert accepted == usable
    if accepted:
        RA.polarization_basis(v)                        # never refused after the schema accepted


@pytest.mark.parametrize("call, kind, key", [
    (lambda: spinviz.symmetric_top(math.nan, 0.0), SpecError, "delta"),
    (lambda: spinviz.symmetric_top(0.3, math.inf), SpecError, "chi"),
    (lambda: spinviz.symmetric_top("x", 0.0), SpecTypeError, "delta"),
    (lambda: spinviz.symmetric_top(0.3, None), SpecTypeError, "chi"),
    (lambda: spinviz.symmetric_top(1.0, 0.0), SpecError, "delta"),
    (lambda: spinviz.Body("b", "dimensionless", (1.0, 1.0), (0.0, 0.0, 1.0)), SpecTypeError, "inertia"),
    (lambda: spinviz.Body("b", "dimensionless", "abc", (0.0, 0.0, 1.0)), SpecTypeError, "inertia"),
    (lambda: spinviz.Body("b", "dimensionless", (1.0, 1.0, -1.0), (0.0, 0.0, 1.0)), SpecError, "inertia"),
    (lambda: spinviz.Body("b", "dimensionless", (1.0, 1.0, 1.0), "z"), SpecTypeError, "dipole"),
    (lambda: spinviz.Body("b", "dimensionless", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), SpecError, "dipole"),
    (lambda: spinviz.Body("b", "metric", (1.0, 1.0, 1.0), (0.0, 0.0, 1.0)), SpecError, "units"),
    (lambda: spinviz.Body(3, "cgs", (1.0, 1.0, 1.0), (0.0, 0.0, 1.0)), SpecTypeError, "name"),
    (lambda: P.dast_cube(a_nm=-1.0), SpecError, "a_nm"),
    (lambda: P.dast_cube(a_nm="big"), SpecTypeError, "a_nm"),
    (lambda: P.cellulose_rod(density=math.nan), SpecError, "density"),
    (lambda: P.dast_family1(c_nm=None), SpecTypeError, "c_nm"),
])
def test_body_constructors_raise_the_schemas_errors(call, kind, key):
    """``symmetric_top(nan, 0)``, a two-value ``Body`` inertia, strings where numbers go: a
    ``SpecError`` (``SpecTypeError`` for the wrong kind) naming the argument -- ``BodyError``
    is one."""
    refused(call, kind, key)


hostile = st.one_of(st.none(), st.booleans(), st.text(max_size=8), st.floats(allow_nan=True, allow_infinity=True),
                    st.integers(-10**30, 10**30), st.lists(st.floats(), max_size=4),
                    st.sampled_from([0.0, -1.0, 1e-300, 1e300, [1.0, 1.0], (1.0, 1.0, 1.0, 1.0), {}, object()]))
CALLABLES = {
    "symmetric_top": (spinviz.symmetric_top, ("delta", "chi")),
    "Body": (lambda inertia, dipole, units: spinviz.Body("b", units, inertia, dipole), ("inertia", "dipole", "units")),
    "dast_box": (P.dast_box, ("a_nm", "b_nm", "c_nm", "density")),
    "cellulose_rod": (P.cellulose_rod, ("density",)),
}


@given(data=st.data())
def test_hostile_arguments_to_a_body_constructor_get_one_typed_error(data):
    """Any value for any argument: a body, or a ``SpecError`` naming that argument."""
    name = data.draw(st.sampled_from(sorted(CALLABLES)))
    fn, params = CALLABLES[name]
    good = {"delta": 0.3, "chi": 0.5, "inertia": (1.0, 1.0, 0.5), "dipole": (0.0, 0.0, 1.0), "units": "dimensionless",
            "a_nm": 100.0, "b_nm": 100.0, "c_nm": 50.0, "density": 1.3}
    kw = {p: good[p] for p in params}
    bad = data.draw(st.sampled_from(params))
    kw[bad] = data.draw(hostile)
    try:
        body = fn(**kw)
    except SpecError as e:
        assert bad in [k.strip() for k in e.key.split(",")], (name, kw, e)   # a rule joining dimensions names them all
        return
    assert np.all(np.isfinite(body.inertia)) and np.all(np.isfinite(body.dipole))
