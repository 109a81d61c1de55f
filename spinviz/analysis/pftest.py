"""The start-free test: which law does a series of (line frequency, power) follow?

Comparing the models at equal times presumes the same, known start.  What needs no start is
the relation between the line's power and its frequency (``physics.longitudinal``): for a top
with d along its axis (chi = 0) or a spherical top (delta = 0) there is one line, at |L|/(2 pi I1),
and

* truncated (5.4), (6.9): P = A f^4 (the dipole's angle to L fixed);
* reduced (5.2), (6.7):   P = A f^2 (f^2 - f_inf^2), f_inf the line it levels off at.

The truncated law is the reduced one at f_inf = 0 (a reduced top spun exactly across its dipole
is the truncated one, (3.9)), so the test is one of f_inf > 0.  Three fits of ln P against f,
each by weighted least squares with the amplitude A (and the exponent) profiled out and f_inf
by a bounded one-dimensional search:

* ``truncated``: ln P = a + 4 ln f;
* ``reduced``:   ln P = a + 4 ln f + ln(1 - f_inf^2/f^2), f_inf in [0, min f);
* ``general``:   ln P = a + n ln f + ln(1 - f_inf^2/f^2): the exponent n (4 for both laws: the
  Larmor omega^4 of a dipole turning at a fixed angle) and f_inf, with uncertainties.

Errors: sigma_lnP = sigma_P / P, and the frequency's own error carried by the law's slope
(effective variance, sigma^2 = sigma_lnP^2 + (dlnP/dlnf)^2 (sigma_f/f)^2).  The evidence against
the truncated law is Z = sqrt(chi2_truncated - chi2_reduced), the likelihood-ratio significance
(one extra parameter on its boundary: one-sided, so Z is the Gaussian sigma).  Each law's
goodness of fit is its chi2's p-value, as a one-sided Gaussian Z.  Uncertainties of f_inf are
the profile's Delta chi2 = 1 interval; where f_inf is consistent with 0, its one-sided 95 % upper
limit (Delta chi2 = 2.71).  The verdict:

* "reduced": the truncated law rejected at Z >= 5 and the reduced law fits (its Z_fit < 5);
* "truncated": the truncated law fits and f_inf is consistent with 0 (Z < 3);
* "neither": neither law fits at 5 sigma; "undecided" otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..physics import longitudinal as LG
from ..physics import models as M

DECISION_Z = 5.0
CONSISTENT_Z = 3.0
UPPER_95 = 2.705543454095404      # Delta chi2 of a one-sided 95 % limit (1.645^2)


@dataclass(frozen=True)
class Series:
    """A series of line measurements, (M,) each: f_hz, power (any one unit), their 1-sigma errors;
    t_s the times (or None); ``unit`` of the powers; ``source`` in words."""

    f_hz: np.ndarray
    power: np.ndarray
    sigma_f_hz: np.ndarray
    sigma_power: np.ndarray
    t_s: np.ndarray | None = None
    unit: str = "arbitrary units"
    source: str = ""

    def __len__(self) -> int:
        return int(np.asarray(self.f_hz).size)


@dataclass
class LawFit:
    """One law's best fit: ``params`` {name: value}, chi2 with dof, and the one-sided Gaussian
    Z of its p-value (``z_fit`` >= 5: the law does not describe the data)."""

    law: str
    params: dict
    chi2: float
    dof: int
    z_fit: float


@dataclass
class PfTest:
    """The three fits and the verdict (module docstring); f_inf in Hz with its Delta chi2 = 1
    interval, or its 95 % upper limit; ``z`` the evidence against the truncated law;
    ``z_expected`` (when an expected f_inf is given: a known start) how strongly the data
    reject the reduced law with that f_inf."""

    n: int
    truncated: LawFit
    reduced: LawFit
    general: LawFit
    exponent: float
    exponent_sigma: float
    f_inf: float
    f_inf_interval: tuple
    f_inf_upper95: float | None
    z: float
    verdict: str
    f_range: tuple
    f_inf_expected: float | None = None
    z_expected: float | None = None
    notes: list = field(default_factory=list)

    def record(self) -> dict:
        """The test as plain numbers (JSON; None for an infinite or undefined number)."""
        def num(x):
            return float(x) if x is not None and math.isfinite(x) else None

        def law(x):
            return {"params": {k: num(v) for k, v in x.params.items()}, "chi2": num(x.chi2), "dof": x.dof,
                    "z_fit": num(x.z_fit)}

        return {"measurements": self.n, "f_range_hz": list(self.f_range), "verdict": self.verdict,
                "z_against_truncated": num(self.z), "exponent": num(self.exponent),
                "exponent_sigma": num(self.exponent_sigma), "f_inf_hz": num(self.f_inf),
                "f_inf_interval_hz": [num(x) for x in self.f_inf_interval], "f_inf_upper95_hz": num(self.f_inf_upper95),
                "f_inf_expected_hz": num(self.f_inf_expected), "z_against_expected_reduced": num(self.z_expected),
                "reduced_law_rejected_outright": self.z_expected is not None and not math.isfinite(self.z_expected),
                "truncated": law(self.truncated), "reduced": law(self.reduced), "general": law(self.general),
                "notes": self.notes}

    def summary(self) -> list[str]:
        """The result in words, a few lines."""
        f = U.format_frequency
        lo, hi = self.f_inf_interval
        out = [f"{self.n} measurements, {f(self.f_range[0])} .. {f(self.f_range[1])}: exponent n = "
               f"{self.exponent:.4g} ± {self.exponent_sigma:.2g} (both laws: 4)"]
        if self.f_inf_upper95 is not None:
            out.append(f"f_inf consistent with 0 (best {f(self.f_inf)}); 95 % upper limit {f(self.f_inf_upper95)}")
        else:
            out.append(f"f_inf = {f(self.f_inf)} (Δχ² = 1: {f(lo)} .. {f(hi)})")
        out.append(f"truncated law P ∝ f⁴: χ² = {self.truncated.chi2:.4g} for {self.truncated.dof} dof (Z_fit = "
                   f"{self.truncated.z_fit:.2f}); reduced law P ∝ f²(f² − f∞²): χ² = {self.reduced.chi2:.4g} for "
                   f"{self.reduced.dof} (Z_fit = {self.reduced.z_fit:.2f})")
        text = f"the truncated law is rejected at Z = {self.z:.3g}"
        if self.z_expected is not None:
            text += f"; the reduced law with this start's f_inf = {f(self.f_inf_expected)} " + (
                f"at Z = {self.z_expected:.3g}" if math.isfinite(self.z_expected) else
                "outright (the line falls below it)")
        out.append(text)
        out.append(f"verdict: {VERDICTS[self.verdict]}")
        return out


VERDICTS = {"reduced": f"reduced (the line levels off: {M.REDUCED.line.formula}, f∞ > 0 at 5σ)",
            "truncated": f"truncated ({M.TRUNCATED.line.formula} fits, f∞ consistent with 0)",
            "neither": "neither law fits at 5σ", "undecided": "undecided (3σ ≤ Z < 5σ)"}


def line_law(body) -> tuple[str | None, str]:
    """(line, reason): the line the test uses for ``body`` and its laws, or (None, why there is none)."""
    if LG.has_line_law(body.delta, body.chi, body.is_symmetric):
        laws = ", ".join(f"{m} {M.get(m).line.formula} {M.get(m).line.equation}" for m in ("truncated", "reduced"))
        return ("the rotation line |L|/(2π I1), the only one (d along the symmetry axis, or a sphere, cones about L); "
                + laws), ""
    shape = "an asymmetric top" if not body.is_symmetric else f"a symmetric top with δ = {body.delta:.3g}, χ = " \
                                                              f"{math.degrees(body.chi):.3g}°"
    return None, (f"{shape} has no power-frequency law: the paper's laws hold for a dipole along the axis (χ = 0) or a "
                  f"spherical top (δ = 0); its lines (|L|/I1 + κ δΩ3) share the power in ways that depend on the start")


# --- the fits -------------------------------------------------------------------------------
def _z_fit(chi2: float, dof: int) -> float:
    """The one-sided Gaussian Z of chi2's p-value for ``dof`` degrees of freedom (0 for p >= 1/2);
    where p underflows, the Wilson-Hilferty normal approximation of chi2 (good to a few % there)."""
    from scipy.special import chdtrc, ndtri

    k = max(dof, 1)
    p = float(chdtrc(k, chi2))
    if p > 1e-300:
        return float(max(-ndtri(p), 0.0))
    return float(((chi2 / k) ** (1.0 / 3.0) - (1.0 - 2.0 / (9.0 * k))) / math.sqrt(2.0 / (9.0 * k)))


class _Data:
    """ln f, ln P and the errors of a series, with the weighted linear fits the laws profile."""

    def __init__(self, s: Series):
        self.f = np.asarray(s.f_hz, dtype=float)
        self.lf = np.log(self.f)
        self.y = np.log(np.asarray(s.power, dtype=float))
        self.sy = np.asarray(s.sigma_power, dtype=float) / np.asarray(s.power, dtype=float)
        self.sf = np.asarray(s.sigma_f_hz, dtype=float) / self.f
        self.fmin = float(self.f.min())

    def chi2(self, f_inf: float, n_free: bool, n: float = 4.0):
        """(chi2, a, n) at f_inf, the amplitude a (and the exponent when ``n_free``) fitted."""
        q = np.minimum((f_inf / self.f) ** 2, 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            shape = np.log1p(-q)
            slope = n + 2.0 * q / (1.0 - q)                      # dlnP/dlnf of the law
        w = 1.0 / (self.sy**2 + (slope * self.sf) ** 2)
        r = self.y - shape
        if not n_free:
            a = float(np.sum(w * (r - n * self.lf)) / np.sum(w))
            return float(np.sum(w * (r - a - n * self.lf) ** 2)), a, n
        sw, sx, sy = np.sum(w), np.sum(w * self.lf), np.sum(w * r)
        sxx, sxy = np.sum(w * self.lf**2), np.sum(w * self.lf * r)
        det = sw * sxx - sx**2
        n_fit = float((sw * sxy - sx * sy) / det)
        a = float((sy - n_fit * sx) / sw)
        return float(np.sum(w * (r - a - n_fit * self.lf) ** 2)), a, n_fit

    def profile(self, n_free: bool):
        """(f_inf, chi2(f_inf) callable) at the minimum of the profile over f_inf in [0, min f)."""
        from scipy.optimize import minimize_scalar

        def c(s):
            return self.chi2(s * self.fmin, n_free)[0]

        grid = np.unique(np.concatenate([np.linspace(0.0, 0.9, 91), 1.0 - np.geomspace(0.1, 1e-12, 120)]))
        vals = np.array([c(s) for s in grid])
        i = int(np.nanargmin(vals))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
        best = (grid[i], vals[i])
        if hi > lo:
            r = minimize_scalar(c, bounds=(lo, hi), method="bounded", options={"xatol": 1e-13})
            if r.fun < best[1]:
                best = (float(r.x), float(r.fun))
        return best[0] * self.fmin, best[1], c

    def interval(self, s_best: float, chi_min: float, c, delta: float) -> tuple[float, float]:
        """Where the profile c(s) rises by ``delta`` on each side of s_best, as f_inf (Hz)."""
        from scipy.optimize import brentq

        def g(s):
            return c(s) - chi_min - delta

        lo = 0.0 if g(0.0) <= 0 else brentq(g, 0.0, s_best) if s_best > 0 else 0.0
        top = 1.0 - 1e-12
        hi = top if g(top) <= 0 else brentq(g, s_best, top)
        return lo * self.fmin, hi * self.fmin


def _general_sigma_n(d: _Data, f_inf: float, a: float, n: float) -> float:
    """The exponent's uncertainty in the general fit: from the chi2 Hessian in (a, n, f_inf) where
    f_inf is inside its range, else from (a, n) at f_inf = 0."""
    def chi(p):
        q = (p[2] / d.f) ** 2
        shape = np.log1p(-q)
        slope = p[1] + 2.0 * q / (1.0 - q)
        w = 1.0 / (d.sy**2 + (slope * d.sf) ** 2)
        return float(np.sum(w * (d.y - shape - p[0] - p[1] * d.lf) ** 2))

    p0 = np.array([a, n, f_inf])
    free = [0, 1, 2] if f_inf > 1e-6 * d.fmin else [0, 1]
    h = np.array([1e-4, 1e-4, 1e-3 * min(f_inf, d.fmin - f_inf)])      # f_inf's step stays inside [0, min f)
    def at(i, j, si, sj):
        p = p0.copy()
        p[i] += si * h[i]
        p[j] += sj * h[j]
        return chi(p)

    H = np.zeros((len(free), len(free)))
    for ii, i in enumerate(free):
        for jj, j in enumerate(free):
            H[ii, jj] = (at(i, j, 1, 1) - at(i, j, 1, -1) - at(i, j, -1, 1) + at(i, j, -1, -1)) / (4 * h[i] * h[j])
    try:
        cov = 2.0 * np.linalg.inv(H)
    except np.linalg.LinAlgError:
        return math.inf
    v = cov[1, 1]
    return float(math.sqrt(v)) if v > 0 else math.inf


def fit(series: Series, f_inf_expected: float | None = None) -> PfTest:
    """The start-free test of ``series`` (module docstring); ``f_inf_expected`` (Hz): the reduced
    line of a known start, to say how strongly the data reject the reduced law with it."""
    d = _Data(series)
    m = len(series)
    c_t, a_t, _ = d.chi2(0.0, False)
    f_r, c_r, prof_r = d.profile(False)
    _, a_r, _ = d.chi2(f_r, False)
    f_g, c_g, _ = d.profile(True)
    _, a_g, n_g = d.chi2(f_g, True)
    z = math.sqrt(max(c_t - c_r, 0.0))
    s_best = f_r / d.fmin
    interval = d.interval(s_best, c_r, prof_r, 1.0)
    upper = d.interval(s_best, c_r, prof_r, UPPER_95)[1] if z < CONSISTENT_Z else None
    fits = {"truncated": LawFit("truncated", {"a": a_t, "n": 4.0, "f_inf_hz": 0.0}, c_t, m - 1, 0.0),
            "reduced": LawFit("reduced", {"a": a_r, "n": 4.0, "f_inf_hz": f_r}, c_r, m - 2, 0.0),
            "general": LawFit("general", {"a": a_g, "n": n_g, "f_inf_hz": f_g}, c_g, m - 3, 0.0)}
    for x in fits.values():
        x.z_fit = _z_fit(x.chi2, x.dof)
    z_exp = None
    if f_inf_expected is not None:
        z_exp = (math.sqrt(max(d.chi2(f_inf_expected, False)[0] - c_r, 0.0)) if f_inf_expected < d.fmin else math.inf)
    if fits["truncated"].z_fit >= DECISION_Z and fits["reduced"].z_fit >= DECISION_Z:
        verdict = "neither"
    elif z >= DECISION_Z and fits["reduced"].z_fit < DECISION_Z:
        verdict = "reduced"
    elif z < CONSISTENT_Z and fits["truncated"].z_fit < DECISION_Z:
        verdict = "truncated"
    else:
        verdict = "undecided"
    return PfTest(n=m, truncated=fits["truncated"], reduced=fits["reduced"], general=fits["general"], exponent=n_g,
                  exponent_sigma=_general_sigma_n(d, f_g, a_g, n_g), f_inf=f_r, f_inf_interval=interval,
                  f_inf_upper95=upper, z=z, verdict=verdict, f_range=(float(d.f.min()), float(d.f.max())),
                  f_inf_expected=f_inf_expected, z_expected=z_exp)


# --- series ---------------------------------------------------------------------------------
def synthetic(budget, rng, source: str = "") -> Series | None:
    """One estimate per output instant of ``budget`` (``receiver.Budget``) where its strongest
    line is detected in the radiation zone, each from one integration: the true frequency and
    power toward the antenna (W/sr: the received power over the antenna's known effective area
    times R^2) with Gaussian errors of the receiver's bounds (ln P normal); None when fewer than
    four instants qualify."""
    rows = np.arange(budget.t.size)
    k = budget.dominant
    ok = np.isfinite(budget.sigma_f) & np.isfinite(budget.sigma_lnp)
    if np.count_nonzero(ok) < 4:
        return None
    f = budget.freq[rows, k][ok]
    p = budget.power_sr[rows, k][ok] * U.ERG_PER_S_IN_W
    sf, sp = budget.sigma_f[ok], budget.sigma_lnp[ok]
    f_obs = f + sf * rng.standard_normal(f.size)
    p_obs = p * np.exp(sp * rng.standard_normal(f.size))
    return Series(f_hz=f_obs, power=p_obs, sigma_f_hz=sf, sigma_power=sp * p_obs, t_s=budget.t[ok], unit="W/sr",
                  source=source or f"{budget.model}: one integration at each of {f.size} instants")


def from_measurements(data: dict, unit: str, source: str) -> Series:
    """A ``Series`` from ``inputs.measurements.read_measurements``'s arrays."""
    t = np.asarray(data["t_s"], dtype=float) if "t_s" in data else None
    return Series(f_hz=np.asarray(data["f_hz"], dtype=float), power=np.asarray(data["power"], dtype=float),
                  sigma_f_hz=np.asarray(data["sigma_f_hz"], dtype=float),
                  sigma_power=np.asarray(data["sigma_power"], dtype=float), t_s=t, unit=unit, source=source)
