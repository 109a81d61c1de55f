"""``spinviz atlas evidence KIND``: the options each kind takes, the tolerance study's
invariants, and the convergence rows kept in an atlas store that stays verifiable."""

import json

import numpy as np
import pytest

from spinviz.errors import SpecError, SpecTypeError, UsageError
from spinviz.regimes import api
from spinviz.regimes.store import dataset as DS
from spinviz.validation.atlas import convergence as CV
from spinviz.validation.atlas import evidence

SPEC = """title = "evidence test"
models = ["reduced"]
[grid]
delta = [0.3]
chi_deg = [30.0]
[members]
count = 2
seed = 1
omega = 0.04
[run]
tau_end = 1e6
"""


@pytest.mark.parametrize("kind, options, error, message", [
    ("crosscheck", {"tau_end": 1e8}, SpecError, "tau_end: not used by evidence crosscheck (it takes members)"),
    ("tolerance", {"out": "x.zarr"}, SpecError, "out: not used by evidence tolerance"),
    ("validate", {"horizons": (1e10, 1e12)}, SpecError, "horizons: not used by evidence validate"),
    ("convergence", {"horizons": (1e12, 1e10)}, SpecError, "horizons: must increase"),
    ("convergence", {"horizons": "1e10,x"}, SpecTypeError, "horizons: must be a list of horizons tau"),
    ("convergence", {"horizons": (1e10, 1e300)}, SpecError, "horizons: each must lie in [100000, 1e+20]"),
    ("handover", {"horizons": (1e12, 1e18)}, SpecError, "horizons: each must lie in [100000, 1e+16]"),
    ("handover", {"workers": 2}, SpecError, "workers: not used by evidence handover"),
    ("basins", {"tau_end": float("inf")}, SpecError, "tau_end: must be finite"),
    ("physical", {"tau_end": 0.0}, SpecError, "tau_end: must lie in [100000, 1e+16]"),
    ("physical", {"tau_end": float("nan")}, SpecError, "tau_end: must be finite"),
    ("convergence", {"out": "/nonexistent/a.zarr"}, UsageError, "--out /nonexistent/a.zarr: not an atlas store"),
    ("nonsense", {}, UsageError, "evidence: nonsense is not one of validate, crosscheck, physical, convergence, "
                                 "tolerance, handover, basins, bound, flows"),
])
def test_options_a_kind_does_not_take_are_refused_before_work(kind, options, error, message, monkeypatch):
    """Each refused before any work: the computation itself raises if reached."""
    monkeypatch.setattr(evidence, "_compute", lambda req: pytest.fail("reached the work"))
    with pytest.raises(error) as e:
        evidence.run(kind, 1, **options)
    assert message in str(e.value)


def test_the_evidence_listing_names_every_kind(capsys):
    """``spinviz atlas evidence --help`` prints each kind with its description (argparse
    expands '%' in help texts: a description must survive that)."""
    from spinviz.commands import main

    with pytest.raises(SystemExit) as e:
        main(["atlas", "evidence", "--help"])
    assert e.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for kind in evidence.KINDS.values():
        assert f"{kind.name} {' '.join(kind.summary.split()[:4])}" in text, kind.name


@pytest.mark.parametrize("kind", sorted(evidence.KINDS))
def test_each_kind_is_a_sub_command_with_exactly_its_options(kind, capsys):
    """``spinviz atlas evidence KIND --help`` lists --members, the options the registry says the
    kind takes and --json, nothing else; an option it does not take is refused by the parser."""
    from spinviz.commands import main

    with pytest.raises(SystemExit) as e:
        main(["atlas", "evidence", kind, "--help"])
    assert e.value.code == 0
    text = capsys.readouterr().out
    flags = {w.rstrip(",") for w in text.split() if w.startswith("--")}
    taken = {"--" + o.replace("_", "-") for o in evidence.KINDS[kind].options}
    assert flags == {"--help", "--members", "--json"} | taken
    missing = sorted({"--tau-end", "--horizons", "--workers", "--out"} - taken)
    if missing:
        with pytest.raises(SystemExit) as e:
            main(["atlas", "evidence", kind, missing[0], "1"])
        assert e.value.code == 2 and f"unrecognized arguments: {missing[0]}" in capsys.readouterr().err


@pytest.mark.slow
def test_tolerance_rows_against_the_tightest_rtol():
    """The tightest rtol is its own reference (all labels the same, end states identical);
    a looser one moves the end states more than a tighter one does."""
    rows = CV.tolerance(members=2, rtols=(1e-5, 1e-8, 1e-11), cells=3, tau_end=1e7)
    assert [(r["model"], r["rtol"]) for r in rows] == [(m, t) for m in ("reduced", "truncated")
                                                       for t in (1e-5, 1e-8, 1e-11)]
    for model in ("reduced", "truncated"):
        by = {r["rtol"]: r for r in rows if r["model"] == model}
        assert by[1e-11]["same_label"] == 1.0 and by[1e-11]["end_state_max"] == 0.0
        assert all(r["runs"] == 18 and r["reference_rtol"] == 1e-11 for r in by.values())
        assert by[1e-5]["end_state_median"] > by[1e-8]["end_state_median"] > 0
    assert "| reduced | 1e-05 |" in CV.format_tolerance(rows)


def test_handover_evidence_row_against_brute_force():
    """One point of the hand-over evidence: engine and brute force on the same starts, the
    labels compared, every handed-over end state within its bound of brute force's."""
    from spinviz.validation.atlas import against_brute_force as HV

    row = HV.compare_point("3 deep", "reduced", 0.8, 11.4, 0.1, 4, 1e10, 1e-10)
    assert row["agreement"] == {"same": 4} and row["engine"] == {"3": 4} and row["handed_over"] == 4
    assert row["beyond_bound"] == 0 and row["max_diff_over_bound"] < 1.0 and row["references"] == []
    assert "| 3 deep | reduced | 1e+10 | 3 4 | 3 4 (3 4) | same 4 |" in HV.format_table([row])
    assert HV.agreement("other", "3") == "undecided" and HV.agreement("1|2", "1") == "compatible"


@pytest.mark.slow
def test_convergence_rows_kept_in_the_store_which_stays_verifiable(tmp_path):
    spec = tmp_path / "e.toml"
    spec.write_text(SPEC)
    out = str(tmp_path / "e.zarr")
    api.atlas(str(spec), out, workers=1, processes=False, progress=False)
    rows = [{"point": "x", "labels": {"1e10": {"3": 1.0}}}]
    CV.record(out, rows)
    assert DS.verify(out).clean
    assert json.loads(DS.open_atlas(out).attrs["convergence"]) == rows
    with open(f"{out}/.zgroup", "a") as f:                       # metadata damaged: nothing blessed
        f.write(" ")
    with pytest.raises(ValueError, match="do not match their checksums"):
        CV.record(out, rows)
    assert not DS.verify(out).clean
    assert np.isfinite(DS.open_atlas(out)["confidence"].values).all()
