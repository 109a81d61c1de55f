"""The hodographs' representative runs: each type shown from the cell deepest inside its
domain, away from every boundary, on a diagram whose domains are known in closed form."""

import math

import numpy as np
import pytest
import xarray as xr

from spinviz.physics import asymptotics as FM
from spinviz.regimes import TYPE_CODES
from spinviz.regimes.figures import hodographs as HG
from spinviz.validation.atlas.validate import spinviz_domain

N = 32                                     # the figure atlas's grid: 32 x 32 cell centres


@pytest.fixture(scope="module")
def diagram():
    """A reduced-model store as ``open_atlas`` gives it, each cell's 2 starts labelled -- at
    tau_end and as tau -> oo -- by spinviz's reading of the averaged flow (type 1 below
    alpha(4.14) = -1, 2 up to (4.15), 3 where (4.16) is positive, 4 up to beta(4.18) = -3/4,
    5 beyond); the starts' confidences differ, the first one's series kept."""
    deltas = -1.0 + (np.arange(N) + 0.5) * 2.0 / N
    chis = (np.arange(N) + 0.5) * 0.5 * math.pi / N
    lab = np.array([[spinviz_domain(float(d), float(c)) for c in chis] for d in deltas], dtype="<U11")
    lab = np.repeat(lab[None, :, :, None], 2, axis=3)
    conf = np.broadcast_to(np.array([0.9, 0.95]), lab.shape).copy()
    dims = ("model", "delta", "chi", "member")
    return xr.Dataset({"label": (dims, lab), "limit_label": (dims, lab), "confidence": (dims, conf),
                       "candidate": (dims, np.zeros(lab.shape, dtype=np.int8)),
                       "series": (("model", "delta", "chi", "start", "sample", "axis"), np.zeros((1, N, N, 1, 1, 3)))},
                      coords={"model": ["reduced"], "delta": deltas, "chi": chis, "member": [0, 1], "start": [0]})


def test_depth_counts_grid_steps_to_the_nearest_other_cell_or_edge():
    pure = np.zeros((7, 9), dtype=bool)
    pure[1:6, 2:9] = True                            # 5 x 7 block touching the right-hand edge
    d = HG.depth(pure)
    assert d[3, 5] == 3.0                            # 3 steps to row 0 and to row 6, and to the edge at column 9
    assert d[1, 2] == 1.0 and d[3, 8] == 1.0         # next to an outside cell, next to the edge
    assert np.all(d[~pure] == 0.0) and d.max() == 3.0


def test_every_type_is_shown_from_deep_inside_its_domain(diagram):
    """Every type found gets a panel; each representative's cell lies at least MARGIN_CELLS
    grid steps from any cell of another type; type 3's -- whose domain is the thin band of
    (4.17) and the region below delta = -1/2 -- lies away from the lines that bound it,
    alpha(4.14) = -1/2 ((4.15)) and beta(4.18) = -1/2, by more than 0.1 in the exponents
    (not ~0.002 from alpha = -1/2, where the balanced state merges with the axial one and a
    run creeps towards it for tens of decades); the more confident start is taken, the kept
    series first."""
    reps = HG.representatives(diagram)
    assert sorted(r[1] for r in reps) == ["1", "2", "3", "4", "5"]
    for _, name, d, c, k, conf, deep in reps:
        assert deep >= HG.MARGIN_CELLS, (name, d, math.degrees(c), deep)
        assert k == 0 and conf == 0.9                 # the start whose series is kept
    _, _, d, c, *_ = next(r for r in reps if r[1] == "3")
    alpha, beta = FM.type2_eq4_14(d, c)["alpha"], FM.type4_eq4_18(d, c)["beta"]
    assert alpha + 0.5 > 0.1 and beta + 0.5 > 0.1, (d, math.degrees(c), alpha, beta)


def test_the_figure_atlas_hodographs_show_type_3_away_from_its_boundaries():
    """The committed extract of the figure atlas (what the docs' hodographs are drawn from):
    its type-3 panel comes from a cell more than 0.1 in the exponents from alpha(4.14) = -1/2
    and beta(4.18) = -1/2, at least MARGIN_CELLS inside its domain, and the extract keeps that
    run's series (the picture is drawn from it, not integrated again)."""
    from pathlib import Path

    saved = np.load(Path(__file__).resolve().parents[1] / "examples" / "data" / "atlas_figure_labels.npz")
    names = {code: name for name, code in TYPE_CODES.items()}
    dims = ("model", "delta", "chi", "member")
    decode = np.vectorize(names.get, otypes=[str])
    ds = xr.Dataset({"label": (dims, decode(saved["regime_0"])), "limit_label": (dims, decode(saved["label_inf_0"])),
                     "candidate": (dims, saved["candidate_0"]), "confidence": (dims, saved["confidence"]),
                     "series": (("model", "delta", "chi", "start", "sample", "axis"), saved["series"])},
                    coords={"model": saved["models"], "delta": saved["delta_0"], "chi": saved["chi_0"],
                            "member": np.arange(saved["regime_0"].shape[-1]), "start": np.arange(saved["series"].shape[3])})
    reps = {(r[0], r[1]): r for r in HG.representatives(ds)}
    model, _, d, c, k, _, deep = reps[("reduced", "3")]
    alpha, beta = FM.type2_eq4_14(d, c)["alpha"], FM.type4_eq4_18(d, c)["beta"]
    assert alpha + 0.5 > 0.1 and beta + 0.5 > 0.1 and deep >= HG.MARGIN_CELLS, (d, math.degrees(c), alpha, beta, deep)
    i, j = list(ds["delta"].values).index(d), list(ds["chi"].values).index(c)
    assert np.isfinite(saved["series"][list(saved["models"]).index(model), i, j, k]).all()
