"""The boxes atlas (``regimes.asymmetric``): the shape flow's attractors, the symmetric families of
figure 5 reproduced ((4.12)'s stable state, (4.14)'s exponent, (4.16)'s balanced state), the DAST box,
and the command's arguments."""

import math

import numpy as np
import pytest

from spinviz.commands import main
from spinviz.errors import SpecError
from spinviz.inputs.boxes import BoxesRequest
from spinviz.physics import polhode as PH
from spinviz.regimes.asymmetric import atlas as boxes_atlas
from spinviz.regimes.asymmetric import shape as SH

D_DAST = (math.cos(math.radians(35.0)), 0.0, math.sin(math.radians(35.0)))


@pytest.mark.parametrize("model", ["reduced", "truncated"])
@pytest.mark.parametrize("family, ratio", [(1, 0.5), (1, 0.8), (1, 1.6), (2, 0.6), (2, 1.2), (2, 1.6), (2, 2.0)])
def test_the_families_of_figure_5_are_the_symmetric_top(model, family, ratio):
    """On a = b (family 1, chi = 55 deg about c) and b = c (family 2, chi = 35 deg about a) the box is a
    symmetric top: its shape flow's attractor is (4.12)'s stable state -- the axial state (types 1, 2)
    an attracting symmetry axis with the exponent alpha of (4.14) to round-off, the balanced state
    ("3", (4.16)) a fixed polhode at the same |L|^2/2E, the transverse state (4, 4->5, ?) the
    separatrix (the equator of a symmetric top)."""
    c = boxes_atlas.symmetric_check(model, family, ratio)
    expect = {"axial": "axis", "balanced": "polhode", "transverse": "separatrix"}[c["expected"]]
    assert c["found"] == [expect]
    if c["alpha"] is not None:
        assert c["alpha"][1] == pytest.approx(c["alpha"][0], rel=1e-12)
    if c["D"] is not None:
        assert c["D"][1] == pytest.approx(c["D"][0], rel=1e-9)


def test_the_paper_family_1_plate_is_type_1():
    """The 100 x 100 x 50 nm plate (delta = -0.6, chi = 55 deg, section 6.2): the reduced spin settles
    about c with alpha = -1.31 < -1 (type 1: the forced tilt outlives the polhode, (4.9)), the
    truncated one about c too (alpha = -0.56)."""
    J, d = boxes_atlas.box_body(1.0, 0.5, D_DAST)
    red, tru = SH.shape_flow(J, d, "reduced"), SH.shape_flow(J, d, "truncated")
    (a,), (b,) = red.attractors, tru.attractors
    assert (a.kind, a.axis, a.label) == ("axis", 2, "1") and a.alpha == pytest.approx(-1.308, abs=1e-3)
    assert (b.kind, b.axis, b.label) == ("axis", 2, "axis") and b.alpha == pytest.approx(-0.56, abs=1e-3)


def test_the_dast_box_100_80_60():
    """The scene's box: the reduced model has two attractors -- about a (d 35 deg from L) and about c
    (55 deg) -- split by an unstable polhode, a third of evenly spread starts ending about a; the
    truncated model sends every start to c, through the separatrix from a's lobes (with Neishtadt's
    odds, 99.8 % into the lobe of the same sign); shares sum to 1."""
    J, d = boxes_atlas.box_body(0.8, 0.6, D_DAST)
    starts = SH.isotropic_starts(400)
    red, tru = SH.shape_flow(J, d, "reduced"), SH.shape_flow(J, d, "truncated")
    assert sorted((a.kind, a.axis) for a in red.attractors) == [("axis", 0), ("axis", 2)]
    assert [(a.kind, a.axis) for a in tru.attractors] == [("axis", 2)]
    r = boxes_atlas.cell(0.8, 0.6, "reduced", D_DAST, starts)
    t = boxes_atlas.cell(0.8, 0.6, "truncated", D_DAST, starts)
    assert sum(r["axis_share"]) == pytest.approx(1.0) and sum(t["axis_share"]) == pytest.approx(1.0)
    assert 0.25 < r["axis_share"][0] < 0.45 and t["axis_share"][2] == pytest.approx(1.0)
    (_, s, p), _ = tru.odds[(0, 1.0)]
    assert s == 1.0 and p > 0.99


def test_a_cube_has_no_shape_flow():
    with pytest.raises(PH.NoPolhode):
        SH.shape_flow((1.0, 1.0, 1.0), D_DAST, "reduced")
    assert not boxes_atlas.cell(1.0, 1.0, "reduced", D_DAST, SH.isotropic_starts(10))["ok"]


def test_isotropic_starts_are_unit_and_balanced():
    s = SH.isotropic_starts(500)
    np.testing.assert_allclose(np.linalg.norm(s, axis=1), 1.0)
    assert np.all(np.abs(s.mean(axis=0)) < 2e-3)


@pytest.mark.parametrize("kw, key", [({"grid": 1}, "grid"), ({"lo": 1.0, "hi": 1.0}, "lo"), ({"lo": 1.5}, "lo"),
                                     ({"models": ("reduced", "foo")}, "models"), ({"starts": 5}, "starts"),
                                     ({"grid": 400, "starts": 100_000}, "grid")])
def test_bad_arguments_are_named(kw, key):
    with pytest.raises(SpecError) as e:
        BoxesRequest(**kw)
    assert e.value.key == key


@pytest.mark.slow
def test_the_command_writes_the_atlas_and_its_picture(tmp_path, capsys):
    """A 3 x 3 plane of one model: the netCDF holds the shares per edge (summing to 1 with the
    polhode's and the separatrix's, or NaN for the cube), and the PNG is written."""
    import xarray as xr

    nc, png = tmp_path / "b.nc", tmp_path / "b.png"
    assert main(["atlas", "boxes", "--grid", "3", "--starts", "40", "--models", "truncated", "--out", str(nc), "--plot", str(png),
                 "--quiet"]) == 0
    ds = xr.open_dataset(nc)
    tot = ds["axis_share"].sum("axis") + ds["polhode_share"] + ds["separatrix_share"]
    ok = np.isfinite(ds["polhode_share"].values)
    np.testing.assert_allclose(tot.values[ok], 1.0)
    assert (~ok).sum() == 1                           # the cube
    assert png.stat().st_size > 10_000
