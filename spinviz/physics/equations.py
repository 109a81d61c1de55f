"""Equations of motion: reduced (2.2)+(2.3), truncated (2.5), free, and the kinematics.

All three Euler equations are written for any diagonal inertia J = (J1, J2, J3) and any
body-frame radiation coupling vector g = sqrt(2 / (3 c^3)) d, so the torque of the paper,
(2/3c^3) d x {...}, reads g x {...}.  The same formulas serve both unit systems:

* CGS: J = (I1, I2, I3) in g cm^2, g = sqrt(2/3c^3) d, Omega in rad/s, t in s;
* dimensionless (4.1): J = (1, I2/I1, I3/I1), g = d/|d| (unit), so tau0 = |g|^2/J1 = 1.

The rate functions take and return components ``(w1, w2, w3)``.  Written component-wise,
one implementation works on Python floats (the fast path inside the ODE right-hand
side, free of NumPy's per-call overhead on 3-vectors), on NumPy arrays of any shape
(vectorized evaluation along a trajectory) and on complex numbers (exact Jacobians by
complex-step differentiation, see ``models.jacobian``).  The models by name -- which rate
is which equation, and what else spinviz knows of each -- are ``physics.models``.
"""

from __future__ import annotations

import numpy as np

from ..rotations import world_from_body


def free_rate(w1, w2, w3, J, g):
    """Omega_dot of the torque-free top (2.3a): -J^-1 (Omega x J Omega).  ``g`` is ignored."""
    J1, J2, J3 = J
    L1, L2, L3 = J1 * w1, J2 * w2, J3 * w3
    return -(w2 * L3 - w3 * L2) / J1, -(w3 * L1 - w1 * L3) / J2, -(w1 * L2 - w2 * L1) / J3


def reduced_terms(w1, w2, w3, J, g, free):
    """Omega_dot of the reduced Euler equation: (2.2) with (2.3a), (2.3b) on the right.

    J Omega_dot + Omega x J Omega = g x { g x (Omega^2 Omega - Omega_ddot)
                                        + (g . Omega_dot) Omega + 2 (g . Omega) Omega_dot },

    with Omega_dot, Omega_ddot on the right replaced by their free-motion values.
    ``free`` = 1 gives the whole rate; ``free`` = 0 only the radiation part J^-1 torque, which
    for real particles is 1e-16 of the free part and would drown in its round-off if the two
    were summed first (the averaged slow flow needs it alone).
    """
    J1, J2, J3 = J
    g1, g2, g3 = g
    # Cross products are written out (no helper calls) so that numba can compile this
    # very function for the integrator kernels: one source for every caller.
    L1, L2, L3 = J1 * w1, J2 * w2, J3 * w3
    c1, c2, c3 = w2 * L3 - w3 * L2, w3 * L1 - w1 * L3, w1 * L2 - w2 * L1   # Omega x J Omega
    a1, a2, a3 = -c1 / J1, -c2 / J2, -c3 / J3                               # (2.3a)
    # (2.3b): Omega_ddot = -J^-1 (Omega_dot x J Omega + Omega x J Omega_dot)
    K1, K2, K3 = J1 * a1, J2 * a2, J3 * a3
    b1 = -((a2 * L3 - a3 * L2) + (w2 * K3 - w3 * K2)) / J1
    b2 = -((a3 * L1 - a1 * L3) + (w3 * K1 - w1 * K3)) / J2
    b3 = -((a1 * L2 - a2 * L1) + (w1 * K2 - w2 * K1)) / J3
    w_sq = w1 * w1 + w2 * w2 + w3 * w3
    ga = g1 * a1 + g2 * a2 + g3 * a3
    gw2 = 2.0 * (g1 * w1 + g2 * w2 + g3 * w3)
    p1, p2, p3 = w_sq * w1 - b1, w_sq * w2 - b2, w_sq * w3 - b3
    h1 = g2 * p3 - g3 * p2 + ga * w1 + gw2 * a1
    h2 = g3 * p1 - g1 * p3 + ga * w2 + gw2 * a2
    h3 = g1 * p2 - g2 * p1 + ga * w3 + gw2 * a3
    n1, n2, n3 = g2 * h3 - g3 * h2, g3 * h1 - g1 * h3, g1 * h2 - g2 * h1   # radiation torque
    return (n1 - free * c1) / J1, (n2 - free * c2) / J2, (n3 - free * c3) / J3


