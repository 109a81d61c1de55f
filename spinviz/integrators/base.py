"""The one interface every integrator implements, and the registry of them by name.

An integrator receives a ``Problem`` in *spin units*: the dimensionless system (4.1)
further scaled so that |omega(0)| = 1 (time in radians of initial spin, 1/|omega0| of
tau).  Then the free motion is O(1) whatever the body, and the radiation torque carries
the one small number of the problem, eps_rad = tau0 |Omega0| (1e-25 to 1e-16 for real
particles), folded into the coupling vector: |g|^2 = eps_rad.  See ``simulate``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..physics.models import System

KINEMATICS = ("quaternion", "euler_zxz", "none")


@dataclass(frozen=True)
class Problem:
    """An initial-value problem for the Euler equation with (optionally) orientation.

    system : the model, J = I/I1 and the scaled coupling g.
    omega0 : shape (3,), body-frame angular velocity at t_eval[0].
    q0 : shape (4,), (w, x, y, z), orientation at t_eval[0] (used when kinematics = "quaternion").
    euler0 : shape (3,), ZXZ (phi, theta, psi) rad at t_eval[0] (kinematics = "euler_zxz").
    t_eval : shape (N,), increasing output times; the run spans t_eval[0] .. t_eval[-1].
    kinematics : "quaternion" (q_dot = 1/2 q (x) (0, Omega)), "euler_zxz" (the Poisson
        equations (6.4), for comparison) or "none" (Euler equation only).
    """

    system: System
    omega0: np.ndarray
    t_eval: np.ndarray
    q0: np.ndarray | None = None
    euler0: np.ndarray | None = None
    kinematics: str = "quaternion"


@dataclass
class Solution:
    """Raw integrator output at ``Problem.t_eval``.

    omega : (N, 3); q : (N, 4) or None; euler : (N, 3) or None; stats : method, nfev,
    nsteps, and anything the method wants to report; success False with ``message`` when
    the method gave up (never a silently wrong array).  slow : for ``secular`` runs, the
    slow geometry (q_L: world z -> L_world, phi_L, theta_L, psi_L (N,), q_frame).
    status : ``status`` code of how the run ended (OK = 0).  reached : samples obtained before
    it ended (``len(t)`` on success; methods that keep partial output fill the rest with NaN).
    """

    t: np.ndarray
    omega: np.ndarray
    q: np.ndarray | None = None
    euler: np.ndarray | None = None
    success: bool = True
    message: str = ""
    stats: dict = field(default_factory=dict)
    slow: dict | None = None
    status: int = 0
    reached: int | None = None


@dataclass(frozen=True)
class Integrator:
    """A method behind the ``simulate`` driver.

    name : lower-case registry key; order : the declared order (None if adaptive-only);
    fixed_step : True when ``step`` (not rtol/atol) controls accuracy;
    solve(problem, rtol, atol, step) -> Solution;
    kinematics : the kinematics it supports; symmetric_only : needs I1 = I2; stiff : an
    implicit method; detects_stiffness : accepts ``stop_on_stiffness=True``;
    description : one line for ``spinviz methods`` and docs/integrators.md.
    rtol_floor : the tolerance below which its error stops following rtol (measured on the
    benchmark's askew bodies, ``spinviz bench``), or None (fixed step, or reported per run).
    compiled : runs the numba kernels, which know a model by its ``kernel_id``
    (``physics.models``): a model without one cannot use it.
    """

    name: str
    order: int | None
    fixed_step: bool
    solve: Callable[..., Solution]
    description: str
    kinematics: tuple[str, ...] = ("quaternion", "none")
    symmetric_only: bool = False
    stiff: bool = False
    detects_stiffness: bool = False
    rtol_floor: float | None = None
    compiled: bool = False


_REGISTRY: dict[str, Integrator] = {}


def register(integrator: Integrator) -> Integrator:
    """Add an integrator to the registry (name must be lower case and new)."""
    key = integrator.name
    if key != key.lower() or key in _REGISTRY:
        raise ValueError(f"integrator name {key!r} must be lower case and unique")
    _REGISTRY[key] = integrator
    return integrator


def get(name: str) -> Integrator:
    """The integrator registered as ``name`` (case-insensitive); a clear error otherwise."""
    key = str(name).lower()
    try:
        return _REGISTRY[key]
    except KeyError:
        raise ValueError(f"unknown method {name!r}; valid: auto, {', '.join(sorted(_REGISTRY))}") from None


def names() -> list[str]:
    """Registered method names, sorted."""
    return sorted(_REGISTRY)
