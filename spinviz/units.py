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
M_PER_CM = 1.0e-2                # 1 cm in m (the glTF export states real sizes in metres)
HBAR = 1.054571817e-27           # reduced Planck constant, erg s (CODATA 2018, exact since 2019)
ERG_PER_S_IN_W = 1.0e-7          # 1 erg/s in W
STATV_PER_CM_IN_V_PER_M = 2.99792458e4   # 1 statV/cm in V/m (c / 1e4 in SI digits)
K_BOLTZMANN = 1.380649e-16       # Boltzmann constant, erg/K (exact since 2019)

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

    The printed (3.3)-(3.5) have c^2 where (3.8) has c^3; c^3 is right: the general reduced
    equation (2.2)+(2.3) reproduces (3.3)-(3.5) with it (``tests/test_equations.py``).
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


# --- radiation (the observables of ``physics.radiation``) ----------------------------------
# Each quantity is computed in the variables (4.1) with the coupling g = sqrt(2/3c^3) d of unit
# size, so (2/3c^3) d^2 = I1 tau0 = 1; back in CGS it carries I1^a tau0^b (and |d| for the dipole).
RADIATION_UNITS = {
    # kind: (power of I1, power of tau0, CGS unit, dimensionless unit)
    "power": (1, -3, "erg/s", "I1/tau0^3"),
    "power_per_sr": (1, -3, "erg/s/sr", "I1/tau0^3/sr"),
    "torque": (1, -2, "erg", "I1/tau0^2"),
    "energy": (1, -2, "erg", "I1/tau0^2"),
    "angular_momentum": (1, -1, "erg s", "I1/tau0"),
}
DIPOLE_UNITS = ("statC cm", "statC cm/s", "statC cm/s^2", "statC cm/s^3")


def radiation_from_dimensionless(x, kind: str, inertia1: float, tau0: float):
    """A radiation quantity of ``kind`` (a key of ``RADIATION_UNITS``) from the variables (4.1)
    (g of unit size) to CGS: times I1^a tau0^b.  Dimensionless bodies (I1 relative, tau0 = 1)
    pass through unchanged up to I1."""
    a, b, _, _ = RADIATION_UNITS[kind]
    return np.asarray(x, dtype=float) * (float(inertia1) ** a) * (float(tau0) ** b)


def radiation_unit(kind: str, units: str) -> str:
    """The unit label of a radiation quantity in a unit system ("cgs" or "dimensionless")."""
    cgs_unit, dimless_unit = RADIATION_UNITS[kind][2:]
    return cgs_unit if units == "cgs" else dimless_unit


def field_rms_from_power_per_sr(power_per_sr_cgs, distance_cm: float):
    """RMS far field, statV/cm, at ``distance_cm`` from a source radiating dP/dOmega (erg/s/sr)
    towards the observer: the Poynting flux c <E^2> / 4 pi equals dP/dOmega / R^2."""
    return np.sqrt(4.0 * math.pi * np.asarray(power_per_sr_cgs, dtype=float) / C_LIGHT) / float(distance_cm)


def format_frequency(f_hz: float) -> str:
    """A frequency in its best unit: mHz .. THz."""
    f = float(f_hz)
    a = abs(f)
    if not math.isfinite(f) or a == 0.0:
        return f"{f:.3g} Hz"
    for scale, name in ((1e12, "THz"), (1e9, "GHz"), (1e6, "MHz"), (1e3, "kHz"), (1.0, "Hz")):
        if a >= scale:
            return f"{f / scale:.4g} {name}"
    return f"{f * 1e3:.3g} mHz"


# --- receivers ----------------------------------------------------------------------------------
def gain_from_dbi(gain_dbi):
    """An antenna gain in dBi as a ratio to the isotropic antenna: 10^(dBi/10)."""
    return 10.0 ** (np.asarray(gain_dbi, dtype=float) / 10.0)


def noise_density_from_temperature(temperature_k):
    """The one-sided noise spectral density of a system at noise temperature T: N0 = k_B T, erg
    (= erg/s per Hz)."""
    return K_BOLTZMANN * np.asarray(temperature_k, dtype=float)


def erg_per_s_from_w(x_w):
    """A power (or a power spectral density, W/Hz) in erg/s (erg/s/Hz)."""
    return np.asarray(x_w, dtype=float) / ERG_PER_S_IN_W


def wavelength_cm(f_hz):
    """The free-space wavelength c / f of a line at f Hz, cm."""
    return C_LIGHT / np.asarray(f_hz, dtype=float)


# --- a trap's environment ---------------------------------------------------------------------
DYN_PER_CM2_IN_MBAR = 1.0e3      # 1 mbar = 100 Pa = 1000 dyn/cm^2


def pressure_from_mbar(p_mbar):
    """A pressure in mbar as dyn/cm^2 (erg/cm^3): 1 mbar = 1000 dyn/cm^2."""
    return np.asarray(p_mbar, dtype=float) * DYN_PER_CM2_IN_MBAR


def field_from_v_per_m(e_v_per_m):
    """An electric field in V/m as statV/cm (Gaussian): 1 statV/cm = 29979.2458 V/m."""
    return np.asarray(e_v_per_m, dtype=float) / STATV_PER_CM_IN_V_PER_M
