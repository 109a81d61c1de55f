"""The counts and horizons of the study commands through the schema, before any work:
``atlas evidence``'s ``--members``, ``--tau-end``, ``--horizons``; ``check --sweep``'s
``--seeds`` and ``--runs``; ``bench``'s ``--repeats`` -- finite, in range, the option named
and the limit in the message; a cap against years of work that says how to raise it; and the
same limits in Python, named as arguments."""

import pytest

from spinviz.commands import main
from spinviz.errors import SpecError
from spinviz.inputs import options as O
from spinviz.validation import bench, process_bench, secular_sweep
from spinviz.validation.atlas import convergence, crosscheck, evidence, physical, validate


class Started(Exception):
    """The work itself was reached."""


@pytest.fixture
def no_work(monkeypatch):
    """Every study's work raises ``Started`` if reached: a refused value must never get there."""
    def started(*a, **k):
        raise Started

    monkeypatch.setattr(evidence, "_compute", started)
    monkeypatch.setattr(secular_sweep, "run_case", started)
    monkeypatch.setattr(bench, "make_problem", started)
    monkeypatch.setattr(process_bench, "problem", started)
    monkeypatch.setattr(validate, "atlas", started)
    monkeypatch.setattr(crosscheck, "scipy_run", started)
    monkeypatch.setattr(physical, "integrate_many", started)
    monkeypatch.setattr(convergence, "run_point", started)
    monkeypatch.setattr(convergence, "integrate_many", started)


REFUSED = [
    # unbounded work, values a raw Python/NumPy message would meet, a zero that is not the default,
    # a count the kind's own atlas would refuse under its key
    (["atlas", "evidence", "physical", "--tau-end", "1e300"], "--tau-end: must lie in [100000, 1e+16]"),
    (["atlas", "evidence", "convergence", "--horizons", "1e10,1e300"], "--horizons: each must lie in [100000, 1e+20]"),
    (["atlas", "evidence", "physical", "--tau-end", "nan"], "--tau-end: must be finite, got nan"),
    (["atlas", "evidence", "physical", "--tau-end", "inf"], "--tau-end: must be finite, got inf"),
    (["atlas", "evidence", "physical", "--tau-end", "-1"], "--tau-end: must lie in [100000, 1e+16]"),
    (["atlas", "evidence", "physical", "--tau-end", "1e-300"], "--tau-end: must lie in [100000, 1e+16]"),
    (["atlas", "evidence", "physical", "--tau-end", "0"], "--tau-end: must lie in [100000, 1e+16]"),
    (["atlas", "evidence", "convergence", "--horizons", "nan,1e12"], "--horizons: must be finite"),
    (["atlas", "evidence", "convergence", "--horizons", "1e12,1e10"], "--horizons: must increase"),
    (["atlas", "evidence", "convergence", "--horizons", "1e10"], "--horizons: give 2 to 8 horizons, got 1"),
    (["atlas", "evidence", "validate", "--members", "1000000000"], "--members: evidence validate with 1000000000 "
                                                                      "member(s) per point would take ~"),
    (["atlas", "evidence", "crosscheck", "--members", "100000"], "--members: evidence crosscheck with 100000"),
    (["check", "--sweep", "--seeds", "1-99999999"], "--seeds: 99999999 seed(s) x 40 runs (~0.2 s a run) would take ~"),
    (["check", "--sweep", "--runs", "1000000000"], "--runs: 3 seed(s) x 1000000000 runs"),
    (["check", "--sweep", "--seeds", "5-1"], "--seeds: no seeds in 5-1"),
    (["bench", "--repeats", "1000000000"], "--repeats: 1000000000 repeats of every point"),
    (["bench", "--process", "--repeats", "1000000000"], "--repeats: 1000000000 repeats of every point"),
    (["bench", "--problems", "nope"], "--problems: unknown 'nope'; valid: "),
]


@pytest.mark.parametrize("argv, message", REFUSED, ids=[" ".join(a[:4]) for a, _ in REFUSED])
def test_a_bad_count_or_horizon_is_refused_naming_its_option_before_any_work(no_work, capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"spinviz: error: {message}"), err
    if "would take" in message:
        assert "raises the cap with SPINVIZ_MAX_DAYS=DAYS" in err     # how someone who means it goes on


def test_a_user_who_means_it_raises_the_cap(no_work, monkeypatch, capsys):
    """With the cap raised the same request is accepted -- and reaches the work (here: stopped)."""
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "1e9")
    with pytest.raises(Started):
        main(["check", "--sweep", "--runs", "1000000000"])
    monkeypatch.setenv("SPINVIZ_MAX_DAYS", "soon")
    assert main(["check", "--sweep", "--runs", "1000000000"]) == 2
    assert "SPINVIZ_MAX_DAYS: must be a number of days, got 'soon'" in capsys.readouterr().err


@pytest.mark.parametrize("call, key", [
    (lambda: secular_sweep.run(range(1, 100000000), 40), "seeds"),
    (lambda: secular_sweep.run([1, 2], 10**9), "runs"),
    (lambda: secular_sweep.run([-1], 1), "seeds"),
    (lambda: bench.run(bench.Plan(repeats=10**9)), "repeats"),
    (lambda: process_bench.run(repeats=10**9), "repeats"),
    (lambda: process_bench.run(turns=float("inf")), "turns"),
    (lambda: physical.compare(tau_end=1e300), "tau_end"),
    (lambda: physical.compare(members=0), "members"),
    (lambda: convergence.study(horizons=(1e10, 1e300)), "horizons"),
    (lambda: evidence.run("tolerance", members=10**9), "members"),
    (lambda: evidence.run("crosscheck", members=10**6), "members"),
    (lambda: evidence.run("validate", members=10**9), "members"),
    (lambda: evidence.run("physical", tau_end=0.0), "tau_end"),
])
def test_the_same_limits_in_python_named_as_arguments(no_work, call, key):
    with pytest.raises(SpecError) as e:
        call()
    assert e.value.key == key


def test_a_range_of_seeds_is_judged_without_listing_it():
    """``--seeds 0-999999999999999``: the schema counts a range (its length, never the list) and
    refuses its work; listing it first would take the memory of the machine."""
    with pytest.raises(SpecError) as e:
        O.SweepRequest(seeds=range(0, 10**15), runs=1)
    assert e.value.key == "seeds" and "years" in e.value.reason
    assert O.count_of(range(0, 10**30)) == 10**30 and O.count_of(range(5, 1)) == 0
