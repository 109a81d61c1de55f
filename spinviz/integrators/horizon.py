"""Whether ``secular``'s slow flow can reach a horizon, judged before any work.

``secular`` (alone, or as the second stage of ``taylor -> secular``) does not resolve the turns,
so the turn count that bounds the resolving methods says nothing about it.  Two things bound
it instead, and both follow from the averaged flow of ``physics.averaged`` ((4.12) and its
truncated counterpart), which is cheap to integrate in the braking time sigma = int eps |w|^2 dt
(spin units, eps = tau0 |Omega0|):

* **its steps**.  The slow flow takes explicit Dormand-Prince 8(5,3) steps (``slowflow``).
  Where both amplitudes fall as 1/sqrt(t) the rates fall as 1/t and each decade of time costs
  the same few tens of steps.  Where one amplitude persists -- the reduced model's residual
  rotation about a dipole on the axis ((5.2): omega3 is not braked), the DAST cube -- the other
  decays at a fixed rate lambda, and an explicit method's step is then held at the edge of its
  stability region, h lambda ~ ``STABILITY_EDGE``, whatever the accuracy asked: the steps grow
  with the horizon itself (measured on the cube: 0.156 steps per Theta from 1e4 to 1e8 Theta,
  so 1e30 Theta would need 1e29).  The forecast integrates lambda(t) / ``STABILITY_EDGE``
  along the averaged flow, lambda the largest decay rate of its Jacobian, and adds
  ``STEPS_PER_DECADE`` a decade for accuracy.
* **its numbers**.  The slow flow's rates are products like eps |w|^4 (a torque of order
  eps |w|^3 times a component of omega, in its averages and error norms).  Once they fall below
  float64's normal range (2.2e-308) they lose their digits and then vanish: the steps are
  rejected by the thousand and the run ends "outside the finite numbers" (measured on the top
  delta = 0.3, chi = 0.7 handed over at tau0 |Omega| = 1e-3: clean to eps |w|^4 ~ 1e-315, its
  steps rejected 5e4 times by ~1e-320).  The forecast finds when eps |w|^4, in the units of the
  secular stage, reaches ``FLOOR`` -- 1e8 above the normal range's edge, for the coefficients
  and one step's fall.

Where the averaged flow does not exist (the torque-free top) nothing brakes: |w| stays, and
only the accuracy steps count.  A prolate top's resonances and the oscillating regime "5"
(``secular``'s refusals after the fact) are not forecast: the averaged flow cannot see them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

STABILITY_EDGE = 6.4        # h lambda at which DP853's steps settle on a decaying component (measured, the cube)
STEPS_PER_DECADE = 30.0     # accuracy-bound steps of the averaged flow per decade of time (measured 21)
FLOOR = 1e-300              # eps |w|^4 (secular's spin units) below which its rates leave float64's normal range
STEP = 0.2                  # the forecast's RK4 step: ln wp and ln |w3| change by at most ~20 % of their share a step
MAX_STEPS = 50_000          # forecast steps (ln |w| falls by ~0.2 a step: 1e4 covers float64's whole range)
TINY = 1e-300


@dataclass(frozen=True)
class Forecast:
    """What the averaged flow predicts for a secular stage over [0, t_max] (spin units of the
    run): ``steps`` the slow flow's steps from the stage's start (|w| = ``scale``) to t_max, or
    to ``t_floor`` if sooner; ``t_floor`` when eps |w|^4 in the stage's units reaches ``FLOOR``
    (inf: not by t_max); ``t_steps`` when the steps reach ``limit`` (inf: not by t_max);
    ``t_stage`` when the stage starts (0 for ``secular`` alone)."""

    steps: float
    t_floor: float
    t_steps: float
    t_stage: float


def _coefficients(system):
    """(P, Q, R, S) of the averaged flow of a spin-unit symmetric top, or None (no flow: the free
    top).  A sphere is taken with e3 along d (chi = 0), as ``secular.prepare`` does."""
    averaged = system.spec.averaged
    if averaged is None or not system.spec.brakes:
        return None
    J = [float(x) for x in system.inertia]
    delta = 1.0 - J[2] / J[0]
    g = np.asarray(system.coupling, dtype=float)
    chi = 0.0 if abs(delta) < 1e-12 else math.atan2(math.hypot(g[0], g[1]), g[2])
    return averaged.coefficients(delta, chi)


def _decay_rate(P, Q, R, S, a, b) -> float:
    """The largest decay rate (per unit sigma, times |w|^2) of the averaged flow's Jacobian in
    (wp, w3) at wp^2 = a, w3^2 = b: what an explicit method's step must stay below."""
    wpw3 = math.sqrt(a * b)
    j11, j12 = -(3.0 * P * a + Q * b), -2.0 * Q * wpw3
    j21, j22 = -2.0 * R * wpw3, -(R * a + 3.0 * S * b)
    tr, det = j11 + j22, j11 * j22 - j12 * j21
    disc = math.sqrt(max(tr * tr - 4.0 * det, 0.0))
    return max(abs(0.5 * (tr - disc)), abs(0.5 * (tr + disc)))


