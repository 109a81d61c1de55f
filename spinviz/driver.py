"""The one driver: body + model + initial state -> frozen ``Trajectory``.

Units are converted once here (``integrators.scaling``): the integrators see *spin units*,
the dimensionless variables (4.1) with time further scaled so that |omega(0)| = 1.  The
method is chosen by name or by ``integrators.auto``; a run that fails raises
``SimulationError`` with one line saying why, never an array of NaN.
"""

from __future__ import annotations

import time

import numpy as np

from . import rotations as R
from . import units as U
from .errors import SimulationError
from .integrators import get
from .integrators.auto import HARD_MAX_TURNS, check_cost, choose_method, estimated_turns
from .integrators.scaling import body_spin_problem, check_scale
from .physics.bodies import Body
from .physics.equations import truncated_singularity
from .trajectory import Trajectory

__all__ = ["simulate", "SimulationError"]


def simulate(
    body: Body,
    model: str,
    omega0,
    *,
    t_end: float | None = None,
    samples: int | None = None,
    t_eval=None,
    q0=None,
    euler_zxz0=None,
    method: str = "auto",
    rtol: float = 1e-10,
    atol: float = 1e-12,
    step: float | None = None,
    kinematics: str = "quaternion",
) -> Trajectory:
    """Integrate the Euler equation of ``model`` with orientation; return a ``Trajectory``.

    body : Body -- its ``units`` decide the units of everything below.
    model : "reduced" (2.2)+(2.3), "truncated" (2.5) or "free".
    omega0 : shape (3,), body-frame angular velocity at t = 0 (rad/s or dimensionless).
    t_end, samples : output at ``samples`` instants evenly spaced over [0, t_end]; or
    t_eval : shape (N,), increasing output times from 0 (s or tau).
    q0 : shape (4,), (w, x, y, z), initial orientation; or euler_zxz0 : (phi, theta, psi) rad.
    method : a registered integrator name, or "auto".
    rtol, atol : tolerances for adaptive methods (atol in spin units, |omega(0)| = 1).
    step : step size for fixed-step methods, in units of t (s or tau).
    kinematics : "quaternion" (default), "euler_zxz" (the Poisson equations (6.4), for
    comparison; singular at theta = 0) or "none" (no orientation: Euler equation only).
    """
    omega0 = np.asarray(omega0, dtype=float)
    check_scale(body, omega0)
    t_eval = output_times(t_end, samples, t_eval)
    q_init, euler_init = initial_orientation(q0, euler_zxz0)
    problem, eps = body_spin_problem(body, model, omega0, t_eval, q_init, euler_init, kinematics)
    if model == "truncated":
        check_truncated_solvable(body, omega0)
    time_scale = eps / body.tau0                   # spin-unit time per unit of t
    method = str(method).lower()
    auto = method == "auto"
    horizon = float(t_eval[-1])
    if auto:
        method, reason = choose_method(body, model, omega0, horizon, kinematics, spin=(problem, eps))
    else:
        reason = "chosen by the user"
    check_cost(body, model, omega0, horizon, "auto" if auto else method, step, spin=(problem, eps),
               kinematics=kinematics, picked=method if auto else None)
    # a declining secular run can be handed to lie-dop853 when that one's cost check would pass
    resolvable = (auto and method == "secular"
                  and estimated_turns(body, model, omega0, horizon, (problem, eps)) <= HARD_MAX_TURNS)
    integrator = _integrator(method, body, kinematics)
    kw = {"rtol": rtol, "atol": atol}
    if step is not None:
        kw["step"] = step * time_scale
    start = time.perf_counter()
    sol, integrator, reason = _solve(integrator, problem, kw, auto, reason, time_scale, resolvable=resolvable)
    runtime = time.perf_counter() - start
    stats = _stats_in_units(sol.stats, time_scale)
    stats.update(method=integrator.name, method_reason=reason, runtime_s=runtime, eps_rad=eps, rtol=rtol, atol=atol)
    if step is not None:
        stats["step"] = step
    return Trajectory(t=t_eval, omega=U.omega_from_dimensionless(sol.omega * eps, body.tau0), q=sol.q,
                      euler=sol.euler, body=body, model=model, stats=stats, slow=sol.slow)


def _stats_in_units(stats: dict, time_scale: float) -> dict:
    """The integrator's stats with its times (spin units) in the trajectory's (s or tau0)."""
    out = dict(stats)
    for key in ("stiff_at", "runaway_at"):
        if key in out:
            out[key] = out[key] / time_scale
    if "segments" in out:
        out["segments"] = [[t / time_scale, mode] for t, mode in out["segments"]]
    if "resonances" in out:
        out["resonances"] = [[m, t / time_scale, kick] for m, t, kick in out["resonances"]]
    return out


def output_times(t_end=None, samples=None, t_eval=None) -> np.ndarray:
    """The output instants: ``t_eval`` as given, or ``samples`` evenly spaced over [0, t_end]."""
    if t_eval is None:
        if t_end is None or samples is None:
            raise ValueError("give t_end and samples, or t_eval")
        t_eval = np.linspace(0.0, float(t_end), int(samples))
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or t_eval.size < 2 or np.any(np.diff(t_eval) <= 0) or t_eval[0] != 0.0:
        raise ValueError("t_eval must be increasing, start at 0 and hold at least two instants")
    return t_eval


