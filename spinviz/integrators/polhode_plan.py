"""Before a ``polhode`` run: where the averaged flow takes the spin (``predict``: the hand-over's
instant and the turns before it, for ``auto``) and whether the horizon can be represented at all
(``horizon_problem``: refused before any work)."""

from __future__ import annotations

import math

import numpy as np

from ..physics import polhode as PH
from .polhode import _Clock
from .polhode_flow import Flow

PREDICT_RTOL = 1e-5
PREDICT_LEGS = 6


_PREDICTIONS: dict = {}


def predict(system, omega, target: float, t_max: float) -> tuple[float, float]:
    """(time, turns) from the spin-unit state ``omega`` (3,) until |omega| <= ``target``, as the
    averaged flow predicts it (first order, no phases: a plan, not a result; a separatrix passed
    continues on the other side at the same |L| and energy); (inf, turns to ``t_max``) when it
    does not get there.  |omega| is read as sqrt(2E / J_s), its largest on the polhode, for the
    target, and as sqrt(2E / J_m) for the turns.  Remembered for the last few questions (``auto``
    asks the same one up to four times for one run: the choice, the turns, the cost check, its
    message)."""
    key = (system, tuple(float(x) for x in omega), float(target), float(t_max))
    hit = _PREDICTIONS.get(key)
    if hit is None:
        if len(_PREDICTIONS) > 32:
            _PREDICTIONS.clear()
        hit = _PREDICTIONS[key] = _predict(system, omega, target, t_max)
    return hit


def _predict(system, omega, target: float, t_max: float) -> tuple[float, float]:
    """``predict`` itself: leg by leg between separatrices."""
    J = np.asarray(system.inertia, dtype=float)
    w = np.asarray(omega, dtype=float)
    if float(np.linalg.norm(w)) <= target:
        return 0.0, 0.0
    s, m, l = PH.extreme_axes(J)
    t, turns = 0.0, 0.0
    for _ in range(PREDICT_LEGS):
        try:
            c, s_c = PH.encircled_axis(J, w)
        except PH.NoPolhode:
            w = w + 1e-6 * np.linalg.norm(w) * np.eye(3)[s]      # off the separatrix by a hair
            c, s_c = PH.encircled_axis(J, w)
        sol, clock = _predict_leg(system, J, c, s_c, w, t, turns, target, t_max)
        t, turns = float(clock.t(sol.t[-1])), float(sol.y[2, -1])
        if sol.status != 1:
            return math.inf, turns
        if sol.t_events[0].size:
            return t, turns
        # on to the other side: the same X and 2E about the other extreme axis
        X = math.exp(sol.y[0, -1])
        o = s if c == l else l
        Y = X / J[m] * (1.0 - 0.02 * (1.0 if o == l else -1.0))     # just past it: h = X - J_m 2E changes sign
        w = PH.Polhode(tuple(J), o, 1.0, X, abs(J[o] * Y - X)).omega(0.0)
    return math.inf, turns


def _predict_leg(system, J, c: int, s_c: float, w, t: float, turns: float, target: float, t_max: float):
    """One leg of ``_predict`` about the axis c: (solve_ivp's solution in the clock's s, the clock);
    its events are |omega| reaching ``target`` and the separatrix coming within 1 %."""
    from scipy.integrate import solve_ivp

    s, m, l = PH.extreme_axes(J)
    flow = Flow(system, c, s_c)
    Jc, Jm = float(J[c]), float(J[m])
    sig = 1.0 if c == l else -1.0      # 2E = (X + sig p) / J_c

    def norm(y, J_as=Jm):
        X, p = math.exp(y[0]), math.exp(y[1])
        return math.sqrt(max((X + sig * p) / Jc, 0.0) / J_as)

    x = flow.x_of(w)
    r0 = flow.rates(x)
    clock = _Clock(t, 1.0 / max(abs(float(r0[0])) + abs(float(r0[1])), 1.0 / max(t_max - t, 1e-300)))

    def rhs(s_, y):
        r = flow.rates(y[:2])
        return np.array([r[0], r[1], norm(y) / (2.0 * math.pi)]) * clock.dtds(s_)

    def reached(_s, y):
        # |omega| <= sqrt(2E / J_s) all round the polhode: reached when even the largest is below target
        return norm(y, float(J[s])) - target

    def separatrix(_s, y):
        return float(flow.polhode(y[:2]).separatrix_distance) - 0.01

    reached.terminal = separatrix.terminal = True
    reached.direction = separatrix.direction = -1.0
    sol = solve_ivp(rhs, (0.0, float(clock.s(t_max))), np.array([x[0], x[1], turns]), method="DOP853",
                    rtol=PREDICT_RTOL, atol=np.array([1e-9, 1e-9, 1e300]), events=(reached, separatrix))
    return sol, clock


def horizon_problem(system, t_end: float) -> str | None:
    """Why a horizon cannot be run by the averaged flow before any work, or None: a horizon
    float64 cannot hold, or one at which |L|^2 of the braked spin underflows (|omega|^2 falls
    like 1/(eps t) at the slowest, |omega|^2 < 1e-250 spin units: the polhode's size, a fraction
    of it, is then beyond float64)."""
    if not math.isfinite(t_end):
        return "the horizon in spin units (t_end x tau0 |Omega0| / tau0) is beyond float64"
    eps = float(np.dot(system.coupling, system.coupling))
    if system.model != "free" and eps * t_end > 1e250:
        return (f"the spin would brake by ~{math.sqrt(eps * t_end):.2g}x by t_end: |L|^2 falls below what float64 "
                f"holds for the polhode (~1e-250 of its start)")
    return None
