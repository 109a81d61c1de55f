"""``method = "auto"``: which integrator a run gets, and why (stored as stats["method_reason"])."""

from __future__ import annotations

import math

import numpy as np

from ..errors import SpecError
from .base import get
from .full_to_averaged import NAME as HANDOVER
from .full_to_averaged import NAME_POLHODE as HANDOVER_POLHODE
from .full_to_averaged import NAMES as HANDOVERS
from .scaling import body_spin_problem
from .secular import EPS_MAX

MAX_RESOLVED_TURNS = 1e6     # beyond this, resolving every turn costs more than ~10 s
HARD_MAX_TURNS = 5e7         # taylor resolves an askew asymmetric body at ~17 us a turn (rtol 1e-10, 7.7 steps a turn): ~15 min
# radiation decay rate / spin rate above which radau beats Taylor's method (measured on thin askew
# tops: taylor 7-400x faster than radau from 1.5e2 to 1.6e5, a tie at 5e5, radau 1.3-2x faster at
# 1.6e6 .. 1.6e7; an explicit Runge-Kutta method was stability-bound from ~10)
STIFF_RATIO = 5e5


def braking_coefficient(problem) -> float:
    """kappa: the initial relative decay rate of |omega| in units of eps_rad |omega|^2 (spin
    units), from the model's own radiation torque -- averaged over the free precession phase
    for a symmetric top, whose braking depends on where omega_perp points in the body.
    1 for rotation about a principal axis perpendicular to d ((3.7)), 0 where nothing brakes."""
    s = problem.system
    w = np.asarray(problem.omega0, dtype=float)
    rad = s.radiation()
    if s.is_symmetric:
        wp, p0 = math.hypot(w[0], w[1]), math.atan2(w[1], w[0])
        p = p0 + 2.0 * math.pi * np.arange(32) / 32
        ws = np.stack([wp * np.cos(p), wp * np.sin(p), np.full(p.shape, w[2])])
        a = np.array(rad(*ws))
        decay = -float(np.mean(np.sum(ws * a, axis=0)))
    else:
        decay = -float(np.dot(w, rad(*w)))
    eps = float(np.dot(s.coupling, s.coupling))
    w2 = float(w @ w)
    return max(0.0, decay / (eps * w2 * w2)) if eps > 0 and w2 > 0 else 0.0


MAX_FIXED_STEPS = 1e10
AVERAGED = ("secular", "polhode")   # methods that follow the slow variables, not each turn


def check_cost(body, model: str, omega0, t_end: float, method: str = "auto", step: float | None = None,
               spin=None, kinematics: str = "quaternion", picked: str | None = None, braking_rate: float = 0.0) -> None:
    """Refuse, before any work, a run that cannot finish: more than 1e10 fixed steps, or more
    than ``HARD_MAX_TURNS`` turns (estimated with braking) for a method that resolves every
    turn.  ``secular`` follows the slow variables instead and has no such limit; ``auto`` is
    judged by the method it picks (``picked``, when the caller has already chosen it).  The
    hand-over ``taylor -> secular`` is judged through both stages: its full stage by the turns
    before tau0 |Omega| has braked to ``secular.EPS_MAX``, as the averaged flow predicts them
    (``handover.plan``; ``choose_method`` picks it only where they can finish), and its slow
    flow, like ``secular``'s, by its steps and the range of float64 it stays in
    (``horizon.check_secular``).  ``braking_rate``: a braking of |omega| beside the radiation's,
    at least this exponential rate (1/time; a trap's gas), which bounds the turns too.
    ``SpecError`` names "step" or "t_end"."""
    method = str(method).lower()
    auto = method == "auto"
    if not body.is_symmetric and (auto or method == "polhode"):
        # before any prediction: a horizon the averaged flow cannot represent is refused at once
        _check_polhode_horizon(body, model, omega0, t_end, spin, "polhode")
    if auto:
        method = picked or choose_method(body, model, omega0, t_end, kinematics, spin=spin)[0]
    if method in (HANDOVER, "secular"):
        # both stages: the full stage is picked only where it can finish, the slow flow's steps and
        # float64 range are forecast (horizon.check_secular)
        from .horizon import check_secular

        check_secular(body, model, omega0, t_end, spin, handover=method == HANDOVER)
        return
    if method in HANDOVERS or method == "polhode":
        # the full stage: choose_method picks a hand-over only where it can finish; the averaged stage:
        # refused at once where its horizon is beyond what it can represent
        _check_polhode_horizon(body, model, omega0, t_end, spin, method)
        return
    if get(method).fixed_step:
        if step is not None and t_end / step > MAX_FIXED_STEPS:
            raise SpecError("step", f"t_end / step = {t_end / step:.3g} steps; at most {MAX_FIXED_STEPS:g} can finish")
        return
    turns = estimated_turns(body, model, omega0, t_end, spin)
    if braking_rate > 0.0:          # |omega| <= |omega0| exp(-rate t): the turns are at most its integral
        turns = min(turns, float(np.linalg.norm(omega0)) * -math.expm1(-braking_rate * t_end)
                    / (2.0 * math.pi * braking_rate))
    if turns > HARD_MAX_TURNS:
        who = method
        if auto:
            who = (f"{method} (averaging over the polhode does not apply: {_polhode_note(body, model, omega0, t_end, spin)})"
                   if not body.is_symmetric else
                   f"{method} (averaging does not apply: tau0 |Omega0| is not small"
                   f"{_handover_note(body, model, omega0, t_end, spin)})")
        raise SpecError("t_end", f"the body turns ~{turns:.3g} times (estimated with braking) and {who} resolves each "
                                 f"turn: at most {HARD_MAX_TURNS:g} can finish")


