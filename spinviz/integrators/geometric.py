"""Lie-group (exponential-map) integrators: |q| = 1 by construction.

* ``lie-dop853`` -- adaptive, DOP853 error control and dense output on (Omega, u); the
  default method.
* ``lie-rk4``, ``lie-rk8`` -- fixed step, classic RK4 and the 8th-order DOP853 formula.

See ``kernels`` for the formulation (Munthe-Kaas RK with the exact SO(3) dexp^-1).
"""

from __future__ import annotations

import numpy as np

from ..interrupt import call_stoppable
from . import status as ST
from . import tableaus as T
from .base import Integrator, Problem, Solution, register

MAX_STEPS = 200_000_000


def _args(problem: Problem):
    s = problem.system
    J = tuple(float(x) for x in s.inertia)
    g = tuple(float(x) for x in s.coupling)
    w0 = np.asarray(problem.omega0, dtype=float)
    q0 = np.asarray(problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0), dtype=float)
    t = np.asarray(problem.t_eval, dtype=float)
    return ST.MODEL_ID[s.model], J, g, w0, q0, t, problem.kinematics == "quaternion"


def _solution(problem, w, q, status, stats):
    ok = status == ST.OK
    with_q = problem.kinematics == "quaternion"
    return Solution(
        t=np.asarray(problem.t_eval, dtype=float),
        omega=w if ok else np.full_like(w, np.nan),
        q=(q if ok else np.full_like(q, np.nan)) if with_q else None,
        success=ok,
        message="" if ok else ST.MESSAGES.get(status, f"status {status}"),
        stats=stats,
    )


def solve_lie_dop853(problem: Problem, rtol: float = 1e-10, atol: float = 1e-12, step: float | None = None,
                     max_steps: int = MAX_STEPS, stop_on_stiffness: bool = False) -> Solution:
    """Adaptive Lie-group DOP853; ``step`` caps the step size; with ``stop_on_stiffness``
    it gives up as soon as it detects stiffness (the driver then switches to radau)."""
    from . import kernels as KN  # numba compiles (or loads from cache) on first use only

    model, J, g, w0, q0, t, with_q = _args(problem)
    h_max = float(step) if step else np.inf
    w_max = ST.runaway_bound(float(np.dot(g, g)))
    w, q, nfev, nsteps, nrej, status, t_event = call_stoppable(
        KN.lie_dop853, model, J, g, w0, q0, t, float(rtol), float(atol), h_max, with_q, int(max_steps),
        bool(stop_on_stiffness), w_max, *KN.DOP853_ARRAYS)
    stats = {"nfev": int(nfev), "nsteps": int(nsteps), "nrejected": int(nrej)}
    if status == ST.RUNAWAY:
        stats.update(runaway_at=float(t_event), runaway_omega=w[-1].tolist())
    elif t_event >= 0.0:
        stats["stiff_at"] = float(t_event)
    return _solution(problem, w, q, status, stats)


def _fixed(tableau: T.Tableau):
    def solve(problem: Problem, rtol: float | None = None, atol: float | None = None, step: float | None = None,
              max_steps: int = MAX_STEPS) -> Solution:
        if step is None or not step > 0:
            raise ValueError(f"method lie-{tableau.name} is fixed-step: give step > 0")
        from . import kernels as KN

        model, J, g, w0, q0, t, with_q = _args(problem)
        w, q, nfev, nsteps, status = call_stoppable(
            KN.lie_fixed, model, J, g, w0, q0, t, float(step), tableau.A, tableau.b, with_q, int(max_steps))
        return _solution(problem, w, q, status, {"nfev": int(nfev), "nsteps": int(nsteps)})

    return solve


register(Integrator(
    name="lie-dop853", order=8, fixed_step=False, solve=solve_lie_dop853, detects_stiffness=True,
    description="Lie-group DOP853 (RKMK, exact SO(3) dexp^-1), adaptive with dense output; |q| = 1 by construction; "
                "compiled; the default",
))
register(Integrator(
    name="lie-rk4", order=4, fixed_step=True, solve=_fixed(T.RK4),
    description="Lie-group classic RK4, fixed step; |q| = 1 by construction; compiled",
))
register(Integrator(
    name="lie-rk8", order=8, fixed_step=True, solve=_fixed(T.DOP853),
    description="Lie-group 8th-order Dormand-Prince formula, fixed step; |q| = 1 by construction; compiled",
))
