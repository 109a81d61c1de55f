"""The one driver: body + model + initial state -> frozen ``Trajectory``; problems -> solutions.

Every run goes through here, single (``simulate``, ``solve``) or by the thousand (``solve_many``,
the atlas): the integrators see typed ``Problem`` objects in *spin units* (the dimensionless
variables (4.1) with time further scaled so that |omega(0)| = 1, see ``integrators.scaling``),
the method is chosen by name or by ``integrators.auto``, and the guards live here once:

* a truncated start on or near the singular surface of (2.5) is refused;
* a run that runs away (the reduction (2.3) breaking down) says when;
* nothing non-finite is handed on, and a run that fails raises ``SimulationError`` with one
  line (``simulate``) or keeps its samples so far and its reason (``solve_many``);
* a tolerance the method cannot honour is said, in the stats and on the command line
  (``accuracy_notes``), never silently returned as less.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from . import rotations as R
from . import units as U
from .errors import SimulationError, SpecTypeError, SpinvizError
from .inputs.simulation import SimulationRequest
from .integrators import Problem, Solution, get
from .integrators import status as ST
from .integrators.auto import HANDOVER, HANDOVERS, HARD_MAX_TURNS, choose_method, estimated_turns
from .integrators.scaling import body_spin_problem, spin_problem
from .physics.bodies import Body
from .physics.equations import truncated_singularity
from .physics.models import System
from .trajectory import Trajectory

__all__ = ["simulate", "simulate_request", "SimulationRequest", "solve", "solve_many", "SimulationError", "Run"]

ATOL_FROM_RTOL = 1e-2      # atol = rtol / 100 when not given: in spin units the state is O(1), so atol >= rtol would rule


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
    atol: float | None = None,
    step: float | None = None,
    kinematics: str = "quaternion",
    environment=None,
) -> Trajectory:
    """Integrate the Euler equation of ``model`` with orientation; return a ``Trajectory``.

    Parameters
    ----------
    body : Body
        Its ``units`` ("cgs" or "dimensionless") decide the units of everything below.
    model : {"reduced", "truncated", "free"}
        The reduced equation (2.2)+(2.3), the truncated one (2.5), or the torque-free top.
    omega0 : array_like, shape (3,)
        Body-frame angular velocity at t = 0, rad/s (CGS) or 1/tau0 (4.1).
    t_end : float, optional
        The horizon, s (CGS) or tau0: output at ``samples`` instants evenly spaced over
        [0, t_end].  Give either ``t_end`` and ``samples`` or ``t_eval``.
    samples : int, optional
        How many output instants (with ``t_end``).
    t_eval : array_like, shape (N,), optional
        Increasing output times from 0, s or tau0.
    q0 : array_like, shape (4,), optional
        Initial orientation as a quaternion (w, x, y, z), scalar first (normalized here), of
        O = R_world_from_body.  Give ``q0`` or ``euler_zxz0``; default the identity.
    euler_zxz0 : array_like, shape (3,), optional
        Initial orientation as ZXZ Euler angles (phi, theta, psi), rad.
    method : str
        A registered integrator name (``spinviz methods``), or "auto".
    rtol : float
        Relative tolerance of adaptive methods, in spin units (|omega(0)| = 1, |q| = 1: relative
        to the initial spin).
    atol : float, optional
        Absolute tolerance in the same units; default rtol / 100.
    step : float, optional
        Step of fixed-step methods, in units of t (s or tau0).
    kinematics : {"quaternion", "euler_zxz", "none"}
        "quaternion" (default); "euler_zxz", the Poisson equations (6.4), for comparison
        (singular at theta = 0); "none", no orientation (the Euler equation only).
    environment : spinviz.Environment or dict, optional
        The trap (``inputs.environment``): a residual gas (``pressure_mbar``, ``gas``, ...)
        whose collisions act at their random instants (reproduced by its ``seed``) and a
        static field ``field_v_per_m`` (world frame).  A CGS body with a surface; None (the
        default) or all zero is the perfect vacuum, bit for bit.

    Returns
    -------
    Trajectory
        t (N,), omega_body (N, 3) body frame and q (N, 4) (w, x, y, z) at the output
        instants, in the body's units, with ``stats`` (method, cost, run time, and the
        accuracy notes of a run that could not meet its tolerance).

    Raises
    ------
    SpecError
        A bad argument, named (``SpecTypeError``, also a TypeError, for a value of the wrong
        kind); the arguments are checked once, by ``spinviz.inputs.simulation.SimulationRequest``,
        shared with scenes and the command line.
    SimulationError
        The integration could not be done (an integrator gave up, a runaway, a singular start).
    """
    return simulate_request(SimulationRequest(
        body=body, model=model, omega0=omega0, t_end=t_end, samples=samples, t_eval=t_eval, q0=q0,
        euler_zxz0=euler_zxz0, method=method, rtol=rtol, atol=atol, step=step, kinematics=kinematics,
        environment=environment))


def simulate_request(request: SimulationRequest) -> Trajectory:
    """Run a validated ``SimulationRequest`` (``Scene.request(model)`` makes one for a scene):
    ``simulate`` with its arguments already checked; returns the ``Trajectory``."""
    if not isinstance(request, SimulationRequest):
        raise SpecTypeError("request", f"must be a SimulationRequest, got {type(request).__name__}")
    body, model, kinematics = request.body, request.model, request.kinematics
    omega0 = np.array(request.omega0)
    t_eval = request.times()
    rtol, atol, step = request.rtol, request.atol_or_default, request.step
    q_init, euler_init = initial_orientation(request.q0, request.euler_zxz0)
    problem, eps = body_spin_problem(body, model, omega0, t_eval, q_init, euler_init, kinematics)
    if model == "truncated":
        check_truncated_solvable(problem.system, problem.omega0)
    time_scale = eps / body.tau0                   # spin-unit time per unit of t
    method = request.method
    auto = method == "auto"
    horizon = float(t_eval[-1])
    if auto:
        method, reason = choose_method(body, model, omega0, horizon, kinematics, spin=(problem, eps), rtol=rtol)
    else:
        reason = "chosen by the user"
    # a declining secular run can be handed to a resolving method when its cost check would pass
    resolvable = (auto and method in ("secular", "polhode")
                  and estimated_turns(body, model, omega0, horizon, (problem, eps)) <= HARD_MAX_TURNS)
    if method not in HANDOVERS:
        _check_method(method, body, kinematics)
    start = time.perf_counter()
    env = request.environment if request.environment is not None and request.environment.active else None
    try:
        if env is not None:
            sol, name, reason = _solve_in_environment(problem, method, env, body, eps, rtol, atol,
                                                      None if step is None else step * time_scale, reason)
        else:
            sol, name, reason = solve(problem, method, rtol=rtol, atol=atol,
                                      step=None if step is None else step * time_scale, auto=auto, reason=reason,
                                      resolvable=resolvable)
    except SpinvizError:
        raise
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as e:
        # a numerical library giving up on the equations (e.g. (6.4) at sin theta = 0 under an
        # implicit method, whose Jacobian turns non-finite): a run that cannot be done, said as such
        raise SimulationError(f"the integration failed ({type(e).__name__}: {e}; method {request.method!r}"
                              f"{f', started as {method!r}' if auto else ''})") from e
    runtime = time.perf_counter() - start
    if not sol.success:
        raise SimulationError(_failure_message(problem, sol, name, time_scale))
    stats = _stats_in_units(sol.stats, time_scale)
    notes = accuracy_notes("taylor" if name in HANDOVERS else name, rtol, atol)
    stats.update(method=name, method_reason=reason, runtime_s=runtime, eps_rad=eps, rtol=rtol, atol=atol,
                 tolerance_met=not notes)
    if notes:
        stats["accuracy_notes"] = notes
    if step is not None:
        stats["step"] = step
    if env is not None:
        stats["environment"] = env.record()
    return Trajectory(t=t_eval, omega=U.omega_from_dimensionless(sol.omega * eps, body.tau0), q=sol.q,
                      euler=sol.euler, body=body, model=model, stats=stats, slow=sol.slow)


def _solve_in_environment(problem, method: str, env, body: Body, eps: float, rtol: float, atol: float, step, reason):
    """``solve`` for a run in a trap (``integrators.environment``): the environment in the
    integrators' terms -- CGS, the spin unit |Omega0| = eps / tau0 -- and its random stream
    from the environment's seed."""
    from .integrators.environment import solve_in_environment
    from .integrators.taylor_env import EnvRun

    gas = env.gas_model()
    surface = None
    if gas is not None:
        from .physics.surface import surface_of

        surface = surface_of(body)
    run = EnvRun(gas, surface, tuple(body.inertia), tuple(body.dipole), env.field_cgs(), eps / body.tau0,
                 np.random.default_rng(env.seed))
    sol, name, reason = solve_in_environment(problem, method, run, rtol=rtol, atol=atol, step=step, reason=reason)
    if sol.success:
        _check_finite(sol)
    return sol, name, reason


