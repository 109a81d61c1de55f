"""The atlas's adaptive refinement end to end: ``[refine] levels`` computes the
children of exactly the cells ``refine.flags`` marks, keeps each level as a store of its own
inside the atlas, resumes level by level, and ``--verify`` covers every level.  (The spec pins
the brute-force engine: these are the store's mechanics, on a flagged pattern whose damaged
chunk holds only computed runs; refinement on the limit labels: test_handover_engine.py.)"""

import os
import shutil

import numpy as np
import pytest
import zarr

from spinviz.commands import atlas as command
from spinviz.regimes import api
from spinviz.regimes.engine import refine as RF
from spinviz.regimes.store import dataset as DS
from spinviz.regimes.store import levels as LV

SPEC = """title = "refine test"
models = ["reduced"]
[grid]
delta = { min = -1.0, max = 1.0, cells = 4 }
chi_deg = { min = 0.0, max = 90.0, cells = 4 }
[members]
count = 4
seed = 3
omega = 0.04
[run]
engine = "taylor"
tau_end = 1e8
rtol = 1e-8
[refine]
levels = 1
"""


@pytest.fixture(scope="module")
def refined(tmp_path_factory):
    d = tmp_path_factory.mktemp("refine")
    spec = d / "r.toml"
    spec.write_text(SPEC)
    out = str(d / "r.zarr")
    res = api.atlas(str(spec), out, workers=1, processes=False, progress=False)
    return str(spec), out, res


def regime(path):
    return np.asarray(zarr.open_group(path, mode="r", zarr_format=2)["regime"])


@pytest.mark.slow
def test_level_one_computes_exactly_the_children_of_flagged_cells(refined):
    _, out, res = refined
    types, done0 = LV.level_types(out, 0)
    assert done0.all()
    maj, share = RF.majority(types)
    flagged = RF.flags(maj, share, done0, RF.effective([maj], [done0]))
    assert 0 < flagged.sum() < flagged.size                   # a boundary crosses the 4 x 4 grid, not everywhere
    level1 = DS.level_path(out, 1)
    _, done1 = LV.level_types(level1, 0)
    np.testing.assert_array_equal(done1, RF.children(flagged))
    g = zarr.open_group(level1, mode="r", zarr_format=2)
    np.testing.assert_allclose(np.asarray(g["delta"]), LV.centres(-1.0, 1.0, 4, 1), rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.asarray(g["chi_deg"]), LV.centres(0.0, 90.0, 4, 1), rtol=0, atol=1e-12)
    assert res.levels == 1 and res.total == 64 + 4 * int(done1.sum()) == res.computed
    # the level's runs are real runs: every computed one labelled, every other one "missing" (code 0)
    codes = regime(level1)[0]
    assert (codes[done1] > 0).all() and (codes[~done1] == 0).all()


@pytest.mark.slow
def test_rerun_computes_nothing_and_a_lost_level_is_recomputed_identically(refined, tmp_path):
    spec, out, res = refined
    copy = str(tmp_path / "r.zarr")
    shutil.copytree(out, copy)
    again = api.atlas(spec, copy, workers=1, processes=False, progress=False)
    assert again.computed == 0 and again.reused == res.total
    shutil.rmtree(DS.level_path(copy, 1))
    third = api.atlas(spec, copy, workers=1, processes=False, progress=False)
    assert third.computed == res.total - 64 and third.reused == 64
    np.testing.assert_array_equal(regime(DS.level_path(copy, 1)), regime(DS.level_path(out, 1)))


@pytest.mark.slow
def test_verify_covers_every_level_and_resume_repairs_a_damaged_one(refined, tmp_path, capsys):
    spec, out, res = refined
    copy = str(tmp_path / "r.zarr")
    shutil.copytree(out, copy)
    assert DS.stored_levels(copy) == [copy, DS.level_path(copy, 1)]
    assert command.verify(copy) == 0
    assert capsys.readouterr().out.rstrip().endswith(f"ok: {res.total} runs verified over 2 refinement levels")
    level1 = DS.level_path(copy, 1)
    chunk = os.path.join(level1, "regime", "0.0.0.0")
    with open(chunk, "r+b") as f:                             # one flipped byte in level 1
        b = f.read(1)
        f.seek(0)
        f.write(bytes([b[0] ^ 0xFF]))
    assert command.verify(copy) == 1
    said = capsys.readouterr().out
    assert "level 1: regime: DAMAGED (1 chunk" in said and "level 0: regime: ok" in said
    fixed = api.atlas(spec, copy, workers=1, processes=False, progress=False)
    assert fixed.repaired > 0 and fixed.computed == fixed.repaired
    np.testing.assert_array_equal(regime(level1), regime(DS.level_path(out, 1)))
    assert DS.verify(level1).clean


