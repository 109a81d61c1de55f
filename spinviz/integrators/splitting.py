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
the 8th-order DOP853 formula in substeps of at most 1/50 of the local decay time.
"""

from __future__ import annotations

from ..interrupt import call_stoppable
from . import tableaus as T
from .base import Integrator, Problem, Solution, register
from .geometric import MAX_STEPS, _args, _solution

RH_MAX = 0.02


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
                                                        int(max_steps), RH_MAX, T.DOP853.A, T.DOP853.b)
        return _solution(problem, w, q, status, {"nfev": int(nfev), "nsteps": int(nsteps), "stages": len(gammas)})

    return solve


_NAMES = {2: "Strang", 4: "Yoshida triple jump", 6: "Kahan-Li s9", 8: "Kahan-Li s17"}
for _p in (2, 4, 6, 8):
    register(Integrator(
        name=f"split{_p}", order=_p, fixed_step=True, solve=_solver(_p), symmetric_only=True,
        description=f"exact free flow of the symmetric top composed with the radiation torque, {_NAMES[_p]} "
                    f"(order {_p}); compiled",
    ))
