"""When the two models part, as a function of the resolution: from the same, known start, the
first time each observable differs between them by a given amount -- and the time this
receiver sees it, where the difference reaches 5 of its standard errors in one integration.

Observables and their differences (dimensionless, so a resolution is one number):

* power: |ln(P_a / P_b)| of the power toward the detector (a relative resolution: sigma_P / P);
* frequency: |f_a / f_b - 1| of the strongest line (sigma_f / f);
* polarization: the difference of the linear polarization's angles, rad (counted only where
  both lines are at least 10 % linearly polarized: a circular signal's angle means nothing).

The differences start from zero and first grow as t (power) and t^2 (frequency) -- the models
agree to first order in the rotation, not in the power -- so the fine resolutions a receiver
reaches part them early, where the integrated runs are not accurate enough: their relative
errors are ~1e-11 (measured against (5.2), (5.4)).  For a top with the closed forms of
``physics.longitudinal`` (chi = 0 or delta = 0) the power and frequency differences are taken
from them on a dense log grid (exact to round-off: resolutions below 1e-14, fifty ulps of the
frequency ratio, are left out); otherwise from the runs, and resolutions below ten times the
integrator's relative tolerance are left out (``floor``).

``parting_time(t, D, r)`` is the first time the running maximum of D reaches r (linear
interpolation), so it never decreases with r.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..physics import models as M
from .detector import Detection

OBSERVABLES = ("power", "frequency", "polarization")
MIN_LINEAR = 0.1
DECISION_SIGMA = 5.0
CLOSED_FLOOR = 1e-14          # fifty ulps of a ratio of two frequencies: below it the closed forms' difference is round-off
LABELS = {"power": "relative power resolution σ_P/P", "frequency": "relative frequency resolution σ_f/f",
          "polarization": "polarization-angle resolution (°)"}
# the resolutions the table lists (the polarization's in degrees at the boundary, radians inside)
TABLE = {"power": (1e-3, 1e-2, 0.1, math.log(2.0)), "frequency": (1e-12, 1e-9, 1e-6, 1e-3, 1e-2),
         "polarization": tuple(math.radians(x) for x in (0.1, 1.0, 5.0))}


def differences(a: Detection, b: Detection) -> dict[str, np.ndarray]:
    """Per instant of two detections: |ln(P_a/P_b)|, |f_a/f_b - 1| and the polarization angles'
    difference (rad; NaN where either line is below 10 % linear)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.abs(np.log(a.power_sr / b.power_sr))
        p = np.where((a.power_sr > 0) & (b.power_sr > 0), p, np.where(a.power_sr == b.power_sr, 0.0, np.inf))
        f = np.abs(a.f_dom / b.f_dom - 1.0)
    d = np.abs((a.pol_angle - b.pol_angle + 0.5 * math.pi) % math.pi - 0.5 * math.pi)
    d = np.where((a.linear >= MIN_LINEAR) & (b.linear >= MIN_LINEAR), d, np.nan)
    return {"power": p, "frequency": f, "polarization": d}


def exact_differences(t, u0: float, b0: float, tau0: float, models=("reduced", "truncated")) -> dict[str, np.ndarray]:
    """|ln(P_a/P_b)| and |f_a/f_b - 1| of the two ``models`` at times t from their closed-form
    lines ((5.2) and (5.4): a top with d along its axis, or a sphere, from the start (u0, b0) of
    ``physics.longitudinal.start_state``)."""
    fa, pa = M.get(models[0]).line.line(t, u0, b0, tau0)
    fb, pb = M.get(models[1]).line.line(t, u0, b0, tau0)
    return {"power": np.abs(np.log(pa / pb)), "frequency": np.abs(fa / fb - 1.0)}


def parting_time(t, D, r: float) -> float | None:
    """The first time the running maximum of D(t) reaches r (linear interpolation between the
    instants), or None within the series."""
    m = np.maximum.accumulate(np.nan_to_num(np.asarray(D, dtype=float), nan=0.0))
    above = np.nonzero(m >= r)[0]
    if above.size == 0:
        return None
    i = int(above[0])
    if i == 0 or m[i] == m[i - 1]:
        return float(t[i])
    return float(t[i - 1] + (r - m[i - 1]) / (m[i] - m[i - 1]) * (t[i] - t[i - 1]))


