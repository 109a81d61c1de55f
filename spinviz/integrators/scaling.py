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
from ..physics.equations import System
from .base import Problem


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
