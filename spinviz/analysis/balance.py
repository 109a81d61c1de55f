"""Does each model balance its angular momentum and its energy against what it radiates?

Along an integrated run (world frame, orientation included), at the end of every quadrature
panel t_p:

* (2.4a):  r_a = L(t_p) - L(0) - int_0^t_p F dt,     F = -(2/3c^3) d_dot x d_ddot;
* (2.1):   r_1 = r_a - [K(t_p) - K(0)],              K = (2/3c^3) d x d_ddot (the integral of the
  Schott-like term (2.4b) is exact: it is a total derivative);
* energy:  r_E = E(t_p) - E(0) + int_0^t_p P dt - [E_S(t_p) - E_S(0)],
  P = (2/3c^3)|d_ddot|^2 and E_S = (2/3c^3) d_dot . d_ddot (the Schott energy).

Every quantity is formed from the stored state and the model's own Omega_dot, Omega_ddot
(``physics.radiation``); the integrals are Gauss-Legendre sums over the run's own output
instants (8 nodes on every quarter turn: exact to round-off for the smooth integrands), so what
remains is the model's departure from the balance plus the integrator's error.

What each model should show (dimensionless eps_rad = tau0 |Omega|):

* truncated (2.5) is (2.4a) solved for Omega_dot: r_a at the integrator's error; r_1 = -(K(t) - K(0)),
  a bounded oscillation; r_E does not close: with dE/dt = Omega . N = -P + (2/3c^3) d_ddot .
  (Omega_dot x d) (N the torque of (2.4a), d_dot = Omega x d) and dE_S/dt = P + (2/3c^3) d_dot . d_dddot,
  dE/dt + P - dE_S/dt = (2/3c^3) d_ddot . (Omega_dot x d) - P - (2/3c^3) d_dot . d_dddot
  is O(1) relative to P for a top that precesses (delta != 0), e.g.
  -(2/3c^3) d^2 delta (1 - delta) Omega3^2 Omega_perp^2 on average for chi = 0;
* reduced (2.2)+(2.3) is (2.1) with the free-motion Omega_dot, Omega_ddot in d_dddot: r_1 and r_E
  are O(eps_rad) relative (the order of its reduction), and r_a equals the Schott integral to
  that order.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from .. import rotations as R
from ..atomic import plain
from ..driver import simulate
from ..physics import radiation as RA
from ..physics.bodies import Body

GL_NODES = 8           # Gauss-Legendre nodes per panel: exact for degree 15, error ~ (panel rate)^16
PANELS_PER_TURN = 4


def quadrature_times(t_end: float, panels: int, nodes: int = GL_NODES):
    """(t_eval, weights, ends): output instants holding the panel ends (0, t_end/panels, ..,
    t_end) and ``nodes`` Gauss-Legendre nodes inside each panel; ``weights`` (t_eval.size,) is
    zero at the ends, so that cumulative sums over a panel's nodes give its integral; ``ends``
    indexes the panel ends in t_eval."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    edges = np.linspace(0.0, float(t_end), panels + 1)
    h = np.diff(edges)
    inner = (edges[:-1, None] + 0.5 * h[:, None] * (x[None, :] + 1.0))
    weights_inner = 0.5 * h[:, None] * w[None, :]
    t = np.concatenate([edges[:-1, None], inner], axis=1).ravel()
    wt = np.concatenate([np.zeros((panels, 1)), weights_inner], axis=1).ravel()
    t = np.append(t, edges[-1])
    wt = np.append(wt, 0.0)
    ends = np.arange(0, panels + 1) * (nodes + 1)
    return t, wt, ends


@dataclass
class BalanceRun:
    """One run's balance residuals at the panel ends (dimensionless, world frame).

    eps : tau0 |Omega0|; turns : the horizon in turns; rel_* : largest |residual| over the run
    relative to the largest |L(t) - L(0)| (angular momentum) or to int P dt (energy).
    """

    model: str
    body: str
    eps: float
    turns: float
    rel_2_4a: float
    rel_2_1: float
    rel_energy: float
    rel_schott_over_dL: float
    rel_energy_defect_predicted: float
    runtime_s: float
    details: dict = field(default_factory=dict)

    def record(self) -> dict:
        """The fields as a JSON-ready dict (``spinviz check --json``)."""
        return plain(asdict(self))


