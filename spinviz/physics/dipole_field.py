"""The whole electric field of a point dipole at any distance: the radiation (1/R), induction
(1/R^2) and quasi-static (1/R^3) terms, and the zone a distance lies in.

The paper works with the radiation field alone (the Larmor power behind (2.4a) and the far
field E = (d_ddot x n) x n / (c^2 R)); a detector a few centimetres from a crystal whose line
is at 7 GHz (wavelength 4.2 cm) or 50 MHz (6 m) is not in that zone.  For a dipole p(t) at
the origin the field at r = R n is, in Gaussian units (Jackson, Classical Electrodynamics,
3rd ed., (9.18) for one frequency; its time-domain form is Jefimenko's field of a point
dipole),

    E(R n, t) = [3 n (n . p) - p] / R^3  +  [3 n (n . p_dot) - p_dot] / (c R^2)  +  [(p_ddot x n) x n] / (c^2 R)

with p and its derivatives at the retarded time t - R/c (``retarded_field``).  For one line,
p(t) = 2 Re(p~ exp(i w t)), the field is E = 2 Re(E~ exp(i w t)) with (``line_field``)

    E~ = exp(-i k R) { [3 n (n . p~) - p~] (1/R^3 + i k/R^2) + k^2 (p~ - n (n . p~)) / R },   k = w / c.

Zones (``zone``): near (k R < 1, the 1/R^3 term leads), intermediate (k R >= 1 but R below a
wavelength) and radiation (R >= lambda; there the 1/R^2 term is below 1/(2 pi) of the
radiation term and the 1/R^3 one below 1/(2 pi)^2).

Pure NumPy; any consistent units (CGS: p in statC cm, R in cm, c in cm/s, E in statV/cm).
"""

from __future__ import annotations

import math

import numpy as np

ZONES = ("near", "intermediate", "radiation")


def retarded_field(p, p_dot, p_ddot, n, R: float, c: float) -> np.ndarray:
    """E at R n from the dipole's p, p_dot, p_ddot (..., 3) at the retarded time t - R/c
    (module docstring, all three terms), (..., 3); n a unit 3-vector."""
    n = np.asarray(n, dtype=float)
    p, p_dot, p_ddot = (np.asarray(x, dtype=float) for x in (p, p_dot, p_ddot))

    def static(v):
        return 3.0 * n * np.sum(v * n, axis=-1, keepdims=True) - v

    transverse = p_ddot - n * np.sum(p_ddot * n, axis=-1, keepdims=True)       # -(p_ddot x n) x n
    return static(p) / R**3 + static(p_dot) / (c * R**2) - transverse / (c**2 * R)


def line_terms(p_amp, n, R: float, k) -> dict:
    """The three terms of one line's complex field amplitude E~ at R n (module docstring), each
    (..., 3) complex, keyed "static" (1/R^3), "induction" (1/R^2) and "radiation" (1/R); the
    common retardation phase exp(-i k R) included.  p_amp (..., 3) complex, k (...) rad per
    length (w / c)."""
    n = np.asarray(n, dtype=float)
    p = np.asarray(p_amp, dtype=complex)
    k = np.asarray(k, dtype=float)[..., None]
    phase = np.exp(-1j * k * R)
    along = np.sum(p * n, axis=-1, keepdims=True)
    static = 3.0 * n * along - p
    return {"static": phase * static / R**3, "induction": phase * 1j * k * static / R**2,
            "radiation": phase * k**2 * (p - n * along) / R}


def line_field(p_amp, n, R: float, k) -> np.ndarray:
    """One line's whole complex field amplitude E~ at R n (the sum of ``line_terms``), (..., 3)."""
    t = line_terms(p_amp, n, R, k)
    return t["static"] + t["induction"] + t["radiation"]


def rms(amplitudes) -> np.ndarray:
    """The RMS of a field 2 Re(sum_k E~_k exp(i w_k t)) of distinct lines (..., K, 3): sqrt(sum
    2 |E~_k|^2), (...)."""
    a = np.asarray(amplitudes)
    return np.sqrt(2.0 * np.sum(np.abs(a) ** 2, axis=(-2, -1)))


def zone(R: float, wavelength) -> np.ndarray:
    """The zone R lies in for a line of ``wavelength`` (same length unit): "near" (2 pi R < lambda),
    "intermediate" (R < lambda) or "radiation" (R >= lambda); (...) strings."""
    lam = np.asarray(wavelength, dtype=float)
    return np.where(R >= lam, "radiation", np.where(2.0 * math.pi * R >= lam, "intermediate", "near"))