def accuracy_notes(method: str, rtol: float, atol: float) -> list[str]:
    """What the run cannot honour of (rtol, atol), one sentence each (empty when all is well).

    In spin units every state component is O(1), so the error is held to about max(rtol,
    atol): an atol above rtol limits it; and below a method's measured floor
    (``Integrator.rtol_floor``, ``spinviz bench``) its error stops following rtol."""
    m = get(method)
    out = []
    if m.fixed_step:
        return out
    if atol > rtol:
        out.append(f"atol = {atol:.2g} exceeds rtol = {rtol:.2g}: in spin units (|omega(0)| = 1) the state is O(1), "
                   f"so the error is held to ~{atol:.2g}, not {rtol:.2g}")
    floor = m.rtol_floor
    if floor is not None and rtol < floor:
        better = [n for n in ("taylor", "taylor-long") if n != method and get(n).rtol_floor < floor]
        hint = f" (method {better[0]!r} follows it to ~{get(better[0]).rtol_floor:.0e})" if better else ""
        out.append(f"{method} stops following the tolerance below rtol ~{floor:.0e} (measured on 400 turns of an askew "
                   f"body, spinviz bench): asked {rtol:.2g}{hint}")
    return out


def _stats_in_units(stats: dict, time_scale: float) -> dict:
    """The integrator's stats with its times (spin units) in the trajectory's (s or tau0)."""
    out = dict(stats)
    for key in ("stiff_at", "runaway_at", "handover_at", "regime_5_from", "failed_at"):
        if out.get(key) is not None:
            out[key] = out[key] / time_scale
    if "full_stage" in out:
        out["full_stage"] = {**out["full_stage"], "until": out["full_stage"]["until"] / time_scale}
    if "segments" in out:
        out["segments"] = [[t / time_scale, mode] for t, mode in out["segments"]]
    if "resonances" in out:
        out["resonances"] = [[m, t / time_scale, kick] for m, t, kick in out["resonances"]]
    if "separatrix_crossings" in out:
        out["separatrix_crossings"] = [{**c, "t": c["t"] / time_scale, "t_out": c["t_out"] / time_scale}
                                       for c in out["separatrix_crossings"]]
    return out


