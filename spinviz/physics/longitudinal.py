"""The one spectral line of a longitudinally polarized symmetric top (chi = 0) or a spherical
top: its frequency and power over time from the closed forms (5.2) (reduced) and (5.4)
(truncated), and the power-frequency laws that follow from them.

With d along the symmetry axis e3 (for a sphere any axes are principal: take e3 along d, as
section 6.2 does), the free motion turns e3 -- hence d -- about L at |L|/I1 and a fixed angle
theta_L, sin theta_L = I1 Omega_perp / |L|; the body's own precession about e3 leaves d alone.
So the top radiates one line, at the rotation frequency

    f = omega_L / 2 pi,   omega_L^2 = |L|^2 / I1^2 = Omega_perp^2 + eps^2 Omega3^2   (eps = I3/I1),

with the Larmor power (2/3c^3) d^2 sin^2 theta_L omega_L^4 = (2/3c^3) d^2 Omega_perp^2 omega_L^2
(and a constant share of it toward a detector, L being fixed in space).  In u = Omega_perp^2
and b = eps^2 Omega3^2 (rad^2/s^2), from the start (u0, b0), CGS time t and tau0 (3.8):

* reduced, (5.2) in the variables (4.1): Omega3 is constant (b = b0) and
  u(t) = u0 b / ((u0 + b) exp(2 tau0 b t) - u0);  the spherical top's (6.7) is eps = 1;
* truncated, (5.4): u = u0 / F^2, b = b0 / F^2, F^2 = 1 + 2 tau0 u0 t (3.9); the sphere's (6.9).

Eliminating t gives the laws a detector can test without knowing the start:

* truncated: u / omega_L^2 = sin^2 theta_L stays at its start value, so P = K f^4;
* reduced:   P = K f^2 (f^2 - f_inf^2) with f_inf = sqrt(b) / 2 pi = eps |Omega3| / 2 pi, the line
  the reduced top levels off at (5 GHz for the DAST cube of section 6.2 spun at pi 1e10 rad/s).

Pure NumPy, vectorized over any broadcastable shapes.  Each model's ``models.LineLaw`` holds
its state and law from here, so a caller asks the model (``models.get(name).line``).
"""

from __future__ import annotations

import math

import numpy as np


def has_line_law(delta: float, chi: float, symmetric: bool, tol: float = 1e-9) -> bool:
    """Whether a top has the one line and the P-f laws of this module: a symmetric top with d
    along its axis (chi = 0 or pi) or a spherical top (delta = 0)."""
    if not symmetric:
        return False
    return abs(delta) <= tol or min(abs(chi), abs(math.pi - chi)) <= tol


def start_state(omega_body, dipole_direction, epsilon: float) -> tuple[float, float]:
    """(u0, b0) = (Omega_perp^2, eps^2 Omega_par^2) of a start Omega (3,) (body frame, rad/s) about
    the unit dipole (body frame): Omega_par along d, Omega_perp across it."""
    w = np.asarray(omega_body, dtype=float)
    n = np.asarray(dipole_direction, dtype=float)
    par = float(w @ n)
    perp = w - par * n
    return float(perp @ perp), float(epsilon**2 * par**2)


def _arrays(*a):
    """Float arrays, or complex ones where a value is complex (``decide`` differentiates the
    states by complex steps)."""
    return tuple(np.asarray(x, dtype=complex if np.iscomplexobj(x) else float) for x in a)


def reduced_state(t, u0, b0, tau0):
    """(u, b) at times t (s) from the start (u0, b0) (rad^2/s^2) under (5.2); everything
    broadcasts.  Evaluated as u0 / (1 + 2 tau0 (u0 + b) t expm1(x)/x), x = 2 tau0 b t, which
    keeps its b -> 0 limit (3.9) (x below 1e-8: its series 1 + x/2)."""
    t, u0, b0, tau0 = _arrays(t, u0, b0, tau0)
    x = 2.0 * tau0 * b0 * t
    small = np.abs(x) < 1e-8
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):     # expm1 -> inf: u -> 0, its limit
        ratio = np.where(small, 1.0 + 0.5 * x, np.expm1(x) / np.where(small, 1.0, x))
    u = u0 / (1.0 + 2.0 * tau0 * (u0 + b0) * t * ratio)
    return u, np.broadcast_to(b0, u.shape)


def truncated_state(t, u0, b0, tau0):
    """(u, b) at times t (s) from the start (u0, b0) (rad^2/s^2) under (5.4): both fall as
    1/F^2, F^2 = 1 + 2 tau0 u0 t; everything broadcasts."""
    t, u0, b0, tau0 = _arrays(t, u0, b0, tau0)
    F2 = 1.0 + 2.0 * tau0 * u0 * t
    return u0 / F2, b0 / F2


def reduced_drift(u, b, tau0):
    """(df/dt / f, d2f/dt2 / f) of the reduced line (5.2): -tau0 u and tau0^2 u (3u + 2b)."""
    return -tau0 * u, tau0 * tau0 * u * (3.0 * u + 2.0 * b)


def truncated_drift(u, b, tau0):
    """(df/dt / f, d2f/dt2 / f) of the truncated line (5.4): -tau0 u and 3 tau0^2 u^2."""
    return -tau0 * u, 3.0 * tau0 * tau0 * u * u


def line_from_state(u, b):
    """(f, shape): the line's frequency f = omega_L / 2 pi (Hz) and its power up to a constant,
    shape = Omega_perp^2 omega_L^2 (rad^4/s^4), of the state (u, b)."""
    w2 = u + b
    return np.sqrt(w2) / (2.0 * math.pi), u * w2


def reduced_law(f, f_inf=0.0):
    """The reduced P-f law up to a constant: f^2 (f^2 - f_inf^2)."""
    f = np.asarray(f, dtype=float)
    return f**2 * (f**2 - np.asarray(f_inf, dtype=float) ** 2)


def truncated_law(f, f_inf=0.0):
    """The truncated P-f law up to a constant: f^4 (``f_inf`` is ignored: the line does not level off)."""
    return np.asarray(f, dtype=float) ** 4