def initial_orientation(q0=None, euler_zxz0=None):
    """(q (w, x, y, z), ZXZ angles) of the start; identity when neither is given."""
    if euler_zxz0 is not None and q0 is not None:
        raise ValueError("give q0 or euler_zxz0, not both")
    if euler_zxz0 is None:
        q = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else R.normalize(q0)
        return q, R.euler_zxz_from_quat(q)
    euler = np.asarray(euler_zxz0, dtype=float)
    return R.quat_from_euler_zxz(euler), euler


def check_truncated_solvable(body: Body, omega0) -> None:
    """(2.5) is linear in Omega_dot with the factor J + g (g x Omega)^T, whose determinant is
    det J (1 + (g x Omega) . J^-1 g) (tau0 = 1).  It is 1 at rest and 1 + O(tau0 |Omega|) for
    any real particle.  Where it is <= 0 the state is cut off from rest by the singular
    surface, and runs started there fall into it (the stress case shows one), so say so
    instead of integrating."""
    s = body.system("truncated")
    den = truncated_singularity(*U.omega_to_dimensionless(omega0, body.tau0), s.inertia, s.coupling)
    if not den > 1e-12:
        raise SimulationError(
            f"the truncated equation (2.5) is singular at the initial state: 1 + (g x Omega).J^-1 g = {den:.3g} "
            f"(tau0 |Omega| ~ 1; it is 1 + O(tau0 |Omega|) for real particles)")


def _integrator(method: str, body: Body, kinematics: str):
    """The registered method, checked against the kinematics and the body it must serve."""
    integrator = get(method)
    if kinematics not in integrator.kinematics:
        raise ValueError(f"method {integrator.name!r} does not support kinematics {kinematics!r}")
    if integrator.symmetric_only and not body.is_symmetric:
        raise ValueError(f"method {integrator.name!r} needs a symmetric top (I1 = I2)")
    return integrator


def _solve(integrator, problem, kw, auto: bool, reason: str, time_scale: float, resolvable: bool = True):
    """Run the method; under ``auto`` an explicit method that meets stiffness the estimate
    from the initial state missed is replaced by radau, and a ``secular`` run that declines
    (a resonance, the oscillating regime) by lie-dop853 when ``resolvable`` (affordable).
    Returns (solution, integrator, reason)."""
    extra = {"stop_on_stiffness": True} if auto and integrator.detects_stiffness else {}
    sol = integrator.solve(problem, **kw, **extra)
    if auto and not sol.success and integrator.name == "secular" and resolvable:
        reason = f"{reason}; but {sol.message} -- so resolved in full by lie-dop853"
        integrator = get("lie-dop853")
        sol = integrator.solve(problem, **kw, stop_on_stiffness=True)
    if auto and not sol.success and not integrator.stiff and integrator.name != "secular" and "runaway_at" not in sol.stats:
        stiff_at = sol.stats.get("stiff_at")
        why = f"stiffness detected at t = {stiff_at / time_scale:.3g}" if stiff_at is not None else sol.message
        reason = f"{integrator.name} gave up ({why}); switched to radau (implicit, exact Jacobian)"
        integrator = get("radau")
        sol = integrator.solve(problem, **kw)
    if "runaway_at" in sol.stats:
        raise SimulationError(_runaway_message(problem, sol.stats, time_scale))
    if not sol.success:
        raise SimulationError(f"{integrator.name}: {sol.message}")
    _check_finite(sol, integrator.name, time_scale)
    return sol, integrator, reason


def _runaway_message(problem, stats, time_scale: float) -> str:
    """One line: what ran away, when, and when it would blow up (|omega| ~ 1/(t* - t) extrapolated
    from the rate at detection)."""
    s = problem.system
    eps = float(np.dot(s.coupling, s.coupling))
    w = np.asarray(stats["runaway_omega"], dtype=float)
    a = np.asarray(s.rate()(*w))
    growth = float(w @ a) / float(w @ w)            # d ln|omega| / dt
    t = stats["runaway_at"] / time_scale
    blow = f"; blow-up extrapolated at t = {(stats['runaway_at'] + 1.0 / growth) / time_scale:.4g}" if growth > 0 else ""
    return (f"the {s.model} solution runs away: tau0 |Omega| grew from {eps:.3g} to {eps * float(np.linalg.norm(w)):.3g} "
            f"by t = {t:.4g} (the reduction (2.3) assumes tau0 |Omega| << 1){blow}")


def _check_finite(sol, name: str, time_scale: float) -> None:
    """Never hand on a non-finite number: the first instant where one appears fails the run."""
    parts = [a for a in (sol.omega, sol.q, sol.euler) if a is not None]
    ok = np.all([np.all(np.isfinite(a), axis=1) for a in parts], axis=0)
    if not np.all(ok):
        i = int(np.argmin(ok))
        raise SimulationError(f"{name}: the solution left the finite numbers by t = {sol.t[i] / time_scale:.4g}")
