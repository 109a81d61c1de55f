"""What a stated receiver makes of the crystal's lines: their signal-to-noise ratio over time,
the resolutions it reaches in frequency, power and polarization angle, and the field where
its antenna stands.

The receiver (``inputs.receiver.ReceiverSpec``): an antenna of effective area A_eff (both
polarizations) at distance R along the detector's line of sight, system noise N0 = k_B T_sys
(one-sided, per polarization channel), an instantaneous band B retuned to follow the line,
and estimates of the line's frequency, power and polarization made over integrations of
t_int each.  For one line (CGS throughout):

* received power S = (dP/dOmega) A_eff / R^2, the radiation zone's flux (R >= lambda only;
  nearer, the 1/R^2 and 1/R^3 terms of ``physics.dipole_field`` are comparable and the flux
  formula does not hold: flagged, no SNR is given there);
* the SNR a coherent (matched-filter) receiver integrates over a time T is rho = 2 S T / N0 --
  for a real tone of amplitude A in white noise of variance sigma^2 per sample, N samples over
  T, rho = N A^2 / (2 sigma^2);
* a drifting line stays coherent -- described by a linear chirp (f, f_dot) to within pi/4 of
  phase at the ends, 2 pi |f_ddot| (T/2)^3 / 6 <= pi/4 -- over T_chirp = (6 / |f_ddot|)^(1/3),
  and stays in the band over B / |f_dot|: the coherent interval is T_c = min(t_int, T_chirp,
  B/|f_dot|), and an integration holds t_int / T_c of them (the cubic term left in the
  phase shifts the fitted centre frequency by f_ddot T_c^2 / 40, alike for two models that
  share f_ddot to the order they agree);
* over a coherent interval the Cramer-Rao bound of a chirp's frequency at the interval's centre
  is that of a tone, sigma_f = sqrt(12) / (2 pi T_c sqrt(rho_c)) (the phase's t and t^2 terms are
  orthogonal there), and of its rate sigma_fdot = sqrt(180) / (pi T_c^2 sqrt(rho_c)); the
  intervals of one integration combine to sigma_f = sqrt(12) / (2 pi T_c sqrt(rho_int)),
  rho_int = 2 S t_int / N0;
* the power (amplitude squared) to sigma_P / P = 2 / sqrt(rho_int), the angle of the linear
  polarization to sigma_psi = 1 / (p sqrt(rho_int)) rad (p its linear fraction: a circular line
  has no angle);
* these bounds hold above threshold, where noise rarely outshines the line: in a periodogram of
  the interval the line's bin holds Y = |sqrt(rho_c/2) + z|^2 times the noise's mean power (z a
  unit complex Gaussian), each of the K = B T_c noise bins an exponential variable, so some noise
  bin beats the line with probability at most K E[exp(-Y)] = (K/2) exp(-rho_c/4); a line counts
  as detected in a coherent interval where rho_c >= 4 ln(K / (2 P_out)), P_out = 1 %
  (``detection_threshold``; a union bound, conservative: a simulated periodogram's outliers
  come to about a third of P_out at its threshold, and the exact 1 % point,
  ``exact_threshold``, is 59.0 where the bound says 70.9, for the 1e6 bins of a 1 MHz band over
  1 s).

A line's drift f_dot and its rate f_ddot come from its frequency over the run's output
instants (second-order finite differences on the non-uniform grid).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .. import units as U
from ..physics import dipole_field as DF
from .detector import Detection

P_OUTLIER = 0.01              # accepted chance that noise outshines the line in one coherent interval
CHIRP_PHASE = math.pi / 4     # unmodelled phase at an interval's ends that still counts as coherent


def crb_tone(rho, T):
    """Cramer-Rao bound on the frequency (Hz) of a real tone of unknown amplitude and phase,
    rho the SNR integrated over the observation time T (s): sqrt(12) / (2 pi T sqrt(rho))."""
    return math.sqrt(12.0) / (2.0 * math.pi * np.asarray(T, dtype=float) * np.sqrt(np.asarray(rho, dtype=float)))


def crb_chirp(rho, T):
    """(sigma_f, sigma_fdot): Cramer-Rao bounds on the centre frequency (Hz) and the rate (Hz/s)
    of a real linear chirp of unknown amplitude and phase over T (s), rho its integrated SNR."""
    rho, T = np.asarray(rho, dtype=float), np.asarray(T, dtype=float)
    return crb_tone(rho, T), math.sqrt(180.0) / (math.pi * T**2 * np.sqrt(rho))


def detection_threshold(bins, p_outlier: float = P_OUTLIER):
    """The coherent SNR above which noise outshines the line in at most ``p_outlier`` of the
    intervals, for ``bins`` independent frequency bins searched: 4 ln(K / (2 p_outlier))."""
    return 4.0 * np.log(np.maximum(np.asarray(bins, dtype=float), 1.0) / (2.0 * p_outlier))


@functools.lru_cache(maxsize=256)
def _exact(bins: float, p_outlier: float) -> float:
    from scipy import integrate, optimize, special

    k = max(float(bins), 1.0)

    def outshone(rho):
        # 1 - E[(1 - exp(-Y))^K], Y = |sqrt(lam) + z|^2, lam = rho/2: density exp(-(y + lam)) I0(2 sqrt(lam y))
        lam = 0.5 * rho

        def f(y):
            r = math.sqrt(y)
            pdf = math.exp(-(r - math.sqrt(lam)) ** 2) * special.i0e(2.0 * math.sqrt(lam) * r)
            return -math.expm1(k * math.log1p(-math.exp(-y))) * pdf

        lo, hi = max(0.0, 0.5 * rho - 20.0 * math.sqrt(rho + 1.0)), 0.5 * rho + 20.0 * math.sqrt(rho + 1.0) + 20.0
        return integrate.quad(f, lo, hi, limit=200, points=[0.5 * rho])[0] - p_outlier

    top = float(detection_threshold(k, p_outlier)) + 10.0
    return float(optimize.brentq(outshone, 1e-6, top, xtol=1e-6))


def exact_threshold(bins, p_outlier: float = P_OUTLIER) -> float:
    """The coherent SNR at which noise outshines the line in exactly ``p_outlier`` of the
    intervals for ``bins`` bins (the line's bin |sqrt(rho/2) + z|^2 against K exponential noise
    bins: 1 - E[(1 - exp(-Y))^K] = p_outlier, by quadrature); ``detection_threshold``'s union
    bound lies above it (59.0 against 70.9 for K = 1e6 at 1 %), so the detection rule is
    conservative by their difference."""
    return _exact(float(np.round(float(bins), 6)), float(p_outlier))


def coherent_interval(fdot, fddot, integration_s: float, bandwidth_hz: float):
    """T_c = min(t_int, T_chirp, B / |f_dot|), s (module docstring)."""
    fdot, fddot = np.abs(np.asarray(fdot, dtype=float)), np.abs(np.asarray(fddot, dtype=float))
    with np.errstate(divide="ignore"):
        chirp = np.where(fddot > 0, np.cbrt(24.0 * CHIRP_PHASE / (math.pi * np.where(fddot > 0, fddot, 1.0))), np.inf)
        band = np.where(fdot > 0, bandwidth_hz / np.where(fdot > 0, fdot, 1.0), np.inf)
    return np.minimum(np.minimum(chirp, band), integration_s)


def drift(t, f):
    """(f_dot, f_ddot) of series f (N, ...) over increasing times t (N,): second-order finite
    differences (``numpy.gradient``, also at the ends), Hz/s and Hz/s^2."""
    t = np.asarray(t, dtype=float)
    if t.size < 3:
        z = np.zeros_like(np.asarray(f, dtype=float))
        return z, z
    fdot = np.gradient(f, t, axis=0, edge_order=2)
    return fdot, np.gradient(fdot, t, axis=0, edge_order=2)


@dataclass
class Budget:
    """One detection through one receiver, per output instant (N,) and line (N, K).

    power_sr (N, K) each line's dP/dOmega toward the antenna, erg/s/sr (what the received power
    measures, the antenna's effective area known); signal (N, K) received power, erg/s (flux
    times area; NaN outside the radiation zone);
    rho (N, K) SNR of one integration; rho_coh, t_coh, threshold (N, K) per coherent interval;
    detected (N, K) rho_coh >= threshold; radiation_zone (N, K) R >= lambda.
    Of the strongest line (index ``dominant`` (N,)): sigma_f (Hz), sigma_lnp (sigma_P / P),
    sigma_pol (rad) per integration -- inf where it is not detected, NaN outside the radiation
    zone -- its linear fraction and zone ("near", "intermediate", "radiation").
    The field at the antenna, all lines (N,): field_full_rms (the three terms),
    field_radiation_rms (the 1/R term alone), V/m.
    """

    model: str
    t: np.ndarray
    distance_cm: float
    bandwidth_hz: float
    freq: np.ndarray
    power_sr: np.ndarray
    signal: np.ndarray
    rho: np.ndarray
    rho_coh: np.ndarray
    t_coh: np.ndarray
    threshold: np.ndarray
    detected: np.ndarray
    radiation_zone: np.ndarray
    dominant: np.ndarray
    sigma_f: np.ndarray
    sigma_lnp: np.ndarray
    sigma_pol: np.ndarray
    linear: np.ndarray
    zone: np.ndarray
    field_full_rms: np.ndarray
    field_radiation_rms: np.ndarray

    def _at(self, a, i):
        return a[i, self.dominant[i]]

    def record(self, i: int) -> dict:
        """The strongest line's budget at sample ``i`` as plain numbers (None for NaN or inf)."""
        def num(x):
            x = float(x)
            return x if math.isfinite(x) else None

        f = float(self._at(self.freq, i))
        out = {"t": float(self.t[i]), "f_hz": f, "wavelength_cm": float(U.wavelength_cm(f)) if f > 0 else None,
               "zone": str(self.zone[i]), "received_w": num(self._at(self.signal, i) * U.ERG_PER_S_IN_W),
               "snr_integration": num(self._at(self.rho, i)), "snr_coherent": num(self._at(self.rho_coh, i)),
               "coherent_interval_s": num(self._at(self.t_coh, i)), "threshold": num(self._at(self.threshold, i)),
               "threshold_exact": exact_threshold(float(self._at(self.t_coh, i)) * self.bandwidth_hz),
               "detected": bool(self._at(self.detected, i)), "sigma_f_hz": num(self.sigma_f[i]),
               "sigma_f_relative": num(self.sigma_f[i] / f) if f > 0 else None, "sigma_power_relative": num(self.sigma_lnp[i]),
               "sigma_polarization_deg": num(math.degrees(self.sigma_pol[i])) if math.isfinite(self.sigma_pol[i]) else None,
               "field_full_rms_v_per_m": float(self.field_full_rms[i]),
               "field_radiation_term_rms_v_per_m": float(self.field_radiation_rms[i])}
        return out