def initial_orientation(q0=None, euler_zxz0=None):
    """(q (w, x, y, z), ZXZ angles) of the start; identity when neither is given."""
    if euler_zxz0 is not None and q0 is not None:
        raise ValueError("give q0 or euler_zxz0, not both")
    if euler_zxz0 is None:
        q = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else R.normalize(q0)
        return q, R.euler_zxz_from_quat(q)
    euler = np.asarray(euler_zxz0, dtype=float)
    return R.quat_from_euler_zxz(euler), euler


def truncated_margin(system: System, omega_body) -> float:
    """1 + (g x omega).J^-1 g at the body-frame state ``omega_body`` (3,) of the dimensionless
    (tau0 = 1) or spin-unit system: (2.5) is
    linear in Omega_dot with the factor J + g (g x Omega)^T, whose determinant is det J times
    this.  1 at rest and 1 + O(tau0 |Omega|) for any real particle."""
    w = np.asarray(omega_body, dtype=float)
    return float(truncated_singularity(w[0], w[1], w[2], system.inertia, system.coupling))


def check_truncated_solvable(system: System, omega_body, margin: float = 1e-12) -> None:
    """Refuse a truncated start where ``truncated_margin`` <= ``margin``: such a state is cut
    off from rest by the singular surface, and runs started there fall into it (the stress
    case shows one)."""
    den = truncated_margin(system, omega_body)
    if not den > margin:
        raise SimulationError(
            f"the truncated equation (2.5) is singular at the initial state: 1 + (g x Omega).J^-1 g = {den:.3g} "
            f"(tau0 |Omega| ~ 1; it is 1 + O(tau0 |Omega|) for real particles)")


def _check_method(method: str, body: Body, kinematics: str):
    """The registered method, checked against the kinematics and the body it must serve."""
    integrator = get(method)
    if kinematics not in integrator.kinematics:
        raise ValueError(f"method {integrator.name!r} does not support kinematics {kinematics!r}")
    if integrator.symmetric_only and not body.is_symmetric:
        raise ValueError(f"method {integrator.name!r} needs a symmetric top (I1 = I2)")
    return integrator


