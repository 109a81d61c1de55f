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
from . import units as U
from .integrators import Problem, get
from .physics.bodies import Body
from .physics.equations import System, truncated_singularity
from .trajectory import Trajectory


class SimulationError(RuntimeError):
    """An integrator gave up; the message says which and why (never a silent NaN array)."""


def spin_problem(system: System, omega0, t_eval, q0=None, euler0=None, kinematics: str = "quaternion"):
    """(Problem, eps_rad): a dimensionless problem (4.1) -- system with tau0 = 1, omega0 and
    t_eval in 1/tau0 and tau0 -- put in spin units, |omega(0)| = 1: time times eps_rad, the
    coupling times sqrt(eps_rad) (the torque is quadratic in it)."""
    omega0 = np.asarray(omega0, dtype=float)
    eps = float(np.linalg.norm(omega0)) or 1.0
    k = math.sqrt(eps)
    s = System(model=system.model, inertia=system.inertia, coupling=tuple(k * x for x in system.coupling))
    problem = Problem(system=s, omega0=omega0 / eps, t_eval=np.asarray(t_eval, dtype=float) * eps, q0=q0,
                      euler0=euler0, kinematics=kinematics)
    return problem, eps


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
    problem, eps = spin_problem(body.system(model), U.omega_to_dimensionless(omega0, tau0),
                                U.time_to_dimensionless(t_eval, tau0), q_init, euler_init, kinematics)
    if model == "truncated":
        _check_truncated_solvable(body, omega0)
    time_scale = eps / tau0                     # spin-unit time per unit of t
    method = str(method).lower()
    auto = method == "auto"
    if auto:
        method, reason = choose_method(body, model, omega0, float(t_eval[-1]), kinematics, spin=(problem, eps))
    else:
        reason = "chosen by the user"
    integrator = get(method)
    if kinematics not in integrator.kinematics:
        raise ValueError(f"method {integrator.name!r} does not support kinematics {kinematics!r}")
    if integrator.symmetric_only and not body.is_symmetric:
        raise ValueError(f"method {integrator.name!r} needs a symmetric top (I1 = I2)")
    kw = {"rtol": rtol, "atol": atol}
    if step is not None:
        kw["step"] = step * time_scale
    start = time.perf_counter()
    sol = integrator.solve(problem, **kw, **({"stop_on_stiffness": True} if auto and integrator.detects_stiffness else {}))
    if auto and not sol.success and not integrator.stiff and integrator.name != "secular":
        # the explicit method met stiffness the estimate from the initial state missed
        why = f"stiffness detected at t = {sol.stats['stiff_at'] / time_scale:.3g}" if "stiff_at" in sol.stats else sol.message
        integrator = get("radau")
        reason = f"{method} gave up ({why}); switched to radau (implicit, exact Jacobian)"
        sol = integrator.solve(problem, **kw)
    runtime = time.perf_counter() - start
    if not sol.success:
        raise SimulationError(f"{integrator.name}: {sol.message}")
    stats = dict(sol.stats)
    stats.update(method=integrator.name, method_reason=reason, runtime_s=runtime, eps_rad=eps, rtol=rtol, atol=atol)
    if step is not None:
        stats["step"] = step
    return Trajectory(
        t=t_eval,
        omega=U.omega_from_dimensionless(sol.omega * eps, tau0),
        q=sol.q,
        euler=sol.euler,
        body=body,
        model=model,
        stats=stats,
        slow=sol.slow,
    )


MAX_RESOLVED_TURNS = 1e6     # beyond this, resolving every turn costs more than ~10 s
STIFF_RATIO = 10.0           # radiation decay rate / spin rate above which explicit steps are stability-bound


def _check_truncated_solvable(body: Body, omega0) -> None:
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


def _spin_problem_at(body: Body, model: str, omega0):
    return spin_problem(body.system(model), U.omega_to_dimensionless(omega0, body.tau0), [0.0, 1.0])


def stiffness_ratio(body: Body, model: str, omega0, problem=None) -> float:
    """Fastest decay rate of the linearized Euler equation at omega0, per radian of spin.

    The free motion has purely imaginary eigenvalues (rotation); a large negative real part
    comes from the radiation torque -- |omega| ~ 1 or more in units of 1/tau0, or a thin
    body (eps = I3/I1 -> 0) with an askew dipole, where (4.4) divides by 1 - delta = eps.
    ``problem``: the spin-unit problem of (body, model, omega0) if already built.
    """
    problem = problem if problem is not None else _spin_problem_at(body, model, omega0)[0]
    lam = np.linalg.eigvals(problem.system.jacobian(problem.omega0))
    return float(max(0.0, -np.min(lam.real)))


def choose_method(body: Body, model: str, omega0, t_end: float, kinematics: str = "quaternion",
                  spin=None) -> tuple[str, str]:
    """The method ``method = "auto"`` picks, and why (stored as stats["method_reason"]).

    * more than 1e6 turns of a symmetric top: ``secular`` (slow flow averaged over the
      precession; resolving each turn is neither affordable nor, past 1e16 turns,
      representable in float64);
    * stiff (decay rate > 10 x spin rate): ``radau`` with the exact Jacobian;
    * otherwise ``lie-dop853``; if it then detects stiffness, the driver switches to radau.

    ``spin``: (problem, eps_rad) from ``spin_problem`` if the caller already has them.
    """
    problem, eps = spin if spin is not None else _spin_problem_at(body, model, omega0)
    turns = t_end * eps / body.tau0 / (2.0 * math.pi)
    if kinematics == "euler_zxz":
        return "dop853", "Euler-angle kinematics (6.4) is integrated by scipy methods only"
    if turns > MAX_RESOLVED_TURNS and body.is_symmetric:
        from .integrators.secular import NotApplicable, prepare

        try:
            prepare(problem)
            ulp = float(np.spacing(2.0 * math.pi * turns))
            phase = f"; the spin phase is beyond float64 (1 ulp = {ulp:.2g} rad)" if ulp > 1e-3 else ""
            return "secular", (f"{turns:.3g} turns of a symmetric top: averaged slow flow "
                               f"(relative error O(tau0 Omega) = {eps:.2g}){phase}")
        except NotApplicable:
            pass                                        # precession too slow to average (mu > MU_MAX)
    ratio = stiffness_ratio(body, model, omega0, problem)
    if ratio > STIFF_RATIO:
        return "radau", f"stiff: decay rate {ratio:.3g} x the spin rate; implicit Radau with the exact Jacobian"
    return "lie-dop853", f"non-stiff (decay/spin = {ratio:.2g}), {turns:.3g} turns resolved; |q| = 1 by construction"