class _Flow:
    """The averaged flow in sigma on x = (ln wp, ln |w3|, t, stability-bound steps), and the step
    count of a secular stage that starts at ``t_stage`` (``base``: the steps counted before it)."""

    def __init__(self, coef, eps: float):
        self.coef, self.eps = coef, eps
        self.t_stage, self.base = math.inf, 0.0

    def rate(self, x):
        """d/dsigma of x."""
        P, Q, R, S = self.coef
        a, b = math.exp(2.0 * x[0]), math.exp(2.0 * x[1])
        n2 = max(a + b, TINY)
        return (-(P * a + Q * b) / n2, -(R * a + S * b) / n2, 1.0 / (self.eps * n2),
                _decay_rate(P, Q, R, S, a, b) / (n2 * STABILITY_EDGE))

    def step(self, x, t_max: float):
        """(the next state, ln |w| before, after): a step holding each component's log to ``STEP``
        of its share of |w|^2 (a dying component falls as it likes), never far past t_max."""
        k1 = self.rate(x)
        a, b = math.exp(2.0 * x[0]), math.exp(2.0 * x[1])
        n2 = a + b
        h = STEP * n2 / max(abs(k1[0]) * a, abs(k1[1]) * b, TINY)
        h = min(h, 2.0 * (t_max - x[2]) * self.eps * max(n2, TINY))     # t would overflow far past t_max
        y = _rk4(self.rate, x, k1, h)
        return y, 0.5 * math.log(max(n2, TINY)), 0.5 * math.log(max(math.exp(2.0 * y[0]) + math.exp(2.0 * y[1]), TINY))

    def steps_at(self, x, t: float) -> float:
        """The secular stage's steps up to the state x at time t."""
        if t < self.t_stage:
            return 0.0
        return (x[3] - self.base) + STEPS_PER_DECADE * math.log10(1.0 + self.eps * (t - self.t_stage))


def forecast(system, omega, t_max: float, scale: float = 1.0, limit: float = math.inf) -> Forecast:
    """The slow flow's steps and range over [0, t_max] from the spin-unit state ``omega`` (3,),
    the secular stage starting where |w| first falls to ``scale`` (1: at once; the hand-over's
    norm for ``taylor -> secular``).  RK4 in sigma on (ln wp, ln |w3|) as ``full_to_averaged.predict``,
    carrying t, the stability-bound steps and the crossings."""
    w = np.asarray(omega, dtype=float)
    eps = float(np.dot(system.coupling, system.coupling))
    wp, w3 = math.hypot(w[0], w[1]), abs(float(w[2]))
    coef = _coefficients(system)
    if coef is None or eps == 0.0 or math.hypot(wp, w3) == 0.0:
        steps = STEPS_PER_DECADE * math.log10(1.0 + max(eps, TINY) * t_max)
        return Forecast(steps, math.inf, math.inf if steps <= limit else 0.0, 0.0)
    flow = _Flow(coef, eps)
    ln_floor = 0.25 * math.log(FLOOR * scale**3 / eps)                 # eps |w|^4 / scale^3 = FLOOR
    x = [math.log(max(wp, TINY)), math.log(max(w3, TINY)), 0.0, 0.0]
    if math.hypot(wp, w3) <= scale:
        flow.t_stage = 0.0
    t_steps = math.inf
    for _ in range(MAX_STEPS):
        y, ln_old, ln_new = flow.step(x, t_max)
        if not math.isfinite(flow.t_stage) and ln_new <= math.log(scale):
            z = _between(x, y, (ln_old - math.log(scale)) / (ln_old - ln_new) if ln_old > ln_new else 1.0)
            flow.t_stage, flow.base = z[2], z[3]
            if flow.t_stage >= t_max:
                return Forecast(0.0, math.inf, math.inf, flow.t_stage)
        if ln_new <= ln_floor < ln_old:
            z = _between(x, y, (ln_old - ln_floor) / (ln_old - ln_new))
            if z[2] < t_max:
                return Forecast(flow.steps_at(z, z[2]), z[2], t_steps, flow.t_stage)
        end = y[2] >= t_max
        if end:
            y = _between(x, y, (t_max - x[2]) / (y[2] - x[2]) if y[2] > x[2] else 1.0)
        if not math.isfinite(t_steps) and flow.steps_at(y, y[2]) > limit:
            t_steps = _crossing(x, y, limit, flow.steps_at)
        if end:
            return Forecast(flow.steps_at(y, t_max), math.inf, t_steps, flow.t_stage)
        x = y
    # the flow has not reached t_max in MAX_STEPS steps of sigma: |w| falls by ~e^-2000 over them,
    # far below the floor, which has been met (returned above) unless nothing brakes
    return Forecast(flow.steps_at(x, x[2]), math.inf, t_steps, flow.t_stage)


