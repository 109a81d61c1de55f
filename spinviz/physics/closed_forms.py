"""The paper's closed-form solutions, each under its equation number.

Time arguments are arrays of shape (N,).  Forms written by the paper in CGS ((3.9), (6.x))
take ``tau0`` in seconds and Omega in rad/s; pass tau0 = 1 to use them in the
dimensionless variables (4.1).  Forms written dimensionless ((5.x)) take tau = t/tau0 and
omega = tau0 Omega.  Angular velocities are body-frame, returned as shape (N, 3);
Euler angles are ZXZ (phi, theta, psi) in rad, shape (N, 3) (convention of (6.4)).
"""

from __future__ import annotations

import math

import numpy as np


def _t(t):
    return np.atleast_1d(np.asarray(t, dtype=float))


def F_eq3_9(t, tau0: float, omega20: float):
    """F(t) = sqrt(1 + 2 tau0 Omega20^2 t), defined in (3.9)."""
    return np.sqrt(1.0 + 2.0 * tau0 * omega20**2 * _t(t))


def vartheta_eq6_3(t, tau0: float, omega20: float):
    """vartheta(t) = (F(t) - 1) / (tau0 Omega20^2), (6.3); computed without cancellation.

    F - 1 = x / (F + 1) with x = 2 tau0 Omega20^2 t, so vartheta = 2 t / (F + 1): exact
    also when tau0 Omega20^2 t is far below round-off (physical CGS parameters).
    """
    t = _t(t)
    return 2.0 * t / (F_eq3_9(t, tau0, omega20) + 1.0)


def omega_eq3_9(t, tau0: float, omega20: float):
    """(3.9): Omega1 = Omega3 = 0, Omega2 = Omega20 / F(t); exact for both the reduced (3.4)
    and the truncated (2.5) equation, any delta and chi (rotation about the principal
    axis e2, which is perpendicular to d)."""
    t = _t(t)
    out = np.zeros(t.shape + (3,))
    out[:, 1] = omega20 / F_eq3_9(t, tau0, omega20)
    return out


def rotation_angle_eq3_9(t, tau0: float, omega20: float):
    """Angle turned about e2 under (3.9): integral of Omega2 = Omega20 vartheta(t), rad."""
    return omega20 * vartheta_eq6_3(t, tau0, omega20)


def _decay_factor(tau, a: float, u0: float):
    """Phi of (5.2) with a = eps^2 w3^2, u0 = w20^2: Phi^2 = (kappa-1)/(kappa e^{2 a tau} - 1).

    Rewritten as 1 / (1 + kappa u0 * 2 tau * expm1(x)/x), x = 2 a tau, which is free of
    cancellation as eps -> 0 and tends to 1/F (the limit (6.1)) when a = 0.
    """
    tau = _t(tau)
    kappa = 1.0 + a / u0
    x = 2.0 * a * tau
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(x != 0.0, np.expm1(x) / np.where(x != 0.0, x, 1.0), 1.0)
    return 1.0 / np.sqrt(1.0 + kappa * u0 * 2.0 * tau * ratio)


def omega_eq5_2(tau, delta: float, omega20: float, omega30: float):
    """(5.2): reduced equation, longitudinal dipole (chi = 0), omega10 = 0; dimensionless.

    omega1 = w20 Phi sin(delta w3 tau), omega2 = w20 Phi cos(delta w3 tau), omega3 = w30,
    Phi = sqrt((kappa - 1)/(kappa e^{2 eps^2 w3^2 tau} - 1)), kappa = 1 + eps^2 w3^2 / w20^2,
    eps = 1 - delta.  Exact for any delta (also delta = 0, the spherical top).
    """
    tau = _t(tau)
    eps = 1.0 - delta
    phi = _decay_factor(tau, eps**2 * omega30**2, omega20**2)
    ph = delta * omega30 * tau
    return np.stack([omega20 * phi * np.sin(ph), omega20 * phi * np.cos(ph), np.full_like(tau, omega30)], axis=-1)