def _line_linear_fraction(line_field) -> np.ndarray:
    """The linear fraction of each line's polarization, (N, K), from its amplitudes on (u1, u2)."""
    e1, e2 = line_field[..., 0], line_field[..., 1]
    i = np.abs(e1) ** 2 + np.abs(e2) ** 2
    q = np.abs(e1) ** 2 - np.abs(e2) ** 2
    u = 2.0 * np.real(e1 * np.conj(e2))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(i > 0, np.hypot(q, u) / np.where(i > 0, i, 1.0), 0.0)


def field_at_antenna(det: Detection, distance_cm: float) -> dict:
    """The RMS field at the antenna (V/m), all lines, (N,) each: "full" (the 1/R, 1/R^2 and 1/R^3
    terms), "radiation" (1/R alone) and "near" (1/R^2 and 1/R^3 alone), from each line's dipole
    amplitude p~ = -d_ddot~ / w^2 (``physics.dipole_field``)."""
    w = 2.0 * math.pi * det.freq
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(w[..., None] > 0, -det.line_ddot / np.where(w > 0, w, 1.0)[..., None] ** 2, 0.0)
    terms = DF.line_terms(p, det.line_of_sight, distance_cm, w / U.C_LIGHT)
    to_v = U.STATV_PER_CM_IN_V_PER_M
    return {"full": DF.rms(terms["static"] + terms["induction"] + terms["radiation"]) * to_v,
            "radiation": DF.rms(terms["radiation"]) * to_v,
            "near": DF.rms(terms["static"] + terms["induction"]) * to_v}


