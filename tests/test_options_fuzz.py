"""Every option of every command, fuzzed from the parser itself: the subparsers and their
actions (flags, choices, argument types) are walked, so a new option is fuzzed without a new
test.  Hostile values -- nan, inf, -1, 0, huge, 1e-300, empty, unicode, long -- must get
either acceptance or one line on stderr naming the option, an exit status of the command's
own set, and no traceback; a value no option can take (non-finite or astronomically large
numbers) must be refused before any work: every heavy entry point raises if it is reached.

Deterministic in CI (conftest's "ci" profile, derandomized); ``HYPOTHESIS_PROFILE=fuzz``
runs a longer random hunt."""

import argparse
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spinviz import commands
from spinviz.commands import shared
from spinviz.validation.atlas.evidence import KINDS

ROOT = Path(__file__).resolve().parents[1]
SCENE = str(ROOT / "scenes" / "dast_cube.toml")
BASE = {                         # a valid invocation of each command, before the options fuzzed
    "check": [], "info": ["dast_cube"], "simulate": [SCENE, "--out", "t.npz"], "render": [SCENE],
    "compare": [SCENE], "observe": [SCENE], "decide": [SCENE], "listen": [SCENE, "--out", "s.wav"], "bench": [],
    "stress": [],
    "report": [], "methods": [], "atlas run": ["SPEC"], "atlas verify": ["nothing.zarr"], "atlas bench": ["SPEC"],
    "atlas boxes": ["--out", "b.nc"],
}
STATUSES = {0, 1, 2, 75}         # success, a failed run, bad input, a busy store or lost cluster
NUMBER_TYPES = {shared.whole, shared.real, shared.positive}
# what no numeric option takes (the largest legitimate values are 1e20 horizons and 1e30 cm)
MUST_REFUSE = ["nan", "inf", "-inf", "NaN", "1e300", "1" + "0" * 40]
NUMBERS = ["nan", "inf", "-inf", "-1", "0", "1", "2", "3", "0.5", "1e-300", "1e300", "1e16", "-0", "5e-324",
           "1" + "0" * 40, "1e10", "100000"]
TEXTS = ["", " ", "abc", "\u03c9\u202e", "x" * 300, "-", "a,b", ",", "1-2", "5-1", "/", "/dev/null", "sub/dir/x.png",
         "\U0001f600.toml"]


class Reached(Exception):
    """A heavy entry point was reached: the options were accepted."""


def heavy_entries():
    """The modules' attributes that start real work, for every command."""
    from spinviz import driver, pipeline
    from spinviz.analysis import decide
    from spinviz.regimes import bench as atlas_bench
    from spinviz.regimes import compute
    from spinviz.regimes.asymmetric import atlas as boxes_atlas
    from spinviz.regimes.store import dataset
    from spinviz.validation import bench, checks, process_bench, render_bench, report, secular_sweep, stress
    from spinviz.validation.atlas import evidence

    return [(driver, "simulate_request"), (driver, "simulate"), (pipeline, "require_render_stack"),
            (render_bench, "require_render_stack"), (checks, "run_all"), (secular_sweep, "run_case"),
            (bench, "make_problem"), (process_bench, "problem"), (stress, "run_all"), (report, "generate"),
            (compute, "compute"), (atlas_bench, "atlas"), (dataset, "Writer"), (evidence, "_compute"),
            (decide, "setup_from_scene"), (decide, "run"), (boxes_atlas, "atlas")]


@pytest.fixture
def world(monkeypatch, tmp_path, small_atlas_spec):
    """Heavy work raises ``Reached``; the command runs in a scratch directory."""
    def reached(*a, **k):
        raise Reached

    for mod, name in heavy_entries():
        monkeypatch.setattr(mod, name, reached)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "30")
    return str(small_atlas_spec)


def parser_actions() -> dict:
    """command path ("atlas evidence basins") -> [argparse actions with an option string], from
    ``commands.parser()``, every nested sub-command walked to its leaves."""
    out = {}

    def walk(p, path):
        sub = next((a for a in p._actions if isinstance(a, argparse._SubParsersAction)), None)
        if sub is None:
            out[" ".join(path)] = [a for a in p._actions if a.option_strings and not isinstance(a, argparse._HelpAction)]
            return
        for name, q in sub.choices.items():
            walk(q, [*path, name])

    walk(commands.parser(), [])
    return out


ACTIONS = parser_actions()
NUMERIC = [(name, a.option_strings[-1]) for name, acts in ACTIONS.items() for a in acts if a.type in NUMBER_TYPES]


