"""A detector far away along a line of sight n: what it records from a run.

The far field is E = (d_ddot x n) x n / (c^2 R) at the retarded time t + R/c (a constant shift,
left out: times are the source's).  Near each stored state the symmetric top's motion is its
free precession -- a turn about L at |L|/I1 composed with the body's precession at delta Omega3
-- so d_ddot is a sum of spectral lines at m |L|/I1 + kappa delta Omega3 (``physics.radiation.Lines``,
formed with the model's own Omega_dot).  From them, per stored instant:

* the power per solid angle toward n and the RMS field at a distance R (both time-averaged over
  the lines), the photon rate per steradian;
* the dominant frequency (the strongest line toward n), the rotation frequency |L|/(2 pi I1) and
  the body precession frequency |delta Omega3|/2 pi;
* the polarization (Stokes I, Q, U, V summed over the lines): angle of the linear part from
  u1 (``physics.radiation.polarization_basis``), linear and circular fractions.

For a real particle (``secular``, 1e16+ turns) the fast phases are not resolved, but none of
the above needs them: line frequencies and powers come from the slow variables (|Omega_perp|,
Omega3, L and theta_L), the phases only shift each line's phase.  A waveform drawn from the
lines (``waveform``) then has its phases reconstructed, and says so.

Symmetric tops only (I1 = I2), with orientation; numbers in the body's units (CGS: Hz, erg/s/sr,
V/m; dimensionless: 1/tau0, I1/tau0^3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..physics import radiation as RA
from ..trajectory import Trajectory


@dataclass
class Detection:
    """What a detector along ``line_of_sight`` records from one run, per stored instant (N,).

    freq (N, K) line frequencies (Hz, or cycles per tau0), non-negative; line_power_sr (N, K)
    each line's dP/dOmega toward n; line_field (N, K, 2) complex field amplitudes on (u1, u2) with
    E(t) = 2 Re(line_field exp(2 pi i freq t)) (V/m at ``distance_cm``, or in g units); line_ddot
    (N, K, 3) complex world-frame amplitudes of the dipole's second derivative, d_ddot(t) =
    2 Re(line_ddot exp(2 pi i freq t)) (statC cm/s^2, or |d|/tau0^2), for the field at any
    distance (``physics.dipole_field``); power
    (N,) total Larmor power averaged over the precession; power_sr (N,) dP/dOmega toward n;
    field_rms (N,); f_dom, f_rot, f_prec (N,); pol_angle (N,) rad from u1 in [-pi/2, pi/2);
    linear, circular (N,) fractions; photons_sr (N,) photons per second per steradian (CGS).
    """

    model: str
    units: str
    t: np.ndarray
    line_of_sight: np.ndarray
    distance_cm: float
    freq: np.ndarray
    line_power_sr: np.ndarray
    line_field: np.ndarray
    line_ddot: np.ndarray
    power: np.ndarray
    power_sr: np.ndarray
    field_rms: np.ndarray
    f_dom: np.ndarray
    f_rot: np.ndarray
    f_prec: np.ndarray
    pol_angle: np.ndarray
    linear: np.ndarray
    circular: np.ndarray
    photons_sr: np.ndarray | None
    phase_resolved: bool
    notes: list = field(default_factory=list)

    @property
    def freq_unit(self) -> str:
        """Unit of ``freq``: Hz (CGS) or cycles per tau0 (dimensionless)."""
        return "Hz" if self.units == "cgs" else "1/tau0"

    @property
    def power_unit(self) -> str:
        """Unit of the powers: erg/s (CGS) or I1/tau0^3 (``units.RADIATION_UNITS``)."""
        return U.radiation_unit("power", self.units)

    @property
    def power_sr_unit(self) -> str:
        """Unit of the powers per solid angle: erg/s/sr (CGS) or I1/tau0^3/sr."""
        return U.radiation_unit("power_per_sr", self.units)

    @property
    def field_unit(self) -> str:
        """Unit of the field amplitudes: V/m at ``distance_cm`` (CGS) or (I1/tau0^3)^1/2."""
        return "V/m" if self.units == "cgs" else "(I1/tau0^3)^1/2"

    def record(self, i: int) -> dict:
        """The scalar observables at sample ``i`` as plain numbers."""
        out = {"t": float(self.t[i]), "power": float(self.power[i]), "power_per_sr": float(self.power_sr[i]),
               "field_rms": float(self.field_rms[i]), "f_dominant": float(self.f_dom[i]),
               "f_rotation": float(self.f_rot[i]), "f_precession": float(self.f_prec[i]),
               "polarization_angle_deg": math.degrees(float(self.pol_angle[i])),
               "linear_fraction": float(self.linear[i]), "circular_fraction": float(self.circular[i])}
        if self.photons_sr is not None:
            out["photons_per_s_sr"] = float(self.photons_sr[i])
        return out


def default_line_of_sight(traj: Trajectory) -> np.ndarray:
    """Perpendicular to the initial angular momentum: L(0) x z normalized, or x when L(0) is
    along z (a detector in the plane of the rotation sees its full, linearly polarized signal)."""
    L0 = traj.angular_momentum_world()[0]
    n = np.cross(L0, [0.0, 0.0, 1.0])
    if np.linalg.norm(n) <= 1e-9 * np.linalg.norm(L0):
        return np.array([1.0, 0.0, 0.0])
    return n / np.linalg.norm(n)


def detect(traj: Trajectory, line_of_sight=None, distance_cm: float = 1.0, M: int = 16) -> Detection:
    """The detector's record of ``traj`` (``Detection``); line of sight in the world frame
    (default ``default_line_of_sight``), the field given at ``distance_cm`` (CGS bodies)."""
    body = traj.body
    if not body.is_symmetric:
        raise ValueError("the detector needs a symmetric top (I1 = I2): its lines are those of the free precession")
    if traj.q is None:
        raise ValueError("the detector needs the orientation, which this run did not integrate")
    n = default_line_of_sight(traj) if line_of_sight is None else RA.polarization_basis(line_of_sight)[0]
    tau0, I1, cgs = traj.tau0, body.I1, traj.units == "cgs"
    s = body.system(traj.model)
    w = U.omega_to_dimensionless(traj.omega, tau0)
    lines = RA.symmetric_top_lines(traj.model, w, traj.q, s.inertia, s.coupling, M)
    e, psr = lines.toward(n)
    stokes = lines.stokes(n)
    to_hz = 1.0 / (2.0 * math.pi * tau0)                 # rad per tau0 -> Hz (cycles per tau0 if dimensionless)
    freq = np.abs(lines.angular_frequency) * to_hz
    e = np.where((lines.angular_frequency < 0)[..., None], np.conj(e), e)
    ddot = np.where((lines.angular_frequency < 0)[..., None], np.conj(lines.amplitude), lines.amplitude)
    ddot = ddot * (body.dipole_magnitude / tau0**2 if cgs else 1.0)      # g of unit size -> d_ddot
    line_power_sr = U.radiation_from_dimensionless(psr, "power_per_sr", I1, tau0)
    sig = math.sqrt(I1 / tau0**3) if cgs else 1.0        # g-unit signal -> (erg/s)^1/2
    to_field = (math.sqrt(1.5 / U.C_LIGHT) / distance_cm * U.STATV_PER_CM_IN_V_PER_M) if cgs else 1.0
    power_sr = line_power_sr.sum(axis=1)
    strongest = np.argmax(line_power_sr, axis=1)
    rows = np.arange(freq.shape[0])
    I, Q, Uq, V = stokes.T
    with np.errstate(invalid="ignore", divide="ignore"):
        linear = np.where(I > 0, np.hypot(Q, Uq) / I, 0.0)
        circular = np.where(I > 0, V / I, 0.0)
    photons = None
    if cgs:
        with np.errstate(invalid="ignore", divide="ignore"):
            photons = np.where(freq > 0, line_power_sr / (U.HBAR * 2.0 * math.pi * np.where(freq > 0, freq, 1.0)), 0.0).sum(1)
    notes = []
    if not traj.phase_resolved:
        notes.append("fast phase not resolved (float64 or averaging): line frequencies and powers come from the slow "
                     "variables; waveform phases are reconstructed")
    field_rms = (U.field_rms_from_power_per_sr(power_sr, distance_cm) * U.STATV_PER_CM_IN_V_PER_M if cgs
                 else np.sqrt(8.0 * math.pi / 3.0 * power_sr))
    return Detection(
        model=traj.model, units=traj.units, t=np.asarray(traj.t), line_of_sight=n, distance_cm=float(distance_cm),
        freq=freq, line_power_sr=line_power_sr, line_field=e * sig * to_field, line_ddot=ddot,
        power=traj.radiated_power(), power_sr=power_sr, field_rms=field_rms, f_dom=freq[rows, strongest],
        f_rot=lines.phi_dot * to_hz, f_prec=np.abs(lines.psi_dot) * to_hz,
        pol_angle=0.5 * np.arctan2(Uq, Q), linear=linear, circular=circular, photons_sr=photons,
        phase_resolved=traj.phase_resolved, notes=notes)


def waveform(det: Detection, i: int, periods: float = 3.0, points: int = 600):
    """(t_local, E (points, 2)): the field's two polarizations over ``periods`` rotation periods
    from sample ``i``, synthesized from its lines (seconds, or tau0, from the sample's time)."""
    f = float(det.f_rot[i])
    span = periods / f if f > 0 else 1.0
    t = np.linspace(0.0, span, points)
    ph = np.exp(2j * math.pi * det.freq[i][:, None] * t[None, :])                 # (K, points)
    return t, 2.0 * np.real(np.einsum("kp,km->mp", det.line_field[i], ph))