def _handover_note(body, model: str, omega0, t_end: float, spin=None) -> str:
    """Why a symmetric top that is not fast at the start gets no hand-over: the full stage
    before it, as predicted, is itself unaffordable, or the hand-over never comes."""
    problem, eps = spin if spin is not None else body_spin_problem(body, model, omega0)
    if not eps > EPS_MAX or model == "free":
        return ""
    from .full_to_averaged import TARGET_MARGIN, predict, target_norm

    S = float(t_end) * eps / body.tau0
    t_h, turns_full = predict(problem.system, problem.omega0, TARGET_MARGIN * target_norm(problem), S)
    if math.isfinite(t_h):
        return (f", and the averaged flow predicts it to fall to {EPS_MAX:g} only after ~{turns_full:.3g} turns "
                f"in full")
    return f", nor does braking bring it to {EPS_MAX:g} by t_end (predicted by the averaged flow)"


def _check_polhode_horizon(body, model: str, omega0, t_end: float, spin, method: str) -> None:
    """``SpecError("t_end")`` where the averaged stage of ``polhode`` (alone or after a hand-over)
    cannot represent the horizon (``polhode_plan.horizon_problem``)."""
    if method == HANDOVER:
        return
    from .polhode_plan import horizon_problem

    problem, eps = spin if spin is not None else body_spin_problem(body, model, omega0)
    why = horizon_problem(problem.system, float(t_end) * eps / body.tau0)
    if why:
        raise SpecError("t_end", f"{t_end:g}: {why}")


def _polhode_note(body, model: str, omega0, t_end: float, spin=None) -> str:
    """Why an asymmetric body gets neither ``polhode`` nor the hand-over to it: what stops it."""
    from .polhode import NotApplicable, check_applicable

    problem, eps = spin if spin is not None else body_spin_problem(body, model, omega0)
    try:
        check_applicable(problem)
    except NotApplicable as e:
        if not eps > EPS_MAX or model == "free":
            return str(e)
        S = float(t_end) * eps / body.tau0
        from .full_to_averaged import TARGET_MARGIN, target_norm
        from .polhode_plan import predict

        t_h, turns_full = predict(problem.system, problem.omega0, TARGET_MARGIN * target_norm(problem), S)
        if math.isfinite(t_h):
            return (f"tau0 |Omega0| = {eps:.3g} > {EPS_MAX:g}, and the averaged flow predicts it to fall to {EPS_MAX:g} "
                    f"only after ~{turns_full:.3g} turns in full")
        return (f"tau0 |Omega0| = {eps:.3g} > {EPS_MAX:g}, nor does braking bring it to {EPS_MAX:g} by t_end "
                f"(predicted by the averaged flow)")
    return "it applies"


def _phase_note(turns: float) -> str:
    """What an averaged method's reason adds where the spin phase after ``turns`` is beyond float64."""
    ulp = float(np.spacing(2.0 * math.pi * turns))
    return f"; the spin phase is beyond float64 (1 ulp = {ulp:.2g} rad)" if ulp > 1e-3 else ""


