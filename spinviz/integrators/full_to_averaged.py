"""``auto``'s hand-over for a body whose spin is not yet fast: ``taylor -> secular`` (a
symmetric top) and ``taylor -> polhode`` (any other body; the same stages, with
``polhode.check_applicable`` as the test and ``polhode_plan.predict`` as the predictor).

``secular`` needs a fast spin, tau0 |Omega| <= ``secular.EPS_MAX`` (otherwise the radiation
changes the spin within a few turns and there is nothing to average over).  A top started
slower than that -- the paper's dimensionless |omega0| ~ 0.01 .. 0.1 -- brakes ((3.7): |Omega|
falls like 1/sqrt(t)), so tau0 |Omega(t)| falls through that bound after a few hundred to a few
thousand turns, while the horizon may hold 1e8 turns and more.  This composite integrates the
run in full with Taylor's method (quaternion kinematics, ``taylor.solve_taylor``) until
``secular``'s own applicability test (``secular.prepare``) passes on the current state, then
hands the state -- Omega (body frame) and the orientation q -- over to ``secular`` to t_end.
Neither integrator is changed: each stage is a ``Problem`` in its own spin units
(|omega| = 1 at the stage's start, ``scaling.spin_problem``).

Where the hand-over is: the full stage advances in chunks, each aimed (with 2 % to spare) at
where the averaged flow of ``physics.averaged`` ((4.12); the truncated counterpart) predicts
tau0 |Omega| = ``secular.EPS_MAX``; at each chunk's end ``secular.prepare`` is asked on the
state reached, and the run hands over at the first chunk end where it applies.  Since the
radiation only takes energy out, tau0 |Omega| does not come back above the bound (up to the
exchange between omega_perp and omega3 at fixed energy, a factor sqrt(I1/I3) at most), and
``secular`` itself decides, with its own mu, where along the rest the precession is fast
enough to average and where it stays in full.

What the run says (``Solution.stats``): ``handover_at`` (spin units; the driver converts),
``handover_eps_rad`` (tau0 |Omega| there), ``full_stage`` (taylor's steps, chunks, turns),
then ``secular``'s own statements for the rest; ``phases_resolved`` is False (after the
hand-over the spin phase, and so the orientation about the symmetry axis, is ``secular``'s
estimate, not a resolved phase; before it, q is Taylor's).  ``slow`` holds the slow geometry
over the whole grid, about the hand-over's L: q_L, and (N,) phi_L, theta_L, psi_L -- before the
hand-over the exact ZXZ angles of the resolved q about that fixed axis, after it
``secular``'s -- so resampling and rendering treat the run as a ``secular`` one.
"""

from __future__ import annotations

import math

import numpy as np

from .. import rotations as R
from .base import Problem, Solution
from .scaling import spin_problem

NAME = "taylor -> secular"
NAME_POLHODE = "taylor -> polhode"     # the same hand-over for any body, to ``polhode``
NAMES = (NAME, NAME_POLHODE)
TARGET_MARGIN = 0.98       # each chunk aims at 0.98 x the bound, so one chunk usually suffices
MAX_CHUNKS = 40            # chunk ends at which the test is asked; then the full stage runs to t_end
PREDICT_STEP = 0.05        # the predictor's step: ln wp and ln |w3| change by at most ~5 % a step
PREDICT_STEPS = 2000       # steps of the predictor: ln |w| falls by up to ~100 over them


def _flow_coefficients(system):
    """(P, Q, R, S) of the averaged flow (``physics.averaged``) of a spin-unit system of a
    symmetric top (J = (1, 1, J3), coupling g at the angle chi from e3), or None where there is
    none (the free top, a sphere: no precession to average over)."""
    averaged = system.spec.averaged
    if averaged is None:
        return None
    J = [float(x) for x in system.inertia]
    delta = 1.0 - J[2] / J[0]
    if abs(delta) < 1e-12:
        return None
    g = np.asarray(system.coupling, dtype=float)
    chi = math.atan2(math.hypot(g[0], g[1]), g[2])
    return averaged.coefficients(delta, chi)


