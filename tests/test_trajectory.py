"""The Trajectory as a file and in a notebook: exact round trips, a short repr, xarray."""

import math

import numpy as np
import pytest

import spinviz
from spinviz.physics import bodies as B
from spinviz.physics import presets as P

W = math.pi * 1e10


def same(a, b):
    """Arrays, body, model, stats and slow geometry identical."""
    for name in ("t", "omega", "q", "euler"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None and y is None) or np.array_equal(x, y), name
    assert a.body == b.body and a.body.shape == b.body.shape and a.body.printed == b.body.printed
    assert a.model == b.model and a.stats == b.stats
    assert (a.slow is None) == (b.slow is None)
    for k in (a.slow or {}):
        assert np.array_equal(np.asarray(a.slow[k]), np.asarray(b.slow[k])), k


@pytest.mark.parametrize("make", [
    lambda: spinviz.simulate(B.symmetric_top(0.3, 0.7), "reduced", (0.0, 0.05, 0.3), t_end=100.0, samples=50),
    lambda: spinviz.simulate(B.symmetric_top(0.3, 0.7), "truncated", (0.1, 0.05, 0.3), t_end=50.0, samples=20,
                             method="dop853", kinematics="euler_zxz", euler_zxz0=(0.1, 1.0, 0.2)),
    lambda: spinviz.simulate(P.dast_cube(), "reduced", (0.0, W, W), t_end=1e5, samples=30),      # secular, CGS
    lambda: spinviz.simulate(B.symmetric_top(0.3, 0.7), "free", (0.0, 0.05, 0.3), t_end=10.0, samples=5,
                             kinematics="none"),
    # secular with a hand-over into full (domain "?"): the stats hold nested [time, "full"] lists
    lambda: spinviz.simulate(B.symmetric_top(0.8, 1.17), "reduced", (1.573e-5, -2.458e-5, 6.944e-6),
                             t_end=1.18e8, samples=11, method="secular"),
], ids=["quaternion", "euler_zxz", "secular-cgs", "no-orientation", "secular-segments"])
def test_save_and_load_round_trip_exactly(make, tmp_path):
    tr = make()
    if tr.stats["method"] == "secular" and tr.body.name == "symmetric top":
        assert tr.stats["segments"] and tr.stats["segments"][0][1] == "full"
    tr.save(tmp_path / "run.npz")
    back = spinviz.Trajectory.load(tmp_path / "run.npz")
    same(tr, back)
    if tr.slow is not None:                          # the slow geometry survives: sampling works the same
        same(tr.sample(tr.t[3:7]), back.sample(tr.t[3:7]))


def test_load_refuses_a_file_of_another_kind(tmp_path):
    p = tmp_path / "other.npz"
    np.savez(p, metadata=np.array('{"format": "something-else"}'), t=np.zeros(2))
    with pytest.raises(ValueError, match="not a spinviz trajectory"):
        spinviz.Trajectory.load(p)


def test_repr_is_short_and_says_what_the_run_is():
    tr = spinviz.simulate(B.symmetric_top(0.3, 0.7), "reduced", (0.0, 0.05, 0.3), t_end=100.0, samples=200)
    r = repr(tr)
    assert len(r) < 250 and "\n" not in r
    assert "reduced" in r and "200 samples" in r and "taylor" in r and "quaternion" in r


def test_to_xarray_has_labelled_dims_units_and_metadata():
    tr = spinviz.simulate(P.dast_cube(), "truncated", (0.0, W, W), t_end=1e5, samples=30)
    ds = tr.to_xarray()
    assert ds["omega"].dims == ("time", "axis") and list(ds["axis"].values) == ["e1", "e2", "e3"]
    assert ds["omega"].attrs["units"] == "rad/s" and ds["time"].attrs["units"] == "s"
    assert list(ds["quaternion_component"].values) == ["w", "x", "y", "z"]
    np.testing.assert_array_equal(ds["q"].values, tr.q)
    np.testing.assert_allclose(ds["angle_d_L"].values, tr.angle_d_L())
    assert ds.attrs["model"] == "truncated" and "secular" in ds.attrs["spinviz_trajectory"]


def test_angle_d_L_needs_no_orientation_and_matches_the_world_frame():
    body = B.symmetric_top(-0.6, math.radians(55.0))
    a = spinviz.simulate(body, "reduced", (0.1, 0.2, 0.3), t_end=30.0, samples=20)
    world = np.arccos(np.clip(np.sum(a.dipole_world() * a.angular_momentum_world(), axis=1)
                              / np.linalg.norm(a.angular_momentum_world(), axis=1), -1, 1))
    np.testing.assert_allclose(a.angle_d_L(), world, atol=1e-7)
    b = spinviz.simulate(body, "reduced", (0.1, 0.2, 0.3), t_end=30.0, samples=20, kinematics="none")
    np.testing.assert_allclose(b.angle_d_L(), a.angle_d_L(), atol=1e-9)


def test_angle_d_L_range_brackets_the_swing_over_a_precession_turn():
    """Askew symmetric top (delta = 0.3, chi = 1.0), free motion over several precession turns:
    the instantaneous angle(d, L) sweeps exactly the interval angle_d_L_range gives."""
    body = B.symmetric_top(0.3, 1.0)
    w = (0.2, 0.0, 0.5)                     # precession rate delta w3 = 0.15: period ~42
    tr = spinviz.simulate(body, "free", w, t_end=200.0, samples=4001, rtol=1e-12, atol=1e-14)
    lo, hi = tr.angle_d_L_range()
    a = tr.angle_d_L()
    np.testing.assert_allclose(lo, lo[0], atol=1e-10)          # free motion: theta_L is constant
    assert np.all(a >= lo - 1e-9) and np.all(a <= hi + 1e-9)
    assert a.min() == pytest.approx(lo[0], abs=1e-4) and a.max() == pytest.approx(hi[0], abs=1e-4)
    theta_L = math.atan2(0.2, 0.7 * 0.5)
    assert lo[0] == pytest.approx(abs(theta_L - 1.0)) and hi[0] == pytest.approx(theta_L + 1.0)
