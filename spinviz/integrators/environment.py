"""Which method carries a run in a trap, and what it costs: the driver's ``solve`` for a run
with an environment (``inputs.environment``: a residual gas, a static field).

* ``taylor`` and ``taylor-long``: the field in the equations, every collision applied at its
  instant (``taylor_env``); refused beyond ``MAX_COLLISIONS`` collisions (each restarts the
  integrator: ~0.4 ms with its candidates, measured on the spinning DAST cube);
* ``secular``: the slow flow with the gas's drift and diffusion and the field's precession,
  by chunks (``secular_env``); refused beyond ``secular_env.MAX_CHUNKS`` chunks;
* ``taylor -> secular`` (``auto``'s hand-over): both, one after the other;
* every other method (the Runge-Kutta and implicit methods, the splitting): refused with the
  reason -- they restart nowhere, so no collision can be applied, and their systems carry no
  field.

``auto`` picks as it does in vacuum (the radiation sets the turns), then this table applies.
"""

from __future__ import annotations

import math

import numpy as np

from .base import Problem, Solution
from .full_to_averaged import NAME as HANDOVER

CARRIERS = ("taylor", "taylor-long", "secular", HANDOVER)
MAX_COLLISIONS = 1_000_000     # collisions a full integration may apply (~0.4 ms each: about seven minutes)


def refusal(method: str) -> str | None:
    """Why ``method`` cannot carry an environment (None: it can)."""
    if method in CARRIERS or method == "auto":
        return None
    return (f"method {method!r} cannot carry the environment: the gas's collisions are impulses at random instants "
            f"and the field acts in the world frame, which only taylor, taylor-long and secular (and auto's hand-over "
            f"between them) carry")


def estimated_collisions(gas_model, omega0, horizon_s: float) -> float:
    """Collisions over ``horizon_s`` at the start's rate (an upper estimate: the rate falls as
    the body brakes), from the gas's quadrature at a few nodes."""
    return gas_model.rate(np.asarray(omega0, dtype=float), k=8) * float(horizon_s)


def estimated_chunks(gas_model, body, model: str, omega0, horizon_s: float, samples: int) -> float:
    """Chunks of ``secular_env`` over ``horizon_s``: the output instants, and the gas's and the
    radiation's relative braking at the start over ``secular_env.ETA`` each (an upper estimate
    while both brake: they slow down with the body)."""
    from .secular_env import ETA

    w = np.asarray(omega0, dtype=float)
    L = np.asarray(body.inertia, dtype=float) * w
    rate = 0.0
    if gas_model is not None:
        rate += float(np.linalg.norm(gas_model.torque(w, k=8))) / float(np.linalg.norm(L))
    system = body.system(model)
    from .. import units as U

    wd = U.omega_to_dimensionless(w, body.tau0)
    rad = np.asarray(system.radiation()(*wd), dtype=float)
    rate += float(np.linalg.norm(rad)) / max(float(np.linalg.norm(wd)), 1e-300) / body.tau0
    return samples + float(horizon_s) * rate / ETA


def solve_in_environment(problem: Problem, method: str, env, *, rtol: float, atol: float, step: float | None = None,
                         reason: str = "chosen by the user") -> tuple[Solution, str, str]:
    """Run ``method`` (a carrier; ``auto`` already resolved by the driver) on ``problem`` (spin
    units) in the environment ``env`` (``taylor_env.EnvRun``): (solution, method, why)."""
    from .secular_env import solve_secular_env
    from .taylor_env import solve_taylor_env

    why = refusal(method)
    if why is not None:
        raise ValueError(why)
    if method in ("taylor", "taylor-long"):
        precision = "long double" if method == "taylor-long" else "double"
        sol = solve_taylor_env(problem, env, rtol, atol, step, precision=precision)
        return sol, method, reason
    if method == "secular":
        return solve_secular_env(problem, env, rtol, atol), method, reason
    from .full_to_averaged import solve_handover

    def taylor_stage(sub, e, rtol, atol, step, max_steps, stop_on_stiffness):
        return solve_taylor_env(sub, env.rescaled(e), rtol, atol, step, max_steps=max_steps,
                                stop_on_stiffness=stop_on_stiffness)

    def secular_stage(sub, e, rtol, atol):
        return solve_secular_env(sub, env.rescaled(e), rtol, atol)

    sol = solve_handover(problem, rtol, atol, step, taylor=taylor_stage, secular=secular_stage)
    return sol, HANDOVER, reason


def field_precession(body, omega_body, field_cgs) -> float:
    """The rate (rad/s) at which a static field turns L about itself, averaged over the free
    motion: |d_par (e_ax . L_hat)| |E| / |L| (e_ax the symmetry axis, or d for a sphere; d_par the
    dipole along it); the speed of L's direction is that times sin(angle(L, E))."""
    w = np.asarray(omega_body, dtype=float)
    I = np.asarray(body.inertia, dtype=float)
    L = I * w
    d = np.asarray(body.dipole, dtype=float)
    axis = d / np.linalg.norm(d) if abs(body.delta) < 1e-12 else np.array([0.0, 0.0, 1.0])
    Ln = float(np.linalg.norm(L))
    return abs(float(d @ axis) * float(axis @ L) / Ln) * float(np.linalg.norm(field_cgs)) / Ln if Ln > 0 else math.inf
