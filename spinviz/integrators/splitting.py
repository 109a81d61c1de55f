"""Splitting integrators for symmetric tops: the exact torque-free flow composed with the
radiation torque, ``split2`` (Strang), ``split4`` (Yoshida), ``split6``, ``split8``
(Kahan-Li), fixed step.

The free flow (closed form: precession of Omega about e3 and rotation about L) is exact for
any step, so the step is set by how fast the *torque's effect* changes, not by the spin
period -- wherever the torque commutes with the free motion.  It does for a spherical top
whose torque is along L ((6.10)) and for rotation about a principal axis ((3.9)); then a
step of a fraction of the braking time T is enough whatever the number of turns.  Where the
torque has a component across L that turns with the body ((5.2) with orientation, askew
tops), a step longer than a turn samples that component at a few phases and the error
stops converging: the step must again resolve the spin.  ``spinviz bench`` measures both.

The radiation sub-flow uses the torque alone (no cancellation against the free part) and
the 8th-order Dormand-Prince formula (``tableaus.DP853``) in substeps of at most 1/50 of the local decay time.
"""

from __future__ import annotations

import numpy as np

from ..interrupt import call_stoppable
from ..physics import models as M
from . import status as ST
from . import tableaus as T
from .base import Integrator, Problem, Solution, register

RH_MAX = 0.02
MAX_STEPS = 200_000_000


def _args(problem: Problem):
    """The kernel's arguments: model id, J, g, omega0, q0, t_eval, whether q is integrated."""
    s = problem.system
    J = tuple(float(x) for x in s.inertia)
    g = tuple(float(x) for x in s.coupling)
    w0 = np.asarray(problem.omega0, dtype=float)
    q0 = np.asarray(problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0), dtype=float)
    t = np.asarray(problem.t_eval, dtype=float)
    return M.kernel_id(s.model, "split"), J, g, w0, q0, t, problem.kinematics == "quaternion"


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
        status=status,
        reached=len(w) if ok else 0,
    )


def _solver(order: int):
    gammas = T.COMPOSITIONS[order]

    def solve(problem: Problem, rtol=None, atol=None, step: float | None = None, max_steps: int = MAX_STEPS) -> Solution:
        if step is None or not step > 0:
            raise ValueError(f"method split{order} is fixed-step: give step > 0")
        if not problem.system.is_symmetric:
            raise ValueError(f"method split{order} needs a symmetric top (I1 = I2)")
        from . import kernels as KN

        model, J, g, w0, q0, t, with_q = _args(problem)
        w, q, nfev, nsteps, status = call_stoppable(KN.split_symmetric, model, J, g, w0, q0, t, float(step), gammas, with_q,
                                                        int(max_steps), RH_MAX, T.DP853.A, T.DP853.b)
        return _solution(problem, w, q, status, {"nfev": int(nfev), "nsteps": int(nsteps), "stages": len(gammas)})

    return solve


_NAMES = {2: "Strang", 4: "Yoshida triple jump", 6: "Kahan-Li s9", 8: "Kahan-Li s17"}
for _p in (2, 4, 6, 8):
    register(Integrator(
        name=f"split{_p}", order=_p, fixed_step=True, solve=_solver(_p), symmetric_only=True, compiled=True,
        description=f"exact free flow of the symmetric top composed with the radiation torque, {_NAMES[_p]} "
                    f"(order {_p}); compiled",
    ))