def balance_run(body: Body, model: str, eps: float, direction=(0.3, 0.5, 0.8), euler0=(0.3, 1.1, -0.4),
                turns: float = 20.0, rtol: float = 1e-12, atol: float = 1e-14) -> BalanceRun:
    """Integrate ``model`` for ``turns`` turns at tau0 |Omega0| = ``eps`` (dimensionless body)
    with taylor and measure the balance residuals (module docstring)."""
    if body.units != "dimensionless":
        raise ValueError("balance_run works in the variables (4.1): give a dimensionless body")
    w0 = eps * np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    t_end = turns * 2.0 * math.pi / eps
    t, wt, ends = quadrature_times(t_end, int(round(turns * PANELS_PER_TURN)))
    start = time.perf_counter()
    tr = simulate(body, model, w0, t_eval=t, euler_zxz0=euler0, method="taylor", rtol=rtol, atol=atol)
    runtime = time.perf_counter() - start
    s = body.system(model)
    b = RA.balance(model, tr.omega_body, s.inertia, s.coupling)
    g = np.broadcast_to(np.asarray(s.coupling), tr.omega_body.shape)
    world = lambda v: R.world_from_body(tr.q, v)      # noqa: E731
    L_world = world(b.L_body)
    F_world = world(b.flux_body)
    K_world = world(np.cross(g, b.b2))
    cum = lambda f: np.cumsum(wt[:, None] * f if f.ndim == 2 else wt * f, axis=0)[ends]   # noqa: E731
    dL = L_world[ends] - L_world[0]
    r_a = dL - cum(F_world)
    r_1 = r_a - (K_world[ends] - K_world[0])
    int_P = cum(b.power)
    r_E = (b.energy[ends] - b.energy[0]) + int_P - (b.schott_energy[ends] - b.schott_energy[0])
    # the energy residual predicted from the state alone: int (Omega . N - b1 . b3) dt
    predicted = cum(b.work - b.dipole_work)
    scale_L = float(np.max(np.linalg.norm(dL, axis=1)))
    scale_E = float(int_P[-1])
    return BalanceRun(
        model=model, body=body.name, eps=eps, turns=turns,
        rel_2_4a=float(np.max(np.linalg.norm(r_a, axis=1))) / scale_L,
        rel_2_1=float(np.max(np.linalg.norm(r_1, axis=1))) / scale_L,
        rel_energy=float(np.max(np.abs(r_E))) / scale_E,
        rel_schott_over_dL=float(np.max(np.linalg.norm(K_world[ends] - K_world[0], axis=1))) / scale_L,
        rel_energy_defect_predicted=float(np.max(np.abs(r_E - predicted))) / scale_E,
        runtime_s=runtime,
        details={"method": tr.stats["method"], "samples": int(t.size), "energy_radiated_over_lost":
                 float(int_P[-1] / (b.energy[0] - b.energy[-1])) if b.energy[0] != b.energy[-1] else math.nan},
    )


def pointwise(model: str, omega_body, J, g) -> dict:
    """The balance identities at states ``omega_body`` (..., 3) (body frame, dimensionless), as the
    largest residual relative to the largest |flux (2.4a)|:

    * ``2_4a``: |N - F|, the model's torque against (2.4a);
    * ``2_1``: |N - g x b3|, against (2.1) with the model's own Omega_dot, Omega_ddot;
    * ``2_1_free``: |N - g x b3_free|, against (2.1) with the free-motion derivatives (the
      reduced equation's definition; round-off for it);
    * ``energy``: |Omega . N - b1 . b3| / max P, dE/dt against -P + dE_S/dt.
    """
    b = RA.balance(model, omega_body, J, g)
    scale = float(np.max(np.linalg.norm(b.flux_body, axis=-1)))
    free = RA.free_dipole_torque(omega_body, J, g)
    return {
        "2_4a": float(np.max(np.linalg.norm(b.torque_body - b.flux_body, axis=-1))) / scale,
        "2_1": float(np.max(np.linalg.norm(b.torque_body - b.dipole_torque(g), axis=-1))) / scale,
        "2_1_free": float(np.max(np.linalg.norm(b.torque_body - free, axis=-1))) / scale,
        "energy": float(np.max(np.abs(b.work - b.dipole_work))) / float(np.max(b.power)),
    }


def order_in_eps(eps, errors) -> float | None:
    """The slope of log(error) against log(eps), or None when an error is not positive."""
    e = np.asarray(errors, dtype=float)
    if np.any(~(e > 0)):
        return None
    return float(np.polyfit(np.log(np.asarray(eps, dtype=float)), np.log(e), 1)[0])


def energy_ratio_eq5_4(delta: float, omega20: float, omega30: float) -> float:
    """Truncated, chi = 0, (5.4): the energy it radiates over the energy it loses, at any time,
    (w20^2 + (1 - delta)^2 w30^2) / (w20^2 + (1 - delta) w30^2).  From (5.4) E = E0/F^2, and
    int P dtau = (w20^2 + eps^2 w30^2)(1 - 1/F^2)/2 with eps = I3/I1 = 1 - delta: the truncated top
    loses more energy than it radiates when 0 < delta < 1 (less when delta < 0), as much as it
    radiates only for a sphere."""
    e = 1.0 - delta
    return (omega20**2 + e * e * omega30**2) / (omega20**2 + e * omega30**2)


def energy_defect_rate_chi0(delta: float, omega_perp, omega3):
    """dE/dt + P of the truncated model for a longitudinal dipole (chi = 0) under free
    precession, dimensionless: -delta (1 - delta) omega3^2 omega_perp^2."""
    return -delta * (1.0 - delta) * np.asarray(omega3) ** 2 * np.asarray(omega_perp) ** 2


__all__ = ["BalanceRun", "balance_run", "pointwise", "order_in_eps", "energy_ratio_eq5_4", "quadrature_times",
           "energy_defect_rate_chi0"]