@dataclass
class PartingCurve:
    """One observable's parting time across resolutions: ``resolutions`` (M,) and ``times`` (M,)
    (NaN: never within the run), the difference ``D`` over ``t`` it comes from, its ``source``,
    the smallest resolution it resolves (``floor``); and this receiver's: its 1-sigma error of
    one integration over time (``sigma``, the worse of the two models'; inf where the line is not
    detected, NaN outside the radiation zone), the time the difference first reaches 5 sigma
    (``setup_time``, None if never) and the resolution 5 sigma there."""

    key: str
    t: np.ndarray
    D: np.ndarray
    resolutions: np.ndarray
    times: np.ndarray
    source: str
    floor: float
    sigma: np.ndarray | None = None
    setup_time: float | None = None
    setup_resolution: float | None = None

    def at(self, r: float) -> float | None:
        """The parting time at resolution r (None: never within the run, or below the floor)."""
        return None if r < self.floor else parting_time(self.t, self.D, r)

    def record(self) -> dict:
        """JSON-ready: the curve (resolutions and times, None where never) and the setup's parting."""
        def num(x):
            return float(x) if x is not None and math.isfinite(x) else None

        return {"source": self.source, "floor": self.floor, "resolution": [float(x) for x in self.resolutions],
                "time": [num(x) for x in self.times], "setup_time": num(self.setup_time),
                "setup_resolution": num(self.setup_resolution),
                "unit": "rad" if self.key == "polarization" else "relative"}


def curve(key: str, t, D, source: str, floor: float, points: int = 160) -> PartingCurve:
    """The parting curve of difference D(t) over resolutions from max(floor, its smallest positive
    value) to its largest."""
    t, D = np.asarray(t, dtype=float), np.asarray(D, dtype=float)
    pos = D[np.isfinite(D) & (D > 0)]
    if pos.size == 0 or pos.max() < floor:
        return PartingCurve(key, t, D, np.zeros(0), np.zeros(0), source, floor)
    lo, hi = max(floor, float(pos.min())), float(pos.max())
    r = np.geomspace(lo, hi, points) if hi > lo else np.array([hi])
    times = np.array([x if (x := parting_time(t, D, v)) is not None else np.nan for v in r])
    return PartingCurve(key, t, D, r, times, source, floor)


def setup_parting(c: PartingCurve, t_sigma, sigma, t_first: float) -> PartingCurve:
    """``c`` with the receiver's parting: sigma(t_sigma) (1-sigma of one integration) carried onto
    c's instants (log-log interpolation; its first value before its first instant), and the first
    time >= t_first (one integration) at which D reaches ``DECISION_SIGMA`` sigma."""
    ts, s = np.asarray(t_sigma, dtype=float), np.asarray(sigma, dtype=float)
    keep = ts > 0
    ts, s = ts[keep], s[keep]
    finite = np.isfinite(s) & (s > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ls = np.where(finite, np.log(np.where(finite, s, 1.0)), np.inf)
        x = np.log(np.maximum(c.t, ts[0]))
        li = np.interp(x, np.log(ts), np.where(np.isfinite(ls), ls, 1e300))
    sig = np.where(li > 700, np.inf, np.exp(np.minimum(li, 700)))
    apart = (np.nan_to_num(c.D, nan=0.0) >= DECISION_SIGMA * sig) & (c.D >= c.floor)
    i = np.nonzero(apart & (c.t >= t_first))[0]
    c.sigma = sig
    if i.size:
        j = int(i[0])
        first = int(np.argmax(c.t >= t_first))
        # apart already before the first estimate is complete: the answer is that estimate's time
        c.setup_time = float(t_first) if j == first and j > 0 and apart[j - 1] else float(c.t[j])
        c.setup_resolution = float(DECISION_SIGMA * sig[j])
    return c


def curves(a: Detection, b: Detection, start=None, tau0: float = 1.0, rtol: float = 1e-10) -> dict:
    """The three parting curves of detections a and b (one model each); ``start`` (u0, b0) when
    the closed forms hold (then power and frequency come from them), else from the runs."""
    d = differences(a, b)
    floor = 10.0 * rtol
    runs = "the integrated runs (differences below 10 rtol not resolved)"
    out = {"polarization": curve("polarization", a.t, d["polarization"], runs, floor)}
    if start is not None:
        horizon = float(a.t[-1])
        t = np.unique(np.concatenate([np.geomspace(horizon * 1e-12, horizon, 4000), a.t[a.t > 0]]))
        models = (a.model, b.model)
        exact = exact_differences(t, start[0], start[1], tau0, models)
        source = "closed forms " + ", ".join(M.get(m).line.equation for m in models)
        for key in ("power", "frequency"):
            out[key] = curve(key, t, exact[key], source, CLOSED_FLOOR)
    else:
        for key in ("power", "frequency"):
            out[key] = curve(key, a.t, d[key], runs, floor)
    return {k: out[k] for k in OBSERVABLES}
