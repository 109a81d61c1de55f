"""The one driver: body + model + initial state -> frozen ``Trajectory``.

Units are converted once here.  The integrators see *spin units*: the dimensionless
variables (4.1) with time further scaled by |omega0| = tau0 |Omega0|, so |omega(0)| = 1,
the free motion is O(1), and the radiation torque carries the only small number,
eps_rad = tau0 |Omega0|, through the coupling |g|^2 = eps_rad.  A real cellulose rod
(tau0 = 1.4e-35 s) is then as well-conditioned as a dimensionless test problem.
"""

from __future__ import annotations

import math
import time

import numpy as np

from . import rotations as R
from .integrators import Problem, get
from .physics.bodies import Body
from .physics.equations import System
from .trajectory import Trajectory


class SimulationError(RuntimeError):
    """An integrator gave up; the message says which and why (never a silent NaN array)."""


def spin_scaling(body: Body, omega0) -> float:
    """eps_rad = tau0 |Omega0|: dimensionless spin, the ratio of braking to spin rate.

    Returns 1 for a body at rest (any scale will do)."""
    w = float(np.linalg.norm(np.asarray(omega0, dtype=float))) * body.tau0
    return w if w > 0.0 else 1.0


def spin_system(body: Body, model: str, eps_rad: float) -> System:
    """The body's system (4.1) in spin units: same J, coupling scaled by sqrt(eps_rad)."""
    s = body.system(model)
    k = math.sqrt(eps_rad)
    return System(model=s.model, inertia=s.inertia, coupling=tuple(k * x for x in s.coupling))


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
    if omega0.shape != (3,) or not np.all(np.isfinite(omega0)):
        raise ValueError(f"omega0 must be three finite numbers, got {omega0!r}")
    if t_eval is None:
        if t_end is None or samples is None:
            raise ValueError("give t_end and samples, or t_eval")
        t_eval = np.linspace(0.0, float(t_end), int(samples))
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or t_eval.size < 2 or np.any(np.diff(t_eval) <= 0) or t_eval[0] != 0.0:
        raise ValueError("t_eval must be increasing, start at 0 and hold at least two instants")

    if euler_zxz0 is not None and q0 is not None:
        raise ValueError("give q0 or euler_zxz0, not both")
    if euler_zxz0 is None:
        q_init = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else R.normalize(q0)
        euler_init = R.euler_zxz_from_quat(q_init)
    else:
        euler_init = np.asarray(euler_zxz0, dtype=float)
        q_init = R.quat_from_euler_zxz(euler_init)

    tau0 = body.tau0
    eps = spin_scaling(body, omega0)
    time_scale = eps / tau0                     # spin-unit time per unit of t
    system = spin_system(body, model, eps)
    integrator = get(choose_method(body, model, omega0) if method == "auto" else method)
    if kinematics not in integrator.kinematics:
        raise ValueError(f"method {integrator.name!r} does not support kinematics {kinematics!r}")
    if integrator.symmetric_only and not body.is_symmetric:
        raise ValueError(f"method {integrator.name!r} needs a symmetric top (I1 = I2)")
    problem = Problem(
        system=system,
        omega0=omega0 * tau0 / eps,
        t_eval=t_eval * time_scale,
        q0=q_init,
        euler0=euler_init,
        kinematics=kinematics,
    )
    kw = {"rtol": rtol, "atol": atol}
    if step is not None:
        kw["step"] = step * time_scale
    start = time.perf_counter()
    sol = integrator.solve(problem, **kw)
    runtime = time.perf_counter() - start
    if not sol.success:
        raise SimulationError(f"{integrator.name}: {sol.message}")
    stats = dict(sol.stats)
    stats.update(method=integrator.name, runtime_s=runtime, eps_rad=eps, rtol=rtol, atol=atol)
    if step is not None:
        stats["step"] = step
    return Trajectory(
        t=t_eval,
        omega=sol.omega * eps / tau0,
        q=sol.q,
        euler=sol.euler,
        body=body,
        model=model,
        stats=stats,
    )


def choose_method(body: Body, model: str, omega0) -> str:
    """The method ``method = "auto"`` picks (the Lie-group DOP853 until the stiffness logic lands)."""
    return "lie-dop853"