def omega_eq5_4(tau, delta: float, omega20: float, omega30: float):
    """(5.4): truncated equation, longitudinal dipole, omega10 = 0; dimensionless.

    omega1,2 = (w20/F) {sin, cos}(delta w30 (F - 1) / w20^2), omega3 = w30/F,
    F = sqrt(1 + 2 w20^2 tau).
    """
    tau = _t(tau)
    F = F_eq3_9(tau, 1.0, omega20)
    ph = delta * omega30 * vartheta_eq6_3(tau, 1.0, omega20)
    return np.stack([omega20 / F * np.sin(ph), omega20 / F * np.cos(ph), omega30 / F], axis=-1)


def omega_eq5_7(tau, delta: float, omega_inf: float, omega20: float, omega30: float):
    """(5.7): reduced equation, transverse dipole (chi = pi/2), linearized about the fixed
    point omega_inf e1 (5.6); valid while |omega2|, |omega3| << |omega_inf|; dimensionless.

    lambda2 = -w_inf^2, lambda3 = -(1 + 2 delta)/(1 - delta) w_inf^2,
    omega2 = w20 e^{l2 tau} + (1 - delta)/3 (w30 / w_inf)(e^{l3 tau} - e^{l2 tau}),
    omega3 = w30 e^{l3 tau}.  (The paper's text before (5.6) says "(5.3)"; (5.5) is meant.)
    """
    tau = _t(tau)
    l2 = -omega_inf**2
    l3 = -(1.0 + 2.0 * delta) / (1.0 - delta) * omega_inf**2
    e2, e3 = np.exp(l2 * tau), np.exp(l3 * tau)
    w2 = omega20 * e2 + (1.0 - delta) / 3.0 * omega30 / omega_inf * (e3 - e2)
    return np.stack([np.full_like(tau, omega_inf), w2, omega30 * e3], axis=-1)


def omega_eq6_1(t, tau0: float, omega20: float, omega30: float):
    """(6.1): eps -> 0 limit of (5.2) in CGS: Omega1,2 = (Omega20/F){sin, cos}(Omega3 t), Omega3 = Omega30."""
    t = _t(t)
    F = F_eq3_9(t, tau0, omega20)
    ph = omega30 * t
    return np.stack([omega20 / F * np.sin(ph), omega20 / F * np.cos(ph), np.full_like(t, omega30)], axis=-1)


def omega_eq6_2(t, tau0: float, omega20: float, omega30: float):
    """(6.2)-(6.3): eps -> 0 limit of (5.4) in CGS:
    Omega1,2 = (Omega20/F){sin, cos}(Omega30 vartheta), Omega3 = Omega30/F."""
    t = _t(t)
    F = F_eq3_9(t, tau0, omega20)
    ph = omega30 * vartheta_eq6_3(t, tau0, omega20)
    return np.stack([omega20 / F * np.sin(ph), omega20 / F * np.cos(ph), omega30 / F], axis=-1)


def euler_eq6_5(t, tau0: float, omega20: float, omega30: float):
    """(6.5): phi = Omega20 vartheta(t), theta = pi/2, psi = Omega3 t -- the Poisson
    equations (6.4) solved with (6.1), start phi = psi = 0, theta = pi/2.  Exact only as
    eps = I3/I1 -> 0: at finite eps the motion departs from it by an amount that vanishes with eps."""
    t = _t(t)
    return np.stack([omega20 * vartheta_eq6_3(t, tau0, omega20), np.full_like(t, 0.5 * np.pi), omega30 * t], axis=-1)


def euler_eq6_6(t, tau0: float, omega20: float, omega30: float):
    """(6.6): phi = Omega20 vartheta, theta = pi/2, psi = Omega30 vartheta -- (6.4) with (6.2);
    exact only as eps -> 0."""
    t = _t(t)
    v = vartheta_eq6_3(t, tau0, omega20)
    return np.stack([omega20 * v, np.full_like(t, 0.5 * np.pi), omega30 * v], axis=-1)