@pytest.mark.slow
def test_diagram_tiles_the_plane_once_finer_cells_over_coarser(refined):
    """compose_levels: every point of the delta-chi rectangle in exactly one drawn cell (the
    coarse cells a finer level computed again are left out), every computed level-1 cell
    drawn; drawn with matplotlib, the centre pixel of each unanimous level-1 cell has its
    type's colour, whatever its parent's type was."""
    from matplotlib.colors import to_rgb

    from spinviz.plotting import pyplot
    from spinviz.regimes.figures import cells as CE
    from spinviz.regimes.figures import diagram, draw

    _, out, _ = refined
    levels = draw.open_levels(out)
    assert len(levels) == 2
    cells = CE.compose_levels(levels, "reduced")
    cover = np.zeros((8, 8), dtype=int)
    for c in cells:
        s = 2 ** (1 - c["level"])
        cover[c["i"] * s:(c["i"] + 1) * s, c["j"] * s:(c["j"] + 1) * s] += 1
    assert (cover == 1).all()
    _, done1 = LV.level_types(DS.level_path(out, 1), 0)
    assert {(c["i"], c["j"]) for c in cells if c["level"] == 1} == {tuple(int(v) for v in ij) for ij in zip(*np.nonzero(done1))}

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(4, 4), dpi=100)
    ax.set_xlim(-1, 1)
    ax.set_ylim(0, 90)
    diagram._cells(ax, cells)
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[..., :3] / 255.0
    parents = {(c["i"], c["j"]): c for c in CE.compose(levels[0], "reduced")}
    checked = differ = 0
    for c in cells:
        if c["level"] != 1 or len(c["bars"]) != 1 or c["bars"][0][2] or c["coexist"]:
            continue
        x, y = ax.transData.transform((c["delta"], c["chi_deg"]))
        px = img[img.shape[0] - int(round(y)), int(round(x))]
        np.testing.assert_allclose(px, to_rgb(diagram.COLORS[c["bars"][0][0]]), atol=0.02)
        checked += 1
        differ += parents[(c["i"] // 2, c["j"] // 2)]["bars"][0][0] != c["bars"][0][0]
    plt.close(fig)
    assert checked >= 10 and differ >= 1            # and some of them show what their parent's colour hid


@pytest.mark.slow
def test_atlas_page_in_chromium(refined, tmp_path):
    """--plot's third output, the page: every drawn cell of both levels is a hoverable group,
    the hover text gives the cell's shares; opened at #open=<a level-1 cell> Chromium runs its
    script and draws that cell's stored hodograph (its delta and chi in the heading, coloured
    dots on the right of the page), which the same page without the fragment does not."""
    from browser import CHROMIUM, page_text, screenshot

    from spinviz.regimes.figures import cells as CE
    from spinviz.regimes.figures import draw

    if CHROMIUM is None:
        if os.environ.get("CI"):
            pytest.fail("CI must test the atlas page, but chromium is missing (see .ci/run)", pytrace=False)
        pytest.skip("needs chromium (apt-get install chromium)")
    _, out, _ = refined
    paths = draw.draw(out, [str(tmp_path / f"a{ext}") for ext in (".png", "_hodographs.png", ".html")])
    page = tmp_path / "a.html"
    assert paths[2] == str(page)
    levels = draw.open_levels(out)
    cells = CE.compose_levels(levels, "reduced")
    first = levels[1]["label"].sel(model="reduced").values[..., 0]          # each level-1 cell's first start
    fine = next(c for c in cells if c["level"] == 1 and c["bars"][0][0] == "1" and first[c["i"], c["j"]] == "1")
    dom, text = page_text(page, tmp_path, fragment=f"open={fine['id']}")
    assert dom.count('class="cell') == len(cells)
    assert f"reduced model, \u03b4 = {fine['delta']:+.3f}, \u03c7 = {fine['chi_deg']:.2f}\u00b0: first start, label 1" in text
    n = fine["counts"]["1"]
    assert f"1: {n}/4 ({100 * n // 4} %)" in dom
    shot = screenshot(page, tmp_path, fragment=f"open={fine['id']}")
    blank = screenshot(page, tmp_path)
    right = slice(660, 1280)

    def coloured(img):
        rgb = img[40:500, right].astype(int)                  # beside the diagram, above the legend
        return int(((rgb.max(axis=2) - rgb.min(axis=2)) > 80).sum())

    assert coloured(shot) > 200 and coloured(blank) == 0