def truncated_terms(w1, w2, w3, J, g, free):
    """Omega_dot of the truncated Euler equation (2.5), solved exactly for Omega_dot.

    J Omega_dot + Omega x J Omega = -{ |g x Omega|^2 Omega + (g . (Omega x Omega_dot)) g }.
    Since g . (Omega x Omega_dot) = (g x Omega) . Omega_dot, this is
    (J + g v^T) Omega_dot = r with v = g x Omega, r = -Omega x J Omega - |v|^2 Omega,
    a rank-one update of J, inverted by Sherman-Morrison:
    Omega_dot = J^-1 r - J^-1 g (v . J^-1 r) / (1 + v . J^-1 g).
    The denominator vanishes only when |tau0 Omega| is of order 1, far outside any
    physical regime; ``truncated_singularity`` reports how close a state is.
    ``free`` = 0 drops the free part -J^-1 (Omega x J Omega) (it stays inside v . J^-1 r,
    where it belongs to the torque's (g . (Omega x Omega_dot)) g term).
    """
    J1, J2, J3 = J
    g1, g2, g3 = g
    L1, L2, L3 = J1 * w1, J2 * w2, J3 * w3
    f1, f2, f3 = -(w2 * L3 - w3 * L2) / J1, -(w3 * L1 - w1 * L3) / J2, -(w1 * L2 - w2 * L1) / J3   # free rate
    v1, v2, v3 = g2 * w3 - g3 * w2, g3 * w1 - g1 * w3, g1 * w2 - g2 * w1   # g x Omega
    v_sq = v1 * v1 + v2 * v2 + v3 * v3
    s1, s2, s3 = -v_sq * w1 / J1, -v_sq * w2 / J2, -v_sq * w3 / J3
    u1, u2, u3 = g1 / J1, g2 / J2, g3 / J3
    k = (v1 * (f1 + s1) + v2 * (f2 + s2) + v3 * (f3 + s3)) / (1.0 + v1 * u1 + v2 * u2 + v3 * u3)
    return free * f1 + s1 - k * u1, free * f2 + s2 - k * u2, free * f3 + s3 - k * u3


def free_terms(w1, w2, w3, J, g, free):
    """The torque-free rate times ``free`` (its radiation part is zero)."""
    a1, a2, a3 = free_rate(w1, w2, w3, J, g)
    return free * a1, free * a2, free * a3


def reduced_rate(w1, w2, w3, J, g):
    """Omega_dot of the reduced Euler equation (2.2)+(2.3); see ``reduced_terms``."""
    return reduced_terms(w1, w2, w3, J, g, 1.0)


def truncated_rate(w1, w2, w3, J, g):
    """Omega_dot of the truncated Euler equation (2.5); see ``truncated_terms``."""
    return truncated_terms(w1, w2, w3, J, g, 1.0)


def truncated_singularity(w1, w2, w3, J, g):
    """1 + (g x Omega) . J^-1 g, the Sherman-Morrison denominator of ``truncated_rate``.

    It equals det(J + g (g x Omega)^T) / det J; (2.5) cannot be solved for Omega_dot where
    it is 0.  Dimensionless it is 1 + O(|omega|), so it matters only for |omega| ~ 1.
    """
    J1, J2, J3 = J
    g1, g2, g3 = g
    v1, v2, v3 = g2 * w3 - g3 * w2, g3 * w1 - g1 * w3, g1 * w2 - g2 * w1
    return 1.0 + v1 * g1 / J1 + v2 * g2 / J2 + v3 * g3 / J3


def symmetric_reduced_rate(w1, w2, w3, delta, n1, n3):
    """(4.2)-(4.4): the reduced equation of the symmetric top J = (1, 1, 1 - delta) with the
    coupling g = (n1, 0, n3) in the e1-e3 plane (dimensionless (4.1): n1 = sin chi, n3 = cos chi;
    any |g| in spin units, the torque scaling with |g|^2), solved for omega_dot.

    The paper's own form of (2.2)+(2.3) for this body (with the c^2 of (3.3)-(3.5) read as c^3),
    written out (59 heyoka operations against 91 for ``reduced_terms`` with these J and g: the
    atlas integrates this one); ``tests/test_equations.py`` checks it against the general rate.
    """
    w_sq = w1 * w1 + w2 * w2 + w3 * w3
    wa = w_sq + delta * (delta - 2.0) * w3 * w3          # omega_a^2
    wb = w_sq + delta * (2.0 * w1 * w1 - w2 * w2)        # omega_b^2
    wc = w_sq + delta * (delta + 1.0) * w3 * w3          # omega_c^2
    a1 = delta * w2 * w3 - n3 * n3 * wa * w1 + n1 * n3 * wb * w3
    a2 = -delta * w1 * w3 - (n1 * n1 * wc + n3 * n3 * wa - 3.0 * n1 * n3 * delta * w1 * w3) * w2
    a3 = (n1 * n3 * wa * w1 - n1 * n1 * wb * w3) / (1.0 - delta)
    return a1, a2, a3


