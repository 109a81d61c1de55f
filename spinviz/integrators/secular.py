"""``secular``: the slow flow of a symmetric top, averaged over the free precession, with the
fast phases integrated as plain integrals.  For physically real horizons (1e16-1e25 turns).

Free motion of a symmetric top (I1 = I2, J3 = I3/I1, delta = 1 - J3): in ZXZ angles taken
from a frame whose z axis is L_world,

    theta_L = const, phi_L_dot = |L|/I1 = sqrt(w_perp^2 + J3^2 w3^2), psi_L_dot = delta w3,

and the body-frame angular velocity is (w_perp cos p, w_perp sin p, w3) with p = pi/2 - psi_L.
The radiation torque is weaker than the free motion by eps_rad = tau0 |Omega0| (1e-16 for the
DAST cube).  To first order in eps_rad:

* L_world keeps its direction: the torque's part across L turns with the body, at the spin
  rate, and averages out; the axis moves only by O(eps_rad) (DESIGN.md, section 2);
* (w_perp, w3) follow the torque averaged over the precession phase p -- for the reduced
  equation this is (4.12), here computed from the model's own right-hand side by an
  M-point phase average (exact for the trigonometric polynomials involved; a test checks
  it reproduces (4.12));
* phi_L = integral of |L|/I1 and psi_L = integral of (delta w3 - <p_dot radiation part>).

For a longitudinal dipole (chi = 0) the torque commutes with rotations about e3, so no
average is needed and (w_perp, w3) are exact; a spherical top is first turned so that
e3 is along d (section 6.2 does the same for the DAST cube).  The slow ODE is integrated by
DOP853 on the braking time scale -- a few hundred steps whatever the number of turns.

What float64 cannot resolve: phi_L grows to 2 pi x (number of turns); after 1e16 turns one
ulp of it is ~ 8 rad, so the absolute spin phase is unknowable (``stats['phase_resolution_rad']``).
The renderer shows the spin slowed down and says so; the slow variables are exact to
O(eps_rad) relative.
"""

from __future__ import annotations

import math

import numpy as np

from .. import rotations as R
from ..physics.equations import System
from ..physics.free_top import pose_about_L
from .base import Integrator, Problem, Solution, register

M_PHASES = 32          # phase-average nodes: exact for trigonometric polynomials of degree < 32
MU_MAX = 1e-3          # refuse to average when radiation rate / precession rate exceeds this


class NotApplicable(ValueError):
    """The secular flow does not apply to this problem; the message says why."""


class SlowFlow:
    """The averaged right-hand side for one symmetric top in spin units."""

    def __init__(self, system: System, equivariant: bool):
        # The radiation part alone: added to the O(1) free part first, a 1e-16 torque would
        # be lost in its round-off.  The free motion is added exactly: it only turns
        # (w1, w2) about e3 at the rate -delta w3.
        self.radiation = system.radiation()
        self.J3 = system.inertia[2] / system.inertia[0]
        self.delta = 1.0 - self.J3
        self.equivariant = equivariant
        p = 2.0 * np.pi * np.arange(M_PHASES) / M_PHASES
        self.cos, self.sin = np.cos(p), np.sin(p)

    def rates(self, wp: float, w3: float):
        """(d w_perp, d w3, d p) averaged over the precession phase p."""
        if self.equivariant or wp == 0.0:
            a1, a2, a3 = self.radiation(wp, 0.0, w3)     # at p = 0: w_perp along e1
            dp = a2 / wp if wp != 0.0 else 0.0
            return a1, a3, dp - self.delta * w3
        w1, w2 = wp * self.cos, wp * self.sin
        a1, a2, a3 = self.radiation(w1, w2, np.full_like(w1, w3))
        dwp = float(np.mean(w1 * a1 + w2 * a2)) / wp
        dp = float(np.mean(w1 * a2 - w2 * a1)) / (wp * wp)
        return dwp, float(np.mean(a3)), dp - self.delta * w3

    def rhs(self, t, y):
        wp, w3 = y[0], y[1]
        dwp, dw3, dp = self.rates(wp, w3)
        return np.array([dwp, dw3, math.sqrt(wp * wp + self.J3 * self.J3 * w3 * w3), -dp])