def omega_eq6_7(t, tau0: float, omega20: float, omega30: float):
    """(6.7): reduced equation, spherical top (delta = 0), d along e3, CGS:
    Omega1 = 0, Omega2 = Omega20 |Omega3| (Omega0^2 e^{2 tau0 Omega3^2 t} - Omega20^2)^{-1/2},
    Omega3 = Omega30.  Evaluated as (5.2) with eps = 1 (the same function, stable form)."""
    t = _t(t)
    # (5.2) at eps = 1 in CGS: a tau = tau0 Omega3^2 t and u0 tau = tau0 Omega20^2 t
    phi = _decay_factor(t, tau0 * omega30**2, tau0 * omega20**2)
    return np.stack([np.zeros_like(t), omega20 * phi, np.full_like(t, omega30)], axis=-1)


def asymptotics_eq6_8(tau0: float, omega3: float) -> dict:
    """(6.8) for t >> Theta: psi ~ 0, theta ~ exp(-tau0 Omega3^2 t), phi ~ Omega3 t.

    Returns the two numbers a check can measure: the decay rate of theta (1/s) and the
    limit of phi_dot (rad/s), with theta measured from the final rotation axis.
    """
    return {"theta_decay_rate": tau0 * omega3**2, "phi_rate": abs(omega3)}


def omega_eq6_9(t, tau0: float, omega20: float, omega30: float):
    """(6.9): truncated equation, spherical top, d along e3, CGS:
    Omega1 = 0, Omega2 = Omega20/F, Omega3 = Omega30/F."""
    t = _t(t)
    F = F_eq3_9(t, tau0, omega20)
    return np.stack([np.zeros_like(t), omega20 / F, omega30 / F], axis=-1)


def euler_eq6_10(t, tau0: float, omega20: float, omega30: float):
    """(6.10): exact solution of (6.4) with (6.9): psi = 0, theta = arctan|Omega20/Omega30|,
    phi = sign(Omega3) Omega0 vartheta(t), Omega0 = |Omega(0)|.

    The paper's form needs Omega20 Omega30 >= 0 (then Omega2 = phi_dot sin(theta) has the
    sign of Omega20).  For Omega20 Omega30 < 0 the same motion has psi = pi, returned here.
    Start: phi = 0, theta as above, psi as above; Omega(0) = (0, Omega20, Omega30).
    """
    t = _t(t)
    omega0 = math.hypot(omega20, omega30)
    theta = math.atan(abs(omega20 / omega30)) if omega30 != 0.0 else 0.5 * math.pi
    psi = 0.0 if omega20 * omega30 >= 0.0 else math.pi
    sign = 1.0 if omega30 >= 0.0 else -1.0
    phi = sign * omega0 * vartheta_eq6_3(t, tau0, omega20)
    return np.stack([phi, np.full_like(t, theta), np.full_like(t, psi)], axis=-1)


def averaged_rate_eq4_12(omega_perp, omega3, delta: float, chi: float):
    """(4.12): the reduced equation averaged over the precession phase (dimensionless).

    Returns (d omega_perp / d tau, d omega3 / d tau, d phi_bar / d tau).
    """
    n1, n3 = math.sin(chi), math.cos(chi)
    wp2, w32 = omega_perp * omega_perp, omega3 * omega3
    dwp = -(n3**2 * (wp2 + (1.0 - delta) ** 2 * w32) + 0.5 * n1**2 * (wp2 + (1.0 + delta + delta**2) * w32)) * omega_perp
    dw3 = -0.5 * n1**2 * ((2.0 + delta) * wp2 + 2.0 * w32) * omega3 / (1.0 - delta)
    return dwp, dw3, -delta * omega3


def spiral4_amplitude_sq_eq4_18(chi: float) -> float:
    """A^2 of the spiral solution "4" (4.18): omega_perp^2 tau -> A^2 as tau -> oo, corrected.

    The paper prints A^2 = 1/(2 - xi), xi = tan^2 chi, which is negative for xi > 2 and cannot be
    right.  With omega3 -> 0 faster than omega_perp, (4.12) reduces to d omega_perp / d tau =
    -(n3^2 + n1^2/2) omega_perp^3, so omega_perp^2 tau -> 1/(2 n3^2 + n1^2) = 1/(1 + n3^2)
    = (1 + xi)/(2 + xi) -- 1/(2 - n1^2): the printed xi was probably meant for n1^2.
    (Checked against the averaged and the full equations in the tests.)"""
    xi = math.tan(chi) ** 2
    return (1.0 + xi) / (2.0 + xi)