def solve(problem: Problem, method: str, *, rtol: float, atol: float, step: float | None = None, auto: bool = False,
          reason: str = "chosen by the user", resolvable: bool = True) -> tuple[Solution, str, str]:
    """Run ``method`` on ``problem`` (spin units) and return (solution, method used, why).

    Under ``auto``: a ``secular`` or ``polhode`` run that declines (a resonance, the oscillating regime, a
    stretch in full it cannot afford) is
    resolved in full by ``taylor`` when ``resolvable`` (affordable), and an explicit method
    that meets stiffness the estimate from the initial state missed is replaced by radau;
    ``taylor -> secular`` (``integrators.full_to_averaged``) runs as one method.
    The solution is checked for non-finite values; ``success`` False keeps its samples so far."""
    kw = {"rtol": rtol, "atol": atol}
    if step is not None:
        kw["step"] = step
    if method in HANDOVERS:
        from .integrators.full_to_averaged import solve_handover

        sol = solve_handover(problem, **kw, target="secular" if method == HANDOVER else "polhode")
        if sol.success:
            _check_finite(sol)
        return sol, method, reason
    integrator = get(method)
    extra = {"stop_on_stiffness": True} if auto and integrator.detects_stiffness else {}
    sol = integrator.solve(problem, **kw, **extra)
    if auto and not sol.success and integrator.name in ("secular", "polhode") and resolvable:
        reason = f"{reason}; but {sol.message} -- so resolved in full by taylor"
        integrator = get("taylor")
        sol = integrator.solve(problem, **kw, stop_on_stiffness=True)
    if (auto and not sol.success and not integrator.stiff and integrator.name not in ("secular", "polhode")
            and "runaway_at" not in sol.stats):
        stiff_at = sol.stats.get("stiff_at")
        why = f"stiffness detected at t = {stiff_at:.3g} (spin units)" if stiff_at is not None else sol.message
        reason = f"{integrator.name} gave up ({why}); switched to radau (implicit, exact Jacobian)"
        integrator = get("radau")
        sol = integrator.solve(problem, **kw)
    if sol.success:
        _check_finite(sol)
    return sol, integrator.name, reason


def _failure_message(problem: Problem, sol: Solution, name: str, time_scale: float) -> str:
    """One line: why a run failed, and when: where the integrator stopped (``failed_at``, with
    the hand-over's instant for ``taylor -> secular``), else the last output instant it reached."""
    if "runaway_at" in sol.stats:
        return _runaway_message(problem, sol.stats, time_scale)
    at = sol.stats.get("failed_at")
    if at is not None:
        handed = sol.stats.get("handover_at")
        tail = f"; handed over at t = {handed / time_scale:.4g}" if handed is not None else ""
        return f"{name}: {sol.message} (at t = {at / time_scale:.4g}{tail})"
    if sol.reached is not None and 0 < sol.reached < len(sol.t):
        return f"{name}: {sol.message} (by t = {sol.t[sol.reached - 1] / time_scale:.4g})"
    return f"{name}: {sol.message}"


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


def _check_finite(sol: Solution) -> None:
    """Never hand on a non-finite number: the first instant where one appears fails the run
    (its samples before stay, ``reached`` says how many)."""
    parts = [a for a in (sol.omega, sol.q, sol.euler) if a is not None]
    ok = np.all([np.all(np.isfinite(a), axis=1) for a in parts], axis=0)
    if not np.all(ok):
        i = int(np.argmin(ok))
        sol.success, sol.status, sol.reached = False, ST.NOT_FINITE, i
        sol.message = ST.MESSAGES[ST.NOT_FINITE]


# --- many runs at once: the atlas ------------------------------------------------------------
@dataclass
class Run:
    """One run of ``solve_many``, in the dimensionless units (4.1) of its request.

    tau : (N,) the output grid; omega (``omega_body``) : (N, 3) body frame, NaN after ``reached`` samples;
    status : how it ended (``integrators.status``; OK = 0); reason : one line when not OK;
    t_stop : where it stopped (tau); nsteps : integrator steps (a batch's, for batched runs);
    seconds : wall time of its share of the work.
    """

    tau: np.ndarray
    omega: np.ndarray
    status: int
    reached: int
    t_stop: float
    nsteps: int
    seconds: float
    reason: str = ""

    @property
    def omega_body(self) -> np.ndarray:
        """Body-frame omega, shape (N, 3), 1/tau0: the documented name of the field ``omega``."""
        return self.omega


SINGULAR_START = ST.SINGULAR_START