def prepare(problem: Problem):
    """Validate and set up: (flow, frame rotation for spheres, initial slow state, geometry)."""
    s = problem.system
    J1, J2, J3 = (float(x) for x in s.inertia)
    if not s.is_symmetric:
        raise NotApplicable("secular needs a symmetric top (I1 = I2); this body is asymmetric")
    g = np.asarray(s.coupling, dtype=float)
    w0 = np.asarray(problem.omega0, dtype=float)
    q0 = np.asarray(problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0), dtype=float)
    delta = 1.0 - J3 / J1
    q_frame = np.array([1.0, 0.0, 0.0, 0.0])          # body' = frame with e3 along d (spheres)
    rotated = abs(delta) < 1e-12 and np.linalg.norm(g[:2]) > 1e-15 * np.linalg.norm(g)
    if rotated:
        q_frame = R.quat_between(g, (0.0, 0.0, 1.0))    # rotation taking d to e3
        g = R.world_from_body(q_frame, g)
        w0 = R.world_from_body(q_frame, w0)
        q0 = R.multiply(q0, R.conjugate(q_frame))
    sys_p = System(model=s.model, inertia=(J1, J2, J3), coupling=tuple(g))
    equivariant = bool(np.linalg.norm(g[:2]) <= 1e-14 * np.linalg.norm(g)) or s.model == "free"
    wp0 = float(math.hypot(w0[0], w0[1]))
    eps_rad = float(g @ g)
    if not equivariant:
        prec = abs(delta * w0[2])
        mu = eps_rad * float(w0 @ w0) / prec if prec > 0 else math.inf
        if mu > MU_MAX:
            raise NotApplicable(
                f"secular averages over the free precession, which is too slow here "
                f"(radiation rate / precession rate = {mu:.2g} > {MU_MAX:g}); use a resolving method"
            )
    flow = SlowFlow(sys_p, equivariant)
    L_body = np.array([w0[0], w0[1], J3 / J1 * w0[2]])
    L_world = R.world_from_body(q0, L_body)
    if float(np.linalg.norm(L_world)) > 0:
        q_L, ang0 = R.euler_zxz_about(L_world, q0)
    else:
        q_L, ang0 = np.array([1.0, 0.0, 0.0, 0.0]), R.euler_zxz_from_quat(q0)
    return flow, (q_frame if rotated else None), np.array([wp0, float(w0[2]), 0.0, 0.0]), q_L, ang0, eps_rad


def solve_secular(problem: Problem, rtol: float = 1e-10, atol: float = 1e-12, step: float | None = None) -> Solution:
    t = np.asarray(problem.t_eval, dtype=float)
    try:
        flow, q_frame, y0, q_L, ang0, eps_rad = prepare(problem)
    except NotApplicable as e:
        return Solution(t=t, omega=np.full((t.size, 3), np.nan), success=False, message=str(e))
    kw = {"rtol": rtol, "atol": atol}
    if step:
        kw["max_step"] = step
    from scipy.integrate import solve_ivp

    res = solve_ivp(flow.rhs, (t[0], t[-1]), y0, method="DOP853", t_eval=t, **kw)
    if res.status != 0 or not np.all(np.isfinite(res.y)):
        return Solution(t=t, omega=np.full((t.size, 3), np.nan), success=False,
                        message=f"secular slow flow failed: {res.message}")
    wp, w3, Phi, Psi = res.y
    wp = np.abs(wp)
    phi_L = ang0[0] + Phi
    psi_L = ang0[2] + Psi
    theta_L = np.arctan2(wp, flow.J3 * w3)
    if q_frame is None:
        q_frame = np.array([1.0, 0.0, 0.0, 0.0])
    omega, q = pose_about_L(q_L, phi_L, theta_L, psi_L, wp, w3, q_frame, with_q=problem.kinematics == "quaternion")
    biggest = float(np.max(np.abs(np.concatenate([phi_L, psi_L]))))
    stats = {
        "nfev": int(res.nfev),
        "phase_resolution_rad": float(np.spacing(biggest)),
        "averaging_error_order": eps_rad,
        "L_axis_world": R.world_from_body(q_L, np.array([0.0, 0.0, 1.0])).tolist(),
        "turns": float(biggest / (2.0 * np.pi)),
        "equivariant": flow.equivariant,
    }
    slow = {"q_L": q_L, "phi_L": phi_L, "theta_L": theta_L, "psi_L": psi_L, "q_frame": q_frame}
    return Solution(t=t, omega=omega, q=q, stats=stats, slow=slow)


register(Integrator(
    name="secular", order=None, fixed_step=False, solve=solve_secular, symmetric_only=True,
    description="symmetric top: averaged slow flow + integrated phases, L_world fixed; error O(tau0 Omega); for real horizons",
))
