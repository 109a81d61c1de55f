"""What the atlas page claims about the 4|5 band, the hand-over's stated bound and (4.42):
the basin shares' intervals (exact binomial coverage, closed forms at the ends), the band's
points at equal beta of (4.18) on two deltas, the stated bound's closed form, (4.42)'s A^2
and M^2 read as peak and as r.m.s.; and (slow) the shares measured across the band inside
their intervals, two types sharing a cell and equal betas with different shares."""

import math

import numpy as np
import pytest
from scipy.stats import binom

from spinviz.physics import asymptotics as FM
from spinviz.regimes.engine import handover_engine as HO
from spinviz.validation.atlas import against_brute_force as HV
from spinviz.validation.atlas import validate as V


@pytest.mark.parametrize("n", [32, 128, 256])
def test_share_intervals_cover_every_true_share(n):
    """Clopper-Pearson at 95 %: for every true share p the starts' count k lands with
    probability >= 0.95 on a k whose interval holds p (summed exactly over the binomial), and
    at k = 0, n the interval is the closed form [0, 1 - 0.025^(1/n)], [0.025^(1/n), 1]."""
    ci = [HV.share_interval(k, n) for k in range(n + 1)]
    for p in np.linspace(0.005, 0.995, 199):
        held = [k for k, (lo, hi) in enumerate(ci) if lo <= p <= hi]
        assert binom.pmf(held, n, p).sum() >= 0.95 - 1e-9, p
    assert ci[0][0] == 0.0 and ci[0][1] == pytest.approx(1.0 - 0.025 ** (1.0 / n), rel=1e-9)
    assert ci[n][1] == 1.0 and ci[n][0] == pytest.approx(0.025 ** (1.0 / n), rel=1e-9)
    lo, hi = ci[n // 2]
    assert lo + hi == pytest.approx(1.0, abs=1e-12)


def test_share_interval_is_scipys_exact_binomial_interval():
    from scipy.stats import binomtest

    for k, n in [(0, 32), (1, 32), (13, 32), (31, 32), (32, 32), (90, 256)]:
        ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="exact")
        assert HV.share_interval(k, n) == pytest.approx((ci.low, ci.high), abs=1e-12)