def predict(system, omega, target: float, t_max: float) -> tuple[float, float]:
    """(time, turns) from the spin-unit state ``omega`` (3,) until |omega| <= ``target``
    (spin units), predicted by the averaged flow, d wp/dt = -eps wp (P wp^2 + Q w3^2),
    d w3/dt = -eps w3 (R wp^2 + S w3^2) ((4.12) and its truncated counterpart; eps = |g|^2),
    integrated by RK4 in ln wp, ln |w3| against sigma = int eps |w|^2 dt (the braking time),
    each step changing them by at most ``PREDICT_STEP`` times their share of |w|^2.
    (inf, turns to ``t_max``) when |omega| does not get there by ``t_max`` -- as for a dipole
    on the axis (chi = 0), where omega3 is not braked, or where the flow is not available (a sphere, the free top)."""
    w = np.asarray(omega, dtype=float)
    eps = float(np.dot(system.coupling, system.coupling))
    wp, w3 = math.hypot(w[0], w[1]), abs(float(w[2]))
    norm = math.hypot(wp, w3)
    if norm <= target:
        return 0.0, 0.0
    coef = _flow_coefficients(system)
    if coef is None or eps == 0.0:
        return math.inf, norm * t_max / (2.0 * math.pi)
    P, Q, Rc, S = coef
    tiny = 1e-300

    def f(x):                       # d/dsigma of (ln wp, ln w3, t, turns)
        a, b = math.exp(2.0 * x[0]), math.exp(2.0 * x[1])
        n2 = a + b
        return (-(P * a + Q * b) / n2, -(Rc * a + S * b) / n2, 1.0 / (eps * n2), 1.0 / (2.0 * math.pi * eps * math.sqrt(n2)))

    x = [math.log(max(wp, tiny)), math.log(max(w3, tiny)), 0.0, 0.0]
    for _ in range(PREDICT_STEPS):
        k1 = f(x)
        a, b = math.exp(2.0 * x[0]), math.exp(2.0 * x[1])
        # each component's log is held to PREDICT_STEP a step in proportion to its share of |w|^2
        # (a dying component falls as it likes: it no longer moves |w|)
        h = PREDICT_STEP * (a + b) / max(abs(k1[0]) * a, abs(k1[1]) * b, 1e-300)
        k2 = f([x[i] + 0.5 * h * k1[i] for i in range(4)])
        k3 = f([x[i] + 0.5 * h * k2[i] for i in range(4)])
        k4 = f([x[i] + h * k3[i] for i in range(4)])
        y = [x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) for i in range(4)]
        n_old, n_new = math.hypot(math.exp(x[0]), math.exp(x[1])), math.hypot(math.exp(y[0]), math.exp(y[1]))
        if n_new <= target:          # the crossing, by linear interpolation in ln |w|
            r = (math.log(n_old) - math.log(target)) / (math.log(n_old) - math.log(n_new))
            return x[2] + r * (y[2] - x[2]), x[3] + r * (y[3] - x[3])
        if y[2] >= t_max:
            r = (t_max - x[2]) / (y[2] - x[2])
            return math.inf, x[3] + r * (y[3] - x[3])
        x = y
    return math.inf, x[3] + (t_max - x[2]) * math.hypot(math.exp(x[0]), math.exp(x[1])) / (2.0 * math.pi)


def target_norm(problem: Problem) -> float:
    """|omega| (spin units of ``problem``) at which ``secular`` (and ``polhode``) applies: tau0 |Omega| =
    eps |omega| <= ``secular.EPS_MAX``."""
    from .secular import EPS_MAX

    eps = float(np.dot(problem.system.coupling, problem.system.coupling))
    return EPS_MAX / eps


def predictor(target: str):
    """The predictor of the hand-over to ``target``: ``predict`` ((4.12): symmetric tops) or
    ``polhode_plan.predict`` (the averaged flow of any body)."""
    if target == "polhode":
        from .polhode_plan import predict as predict_polhode

        return predict_polhode
    return predict


def plan(problem: Problem, target: str = "secular") -> tuple[float, float]:
    """(hand-over time, turns resolved in full before it), spin units, as the predictor sees them
    from the start of ``problem``: inf when the hand-over does not come by t_end."""
    t = np.asarray(problem.t_eval, dtype=float)
    return predictor(target)(problem.system, problem.omega0, TARGET_MARGIN * target_norm(problem), float(t[-1] - t[0]))


def _stage(problem: Problem, omega, q, t0: float, times):
    """A stage's problem in its own spin units from the state (omega (3,), q (4,) or None) at
    t0 (spin units of ``problem``), with output at t0 and ``times``; and the scale |omega|."""
    grid = np.concatenate([[t0], np.asarray(times, dtype=float)]) - t0
    sub, e = spin_problem(problem.system, omega, grid, q0=q, kinematics=problem.kinematics)
    return sub, e