def estimated_turns(body, model: str, omega0, t_end: float, spin=None) -> float:
    """Turns of the body over [0, t_end] with braking: |omega| following the law of (3.7),
    d|omega|/ds = -kappa eps |omega|^3, with kappa measured at the start
    (``braking_coefficient``); without braking (kappa = 0) |omega0| t_end / 2 pi.  For a
    symmetric top the larger of that and the averaged flow's count (``handover.predict``):
    kappa at the start misses that omega_perp and omega3 brake at different rates -- with the
    dipole on the axis omega3 is not braked at all ((5.2)), and the law from the start
    undercounts 8e8 turns as 3e5."""
    problem, eps = spin if spin is not None else body_spin_problem(body, model, omega0)
    S = float(t_end) * eps / body.tau0                  # the horizon in spin units (|omega(0)| = 1)
    k = braking_coefficient(problem) * eps
    if k * S < 1e-8:
        turns = S / (2.0 * math.pi)
    else:
        turns = (math.sqrt(1.0 + 2.0 * k * S) - 1.0) / (2.0 * math.pi * k)
    if body.is_symmetric and model != "free":
        from .full_to_averaged import predict

        turns = max(turns, predict(problem.system, problem.omega0, 0.0, S)[1])
    elif model != "free" and turns > ASYMMETRIC_PREDICT_FROM and _has_polhode(problem):
        # kappa at the start misses that the braking slows as the spin settles about an axis
        from .polhode_plan import predict as predict_polhode

        turns = max(turns, predict_polhode(problem.system, problem.omega0, 0.0, S)[1])
    return turns


ASYMMETRIC_PREDICT_FROM = 1e4    # turns (from kappa) above which an asymmetric body's count is also predicted


def _has_polhode(problem) -> bool:
    from ..physics.polhode import NoPolhode, encircled_axis

    try:
        encircled_axis(problem.system.inertia, problem.omega0)
        return True
    except NoPolhode:
        return False


def stiffness_ratio(body, model: str, omega0, problem=None) -> float:
    """Fastest decay rate of the linearized Euler equation at omega0, per radian of spin.

    The free motion has purely imaginary eigenvalues (rotation); a large negative real part
    comes from the radiation torque -- |omega| ~ 1 or more in units of 1/tau0, or a thin
    body (eps = I3/I1 -> 0) with an askew dipole, where (4.4) divides by 1 - delta = eps.
    ``problem``: the spin-unit problem of (body, model, omega0) if already built.
    """
    problem = problem if problem is not None else body_spin_problem(body, model, omega0)[0]
    lam = np.linalg.eigvals(problem.system.jacobian(problem.omega0))
    return float(max(0.0, -np.min(lam.real)))


def choose_method(body, model: str, omega0, t_end: float, kinematics: str = "quaternion",
                  spin=None, rtol: float = 1e-10) -> tuple[str, str]:
    """The method ``method = "auto"`` picks, and why (from ``spinviz bench``'s table, see
    docs/accuracy.md).

    * more than 1e6 turns (estimated with braking) of a symmetric top with tau0 |Omega0| <=
      1e-3: ``secular`` (the hybrid slow flow; resolving each turn is neither affordable nor,
      past 1e16 turns, representable in float64);
    * more than 1e6 turns of a symmetric top with tau0 |Omega0| > 1e-3 (not stiff, not free)
      whose braking brings tau0 |Omega| to 1e-3 before t_end, after at most ``HARD_MAX_TURNS``
      turns, as the averaged flow predicts it: ``taylor -> secular`` (``handover``), Taylor's
      method in full until ``secular`` applies, then ``secular``.  Measured against full
      Taylor runs to 1e11 tau0 (~1e5 turns, five bodies of both models, |omega0| = 0.01 .. 0.1):
      the slow variables within ``secular``'s own ``slow_error_estimate`` (3e-8 .. 1e-4 of
      |Omega|), the full stage a few hundred turns at |omega0| = 0.01;
    * stiff (decay rate > 10 x spin rate): ``radau`` with the exact Jacobian;
    * otherwise ``taylor`` (``taylor-long`` for rtol below 1e-15, where float64 stops): the
      fastest resolving method at every tolerance the bench measured, and the only one whose
      error follows rtol below ~1e-10; if it then detects stiffness, the driver switches to radau.

    ``spin``: (problem, eps_rad) from ``spin_problem`` if the caller already has them.
    """
    problem, eps = spin if spin is not None else body_spin_problem(body, model, omega0)
    turns = estimated_turns(body, model, omega0, t_end, (problem, eps))
    if kinematics == "euler_zxz":
        return "taylor", "Euler-angle kinematics (6.4): resolved by Taylor's method (secular tracks quaternions only)"
    if turns > MAX_RESOLVED_TURNS and body.is_symmetric:
        from .secular import NotApplicable, prepare

        try:
            prepare(problem)
            phase = _phase_note(turns)
            return "secular", (f"~{turns:.3g} turns of a symmetric top (estimated with braking): the slow flow, in "
                               f"full where the precession is slow, averaged where it is fast (tau0 |Omega0| = "
                               f"{eps:.2g}){phase}")
        except NotApplicable:
            pass                                        # tau0 |Omega0| too large for a fast spin
    if turns > MAX_RESOLVED_TURNS and not body.is_symmetric:
        from .polhode import NotApplicable as NoAverage
        from .polhode import check_applicable

        try:
            check_applicable(problem)
            phase = _phase_note(turns)
            return "polhode", (f"~{turns:.3g} turns of an asymmetric body (estimated with braking): the torque averaged "
                               f"over the Euler-Poinsot polhode (tau0 |Omega0| = {eps:.2g}), separatrix crossings in "
                               f"full{phase}")
        except NoAverage:
            pass
    ratio = stiffness_ratio(body, model, omega0, problem)
    if ratio > STIFF_RATIO:
        return "radau", f"stiff: decay rate {ratio:.3g} x the spin rate; implicit Radau with the exact Jacobian"
    if turns > MAX_RESOLVED_TURNS and model != "free":
        choice = _handover_choice if body.is_symmetric else _handover_polhode_choice
        picked = choice(body, model, omega0, t_end, problem, eps, turns)
        if picked is not None:
            return picked
    stiff = (f"decay/spin = {ratio:.2g}: stiff for Runge-Kutta, not yet for Taylor's method (faster than radau "
             f"below {STIFF_RATIO:g}, measured)") if ratio > 10.0 else f"non-stiff (decay/spin = {ratio:.2g})"
    if rtol < get("taylor").rtol_floor:
        return "taylor-long", (f"{stiff}, ~{turns:.3g} turns resolved; rtol {rtol:.2g} is below what float64 holds: "
                               f"Taylor's method in long double")
    return "taylor", f"{stiff}, ~{turns:.3g} turns resolved by Taylor's method"