def test_starts_needed_is_the_fewest_for_the_width():
    n = HV.starts_needed(0.07)
    lo, hi = HV.share_interval(n // 2, n)
    lo2, hi2 = HV.share_interval((n - 2) // 2, n - 2)
    assert 0.5 * (hi - lo) <= 0.07 < 0.5 * (hi2 - lo2)
    assert HV.starts_needed(0.05) > n > HV.starts_needed(0.1)


@pytest.mark.parametrize("delta, beta", [(-0.3, -0.55), (0.1, -0.55), (0.1, -0.9), (0.4, -0.73), (0.5, -0.73),
                                         (0.5, -0.9), (0.8, -0.55), (0.8, -3.0)])
def test_chi_at_beta_inverts_eq_4_18(delta, beta):
    """beta(4.18) = -(2 + delta) xi / (2 (1 - delta)(xi + 2)), xi = tan^2 chi, solved for chi
    (beta between 0 and its value as chi -> 90 deg, -(2 + delta) / (2 (1 - delta)))."""
    chi = HV.chi_at_beta(delta, beta)
    assert 0.0 < chi < 0.5 * math.pi
    assert FM.type4_eq4_18(delta, chi)["beta"] == pytest.approx(beta, rel=1e-12)


def test_band_points_pair_equal_betas_on_two_deltas():
    pts = HV.band_points()
    beta = {p: FM.type4_eq4_18(p[0], math.radians(p[1]))["beta"] for p in pts}
    at5 = [p for p in pts if p[0] == HV.BAND_DELTA]
    at4 = [p for p in pts if p[0] == HV.OTHER_DELTA]
    assert len(at5) == len(at4) == len(HV.BAND_CHI_DEG) + 1 and len(pts) == len(at5) + len(at4) + len(HV.SPREAD_DELTA)
    for b5, b4 in zip(sorted(beta[p] for p in at5), sorted(beta[p] for p in at4)):
        assert abs(b5 - b4) < 2e-4                              # chi rounded to 0.01 deg
    assert (HV.OTHER_DELTA, HV.AUDIT_CHI_DEG) in pts and beta[(HV.OTHER_DELTA, HV.AUDIT_CHI_DEG)] == pytest.approx(
        -0.730, abs=5e-4)
    for d in HV.SPREAD_DELTA:                                   # the audit's beta at deltas farther apart
        (p,) = [p for p in pts if p[0] == d]
        assert beta[p] == pytest.approx(-0.730, abs=5e-4)


def test_stated_bound_closed_form():
    """BOUND_C mu_h^2 |(a, b)| + SMALL_C min(a, b) (mu_h^2 + int mu^2 d ln tau) / min(1, 1 - delta)
    + floor (+ type 1's drift): the smaller amplitude's share is what the first term alone misses."""
    mu, a, b, i2 = 1e-2, 0.8, 0.06, 3e-4
    want = HO.BOUND_C * mu**2 * math.hypot(a, b) + HO.SMALL_C * b * (mu**2 + i2)
    assert HO.stated_bound(mu, a, b, i2) == pytest.approx(want, rel=1e-15)
    assert HO.stated_bound(mu, a, b, i2, floor=1e-7) == pytest.approx(want + 1e-7, rel=1e-15)
    assert HO.stated_bound(mu, a, b, i2, floor=math.nan) == pytest.approx(want, rel=1e-15)
    assert HO.stated_bound(mu, a, b, i2, drift=(2e-3, 10.0)) == pytest.approx(
        want + HO.TYPE1_DRIFT_C * 4e-6 * b * 10.0, rel=1e-15)
    assert HO.stated_bound(mu, b, a, i2) == pytest.approx(want, rel=1e-15)       # symmetric in (a, b)
    # J3 = 1 - delta divides the smaller amplitude's share where it is below 1, never shrinks it
    assert HO.stated_bound(mu, a, b, i2, delta=0.9) == pytest.approx(
        want + 9.0 * HO.SMALL_C * b * (mu**2 + i2), rel=1e-12)
    assert HO.stated_bound(mu, a, b, i2, delta=-0.6) == pytest.approx(want, rel=1e-15)


def test_eq_4_42_read_as_peak_and_as_rms():
    """At (0.8, 1.2 rad), where (4.42) is real: dense samples of 4 starts over tau = 1e10 ...
    2e10.  Read as peaks A^2 is 18 % low and M^2 26 % low, as r.m.s. (2 x the mean square,
    the same for a harmonic swing) 14 % and 27 %: the swing (~40 deg) is anharmonic, so the
    two readings differ, by ~4 points for A^2; B, a mean, is one number (-17.7 %)."""
    r = V.libration_readings(members=4)
    assert -0.19 < r["A^2 peak"][0] < -0.17 and -0.16 < r["A^2 r.m.s."][0] < -0.12
    assert r["A^2 r.m.s."][0] - r["A^2 peak"][0] > 0.02
    assert -0.27 < r["M^2 peak"][0] < -0.25 and -0.29 < r["M^2 r.m.s."][0] < -0.26
    assert -0.19 < r["B"][0] < -0.17 and r["B"][2] - r["B"][1] < 0.005
    table = V.format_libration(r)
    assert "| A^2 | -18." in table and "| peak (the classifier's) | r.m.s. (2 × mean square) |" in table


@pytest.fixture(scope="module")
def band():
    """64 starts at three points of the band: beta -0.65 and -0.72 at delta = 0.5, and the
    audit's (0.4, 47 deg) with beta -0.730."""
    return HV.basins(members=64, points=[(0.5, 40.0), (0.5, 42.0), (0.4, 47.0)], threads=1)


@pytest.mark.slow
def test_band_shares_lie_in_their_intervals_and_two_types_share_the_band(band):
    """Each printed share lies in its own interval; by beta = -0.65 type 4 holds every start
    (the interval's lower end above 0.94); at beta = -0.72 both types hold starts, each
    interval away from 0 and 1 (two attractors, not slowness); the table prints the intervals."""
    by = {(r["delta"], r["chi_deg"]): r for r in band}
    for r in band:
        assert r["members"] == 64 and r["share_4"] + r["share_5"] + r["other"] / 64 == pytest.approx(1.0)
        for t in ("4", "5"):
            lo, hi = r[f"ci_{t}"]
            assert lo <= r[f"share_{t}"] <= hi
    assert by[(0.5, 40.0)]["share_4"] == 1.0 and by[(0.5, 40.0)]["ci_4"][0] > 0.94
    mixed = by[(0.5, 42.0)]
    assert mixed["ci_4"][0] > 0.1 and mixed["ci_5"][0] > 0.1
    assert "% [" in HV.format_basins(band) and "95 % Clopper–Pearson" in HV.format_basins(band)


def test_equal_betas_are_compared_by_fishers_exact_test():
    """Rows off delta = 0.5 are paired with the delta = 0.5 row of the same beta: equal counts
    give p = 1; 95 against 127 of 256 (the band's counts at beta = -0.730, delta = 0.8 and 0.5)
    p = 0.0056, the hypergeometric tail summed by hand below."""
    from scipy.stats import hypergeom

    rows = [{"delta": 0.5, "beta": -0.730, "members": 256, "limit": {"4": 127, "5": 125}},
            {"delta": 0.8, "beta": -0.7301, "members": 256, "limit": {"4": 95, "5": 158}},
            {"delta": 0.4, "beta": -0.7302, "members": 256, "limit": {"4": 127}},
            {"delta": 0.4, "beta": -0.70, "members": 256, "limit": {"4": 1}}]         # no partner: left out
    pairs = HV.equal_beta(rows)
    assert [(q["delta"], q["share"]) for q in pairs] == [(0.8, 95 / 256), (0.4, 127 / 256)]     # by beta, falling
    assert pairs[1]["p"] == pytest.approx(1.0)
    dist = hypergeom(512, 222, 256)                  # 222 type-4 starts among 512, 256 drawn at delta 0.8
    pmf = dist.pmf(np.arange(223))
    by_hand = pmf[pmf <= dist.pmf(95) * (1 + 1e-7)].sum()
    assert pairs[0]["p"] == pytest.approx(by_hand, rel=1e-6) and 0.004 < pairs[0]["p"] < 0.007
