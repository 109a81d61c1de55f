"""The surfaces this wave added, fuzzed from their own schemas (Hypothesis): the model registry
(names, registrations), ``Scene.require``, ``ReceiverSpec.with_options`` and the receiver's
keys, and the front doors ``spinviz.experiment.compare``, ``observe``, ``decide``, ``listen``
and ``test_measurements``.  Any argument, however hostile, gets either acceptance (the work is
reached: here it raises ``Reached``) or one ``SpinvizError`` whose message is one short line of
printable text -- never a ``KeyError``, ``AttributeError`` or a bare ``TypeError`` from deep
inside, never a control character of the argument echoed raw, never the work started on a
value the schema refuses.

Deterministic in CI (conftest's "ci" profile); ``HYPOTHESIS_PROFILE=fuzz`` hunts longer."""

import inspect
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spinviz import experiment
from spinviz.errors import SpecError, SpecTypeError, SpinvizError, printable
from spinviz.inputs.base import fields_of
from spinviz.inputs.receiver import DETECTOR_KEYS, ReceiverSpec
from spinviz.inputs.scene_spec import NEEDS, load_scene
from spinviz.physics import models as M

ROOT = Path(__file__).resolve().parents[1]
CUBE = str(ROOT / "scenes" / "dast_cube.toml")
ESCAPES = "\x1b[31mX\x1b[0m\r\n\u202e\u200b\x00"
TEXTS = ["", " ", "reduced", "decide", "x" * 5000, ESCAPES, "a.wav", "sub/dir/a.wav", "/dev/null", "a.png", "a.csv",
         "a.json", ".", "/", "\udcff.wav"]
ODD = [None, True, False, 0, -1, 1, 2**63, 10**40, -(10**40), 0.0, -0.0, 1e-320, 1e308, math.nan, math.inf, -math.inf,
       b"a.wav", bytearray(b"x"), [], [1.0], [1.0, 2.0, 3.0], (0.0, 0.0, 0.0), {}, {"a": 1}, object(), np.float32(2.0),
       np.array([1.0, 2.0]), np.nan, complex(1, 1), print]
hostile = st.one_of(st.sampled_from(ODD), st.sampled_from(TEXTS), st.text(max_size=12),
                    st.floats(allow_nan=True, allow_infinity=True), st.integers(-(10**25), 10**25),
                    st.lists(st.floats(allow_nan=True), max_size=4))


class Reached(Exception):
    """The work started: every argument was accepted."""


def one_clear_line(e: BaseException) -> None:
    """A refusal as the standards ask: a spinviz error, one printable line of sensible length."""
    assert isinstance(e, SpinvizError), f"{type(e).__name__}: {e}"
    msg = str(e)
    assert msg and printable(msg, 10**6) == msg, repr(msg)      # nothing that colours, splits or reorders a terminal
    assert len(msg) <= 600, len(msg)


def bounds_of(cls) -> dict:
    """field -> (lo, hi) of a request class's ranges (``between``'s, or Field(ge/le)), read from
    the schema so that values just past every bound are tried."""
    import typing

    from spinviz.inputs.base import _bounds

    out = {}
    for name, field in fields_of(cls).items():
        lo, _, hi, _ = _bounds(cls, name)
        metadata = list(field.metadata)
        for arg in typing.get_args(field.annotation):                # an optional field: X | None
            metadata += list(getattr(arg, "__metadata__", ()))
        for m in metadata:
            lo, hi = getattr(getattr(m, "func", None), "bounds", (lo, hi))
        out[name] = (lo, hi)
    return out


def near_bounds(lo, hi) -> list:
    vals = []
    for b in (lo, hi):
        if isinstance(b, int | float) and math.isfinite(b):
            vals += [b, b * (1 + 1e-7) + 1e-300, b * (1 - 1e-7) - 1e-300]
    return vals


RECEIVER_EDGES = {k: near_bounds(*bounds_of(ReceiverSpec).get(k, (None, None))) for k in DETECTOR_KEYS}


def receiver_value(key):
    """Hostile values for a receiver key, the schema's bounds among them."""
    edges = RECEIVER_EDGES.get(key) or [0.0]
    return st.one_of(hostile, st.sampled_from(edges))


