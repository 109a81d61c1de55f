"""Adaptive refinement of the atlas on a synthetic label field with a known boundary."""

import numpy as np

from spinviz.regimes.engine import refine as RF
from spinviz.regimes.store import levels as LV

BOUNDARY = lambda d: 40.0 + 20.0 * d            # noqa: E731  chi (deg) of the synthetic boundary, delta in (-1, 1)


def synthetic(deltas, chis, members=8):
    """Type 1 above the line, 2 below, the same for every member (shape (nd, nc, members))."""
    t = np.where(chis[None, :] > BOUNDARY(deltas)[:, None], 1, 2)
    return np.repeat(t[:, :, None], members, axis=2)


def run_levels(levels, cells=(8, 8)):
    """Refine ``levels`` times from an 8 x 8 grid, computing only the children of flagged cells."""
    nd, nc = cells
    maj, comp = [], []
    computed = np.ones((nd, nc), dtype=bool)
    for k in range(levels + 1):
        d, c = LV.centres(-1.0, 1.0, nd, k), LV.centres(0.0, 90.0, nc, k)
        types = synthetic(d, c)
        m, share = RF.majority(types)
        maj.append(m)
        comp.append(computed)
        if k == levels:
            break
        eff = RF.effective(maj, comp)
        computed = RF.children(RF.flags(m, share, computed, eff))
    return maj, comp


def test_refinement_resolves_a_known_boundary_to_the_stated_width():
    """After 3 levels from 8 x 8 (cells 0.25 x 11.25 deg), every point of the boundary lies in a
    computed finest cell (0.03125 x 1.406 deg -- the stated width), and no cell two coarse
    cells away from it was ever refined."""
    levels = 3
    maj, comp = run_levels(levels)
    fine = comp[levels]
    nd, nc = fine.shape
    assert RF.width(-1.0, 1.0, 8, levels) == 0.25 / 8 and RF.width(0.0, 90.0, 8, levels) == 11.25 / 8
    for d in np.linspace(-0.999, 0.999, 997):
        i = int((d + 1.0) / 2.0 * nd)
        j = int(BOUNDARY(d) / 90.0 * nc)
        assert fine[i, j], (d, BOUNDARY(d))
    # away from the boundary nothing was refined: distance > 2 coarse cells in chi
    for k in range(1, levels + 1):
        d = LV.centres(-1.0, 1.0, 8, k)[:, None]
        c = LV.centres(0.0, 90.0, 8, k)[None, :]
        far = np.abs(c - BOUNDARY(d)) > 2 * 11.25
        assert not np.any(comp[k] & far)


def test_refinement_cost_follows_the_boundary_length():
    """Each level computes about twice the cells of the one before (a line, not an area):
    the counts grow by 1.5-2.5x, far from the 4x of a uniform refinement."""
    _, comp = run_levels(4)
    counts = [int(c.sum()) for c in comp[1:]]
    ratios = np.array(counts[1:]) / np.array(counts[:-1])
    assert np.all((ratios > 1.5) & (ratios < 2.5)), counts


def test_disagreeing_members_flag_a_cell_even_with_agreeing_neighbours():
    types = np.ones((3, 3, 10), dtype=int)
    types[1, 1, :3] = 5                           # 70 % agree < 90 %
    m, share = RF.majority(types)
    f = RF.flags(m, share, np.ones((3, 3), bool), m)
    assert f[1, 1] and f.sum() == 1


def test_approaching_counts_for_the_class_it_approaches():
    from spinviz.regimes.engine import classify as C

    codes = np.array([C.CODE["3"], C.CODE["approaching"], C.CODE["other"]])
    cand = np.array([C.CODE["3"], C.CODE["3"], C.CODE["1|2"]])
    assert list(RF.type_of(codes, cand)) == [C.CODE["3"], C.CODE["3"], C.CODE["other"]]
