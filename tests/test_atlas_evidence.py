"""``spinviz atlas --evidence KIND``: the options each kind takes, the tolerance study's
invariants, and the convergence rows kept in an atlas store that stays verifiable."""

import json

import numpy as np
import pytest

from spinviz.errors import UsageError
from spinviz.regimes import api
from spinviz.regimes.store import dataset as ST
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


@pytest.mark.parametrize("kind, options, message", [
    ("crosscheck", {"tau_end": 1e8}, "--evidence crosscheck: does not use --tau-end"),
    ("tolerance", {"out": "x.zarr"}, "--evidence tolerance: does not use --out"),
    ("validate", {"horizons": "1e10,1e12"}, "--evidence validate: does not use --horizons"),
    ("convergence", {"horizons": "1e12,1e10"}, "--horizons: give at least two increasing positive horizons"),
    ("convergence", {"horizons": "1e10,x"}, "--horizons: expected numbers separated by commas"),
    ("convergence", {"out": "/nonexistent/a.zarr"}, "--out /nonexistent/a.zarr: not an atlas store"),
    ("handover", {"workers": 2}, "--evidence handover: does not use --workers"),
    ("nonsense", {}, "--evidence: nonsense is not one of validate, crosscheck, physical, convergence, tolerance, "
                     "handover, basins, flows"),
])
def test_options_a_kind_does_not_take_are_refused_before_work(kind, options, message):
    with pytest.raises(UsageError) as e:
        evidence.run(kind, 1, **options)
    assert message in str(e.value)


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
    from spinviz.validation.atlas import handover as HV

    row = HV.compare_point("3 deep", "reduced", 0.8, 11.4, 0.1, 4, 1e10, 1e-10)
    assert row["agreement"] == {"same": 4} and row["engine"] == {"3": 4} and row["handed_over"] == 4
    assert row["beyond_bound"] == 0 and row["max_diff_over_bound"] < 1.0 and row["references"] == []
    assert "| 3 deep | reduced | 1e+10 | 3 4 | 3 4 (3 4) | same 4 |" in HV.format_table([row])
    assert HV.agreement("other", "3") == "undecided" and HV.agreement("1|2", "1") == "compatible"


def test_convergence_rows_kept_in_the_store_which_stays_verifiable(tmp_path):
    spec = tmp_path / "e.toml"
    spec.write_text(SPEC)
    out = str(tmp_path / "e.zarr")
    api.atlas(str(spec), out, workers=1, processes=False, progress=False)
    rows = [{"point": "x", "labels": {"1e10": {"3": 1.0}}}]
    CV.record(out, rows)
    assert ST.verify(out).clean
    assert json.loads(ST.open_atlas(out).attrs["convergence"]) == rows
    with open(f"{out}/.zgroup", "a") as f:                       # metadata damaged: nothing blessed
        f.write(" ")
    with pytest.raises(ValueError, match="do not match their checksums"):
        CV.record(out, rows)
    assert not ST.verify(out).clean
    assert np.isfinite(ST.open_atlas(out)["confidence"].values).all()