# --- the model registry ---------------------------------------------------------------------------
@settings(max_examples=max(2, settings.default.max_examples // 3))
@given(name=hostile)
def test_any_name_gets_a_model_or_one_line(name):
    try:
        m = M.get(name)
    except ValueError as e:
        msg = str(e)
        assert msg.startswith("unknown model ") and msg.endswith(f"valid: {', '.join(M.names())}"), msg
        assert "\n" not in msg and printable(msg, 10**6) == msg and len(msg) < 300, repr(msg)
        return
    assert m.name in M.names()


GOOD_MODEL = {"name": "toy", "equations": "(0)", "summary": "a test", "terms": M.FREE.terms}


@given(field=st.sampled_from(["name", "equations", "summary", "terms", "kernel_id", "brakes", "symmetric_rate",
                              "averaged", "line", "type_labels"]), value=hostile)
def test_a_bad_registration_is_refused_when_the_model_is_made(field, value):
    """A model entry whose name is not a lower-case identifier, whose rate is not callable, or
    whose optional parts are of the wrong kind is refused when it is made (``ValueError`` or
    ``TypeError``, one line), not when a run first reaches it."""
    try:
        m = M.Model(**{**GOOD_MODEL, field: value})
    except (ValueError, TypeError) as e:
        msg = str(e)
        assert "\n" not in msg and printable(msg, 10**6) == msg and len(msg) < 300, repr(msg)
        return
    assert isinstance(m.name, str) and m.name.isidentifier() and callable(m.terms)
    assert m.kernel_id is None or isinstance(m.kernel_id, int)


@given(entry=hostile)
def test_only_a_model_can_be_registered(entry):
    with pytest.raises(TypeError, match="register takes a Model"):
        M.register(entry)
    assert M.names() == ("reduced", "truncated", "free")


def test_a_registered_toy_with_a_taken_name_or_kernel_is_refused():
    with pytest.raises(ValueError, match="already registered"):
        M.register(M.Model(**{**GOOD_MODEL, "name": "reduced"}))
    with pytest.raises(ValueError, match="kernel id 1 is taken"):
        M.register(M.Model(**{**GOOD_MODEL, "kernel_id": 1}))
    assert M.names() == ("reduced", "truncated", "free")


# --- Scene.require --------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cube():
    return load_scene(CUBE)


@given(command=hostile)
def test_require_names_an_unknown_command(cube, command):
    try:
        cube.require(command)
    except SpinvizError as e:
        one_clear_line(e)
        assert isinstance(e, SpecError) and e.key == "command", e
        assert e.reason.endswith(f"valid: {', '.join(NEEDS)}"), e.reason
        return
    assert command in NEEDS


# --- the receiver ---------------------------------------------------------------------------------
@given(data=st.data())
def test_receiver_options_get_a_receiver_or_one_line(data):
    keys = data.draw(st.lists(st.sampled_from([*DETECTOR_KEYS, "distance", ESCAPES, "x" * 3000]), max_size=4,
                              unique=True))
    given_ = {k: data.draw(receiver_value(k)) for k in keys}
    try:
        rx = ReceiverSpec().with_options(**given_)
    except SpinvizError as e:
        one_clear_line(e)
        return
    for k in DETECTOR_KEYS:
        v = getattr(rx, k)
        assert v is None or (isinstance(v, float) and math.isfinite(v)), (k, v)
    lo, hi = bounds_of(ReceiverSpec)["distance_cm"]
    assert lo <= rx.distance_cm <= hi


# --- the front doors ------------------------------------------------------------------------------
@pytest.fixture
def world(monkeypatch, tmp_path):
    """Every front door's work raises ``Reached``; files land in a scratch directory."""
    from spinviz import driver
    from spinviz.analysis import decide, observe, pftest, sonify

    def reached(*a, **k):
        raise Reached

    for mod, name in ((driver, "simulate_request"), (observe, "run_scene"), (sonify, "listen_scene"),
                      (decide, "run"), (experiment, "_mapper"), (pftest, "fit")):
        monkeypatch.setattr(mod, name, reached)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "30")
    (tmp_path / "m.csv").write_text("f_hz,power,sigma_f_hz,sigma_power\n" +
                                    "".join(f"{7e9 + i},1e-19,0.01,1e-21\n" for i in range(5)))
    return tmp_path


DOORS = {name: getattr(experiment, name) for name in ("compare", "observe", "decide", "listen", "test_measurements")}


def arguments(fn) -> list[str]:
    """A front door's keyword arguments, from its signature (a new one is fuzzed without a new test)."""
    return [p.name for p in inspect.signature(fn).parameters.values()
            if p.name != "scene" and p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD)]


@pytest.mark.parametrize("door", sorted(DOORS))
@settings(max_examples=max(2, settings.default.max_examples // 3))          # each example reads a scene
@given(data=st.data())
def test_any_arguments_to_a_front_door_get_the_work_or_one_line(world, door, data):
    fn = DOORS[door]
    names = arguments(fn)
    receiver = "receiver" in inspect.signature(fn).parameters or door in ("observe", "listen", "decide")
    pool = names + ([*DETECTOR_KEYS, "bogus_key"] if receiver else [])
    kw = {"out": "a.wav"} if door == "listen" else {}
    if door == "test_measurements":
        kw = {"measurements": "m.csv"}
    for k in data.draw(st.lists(st.sampled_from(pool), max_size=3, unique=True)):
        kw[k] = data.draw(receiver_value(k) if k in DETECTOR_KEYS else hostile)
    scene = data.draw(st.one_of(st.just(CUBE), st.just(load_scene(CUBE)), hostile))
    try:
        fn(scene, **kw)
    except Reached:
        return
    except SpinvizError as e:
        one_clear_line(e)
        return
    except BaseException as e:                      # anything else escaped the schema
        raise AssertionError(f"{door}({scene!r:.60}, {kw!r:.200}) raised {type(e).__name__}: {e}") from e
    assert door == "test_measurements"              # its work (the fit) is patched; the read ran


FOUND = [   # what the hunt turned up, checked in every run
    (lambda: experiment.listen(CUBE, None), SpecTypeError, "out"),
    (lambda: experiment.test_measurements(CUBE, 123), SpecTypeError, "measurements"),
    (lambda: experiment.test_measurements(CUBE, None), SpecTypeError, "measurements"),
    (lambda: load_scene(CUBE).require("nope"), SpecError, "command"),
    (lambda: ReceiverSpec().with_options(**{ESCAPES: 1.0}), SpecError, None),
]


@pytest.mark.parametrize("call, kind, key", FOUND, ids=["listen-out-none", "measurements-int", "measurements-none",
                                                      "require-unknown", "receiver-key-escapes"])
def test_what_the_hunt_found(world, call, kind, key):
    with pytest.raises(kind) as e:
        call()
    one_clear_line(e.value)
    if key is not None:
        assert e.value.key == key
