"""``secular``: real horizons (1e6 .. 1e25 turns) for a symmetric top.

The body-frame motion is the hybrid slow flow of ``slowflow``: the Euler equation in full
where the free precession is slow (and exactly where it stops: the domain "?" of (4.20)),
averaged over the precession where it is fast, with a near-identity transform at every
hand-over.  The orientation is O = R(q_L) Rz(phi) Rx(theta_L) Rz(psi) (x) q_frame with L_world
fixed (the torque across L turns with the spin and averages out), theta_L from the slow
variables, psi = pi/2 - p from the body-frame phase, and phi the precession about L.

What it guarantees, and what it reports (stats; measured against full integration at
eps = tau0 |Omega0| = 1e-4 .. 1e-6, see docs/integrators.md):

* slow variables (|Omega|, omega_perp, omega3, theta_L): about 10 eps^2 where averaged, the
  integrator's tolerance where in full, plus ~30 mu*^2 per hand-over;
* phases (q): about 2 eps max(1, t/T) where averaged, 3 rtol per radian of precession where
  in full, plus the uncertainty of L's direction (O(eps): the orientation is built about L);
  ``phases_resolved`` is False when that estimate exceeds 1e-3 rad, after the oscillating
  regime "5" (where phases decohere), or when float64 cannot hold them;
* the direction of L: fixed to O(eps) except at the resonances |L|/I1 = m delta w3
  (m = 1, 2; only prolate tops, delta > 1/3), where the torque across L stops averaging out
  and L turns by |c_m|/|L| sqrt(2 pi / |dF/dt|) ~ sqrt(eps), in a direction the averaged run
  cannot tell.  The run reports each crossing and the resulting uncertainty, and refuses
  when it exceeds ``L_TOL`` (the driver's ``auto`` then integrates in full if affordable).
  For the real DAST boxes it is ~5e-10 rad.

Not applicable: asymmetric bodies; tau0 |Omega0| > 1e-3 (the radiation then changes the spin
within a few turns, so there is no fast spin to average over).  Unaffordable: long stretches
of the oscillating regime "5" at tiny eps (its full-equation cost grows as eps^-1/2); the run
stops with a message saying so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import rotations as R
from ..interrupt import call_stoppable
from ..physics import models as M
from ..physics.free_top import pose_about_L
from ..physics.models import System
from . import status as ST
from .base import Integrator, Problem, Solution, register

MU_STAR = 1e-3         # FULL above, AVG below HYST x this (mu_ad; measured: 2e-5 in |Omega| at (0.8, 1.2), 30 T)
EPS_MAX = 1e-3         # tau0 |Omega0| above which the spin is not fast compared with the braking
L_TOL = 1e-6           # rad: the largest L-direction uncertainty (resonance kicks) secular accepts
PHASE_TOL = 1e-3       # rad: phases are called resolved below this estimated error
MAX_STEPS = 20_000_000   # about a minute; only long stretches of regime "5" at tiny eps get there
REGIME5_SIGN_CHANGES = 10


class NotApplicable(ValueError):
    """The secular flow does not apply to this problem; the message says why."""


@dataclass
class Setup:
    """A secular run made ready by ``prepare``: the system in the symmetric top's own frame
    (body' = body turned so that e3 is the symmetry axis; d's direction for a sphere), the
    quaternion q_frame (w, x, y, z) taking body' to body, the start w0 (3,) body' frame in spin
    units, q_L (4,) taking world z to L_world, the ZXZ angles (rad) of the start about L,
    eps = tau0 |Omega0|, and whether the torque is equivariant about e3 (d on the axis)."""

    system: System          # in the frame where e3 is the symmetry axis (along d for a sphere)
    q_frame: np.ndarray     # body' from body: identity except for spheres
    w0: np.ndarray          # spin units, in that frame
    q_L: np.ndarray         # world z -> L_world
    ang0: np.ndarray        # ZXZ angles about L at t = 0
    eps: float
    equivariant: bool

    @property
    def J3(self) -> float:
        """I3 / I1."""
        return float(self.system.inertia[2]) / float(self.system.inertia[0])

    @property
    def delta(self) -> float:
        """1 - I3 / I1: the precession rate is delta w3."""
        return 1.0 - self.J3


def prepare(problem: Problem) -> Setup:
    """Validate and set up (raises ``NotApplicable`` with the reason)."""
    s = problem.system
    J1, J2, J3 = (float(x) for x in s.inertia)
    if not s.is_symmetric:
        raise NotApplicable("secular needs a symmetric top (I1 = I2); this body is asymmetric")
    g = np.asarray(s.coupling, dtype=float)
    eps = float(g @ g)
    if s.spec.kernel_id is None:
        raise NotApplicable(f"the model {s.model!r} has no compiled kernel, which secular's slow flow runs on")
    if eps > EPS_MAX and s.spec.brakes:
        raise NotApplicable(f"tau0 |Omega0| = {eps:.3g} > {EPS_MAX:g}: the radiation changes the spin within a few "
                            f"turns, so there is no fast motion to average over; use a resolving method")
    w0 = np.asarray(problem.omega0, dtype=float)
    q0 = np.asarray(problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0), dtype=float)
    q_frame = np.array([1.0, 0.0, 0.0, 0.0])
    if abs(1.0 - J3 / J1) < 1e-12 and np.linalg.norm(g[:2]) > 1e-15 * np.linalg.norm(g):
        # a sphere: any axes are principal, so take e3 along d (as section 6.2 does): the
        # torque then commutes with rotations about e3 and needs no average at all
        q_frame = R.quat_between(g, (0.0, 0.0, 1.0))
        g = R.world_from_body(q_frame, g)
        w0 = R.world_from_body(q_frame, w0)
        q0 = R.multiply(q0, R.conjugate(q_frame))
    system = System(model=s.model, inertia=(J1, J2, J3), coupling=tuple(g))
    equivariant = bool(np.linalg.norm(g[:2]) <= 1e-14 * np.linalg.norm(g)) or s.model == "free"
    L_world = R.world_from_body(q0, np.array([w0[0], w0[1], J3 / J1 * w0[2]]))
    if float(np.linalg.norm(L_world)) > 0:
        q_L, ang0 = R.euler_zxz_about(L_world, q0)
    else:
        q_L, ang0 = np.array([1.0, 0.0, 0.0, 0.0]), R.euler_zxz_from_quat(q0)
    return Setup(system, q_frame, w0, q_L, np.asarray(ang0, dtype=float), eps, equivariant)


def resonance_kicks(setup: Setup, crossings) -> list[dict]:
    """Each recorded passage through |L|/I1 = m delta w3 (m = +-1, +-2: the torque across L has
    only these harmonics in the body-frame phase) with the turn of L it can cause,
    |c_m|/|L| sqrt(2 pi / |dF/dt|) (rad), F = |L| - m delta w3, in a direction set by the
    resonant phase (which an averaged run cannot tell)."""
    from . import slowflow as SF

    s = setup.system
    J = tuple(float(x) for x in s.inertia)
    g = tuple(float(x) for x in s.coupling)
    J3, delta = setup.J3, setup.delta
    model = M.kernel_id(s.model, "secular")
    nodes = SF.M_PHASES
    cM, sM = SF.phase_nodes(nodes)
    out = []
    for t, wp, w3, m in crossings:
        Lc = math.hypot(wp, J3 * w3)
        if Lc == 0.0:
            continue
        dwp, dw3, _, _ = SF.avg_rates(model, J, g, wp, w3, cM, sM, setup.equivariant)
        Fdot = abs((wp * dwp + J3 * J3 * w3 * dw3) / Lc - m * delta * dw3)
        if Fdot == 0.0:
            continue
        c = SF.torque_harmonic(model, J, g, wp, w3, int(m), nodes)
        out.append({"m": int(m), "t": float(t), "kick_rad": float(c / Lc * math.sqrt(2.0 * math.pi / Fdot))})
    return out


def solve_secular(problem: Problem, rtol: float = 1e-10, atol: float = 1e-12, step: float | None = None) -> Solution:
    """The ``secular`` method: the averaged slow flow (4.12) of a symmetric top, with the fast
    phases carried analytically, and its error statements in ``stats``.

    Parameters
    ----------
    problem : Problem
        In spin units (|omega(0)| = 1); omega0 body frame, q0 (w, x, y, z).
    rtol, atol : float
        Tolerances of the slow flow's Dormand-Prince 8(5,3) steps.
    step : float, optional
        Ignored (the method is adaptive); accepted for the common interface.

    Returns
    -------
    Solution
        omega (N, 3) body frame and q (N, 4) at ``problem.t_eval``; ``slow`` holds q_L and the
        (N,) angles phi_L, theta_L, psi_L about L; not successful (with the reason) where the
        flow does not apply, meets the oscillating regime "5", or crosses a resonance whose
        kick on L exceeds ``L_TOL``.
    """
    from . import kernels as KN
    from . import slowflow as SF

    t = np.asarray(problem.t_eval, dtype=float)

    def failed(message, stats=None):
        return Solution(t=t, omega=np.full((t.size, 3), np.nan), success=False, message=message, stats=stats or {})

    try:
        setup = prepare(problem)
    except NotApplicable as e:
        return failed(str(e))
    s = setup.system
    J = tuple(float(x) for x in s.inertia)
    g = tuple(float(x) for x in s.coupling)
    out, cnt, switches, recorded, status = call_stoppable(
        SF.integrate_hybrid, M.kernel_id(s.model, "secular"), J, g, setup.w0, t, float(rtol), float(atol), MU_STAR,
        setup.equivariant, MAX_STEPS, _phi0(setup), *KN.DP853_ARRAYS)
    stats = _stats(setup, cnt, switches, rtol, t)
    if status != ST.OK:
        stats["failed_at"] = float(cnt[14])            # where it stopped, not the last output it reached
        if status == ST.TOO_MANY_STEPS and cnt[8] >= REGIME5_SIGN_CHANGES:
            return failed(f"from {cnt[13] / t[-1]:.3g} of the horizon on, the body is in the oscillating "
                          f"regime '5' (omega3 changed sign {int(cnt[8])} times), where averaging fails and the full "
                          f"equation, whose cost grows as eps^-1/2, needs more than {MAX_STEPS:g} steps; shorten t_end",
                          stats)
        return failed(f"the slow flow: {ST.MESSAGES.get(status, status)}", stats)
    L_unc, refusal = _resonance_budget(setup, recorded, stats, t)
    if refusal:
        return failed(refusal, stats)
    o = out
    phi, p = o[:, 3], o[:, 4]
    # the pose is built on the free circle (radius o[:, 6], phase p): where omega_perp is mostly the
    # forced response (type 1) L_world turns round the spin axis and the body spins at omega3 about it,
    # which the free circle's phase carries; Omega itself is the kernel's, the forced response included
    wp, w3 = o[:, 6], o[:, 2]
    J3 = setup.J3
    theta_L = np.arctan2(wp, J3 * w3)
    psi = 0.5 * np.pi - p
    _, q = pose_about_L(setup.q_L, phi, theta_L, psi, wp, w3, setup.q_frame,
                        with_q=problem.kinematics == "quaternion")
    omega = R.body_from_world(setup.q_frame, o[:, :3])
    biggest = float(np.max(np.abs(phi)))
    resolution = float(np.spacing(biggest))
    # the orientation is no better than the direction of L it is built about
    phase_err = max(stats["phase_error_rad"] + L_unc, resolution)
    stats.update(turns=float(biggest / (2.0 * np.pi)), phase_resolution_rad=resolution, phase_error_rad=phase_err,
                 phases_resolved=bool(phase_err <= PHASE_TOL and stats["phases_resolved"]),
                 L_axis_world=R.world_from_body(setup.q_L, np.array([0.0, 0.0, 1.0])).tolist())
    slow = {"q_L": setup.q_L, "phi_L": phi, "theta_L": theta_L, "psi_L": psi, "q_frame": setup.q_frame}
    return Solution(t=t, omega=omega, q=q, stats=stats, slow=slow)


def _resonance_budget(setup: Setup, recorded, stats: dict, t: np.ndarray) -> tuple[float, str | None]:
    """The resonances the slow flow crossed, charged to the error statements in ``stats``
    (updated in place): (the uncertainty of L's direction, rad; the reason to refuse the run
    when a kick exceeds ``L_TOL``, else None)."""
    s = setup.system
    crossings = resonance_kicks(setup, recorded)
    kicks = np.array([c["kick_rad"] for c in crossings])
    kick_rss = float(np.sqrt(np.sum(kicks**2)))
    # the O(eps) wobble of L under the torque: 2 eps, measured up to 1.1 eps (delta = 0.5, chi = 1.36,
    # eps = 1e-4, 3 T in full as omega3 -> 0); none if free, nor for the truncated model with the dipole
    # on the axis, whose torque lies along L ((6.10); measured 1.5e-8 rad at eps = 1e-4)
    fixed_L = s.model == "free" or (s.model == "truncated" and setup.equivariant)
    wobble = 0.0 if fixed_L else 2.0 * setup.eps
    L_unc = kick_rss + wobble
    stats.update(resonances=[[c["m"], c["t"], c["kick_rad"]] for c in crossings], L_direction_uncertainty_rad=L_unc,
                 L_direction_bound_rad=float(np.sum(kicks)) + wobble)
    # a resonant kick also moves L relative to the body, i.e. the split of |L| between omega_perp and
    # omega3 (measured with L_TOL lifted: delta = 0.8, chi = 1.16, eps = 3e-5: slow error 2.8e-4 against
    # a kick of 2.6e-4), and that error in omega3 drifts the phases for the rest of the run
    # (1.5: measured turns of L are 0.57-1.13 x the predicted kick in spinviz check)
    stats["slow_error_estimate"] += 1.5 * kick_rss
    stats["phase_error_rad"] += 1.5 * abs(setup.delta) * kick_rss * float(t[-1] - t[0])
    if not kick_rss > L_TOL:
        return L_unc, None
    first = crossings[0]
    return L_unc, (f"the run crosses the resonance |L|/I1 = {first['m']} delta omega3 at {first['t'] / t[-1]:.3g} of the "
                   f"horizon, where the torque across L no longer averages out: L's direction becomes uncertain "
                   f"by ~{L_unc:.2g} rad (~sqrt(tau0 Omega)), more than {L_TOL:g}; integrate in full instead")


def _phi0(setup: Setup) -> float:
    """The starting precession angle in the kernel's split of the ZXZ angles about L.

    The kernel carries Sigma = phi + sgn(w3) psi with psi = pi/2 - p, p = atan2(w2, w1).  Where
    e3 lies along +-L (omega_perp = 0) only Sigma is defined -- the quaternion's own split puts
    psi = 0 there -- so phi is taken from Sigma, never from the quaternion's phi alone (which
    turned the body by 90 deg about L)."""
    w = setup.w0
    sgn = 1.0 if w[2] >= 0.0 else -1.0
    sigma0 = float(setup.ang0[0] + sgn * setup.ang0[2])
    return sigma0 - sgn * (0.5 * math.pi - math.atan2(w[1], w[0]))


def _stats(setup: Setup, cnt, switches, rtol: float, t) -> dict:
    """What the run did and how sure it is, before the resonance scan.

    The error statements are bounds fitted to measurements against full integration on random
    bodies (docs/integrators.md; ``spinviz check --sweep``, and a seed of it in
    tests/test_secular_real_scale.py): where averaged, the phases drift by ~ integral of
    mu^2 dt and at least 2 eps max(1, t/T), the slow variables are off by ~ max(15 eps^2,
    mu^2), with mu = eps |w|^2 / |delta w3| the radiation rate over the precession rate (small
    |delta| makes both larger: ~eps/delta^2 per braking time); in full, the phase error is
    ~3 rtol x the phase covered and the slow one rtol sqrt(steps); each hand-over adds ~30
    mu*^2 to the slow variables (300 mu*^2 into full, below), a resonance its kick (in
    solve_secular); and any slow error in omega3 drifts the phases by |delta| x it x the time
    left."""
    eps = setup.eps
    n_full, n_avg = int(cnt[0]), int(cnt[1])
    averaged = n_avg > 0 and not setup.equivariant
    regime5 = cnt[8] >= REGIME5_SIGN_CHANGES and n_full > 0
    phase_err = 3.0 * rtol * (2.0 * np.pi * cnt[7] + cnt[11])
    # in full, the tolerance's local errors add up like a random walk (measured 1.2e-9 = 12 rtol after
    # 5033 full steps: delta = 0.5, chi = 1.36, eps = 1e-4, 3 T)
    slow_err = 30.0 * MU_STAR**2 * int(cnt[5]) + rtol * math.sqrt(n_full)
    if averaged:
        phase_err += max(2.0 * eps * max(1.0, eps * float(t[-1])), cnt[10])
        # + where omega_perp has decayed to its forced response (late type "1"): the transform in
        # (w_perp, p) follows it only while it is small against w_perp
        slow_err += max(15.0 * eps * eps, cnt[6] ** 2) + cnt[12]
    # an error in omega3 is an error in the precession rate delta omega3: it feeds the phases
    # for the rest of the run (measured: a hand-over's 1e-6 became 1.4e-2 rad over 0.9 T)
    delta = setup.delta
    phase_err += abs(delta) * slow_err * float(t[-1] - t[0])
    # a full stretch carries the errors made before it forward, and in domain "?" (omega3 -> 0, the
    # precession stops) the dynamics amplify them: a hand-over's 1.6e-6 in omega3 grew to 2.1e-4 (7x
    # the 30 mu*^2 stated per switch) by 1 T and stayed there to 10 T (delta = 0.8, chi = 1.17,
    # eps = 3e-5); each hand-over into full therefore counts 10x for the slow variables
    to_full = int(np.sum(np.asarray(switches)[:, 1] == 0)) if len(switches) else 0
    slow_err += 270.0 * MU_STAR**2 * to_full
    return {
        "nsteps": n_full + n_avg, "nsteps_full": n_full, "nsteps_averaged": n_avg, "nfev": int(cnt[2] + cnt[3]),
        "nrejected": int(cnt[4]), "switches": int(cnt[5]), "mu_star": MU_STAR,
        "max_mu_averaged": float(cnt[6]), "full_precession_turns": float(cnt[7]),
        "omega3_sign_changes": int(cnt[8]), "regime_5": bool(regime5),
        "regime_5_from": float(cnt[13]) if regime5 else None, "forced_response_error": float(cnt[12]),
        "segments": [[float(a), "full" if int(b) == 0 else "averaged"] for a, b in switches[:50]],
        "equivariant": setup.equivariant,
        "slow_error_estimate": float(slow_err),
        "phase_error_rad": float(phase_err), "phases_resolved": not regime5,
    }


register(Integrator(
    name="secular", order=None, fixed_step=False, solve=solve_secular, symmetric_only=True, compiled=True,
    description="symmetric top over real horizons: body-frame equation in full where the precession is slow, averaged "
                "(with a near-identity transform) where it is fast; L_world fixed, resonances checked",
))