def symmetric_truncated_rate(w1, w2, w3, delta, n1, n3):
    """The truncated equation (2.5) of the same symmetric top, solved for omega_dot: the
    analogue of (4.2)-(4.4) the paper does not print (spinviz's derivation, checked against
    ``truncated_terms`` in ``tests/test_equations.py``).

    With J = (1, 1, 1 - delta), g = (n1, 0, n3): Omega x J Omega = (-delta w2 w3, delta w1 w3, 0);
    v = g x omega = (-n3 w2, n3 w1 - n1 w3, n1 w2); J^-1 g = (n1, 0, n3/(1 - delta)), so
    v . J^-1 g = n1 n3 delta w2 / (1 - delta); and omega_dot = f + s - k J^-1 g with the free
    rate f = (delta w2 w3, -delta w1 w3, 0), s = -|v|^2 J^-1 omega and
    k = v . (f + s) / (1 + v . J^-1 g) (Sherman-Morrison, as in ``truncated_terms``).
    """
    e = 1.0 - delta
    v1, v2, v3 = -n3 * w2, n3 * w1 - n1 * w3, n1 * w2
    v_sq = v1 * v1 + v2 * v2 + v3 * v3
    f1, f2 = delta * w2 * w3, -delta * w1 * w3
    s1, s2, s3 = -v_sq * w1, -v_sq * w2, -v_sq * w3 / e
    k = (v1 * (f1 + s1) + v2 * (f2 + s2) + v3 * s3) / (1.0 + n1 * n3 * delta * w2 / e)
    return f1 + s1 - k * n1, f2 + s2, s3 - k * n3 / e


def quat_rate(q0, q1, q2, q3, w1, w2, w3):
    """q_dot = 1/2 q (x) (0, Omega_body), scalar-first q = (w, x, y, z); O = R(q) body->world."""
    return (
        -0.5 * (q1 * w1 + q2 * w2 + q3 * w3),
        0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
        0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
        0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
    )


def euler_zxz_rate(phi, theta, psi, w1, w2, w3, sin=np.sin, cos=np.cos):
    """The Poisson equations (6.4): (phi_dot, theta_dot, psi_dot) from body Omega.

    Singular at sin(theta) = 0 -- kept as the comparison the quaternion kinematics
    replaces; integrating it near theta = 0 blows up (see ``spinviz stress``).
    ``sin``, ``cos``: the functions to use (NumPy's; heyoka's when building a Taylor system).
    """
    s, c = sin(psi), cos(psi)
    a = w1 * s + w2 * c
    st = sin(theta)
    return a / st, w1 * c - w2 * s, w3 - a * cos(theta) / st


def is_symmetric(inertia) -> bool:
    """I1 = I2 to 1e-12 relative: the paper's symmetric top, e3 the symmetry axis (for a
    Body in g cm^2 and for a System's relative moments alike)."""
    I1, I2 = float(inertia[0]), float(inertia[1])
    return abs(I1 - I2) <= 1e-12 * max(abs(I1), abs(I2))


def kinetic_energy(omega_body, J) -> np.ndarray:
    """Rotational kinetic energy E = 1/2 Omega . J Omega.

    Parameters
    ----------
    omega_body : array_like, shape (..., 3)
        Body-frame angular velocity, rad/s (CGS) or 1/tau0 (4.1).
    J : sequence of 3 float
        Principal moments, g cm^2 (or relative to I1).

    Returns
    -------
    ndarray, shape (...)
        E, erg (or I1/tau0^2).
    """
    omega_body = np.asarray(omega_body, dtype=float)
    return 0.5 * np.sum(np.asarray(J) * omega_body * omega_body, axis=-1)


def angular_momentum_world(q, omega_body, J) -> np.ndarray:
    """Angular momentum in the world frame, L_world = O J Omega_body.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit quaternions (w, x, y, z), scalar first, of O = R_world_from_body.
    omega_body : array_like, shape (..., 3)
        Body-frame angular velocity, rad/s (CGS) or 1/tau0 (4.1).
    J : sequence of 3 float
        Principal moments, g cm^2 (or relative to I1).

    Returns
    -------
    ndarray, shape (..., 3)
        L_world, g cm^2/s (or I1/tau0).
    """
    return world_from_body(q, np.asarray(J) * np.asarray(omega_body, dtype=float))