def _handover_choice(body, model: str, omega0, t_end: float, problem, eps: float, turns: float):
    """(``HANDOVER``, why) for a symmetric top not fast at the start (tau0 |Omega0| >
    ``EPS_MAX``) whose braking, as the averaged flow predicts it (``handover.plan``), brings
    tau0 |Omega| to ``EPS_MAX`` before t_end after at most ``HARD_MAX_TURNS`` turns in full;
    None otherwise (then it is resolved in full, within the usual limit)."""
    from .full_to_averaged import TARGET_MARGIN, predict, target_norm

    S = float(t_end) * eps / body.tau0
    t_h, turns_full = predict(problem.system, problem.omega0, TARGET_MARGIN * target_norm(problem), S)
    if not (math.isfinite(t_h) and turns_full <= HARD_MAX_TURNS):
        return None
    return HANDOVER, (f"~{turns:.3g} turns of a symmetric top whose spin is not fast at the start (tau0 |Omega0| = "
                      f"{eps:.2g} > {EPS_MAX:g}): Taylor's method in full, with quaternions, until braking brings "
                      f"tau0 |Omega| to {EPS_MAX:g} (predicted by the averaged flow after ~{turns_full:.3g} turns, at "
                      f"t ~ {t_h / eps * body.tau0:.3g}), then secular to t_end; the spin phase after the hand-over "
                      f"is not resolved")


def _handover_polhode_choice(body, model: str, omega0, t_end: float, problem, eps: float, turns: float):
    """(``HANDOVER_POLHODE``, why) for an asymmetric body not fast at the start (tau0 |Omega0| >
    ``EPS_MAX``) whose braking, as the averaged flow over the polhode predicts it
    (``polhode_plan.predict``), brings tau0 |Omega| to ``EPS_MAX`` before t_end after at most
    ``HARD_MAX_TURNS`` turns in full; None otherwise."""
    from .full_to_averaged import TARGET_MARGIN, target_norm
    from .polhode_plan import predict

    if not _has_polhode(problem):
        return None
    S = float(t_end) * eps / body.tau0
    t_h, turns_full = predict(problem.system, problem.omega0, TARGET_MARGIN * target_norm(problem), S)
    if not (math.isfinite(t_h) and turns_full <= HARD_MAX_TURNS):
        return None
    return HANDOVER_POLHODE, (f"~{turns:.3g} turns of an asymmetric body whose spin is not fast at the start "
                              f"(tau0 |Omega0| = {eps:.2g} > {EPS_MAX:g}): Taylor's method in full, with quaternions, "
                              f"until braking brings tau0 |Omega| to {EPS_MAX:g} (predicted by the averaged flow after "
                              f"~{turns_full:.3g} turns, at t ~ {t_h / eps * body.tau0:.3g}), then polhode to t_end; the "
                              f"spin phase after the hand-over is not resolved")