def solve_handover(problem: Problem, rtol: float = 1e-10, atol: float = 1e-12, step: float | None = None,
                   target: str = "secular", taylor=None, secular=None) -> Solution:
    """Taylor's method in full until ``target`` ("secular": a symmetric top; "polhode": any
    body) applies, then ``target`` to t_end (module docstring).  ``problem`` in spin units,
    kinematics "quaternion" or "none"; ``step`` caps Taylor's steps.  A stage that fails fails
    the run, with its reason and the samples so far.  ``taylor(sub, e, rtol, atol, step,
    max_steps, stop_on_stiffness)`` and ``secular(sub, e, rtol, atol)`` run a stage's problem
    ``sub`` (spin units ``e`` times the run's): by default ``taylor.solve_taylor`` and the
    target's solver (a trap's run passes its own, ``integrators.environment``)."""
    from . import secular as SC

    t = np.asarray(problem.t_eval, dtype=float)
    full = _FullStage(problem, rtol, atol, step, target, taylor)
    failure = full.run()
    stats = {"full_stage": {"method": "taylor", "nsteps": full.steps, "chunks": full.chunks, "until": full.s},
             "nsteps": full.steps}
    if failure is not None:
        message, status, stage_stats = failure
        stats.update(stage_stats)
        return Solution(t=t, omega=full.omega, q=full.q_out, success=False, message=message, stats=stats,
                        status=status, reached=full.j)
    if full.handover is None:                        # no hand-over before t_end: resolved in full
        stats.update(handover_at=None, phases_resolved=True,
                     handover_note="tau0 |Omega| stayed above secular's bound: resolved in full")
        return Solution(t=t, omega=full.omega, q=full.q_out, stats=stats)
    sub, e = full.handover
    j, s = full.j, full.s
    if secular is not None:
        sol = secular(sub, e, rtol, atol)
    elif target == "polhode":
        from .polhode import solve_polhode

        sol = solve_polhode(sub, rtol, atol)
    else:
        sol = SC.solve_secular(sub, rtol, atol)
    if not sol.success:
        stats.update(handover_at=s)
        if "failed_at" in sol.stats:
            stats["failed_at"] = s + sol.stats["failed_at"] / e
        return Solution(t=t, omega=full.omega, q=full.q_out, success=False, stats=stats, status=sol.status or 1,
                        message=f"after the hand-over at t = {s:.4g} (spin units), {target}: {sol.message}", reached=j)
    full.omega[j:] = sol.omega[1:] * e
    if full.q_out is not None:
        full.q_out[j:] = sol.q[1:]
    sec = dict(sol.stats)
    if "segments" in sec:
        sec["segments"] = [[s + a / e, mode] for a, mode in sec["segments"]]
    if "resonances" in sec:
        sec["resonances"] = [[m, s + a / e, kick] for m, a, kick in sec["resonances"]]
    if sec.get("regime_5_from") is not None:
        sec["regime_5_from"] = s + sec["regime_5_from"] / e
    if "separatrix_crossings" in sec:
        sec["separatrix_crossings"] = [{**c, "t": s + c["t"] / e, "t_out": s + c["t_out"] / e}
                                       for c in sec["separatrix_crossings"]]
    stats.update(sec)
    stats.update(nsteps=full.steps + int(sec.get("nsteps", 0)), handover_at=s,
                 handover_eps_rad=float(np.dot(sub.system.coupling, sub.system.coupling)), phases_resolved=False)
    if target == "polhode":
        return Solution(t=t, omega=full.omega, q=full.q_out, stats=stats)
    q_full = None if full.q_out is None else full.q_out[:j]
    slow = _slow_series(sol.slow, q_full, full.q, full.omega[:j], problem)
    return Solution(t=t, omega=full.omega, q=full.q_out, stats=stats, slow=slow)