def solve_many(model: str, inertia: list, coupling: list, omega0: list, tau, *, method: str = "taylor",
               rtol: float = 1e-8, max_steps: int = 20_000_000, residual_eta=None, singular_margin: float = 1e-12,
               stop=None) -> list[Run]:
    """Euler-only runs (no orientation) of one model, dimensionless (4.1): run i has inertia
    J_i = (1, J2, J3), unit coupling g_i and start omega0_i, all on the output grid ``tau``
    (starting at 0).  The runs go to the integrator in spin units, in batches where it has a
    batch mode (``taylor``: heyoka's SIMD batches), one by one otherwise.

    residual_eta : per run, eta > 0 stops it at the residual rotation |d x omega| < eta |d|
        |omega| (callers pass it where the paper proves that rotation is the end state).
    singular_margin : a truncated start with ``truncated_margin`` below this is not run
        (status ``SINGULAR_START``).
    A failed run keeps its samples so far; none raises (an interrupt does, ``InterruptedError``).
    """
    tau = np.asarray(tau, dtype=float)
    n = len(omega0)
    eta = np.zeros(n) if residual_eta is None else np.asarray(residual_eta, dtype=float)
    runs: list[Run | None] = [None] * n
    todo = []
    for i in range(n):
        system = System(model, tuple(map(float, inertia[i])), tuple(map(float, coupling[i])))
        w0 = np.asarray(omega0[i], dtype=float)
        if model == "truncated" and not truncated_margin(system, w0) >= singular_margin:
            runs[i] = _singular_run(tau, w0, truncated_margin(system, w0), singular_margin)
            continue
        prob, eps = spin_problem(system, w0, tau, kinematics="none")
        todo.append((i, prob, eps))
    if not todo:
        return runs
    t0 = time.perf_counter()
    probs = [p for _, p, _ in todo]
    if method == "taylor" and model != "free" and all(_atlas_body(p.system) for p in probs):
        from .integrators.taylor import solve_batch

        results = [(r.omega, r.status, r.reached, r.t_stop, r.nsteps)
                   for r in solve_batch(probs, rtol, max_steps, eta[[i for i, _, _ in todo]], stop)]
    else:
        results = [_one_by_one(p, method, rtol, max_steps) for p in probs]
    share = (time.perf_counter() - t0) / len(todo)
    for (i, _, eps), (w, st, reached, t_stop, nsteps) in zip(todo, results):
        runs[i] = Run(tau, w * eps, int(st), int(reached), t_stop / eps, int(nsteps), share,
                      _reason(st, tau, reached, t_stop / eps))
    return runs


def _atlas_body(s: System) -> bool:
    """A symmetric top in the atlas's frame, J = (1, 1, 1 - delta), g = (n1, 0, n3): the
    batch integrator's symmetric form (4.2)-(4.4) applies."""
    return s.inertia[0] == 1.0 and s.inertia[1] == 1.0 and s.coupling[1] == 0.0


def _one_by_one(problem: Problem, method: str, rtol: float, max_steps: int):
    sol = get(method).solve(problem, rtol=rtol, atol=rtol * ATOL_FROM_RTOL)
    reached = len(sol.t) if sol.success else int(sol.reached or 0)
    w = np.array(sol.omega, dtype=float)
    w[reached:] = np.nan
    t_stop = float(sol.stats.get("runaway_at", sol.stats.get("stiff_at", sol.t[max(reached - 1, 0)])))
    return w, (ST.OK if sol.success else (sol.status or ST.NOT_FINITE)), reached, t_stop, int(sol.stats.get("nsteps", 0))


def _singular_run(tau, w0, margin: float, limit: float) -> Run:
    w = np.full((len(tau), 3), np.nan)
    w[0] = w0
    return Run(tau, w, SINGULAR_START, 1, 0.0, 0, 0.0,
               f"truncated (2.5) near-singular at the start: 1 + (g x omega).J^-1 g = {margin:.3g} < {limit:g}; "
               f"use a smaller |omega(0)|")


def _reason(status: int, tau, reached: int, t_stop: float) -> str:
    if status == ST.OK:
        return ""
    what = ST.MESSAGES.get(status, f"status {status}")
    if status == ST.STOPPED_RESIDUAL:
        return f"residual rotation about d reached by tau = {t_stop:.3g} (exact end state)"
    last = float(tau[max(reached - 1, 0)])
    return f"{what} at tau = {t_stop:.3g} (samples kept up to tau = {last:.3g})" if math.isfinite(t_stop) else what
