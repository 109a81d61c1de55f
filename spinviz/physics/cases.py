"""The paper's reference problems, each defined once with its exact solution and its source.

A ``Case`` is a dimensionless problem (tau0 = 1): a body, a model, the initial angular
velocity and orientation, a horizon, and the closed forms it must follow.  ``spinviz check``,
``spinviz bench``, ``spinviz stress`` and the tests all build their runs from here.

* ``eq6_10`` -- truncated equation, spherical top (the DAST cube of section 6.2), d along
  e3: Omega is (6.9) and the orientation (6.10), both exact.
* ``eq3_9`` -- either model, askew top (delta = -0.6, chi = 55 deg: the DAST family-1 box),
  rotation about e2: (3.9) exact (Omega1 = Omega3 = 0); an unstable solution (section 4.3).
* ``longitudinal`` -- chi = 0: (5.2) (reduced) or (5.4) (truncated), Omega exact.

``*_turns`` variants pick the spin so that the body turns a given number of times over the
horizon (the benchmark's horizons 1e2 ... 1e6 turns).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import rotations as R
from . import closed_forms as CF
from .bodies import Body, symmetric_top

CHI_FAMILY1 = math.radians(55.0)       # DAST family 1: d at 55 deg from the symmetry axis (section 6.2)


@dataclass(frozen=True)
class Case:
    """One reference problem; times and rates in tau0 units (4.1).

    omega_exact(t) -> (N, 3) body-frame Omega, or None; euler_exact(t) -> (N, 3) ZXZ angles
    (rad) or q_exact(t) -> (N, 4) (w, x, y, z) when the paper gives the orientation in closed
    form (``orientation_exact`` gives q in either case).
    """

    equation: str
    description: str
    source: str
    body: Body
    model: str
    omega0: np.ndarray
    euler0: tuple[float, float, float]
    t_end: float
    omega_exact: Callable[[np.ndarray], np.ndarray] | None = None
    q_exact: Callable[[np.ndarray], np.ndarray] | None = None
    euler_exact: Callable[[np.ndarray], np.ndarray] | None = None

    def orientation_exact(self, t) -> np.ndarray | None:
        """The exact orientation at times t, (N, 4) (w, x, y, z), or None."""
        if self.q_exact is not None:
            return self.q_exact(t)
        if self.euler_exact is not None:
            return R.quat_from_euler_zxz(self.euler_exact(t))
        return None

    @property
    def q0(self) -> np.ndarray:
        """Initial orientation, (w, x, y, z)."""
        return R.quat_from_euler_zxz(self.euler0)

    def run_kwargs(self, samples: int | None = None, t_eval=None) -> dict:
        """Keyword arguments for ``spinviz.simulate(case.body, case.model, **kw)``."""
        times = {"t_eval": t_eval} if t_eval is not None else {"t_end": self.t_end, "samples": samples or 401}
        return {"omega0": np.array(self.omega0), "euler_zxz0": self.euler0, **times}


def eq6_10(omega20: float = 0.1, omega30: float | None = None, periods_T: float = 3.0) -> Case:
    """(6.9)/(6.10): start phi = psi = 0, theta = arctan|Omega20/Omega30|, Omega(0) = (0, Omega20,
    Omega30), over ``periods_T`` T (T = 1/Omega20^2)."""
    w2 = float(omega20)
    w3 = w2 if omega30 is None else float(omega30)
    theta = math.atan(abs(w2 / w3)) if w3 != 0.0 else 0.5 * math.pi
    return Case("6.10", "truncated, DAST cube (spherical top, d along e3): Omega (6.9), orientation (6.10) exact",
                "section 6.2, (6.9) and (6.10)", symmetric_top(0.0, 0.0), "truncated", np.array([0.0, w2, w3]),
                (0.0, theta, 0.0), periods_T / w2**2,
                omega_exact=lambda t: CF.omega_eq6_9(t, 1.0, w2, w3),
                euler_exact=lambda t: CF.euler_eq6_10(t, 1.0, w2, w3))


def eq6_10_turns(turns: float, periods_T: float = 3.0) -> Case:
    """(6.10) with Omega20 = Omega30 chosen so that the body turns ``turns`` times over 3 T:
    phi(3 T) = 2 (sqrt 7 - 1) / w for Omega20 = Omega30 = w / sqrt 2."""
    w = 2.0 * (math.sqrt(1.0 + 2.0 * periods_T) - 1.0) / (2.0 * math.pi * turns)
    return eq6_10(w / math.sqrt(2.0), periods_T=periods_T)


def eq3_9(model: str, omega20: float = 0.1, delta: float = -0.6, chi: float = CHI_FAMILY1,
          periods_T: float = 3.0) -> Case:
    """(3.9): rotation about e2 (Omega1 = Omega3 = 0) of an askew top, exact for both models;
    the orientation turns about e2 by Omega20 vartheta(t)."""
    w = float(omega20)
    return Case("3.9", f"{model}, askew top delta={delta:g} chi={math.degrees(chi):.0f}deg: rotation about e2",
                "section 3, (3.7)-(3.9)", symmetric_top(delta, chi), model, np.array([0.0, w, 0.0]), (0.0, 0.0, 0.0),
                periods_T / w**2,
                omega_exact=lambda t: CF.omega_eq3_9(t, 1.0, w),
                q_exact=lambda t: R.quat_from_axis_angle((0.0, 1.0, 0.0), CF.rotation_angle_eq3_9(t, 1.0, w)))


def eq3_9_turns(turns: float, model: str = "reduced", periods_T: float = 3.0) -> Case:
    """(3.9) with Omega20 chosen so that the body turns ``turns`` times over 3 T:
    the angle at 3 T is (sqrt 7 - 1) / w."""
    w = (math.sqrt(1.0 + 2.0 * periods_T) - 1.0) / (2.0 * math.pi * turns)
    return eq3_9(model, w, periods_T=periods_T)


def longitudinal(model: str, delta: float = 0.3, omega20: float = 0.1, omega30: float = 0.3,
                 periods: float = 5.0, euler0=(0.0, 0.0, 0.0)) -> Case:
    """(5.2) (reduced) over ``periods`` Theta = 1/(eps omega3)^2, or (5.4) (truncated) over
    ``periods`` T = 1/omega20^2: chi = 0, omega10 = 0, Omega exact."""
    eps = 1.0 - delta
    if model == "reduced":
        eq, form, t_end = "5.2", CF.omega_eq5_2, periods / (eps * omega30) ** 2
        what = "residual rotation about d"
    else:
        eq, form, t_end = "5.4", CF.omega_eq5_4, periods / omega20**2
        what = "power-law spin-down to rest"
    return Case(eq, f"{model}, chi=0, delta={delta:g}: Omega(t) exact ({what})", f"section 5.1, ({eq})",
                symmetric_top(delta, 0.0), model, np.array([0.0, omega20, omega30]), tuple(euler0), t_end,
                omega_exact=lambda t: form(t, delta, omega20, omega30))


def eq5_2_turns(turns: float, delta: float = 0.3, periods: float = 3.0) -> Case:
    """(5.2) with orientation, omega20 = omega30 chosen so that the body turns ~``turns`` times
    over 3 Theta (omega3 is constant: turns ~ w3 t_end / 2 pi)."""
    eps = 1.0 - delta
    w3 = periods / (eps**2 * 2.0 * math.pi * turns)
    return longitudinal("reduced", delta, w3, w3, periods, euler0=(0.0, 1.0, 0.0))