def values_for(action) -> st.SearchStrategy:
    """Hostile values an action's type and choices suggest (parsing is the parser's, ranges the schema's)."""
    if action.nargs == 0:
        return st.just(None)                                           # a flag
    if action.choices:
        return st.sampled_from([*action.choices, *TEXTS])
    if action.type in NUMBER_TYPES:
        return st.sampled_from(NUMBERS + TEXTS[:5])
    if action.type in (shared.vector, shared.reals) or getattr(action.type, "__name__", "") == "_seed_list":
        return st.lists(st.sampled_from(NUMBERS), min_size=1, max_size=4).map(",".join) | st.sampled_from(TEXTS)
    if action.type is shared.size:
        return st.sampled_from(["1280x720", "0x0", "-1x5", "99999999x99999999", "x", "1e3x2"] + TEXTS[:4])
    return st.sampled_from(TEXTS + NUMBERS[:4])                         # a path, a name, an address


def run(argv, capsys):
    """(exit status or "reached", stderr) of ``spinviz argv`` in this process."""
    try:
        code = commands.main(argv)
    except Reached:
        return "reached", capsys.readouterr().err
    except SystemExit as e:                                            # argparse's own refusal
        code = e.code
    return code, capsys.readouterr().err


def one_line_or_none(code, err) -> None:
    assert "Traceback" not in err, err
    if code in (0, "reached"):
        return
    assert code in STATUSES, (code, err)
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("spinviz: "), err


# the first numeric option of each command in the default run, every one in .ci/run's second pass
FIRST = {c: o for c, o in reversed(NUMERIC)}


@pytest.mark.parametrize("command, option", [(c, o) if FIRST[c] == o else pytest.param(c, o, marks=pytest.mark.slow)
                                             for c, o in NUMERIC], ids=[f"{c} {o}" for c, o in NUMERIC])
def test_no_option_takes_a_non_finite_or_astronomical_number(world, capsys, command, option):
    """Every numeric option of every command, each value no option can take: exit 2, one line
    naming the option, and the work never reached.  (A context flag is added where the option
    needs one: --sweep, --bench.)"""
    context = {"--seeds": ["--sweep"], "--runs": ["--sweep"], "--frames": ["--bench"]}.get(option, [])
    base = [world if x == "SPEC" else x for x in BASE.get(command, [])]
    for value in MUST_REFUSE:
        code, err = run([*command.split(), *base, *context, option, value], capsys)
        assert code == 2, (command, option, value, code, err)
        one_line_or_none(code, err)
        assert option in err, (option, value, err)


def test_every_command_and_numeric_option_is_covered():
    """The walk found the options (a parser change that hid them from it would show here)."""
    assert {c.split()[0] for c, _ in NUMERIC} >= {"check", "render", "observe", "listen", "bench", "atlas", "compare"}
    assert ("atlas evidence physical", "--tau-end") in NUMERIC and ("bench", "--repeats") in NUMERIC
    assert {c for c in ACTIONS if c.startswith("atlas evidence ")} == {f"atlas evidence {k}" for k in KINDS}


@pytest.mark.parametrize("command", sorted(ACTIONS))
@settings(max_examples=max(2, settings.default.max_examples // 4), suppress_health_check=[HealthCheck.too_slow,
                                                                                            HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_any_options_get_acceptance_or_one_line(world, capsys, command, data):
    """Up to four options of a command at once, each with a hostile value its type suggests."""
    acts = ACTIONS[command]
    argv = command.split() + [world if x == "SPEC" else x for x in BASE.get(command, [])]
    if acts:
        chosen = data.draw(st.lists(st.sampled_from(acts), max_size=4, unique_by=lambda a: a.dest))
        for a in chosen:
            value = data.draw(values_for(a))
            argv += [a.option_strings[-1]] + ([] if value is None else [value])
    code, err = run(argv, capsys)
    one_line_or_none(code, err)
    numeric_values = [argv[i + 1] for i, x in enumerate(argv[:-1])
                      if any(x == o for c, o in NUMERIC if c == command)]
    if any(v in MUST_REFUSE for v in numeric_values):
        assert code == 2, (argv, code, err)                            # refused, the work never reached


FOUND = [   # combinations a long hunt (HYPOTHESIS_PROFILE=fuzz) turns up, checked in every run
    (["atlas", "bench", "SPEC", "--workers", "1" + "0" * 40], "--workers: must be at most"),
    (["render", SCENE, "--duration", "nan", "--bench"], "--duration: must be finite, got nan"),
    (["render", SCENE, "--bench", "--frames", "1" + "0" * 40], "--frames: must lie in [2, "),
    (["atlas", "bench", "SPEC", "--write-path", "--workers", "1" + "0" * 40], "--workers: not used by bench "
                                                                                 "--write-path"),
]


@pytest.mark.parametrize("argv, message", FOUND, ids=[" ".join(a[i] for i in (0, 2, 3)) for a, _ in FOUND])
def test_what_the_hunt_found_is_refused_before_any_work(world, capsys, argv, message):
    code, err = run([world if x == "SPEC" else x for x in argv], capsys)
    assert code == 2 and err.startswith(f"spinviz: error: {message}"), (code, err)
