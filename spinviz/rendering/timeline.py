"""From trajectories to frames: which time each frame shows and what each panel displays.

Pure NumPy (no rendering library): the renderer only draws what this module computes,
and frames are sampled from stored trajectories (``Trajectory.sample``), never by stepping
an integrator.

Time on screen.  Video time v in [0, duration] maps to simulation time linearly,
t = t_end v/duration, or logarithmically, t = k ((1 + t_end/k)^(v/duration) - 1) with a
knee k (default t_end/1000), so early braking and late asymptotics both get screen time.

Spin on screen.  Real spin rates are 1e16-1e25 turns per braking time; no frame rate can
show them.  Two honest modes:

* ``true`` -- each frame shows the simulated orientation at its time.  Used when the body
  turns less than 30 deg between frames and the phase is resolved.
* ``slowed`` -- for symmetric tops the motion is written in ZXZ angles about L_world:
  nutation theta_L (angle of e3 from L), precession phase phi_L (rate |L|/I1) and spin
  phase psi_L (rate delta Omega3).  theta_L and L are shown exactly; the two phases advance
  at ``spin_turns_per_second`` x (their true rate)/(|L|/I1 at t = 0) turns per video
  second, so the braking stays visible while the spin is slowed by a factor (true rad per
  video second / shown rad per video second) that the heads-up line states.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .. import rotations as R
from ..inputs.render import RenderSpec
from ..physics import polhode as PH
from ..physics.free_top import pose_about_L
from ..trajectory import radiated_power
from .frameplan import FramePlan, Panel, ShapeInfo

if TYPE_CHECKING:
    from ..trajectory import Trajectory

__all__ = ["FramePlan", "Panel", "frame_times", "plan_frames", "choose_spin_mode", "time_scale"]

MAX_TRUE_DEG_PER_FRAME = 30.0


def frame_times(spec: RenderSpec, t_end: float, frames: int | None = None):
    """The frame times.

    Parameters
    ----------
    spec : RenderSpec
        Duration, fps and the time map (linear, or log with its knee).
    t_end : float
        The last frame's simulation time, scene time unit.
    frames : int, optional
        F; default ``spec.frames``.

    Returns
    -------
    video_t : ndarray, shape (F,)
        Video seconds, 0 .. duration.
    sim_t : ndarray, shape (F,)
        Simulation time, scene unit, 0 .. t_end (the last exactly t_end).
    dsim_dvideo : ndarray, shape (F,)
        The time map's slope, scene time unit per video second.
    """
    F = frames or spec.frames
    v = np.linspace(0.0, spec.duration, F)
    s = v / spec.duration
    if spec.time_map == "linear":
        t = t_end * s
        slope = np.full(F, t_end / spec.duration)
    else:
        k = spec.knee(t_end)
        base = 1.0 + t_end / k
        t = k * np.expm1(s * math.log(base))
        slope = k * math.log(base) * base**s / spec.duration
    t[-1] = t_end
    return v, t, slope


def _rotation_per_frame(trajs, sim_t) -> float:
    """Upper bound of the rotation between frames in true mode, deg."""
    dt = np.diff(sim_t)
    worst = 0.0
    for tr in trajs:
        w = tr.sample(sim_t).omega_magnitude
        worst = max(worst, float(np.max(np.maximum(w[:-1], w[1:]) * dt)))
    return math.degrees(worst)


def choose_spin_mode(spec: RenderSpec, trajs: list[Trajectory], sim_t) -> tuple[str, str]:
    """("true" | "slowed" | "aliased", why).

    A phase that is not resolved (``Trajectory.phase_resolved`` False: float64 resolution,
    or an averaged ``secular`` or ``polhode`` run) is never shown as the true one: the body is
    then shown slowed (slow geometry exact -- L, the nutation of a symmetric top, the polhode
    of an asymmetric body -- phases re-timed and labelled), as it is where it turns more than
    ``MAX_TRUE_DEG_PER_FRAME`` between frames."""
    if not spec.needs_orientation:
        return "true", "no orientation shown"
    resolved = all(tr.phase_resolved and tr.q is not None for tr in trajs)
    if spec.spin == "true":
        if not resolved:
            raise ValueError("spin = \"true\" needs a resolved spin phase; this run's phase is not resolved "
                             "(use spin = \"slowed\" or \"auto\")")
        return "true", "requested"
    if spec.spin == "slowed":
        return "slowed", "requested"
    if not resolved:
        return "slowed", "spin phase not resolved (float64 or averaging)"
    deg = _rotation_per_frame(trajs, sim_t)
    if deg <= MAX_TRUE_DEG_PER_FRAME and resolved:
        return "true", f"at most {deg:.3g} deg per frame"
    return "slowed", f"up to {deg:.3g} deg per frame"


def time_scale(trajs: list[Trajectory], t_end: float) -> tuple[str, float] | None:
    """The unit of the time bar: Theta = 1/(tau0 Omega3^2 eps^2) (after (5.2)) or T =
    1/(tau0 Omega_perp^2) (after (3.9)) of the initial state -- the one the horizon is a round
    multiple of (scenes give t_end_Theta or t_end_T), else the one that puts t_end between
    0.5 and 50 units; None if neither does."""
    body = trajs[0].body
    w = np.asarray(trajs[0].omega[0], dtype=float)
    cands = []
    with np.errstate(all="ignore"):
        if w[2] != 0.0:
            cands.append(("Θ", float(body.residual_time_Theta(abs(float(w[2]))))))
        wp = math.hypot(float(w[0]), float(w[1]))
        if wp != 0.0:
            cands.append(("T", float(body.braking_time_T(wp))))
    cands = [(n, v) for n, v in cands if math.isfinite(v) and v > 0.0]
    for n, v in cands:
        r = t_end / v
        if 0.25 <= r <= 100.0 and abs(2.0 * r - round(2.0 * r)) < 1e-6 * r:
            return n, v
    for n, v in cands:
        if 0.5 <= t_end / v <= 50.0:
            return n, v
    return None


def plan_frames(spec: RenderSpec, trajs: list[Trajectory], frames: int | None = None) -> FramePlan:
    """Frame times and per-panel display data: what each frame shows, independent of its size.

    Parameters
    ----------
    spec : RenderSpec
        What the video shows; only the arrays ``spec.show`` needs are computed.
    trajs : list of one or two Trajectory
        Runs of the same body and initial state (one panel each, side by side), stored at
        any instants: they are sampled at the frame times, never stepped.
    frames : int, optional
        F; default ``spec.frames``.

    Returns
    -------
    FramePlan
        Frame times (F,); per panel the shown orientation q (F, 4) and R_world_from_body
        (F, 3, 3), world-frame d, Omega and L (F, 3), |Omega| (F,) and the d-L angle; the
        spin mode and, in slowed mode, the slowdown (F,).
    """
    if not 1 <= len(trajs) <= 2:
        raise ValueError("a video shows one or two models")
    body = trajs[0].body
    t_end = float(trajs[0].t[-1])
    video_t, sim_t, slope = frame_times(spec, t_end, frames)
    samples = [tr.sample(sim_t) for tr in trajs]   # once: choose_spin_mode's own sampling then returns these
    mode, why = choose_spin_mode(spec, samples, sim_t)
    resolved = all(tr.phase_resolved for tr in trajs)
    unit = time_scale(trajs, t_end)
    shown, slowdown = _shown_motion(spec, samples, body, mode, video_t, slope)
    ref = samples[0].omega[0]
    scale = (float(np.linalg.norm(ref)) or 1.0,
             float(np.linalg.norm(np.asarray(body.inertia, dtype=float) * ref)) or 1.0)
    panels = [_panel(spec, s, motion, body, scale, exact_angle=mode == "true" and resolved)
              for s, motion in zip(samples, shown)]
    if "power" in spec.show:
        # once per trajectory, here in the parent (the workers only draw); one call per run,
        # since two panels may show the same model
        for panel, s in zip(panels, samples):
            panel.power = radiated_power([s])[s.model]
    return FramePlan(
        spec=spec, video_t=video_t, sim_t=sim_t, panels=panels, units=body.units, body_name=body.name,
        shape=ShapeInfo.of(body.shape), d_body=np.asarray(body.dipole_direction, dtype=float), spin_mode=mode,
        slowdown=slowdown, notes=[f"spin: {mode} ({why})"], time_scale=unit, phase_resolved=resolved,
    )


def _shown_motion(spec: RenderSpec, samples, body, mode: str, video_t, slope):
    """Per panel (q (F, 4), Omega_body (F, 3)) as shown, and the slowdown (F,) or None.

    As simulated, except in slowed mode: there the slow geometry is kept and the precession
    and spin phases advance at ``spin_turns_per_second`` x (their true rate) / (|L|/I1 at
    t = 0 of the first panel) turns per video second."""
    if mode != "slowed":
        return [(s.q, s.omega) for s in samples], None
    if not body.is_symmetric:
        return _shown_polhode(spec, samples, body, video_t, slope)
    geo = [_slow_geometry(s, body) for s in samples]
    rate_ref = geo[0]["phidot"][0] or 1.0
    two_pi_r0 = 2.0 * math.pi * spec.spin_turns_per_second
    shown = []
    for g in geo:
        scale = two_pi_r0 / rate_ref
        phi = g["phi0"] + _cumtrapz(scale * g["phidot"], video_t)
        psi = g["psi0"] + _cumtrapz(scale * g["psidot"], video_t)
        omega_body, q = pose_about_L(g["q_L"], phi, g["theta_L"], psi, g["wp"], g["w3"], g["q_frame"])
        shown.append((q, omega_body))
    # true rad per video second / shown rad per video second (the same for every panel)
    return shown, rate_ref * slope / two_pi_r0


def _shown_polhode(spec: RenderSpec, samples, body, video_t, slope):
    """Slowed mode for an asymmetric body: at each frame the polhode through the simulated
    Omega (its size and axis exact) and L_world exact; the two phases of the free motion -- the
    polhode phase u and the turn Sigma about L (``physics.polhode``) -- advance at
    ``spin_turns_per_second`` x (their true rates) / (Sigma's rate at t = 0 of the first panel)
    turns per video second.  Where the encircled axis changes (a separatrix crossing) the
    phases start again from the simulated state."""
    J = tuple(float(x) for x in body.inertia)
    per = []
    for s in samples:
        L_world = s.angular_momentum_world()
        rows = []
        for f in range(len(s.t)):
            try:
                pol = PH.polhode_of(J, s.omega[f])
            except PH.NoPolhode:
                rows.append(None)
                continue
            wp, nu, c = PH.angle_variables(pol)
            rows.append((pol, wp, nu, c, R.quat_between((0.0, 0.0, 1.0), L_world[f])))
        per.append(rows)
    first = next((r for r in per[0] if r is not None), None)
    rate_ref = abs(first[2]) if first is not None and first[2] != 0.0 else 1.0
    two_pi_r0 = 2.0 * math.pi * spec.spin_turns_per_second
    scale = two_pi_r0 / rate_ref
    shown = []
    for s, rows in zip(samples, per):
        q_out, w_out = np.array(s.q, dtype=float), np.array(s.omega, dtype=float)
        u = sig = 0.0
        prev = None
        for f, row in enumerate(rows):
            if row is None:
                prev = None
                continue
            pol, wp, nu, c, q_L = row
            if prev is None or (prev[0].c, prev[0].s_c) != (pol.c, pol.s_c):
                u = float(pol.phase(s.omega[f]))
                sig = PH.sigma_of(pol, q_L, s.q[f]) - float(PH.sigma_periodic(c, wp, u))
            else:
                dv = video_t[f] - video_t[f - 1]
                u += 0.5 * scale * (wp + prev[1]) * dv
                sig += 0.5 * scale * (nu + prev[2]) * dv
            w, q = pol.pose(q_L, sig + float(PH.sigma_periodic(c, wp, u)), u)
            q_out[f], w_out[f] = q, w
            prev = row
        shown.append((R.unflip(q_out), w_out))
    return shown, rate_ref * slope / two_pi_r0


def _panel(spec: RenderSpec, s: Trajectory, motion, body, scale, exact_angle: bool) -> Panel:
    """One panel's arrays from its sampled trajectory ``s`` and shown motion (q, Omega_body):
    only what ``spec.show`` needs.  scale : (|Omega(0)|, |L(0)|) of the reference panel."""
    show = set(spec.show)
    w_ref, L_ref = scale
    panel = Panel(model=s.model, omega_mag=s.omega_magnitude)
    if spec.needs_orientation:
        q, omega_body = motion
        panel.q, panel.R_world_from_body = q, R.matrix_from_quat(q)
        if "dipole" in show or "trail" in show:
            panel.d_world = R.world_from_body(q, body.dipole_direction)
        if "omega" in show:
            panel.omega_world = R.world_from_body(q, omega_body) / w_ref
        if "L" in show:
            panel.L_world = R.world_from_body(q, np.asarray(body.inertia, dtype=float) * omega_body) / L_ref
    if "hud" in show or "inset" in show:
        # body-frame quantities from the simulated Omega (no orientation needed): the true
        # angle where the shown phase is the true one, its swing over a turn otherwise
        if exact_angle:
            panel.angle_dL_deg = np.degrees(s.angle_d_L())
        else:
            lo, hi = s.angle_d_L_range()
            panel.angle_dL_range_deg = np.degrees(np.stack([lo, hi], axis=-1))
    if "hodograph" in show:
        panel.omega_body = s.omega / w_ref
    return panel


def _cumtrapz(y, x):
    out = np.zeros_like(y)
    out[1:] = np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))
    return out


def _slow_geometry(s: Trajectory, body) -> dict:
    """theta_L, the L frame, the two phase rates and the starting phases, at the frames.

    From the ``secular`` slow geometry when present (its phases may be unresolved: only the
    starting phases are used), otherwise from q and Omega.
    """
    J3 = body.I3 / body.I1
    delta = 1.0 - J3
    w = s.omega
    q_frame = np.array([1.0, 0.0, 0.0, 0.0])
    if s.slow is not None:
        q_frame = np.asarray(s.slow["q_frame"], dtype=float)
        w = R.world_from_body(q_frame, w)                   # into the frame where e3 is the symmetry (or d) axis
    wp, w3 = np.hypot(w[:, 0], w[:, 1]), w[:, 2]
    out = {"wp": wp, "w3": w3, "phidot": np.hypot(wp, J3 * w3), "psidot": delta * w3, "q_frame": q_frame}
    if s.slow is not None:
        q_L = np.broadcast_to(np.asarray(s.slow["q_L"], dtype=float), (w.shape[0], 4))
        out.update(q_L=q_L, theta_L=np.asarray(s.slow["theta_L"]), phi0=float(s.slow["phi_L"][0]),
                   psi0=float(s.slow["psi_L"][0]))
        return out
    L_world = s.angular_momentum_world()
    q_L = np.array([R.quat_between((0.0, 0.0, 1.0), v) for v in L_world])
    # the nutation from the body-frame Omega alone (exact whatever the phase): L_body =
    # (w1, w2, J3 w3) sits at atan2(|w_perp|, J3 w3) from e3
    theta_L = np.arctan2(wp, J3 * w3)
    _, ang0 = R.euler_zxz_about(L_world[0], s.q[0])
    out.update(q_L=q_L, theta_L=theta_L, phi0=float(ang0[0]), psi0=float(ang0[2]))
    return out