def budget(det: Detection, spec) -> Budget:
    """The receiver ``spec`` (``inputs.receiver.ReceiverSpec``) on detection ``det`` (CGS)."""
    if det.units != "cgs":
        raise ValueError("the receiver needs a body in physical units (CGS): a dimensionless scene has no "
                         "distances, powers or noise")
    R, n0, t_int = spec.distance_cm, spec.noise_density, spec.integration_s
    f = det.freq
    lam = np.where(f > 0, U.wavelength_cm(np.where(f > 0, f, 1.0)), np.inf)
    radiation = R >= lam
    with np.errstate(invalid="ignore"):
        signal = np.where(radiation, det.line_power_sr * spec.effective_area_cm2(np.where(f > 0, f, 1.0)) / R**2, np.nan)
    fdot, fddot = drift(det.t, f)
    t_coh = coherent_interval(fdot, fddot, t_int, spec.bandwidth_hz)
    rho = 2.0 * signal * t_int / n0
    rho_coh = 2.0 * signal * t_coh / n0
    threshold = detection_threshold(spec.bandwidth_hz * t_coh)
    detected = np.nan_to_num(rho_coh, nan=0.0) >= threshold
    k = np.argmax(det.line_power_sr, axis=1)
    rows = np.arange(f.shape[0])
    dom = (rows, k)
    linear = _line_linear_fraction(det.line_field)[dom]
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(rho[dom])
        sig_f = np.where(detected[dom], crb_tone(rho[dom], t_coh[dom]), np.inf)
        sig_p = np.where(detected[dom], 2.0 / root, np.inf)
        sig_pol = np.where(detected[dom] & (linear > 0), 1.0 / (np.where(linear > 0, linear, 1.0) * root), np.inf)
    outside = ~radiation[dom]
    sig_f, sig_p, sig_pol = (np.where(outside, np.nan, x) for x in (sig_f, sig_p, sig_pol))
    field = field_at_antenna(det, R)
    return Budget(model=det.model, t=det.t, distance_cm=R, bandwidth_hz=spec.bandwidth_hz, freq=f,
                  power_sr=det.line_power_sr, signal=signal, rho=rho,
                  rho_coh=rho_coh,
                  t_coh=t_coh, threshold=threshold, detected=detected, radiation_zone=radiation, dominant=k,
                  sigma_f=sig_f, sigma_lnp=sig_p, sigma_pol=sig_pol, linear=linear, zone=DF.zone(R, lam[dom]),
                  field_full_rms=field["full"], field_radiation_rms=field["radiation"])