class _FullStage:
    """The full stage of ``solve_handover``: Taylor's method chunk by chunk, output filled in
    (``omega``, ``q_out``: the grid of ``problem``, NaN where not reached), until ``secular``
    applies (``handover``: its problem and scale) or t_end.  j: the next output index; s, w, q:
    the time (spin units of ``problem``) and state reached."""

    def __init__(self, problem: Problem, rtol: float, atol: float, step: float | None, target: str = "secular",
                 taylor=None):
        self.problem, self.rtol, self.atol, self.step = problem, rtol, atol, step
        self.target, self.taylor = target, taylor
        self.t = t = np.asarray(problem.t_eval, dtype=float)
        self.omega = np.full((t.size, 3), np.nan)
        self.w = self.omega[0] = np.asarray(problem.omega0, dtype=float)
        self.q_out = self.q = None
        if problem.kinematics == "quaternion":
            self.q_out = np.full((t.size, 4), np.nan)
            self.q = self.q_out[0] = R.normalize(problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0))
        self.j, self.s, self.steps, self.chunks = 1, float(t[0]), 0, 0
        self.handover = None

    def run(self):
        """Advance to the hand-over or t_end; None, or (message, status, stats) of a failure."""
        if self.target == "polhode":
            from .polhode import NotApplicable
            from .polhode import check_applicable as prepare
        else:
            from .secular import NotApplicable, prepare

        target = target_norm(self.problem)
        t_end = float(self.t[-1])
        ahead = predictor(self.target)
        while self.s < t_end:
            if self.chunks > 0 or float(np.linalg.norm(self.w)) <= target:
                sub, e = _stage(self.problem, self.w, self.q, self.s, self.t[self.j:])
                try:
                    prepare(sub)
                    self.handover = (sub, e)
                    return None
                except NotApplicable:
                    pass
            dt, _ = ahead(self.problem.system, self.w, TARGET_MARGIN * target, t_end - self.s)
            end = t_end if self.chunks >= MAX_CHUNKS or not math.isfinite(dt) else min(t_end, self.s + max(dt, 1.0))
            failure = self._chunk(end)
            if failure is not None:
                return failure
        return None

    def _chunk(self, end: float):
        """One Taylor run from (s, w, q) to ``end``, its samples stored."""
        from .taylor import MAX_STEPS, solve_taylor

        t, j, s = self.t, self.j, self.s
        k = int(np.searchsorted(t, end, side="right"))
        times = t[j:k] if k > j and t[k - 1] == end else np.concatenate([t[j:k], [end]])
        sub, e = _stage(self.problem, self.w, self.q, s, times)
        step = None if self.step is None else self.step * e
        if self.taylor is None:
            sol = solve_taylor(sub, self.rtol, self.atol, step, max_steps=max(1, MAX_STEPS - self.steps),
                               stop_on_stiffness=True)
        else:
            sol = self.taylor(sub, e, self.rtol, self.atol, step, max(1, MAX_STEPS - self.steps), True)
        self.steps += int(sol.stats.get("nsteps", 0))
        self.chunks += 1
        got = min(k - j, len(times) if sol.success else max(sol.reached - 1, 0))
        self.omega[j:j + got] = sol.omega[1:1 + got] * e
        if self.q_out is not None:
            self.q_out[j:j + got] = sol.q[1:1 + got]
        if not sol.success:
            self.j = j + got
            stage = {key: s + sol.stats[key] / e for key in ("stiff_at", "runaway_at") if key in sol.stats}
            if "runaway_omega" in sol.stats:
                stage["runaway_omega"] = (np.asarray(sol.stats["runaway_omega"]) * e).tolist()
            return f"the full stage (taylor): {sol.message}", sol.status, stage
        self.w = sol.omega[-1] * e
        if self.q is not None:
            self.q = R.normalize(sol.q[-1])
        self.j, self.s = k, end
        return None


def _slow_series(slow: dict, q_full, q_h, omega_full, problem: Problem) -> dict:
    """``secular``'s slow geometry extended over the full stage's samples: the ZXZ angles of
    the resolved q about the hand-over's fixed L, unwrapped and put on the same branch as
    ``secular``'s at the hand-over state q_h (where there is no q: theta from Omega, the
    phases NaN)."""
    q_L = np.asarray(slow["q_L"], dtype=float)
    per_sample = q_L.ndim == 2                  # L moves (a trap's run): the hand-over's L is its first row
    q_ref = q_L[0] if per_sample else q_L
    out = {"q_L": slow["q_L"], "q_frame": slow["q_frame"]}
    series = {name: np.asarray(slow[name], dtype=float) for name in ("phi_L", "theta_L", "psi_L")}
    if q_full is not None:
        conj = R.conjugate(q_ref)[None, :]
        ang = R.euler_zxz_from_quat(R.multiply(conj, np.concatenate([q_full, np.asarray(q_h)[None, :]])))
        for k, name in ((0, "phi_L"), (2, "psi_L")):
            a = np.unwrap(ang[:, k])
            ang[:, k] = a + 2.0 * np.pi * np.round((series[name][0] - a[-1]) / (2.0 * np.pi))
        ang = ang[:-1]
    else:
        J3 = float(problem.system.inertia[2]) / float(problem.system.inertia[0])
        w = omega_full
        nan = np.full(len(w), np.nan)
        ang = np.stack([nan, np.arctan2(np.hypot(w[:, 0], w[:, 1]), J3 * w[:, 2]), nan], axis=-1)
    for k, name in enumerate(("phi_L", "theta_L", "psi_L")):
        out[name] = np.concatenate([ang[:, k], series[name][1:]])
    if per_sample:
        out["q_L"] = np.concatenate([np.repeat(q_ref[None, :], ang.shape[0], axis=0), q_L[1:]])
    return out