def _rk4(f, x, k1, h: float) -> list:
    """One classical Runge-Kutta step of size h from x (k1 = f(x) given)."""
    k2 = f([x[i] + 0.5 * h * k1[i] for i in range(4)])
    k3 = f([x[i] + 0.5 * h * k2[i] for i in range(4)])
    k4 = f([x[i] + h * k3[i] for i in range(4)])
    return [x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) for i in range(4)]


def _between(x, y, r: float) -> list:
    """The forecast's state a fraction ``r`` of the way from x to y (linear)."""
    return [x[i] + r * (y[i] - x[i]) for i in range(4)]


def _crossing(x, y, limit, steps_at) -> float:
    """The time within the step x -> y at which the step count reaches ``limit``: t and the
    stability-bound steps are both integrals over sigma, near enough affine in it over one step
    (the accuracy steps, logarithmic in t, are a correction of a few thousand at most)."""
    s0, s1 = steps_at(x, x[2]), steps_at(y, y[2])
    r = min(1.0, max(0.0, (limit - s0) / (s1 - s0))) if s1 > s0 else 1.0
    return x[2] + r * (y[2] - x[2])


def check_slow_flow(system, omega, t_max: float, scale: float = 1.0) -> None:
    """Refuse, before any work, a secular stage that cannot reach ``t_max`` (spin units of the
    run): its spin falls below what float64 carries through its rates, or it needs more than
    ``secular.MAX_STEPS`` steps (``Forecast``).  ``SpecError("t_end", ...)`` says which and how
    much of the horizon the slow flow can reach."""
    from ..errors import SpecError
    from . import secular as SC

    fc = forecast(system, omega, t_max, scale, SC.MAX_STEPS)
    if fc.t_floor < t_max:
        eps = float(np.dot(system.coupling, system.coupling))
        raise SpecError("t_end", f"secular's slow flow leaves float64's range after ~{fc.t_floor / t_max:.2g} of this "
                                 f"horizon: by then tau0 |Omega| ~ {eps * (FLOOR * scale**3 / eps) ** 0.25:.2g} and its "
                                 f"rates (~tau0 |Omega|^4) fall below the smallest normal number; at most that much of "
                                 f"it can finish")
    if fc.steps > SC.MAX_STEPS:
        raise SpecError("t_end", f"secular's slow flow needs ~{fc.steps:.2g} steps (its explicit steps are held to the "
                                 f"decay of the braked component where the other persists: the residual rotation); at "
                                 f"most {SC.MAX_STEPS:g} can finish, which reach ~{fc.t_steps / t_max:.2g} of this "
                                 f"horizon")


def check_secular(body, model: str, omega0, t_end: float, spin=None, handover: bool = False) -> None:
    """``check_slow_flow`` for a run of ``body`` (its units) to ``t_end`` by ``secular``, or by
    ``taylor -> secular`` (``handover``: the slow flow starts where braking brings tau0 |Omega|
    to the hand-over's bound, as ``full_to_averaged.plan`` predicts it).  ``spin``: (problem,
    eps) of ``scaling.body_spin_problem`` if the caller has them."""
    from .scaling import body_spin_problem

    problem, eps = spin if spin is not None else body_spin_problem(body, model, omega0)
    scale = 1.0
    if handover:
        from .full_to_averaged import TARGET_MARGIN, target_norm

        scale = TARGET_MARGIN * target_norm(problem)
    check_slow_flow(problem.system, problem.omega0, float(t_end) * eps / body.tau0, scale)
