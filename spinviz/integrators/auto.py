"""``method = "auto"``: which integrator a run gets, and why (stored as stats["method_reason"])."""

from __future__ import annotations

import math

import numpy as np

from .scaling import body_spin_problem

MAX_RESOLVED_TURNS = 1e6     # beyond this, resolving every turn costs more than ~10 s
STIFF_RATIO = 10.0           # radiation decay rate / spin rate above which explicit steps are stability-bound


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
                  spin=None) -> tuple[str, str]:
    """The method ``method = "auto"`` picks, and why.

    * more than 1e6 turns of a symmetric top: ``secular`` (slow flow averaged over the
      precession; resolving each turn is neither affordable nor, past 1e16 turns,
      representable in float64);
    * stiff (decay rate > 10 x spin rate): ``radau`` with the exact Jacobian;
    * otherwise ``lie-dop853``; if it then detects stiffness, the driver switches to radau.

    ``spin``: (problem, eps_rad) from ``spin_problem`` if the caller already has them.
    """
    problem, eps = spin if spin is not None else body_spin_problem(body, model, omega0)
    turns = t_end * eps / body.tau0 / (2.0 * math.pi)
    if kinematics == "euler_zxz":
        return "dop853", "Euler-angle kinematics (6.4) is integrated by scipy methods only"
    if turns > MAX_RESOLVED_TURNS and body.is_symmetric:
        from .secular import NotApplicable, prepare

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
