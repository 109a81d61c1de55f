"""Spin units: the problem every integrator sees.

The dimensionless variables (4.1) with time further scaled by |omega0| = tau0 |Omega0|, so
|omega(0)| = 1, the free motion is O(1), and the radiation torque carries the only small
number, eps_rad = tau0 |Omega0|, through the coupling |g|^2 = eps_rad.  A real cellulose rod
(tau0 = 1.4e-35 s) is then as well-conditioned as a dimensionless test problem.
"""

from __future__ import annotations

import math

import numpy as np

from .. import units as U
from ..errors import SpecError
from ..physics.models import System
from .base import Problem

# tau0 |Omega0|, the radiation torque relative to the spin: real particles have 1e-25 (rod) to
# 1e-16 (DAST cube).  Near 1 the reduction (2.3) that defines the model no longer holds
# (radiation stops the body within a turn), and beyond ~1e3 the run is hopelessly stiff; far
# below 1e-60 the torque's square root of it underflows in the spin-unit coupling.
EPS_RAD_RANGE = (1e-60, 1e3)


def check_scale(body, omega0) -> float:
    """eps_rad = tau0 |Omega0| after checking that the run is representable and in the
    model's range; ``SpecError`` with key "omega" (the spin) or "body" (tau0) otherwise."""
    w = np.asarray(omega0, dtype=float)
    if w.shape != (3,) or not np.all(np.isfinite(w)):
        raise SpecError("omega", "must be three finite numbers")
    tau0 = body.tau0
    if not (math.isfinite(tau0) and tau0 > 0.0):
        raise SpecError("body", f"tau0 = 2 d^2 / (3 I1 c^3) (3.8) = {tau0:g} s is not a usable number: the dipole "
                                f"({body.dipole_magnitude:g}) or the moments ({body.I1:g}) are beyond float64")
    big = float(np.max(np.abs(w)))
    if big == 0.0:
        raise SpecError("omega", "is zero: a body at rest stays at rest (no radiation, nothing to show)")
    eps = float(tau0 * big * np.linalg.norm(w / big))
    lo, hi = EPS_RAD_RANGE
    if not lo <= eps <= hi:
        why = ("the radiation torque would stop the body within a fraction of a turn: far outside the model's "
               "regime tau0 Omega << 1, and too stiff to integrate") if eps > hi else \
              "the radiation torque is below what float64 can carry through the run"
        raise SpecError("omega", f"tau0 |Omega0| = {eps:.3g} is outside [{lo:g}, {hi:g}]: {why}")
    return eps


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


def body_spin_problem(body, model: str, omega0, t_eval=(0.0, 1.0), q0=None, euler0=None,
                      kinematics: str = "quaternion"):
    """``spin_problem`` of a ``Body`` (CGS or dimensionless): omega0 in rad/s or 1/tau0,
    t_eval in s or tau0; units are converted here, once."""
    tau0 = body.tau0
    return spin_problem(body.system(model), U.omega_to_dimensionless(omega0, tau0),
                        U.time_to_dimensionless(t_eval, tau0), q0, euler0, kinematics)
