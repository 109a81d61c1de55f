"""Units: every conversion in spinviz lives here.

The physics core works in one of two systems, and the scene says which:

* ``"cgs"`` -- Gaussian CGS as in the paper: g, cm, s, statC; inertia in g cm^2,
  dipole in statC cm, angular velocity in rad/s, time in s.
* ``"dimensionless"`` -- the variables (4.1) of the paper, tau = t/tau0 and
  omega = tau0 * Omega, with inertia scaled by I1 so that tau0 = 1.

The integrators always see the dimensionless system: numbers stay O(1) whatever the
physical scale (tau0 = 1.4e-35 s for the cellulose rod), so nothing overflows or
underflows.  Conversion happens once on the way in and once on the way out.
"""

from __future__ import annotations

import math

import numpy as np

# --- physical constants (Gaussian CGS) -------------------------------------------------
C_LIGHT = 2.99792458e10          # speed of light, cm/s (exact)
DEBYE = 1.0e-18                  # 1 D in statC cm
AMU = 1.66053906660e-24          # atomic mass unit, g (CODATA 2018)
NM = 1.0e-7                      # 1 nm in cm

# --- time ------------------------------------------------------------------------------
MINUTE = 60.0
HOUR = 3600.0
DAY = 86400.0
YEAR = 365.25 * DAY              # Julian year, s

UNIT_SYSTEMS = ("cgs", "dimensionless")


def radiation_coupling(dipole_cgs):
    """Coupling vector g = sqrt(2 / (3 c^3)) d of the radiation torque.

    dipole_cgs : array_like, shape (3,) -- body-frame dipole, statC cm.
    Returns ndarray, shape (3,), in units with g^2 = (2/3c^3) d^2, so that the torque of
    (2.2) and (2.5) reads g x {g x ...} and tau0 (3.8) = |g|^2 / I1.
    """
    return math.sqrt(2.0 / (3.0 * C_LIGHT**3)) * np.asarray(dipole_cgs, dtype=float)


def tau0_cgs(dipole_magnitude_cgs: float, inertia1_cgs: float) -> float:
    """tau0 = 2 d^2 / (3 I1 c^3), equation (3.8); seconds.

    The printed (3.3)-(3.5) have c^2 where (3.8) has c^3; c^3 is right (DESIGN.md, 2).
    """
    return 2.0 * dipole_magnitude_cgs**2 / (3.0 * inertia1_cgs * C_LIGHT**3)


def time_to_dimensionless(t, tau0: float):
    """tau = t / tau0 (4.1)."""
    return np.asarray(t, dtype=float) / tau0


def omega_to_dimensionless(omega, tau0: float):
    """omega = tau0 * Omega (4.1); Omega in rad/s."""
    return np.asarray(omega, dtype=float) * tau0


def omega_from_dimensionless(omega, tau0: float):
    """Omega = omega / tau0 (4.1); rad/s."""
    return np.asarray(omega, dtype=float) / tau0


def deg_to_rad(x_deg):
    """Angle in degrees -> radians (degrees exist only at the scene/CLI boundary)."""
    return np.deg2rad(np.asarray(x_deg, dtype=float))


_SI_PREFIXES = ((1e-15, "fs"), (1e-12, "ps"), (1e-9, "ns"), (1e-6, "\u00b5s"), (1e-3, "ms"))


def time_in_unit(seconds: float, long_names: bool = False, years_from: float = YEAR) -> tuple[float, str]:
    """A duration of at least a second in its best unit: (value, unit) with the unit s, min, h,
    days or years ("minutes", "hours" with ``long_names``); years from ``years_from`` seconds on."""
    s = float(seconds)
    a = abs(s)
    for limit, scale, short, long in ((MINUTE, 1.0, "s", "s"), (HOUR, MINUTE, "min", "minutes"),
                                      (DAY, HOUR, "h", "hours"), (years_from, DAY, "days", "days")):
        if a < limit:
            return s / scale, long if long_names else short
    return s / YEAR, "years"


def human_time(seconds: float, digits: int = 3) -> str:
    """Best human unit for a duration in seconds: fs..ms, s, min, h, days, years.

    >>> human_time(3.0e5)
    '3.47 days'
    """
    s = float(seconds)
    if not math.isfinite(s):
        return f"{s} s"
    a = abs(s)
    if a == 0.0:
        return "0 s"
    if a < 1.0:
        for scale, name in reversed(_SI_PREFIXES):
            if a >= scale:
                return f"{s / scale:.{digits}g} {name}"
        return f"{s:.{digits}g} s"
    value, unit = time_in_unit(s)
    return f"{value:.{digits}g} {unit}"


def format_time(t: float, units: str) -> str:
    """Physical time in the best human unit (CGS), or in tau0 (dimensionless)."""
    return human_time(t) if units == "cgs" else f"{t:.4g} \u03c40"


def format_omega(w: float, units: str) -> str:
    """|Omega| in rad/s (CGS), or |omega| in 1/tau0 (dimensionless)."""
    return f"|\u03a9| = {w:.3g} rad/s" if units == "cgs" else f"|\u03c9| = {w:.3g} /\u03c40"
