"""The harmonics of the symmetric top's radiation torque and the averaged flows' coefficients,
per model: the data of ``models.Averaged`` (``physics.averaged`` explains and uses them).

Dimensionless (4.1): J = (1, 1, 1 - delta), d = (n1, 0, n3), z = omega1 + i omega2.  Each term
(m, j, k, l, c(delta, n1, n3)) is the monomial c z^j zb^k w3^l of the radiation part of z' or
omega3' (m = j - k, the harmonic it turns with); ``tests/test_averaged.py`` rebuilds every
table from the models' own rates by a Fourier transform over the precession phase.
"""

from __future__ import annotations

import math

from . import asymptotics as FM
from . import closed_forms as CF

# reduced (4.2)-(4.4): exactly cubic
REDUCED = {
    "z": (
        (-1, 1, 2, 0, lambda d, a, b: 0.5 * a * a),
        (-1, 0, 1, 2, lambda d, a, b: 0.5 * a * a * (d * d + d + 1.0)),
        (0, 1, 1, 1, lambda d, a, b: 0.5 * a * b * (d + 2.0)),
        (0, 0, 0, 3, lambda d, a, b: a * b),
        (1, 2, 1, 0, lambda d, a, b: -0.5 * a * a - b * b),
        (1, 1, 0, 2, lambda d, a, b: -(b * b * (1.0 - d) ** 2 + 0.5 * a * a * (1.0 + d + d * d))),
        (2, 2, 0, 1, lambda d, a, b: 1.5 * d * a * b),
    ),
    "w3": (
        (-2, 0, 2, 1, lambda d, a, b: 0.75 * d * a * a / (d - 1.0)),
        (-1, 1, 2, 0, lambda d, a, b: -a * b / (2.0 * d - 2.0)),
        (-1, 0, 1, 2, lambda d, a, b: 0.5 * a * b * (1.0 - d)),
        (0, 1, 1, 1, lambda d, a, b: 0.5 * a * a * (d + 2.0) / (d - 1.0)),
        (0, 0, 0, 3, lambda d, a, b: a * a / (d - 1.0)),
        (1, 2, 1, 0, lambda d, a, b: -a * b / (2.0 * d - 2.0)),
        (1, 1, 0, 2, lambda d, a, b: 0.5 * a * b * (1.0 - d)),
        (2, 2, 0, 1, lambda d, a, b: 0.75 * d * a * a / (d - 1.0)),
    ),
}

# truncated (2.5): its cubic, leading order in |omega|
TRUNCATED = {
    "z": (
        (-1, 1, 2, 0, lambda d, a, b: 0.25 * a * a),
        (-1, 0, 1, 2, lambda d, a, b: -0.5 * d * a * a),
        (0, 1, 1, 1, lambda d, a, b: a * b * (d + 1.0)),
        (1, 2, 1, 0, lambda d, a, b: -0.5 * a * a - b * b),
        (1, 1, 0, 2, lambda d, a, b: -0.5 * a * a * (d + 2.0)),
        (2, 2, 0, 1, lambda d, a, b: a * b),
        (3, 3, 0, 0, lambda d, a, b: 0.25 * a * a),
    ),
    "w3": (
        (-2, 0, 2, 1, lambda d, a, b: -a * a / (4.0 * d - 4.0)),
        (-1, 0, 1, 2, lambda d, a, b: 0.5 * a * b * (d - 2.0) / (d - 1.0)),
        (0, 1, 1, 1, lambda d, a, b: (-d * b * b + 0.5 * a * a + b * b) / (d - 1.0)),
        (0, 0, 0, 3, lambda d, a, b: a * a / (d - 1.0)),
        (1, 1, 0, 2, lambda d, a, b: 0.5 * a * b * (d - 2.0) / (d - 1.0)),
        (2, 2, 0, 1, lambda d, a, b: -a * a / (4.0 * d - 4.0)),
    ),
}


def reduced_coefficients(delta: float, chi: float) -> tuple[float, float, float, float]:
    """(P, Q, R, S) of the reduced averaged flow (4.12): d wp/dtau = -wp (P wp^2 + Q w3^2),
    d w3/dtau = -w3 (R wp^2 + S w3^2), read off the paper's printed form
    (``closed_forms.averaged_rate_eq4_12``) at unit amplitudes:
    P = n3^2 + n1^2/2, Q = n3^2 (1 - delta)^2 + n1^2 (1 + delta + delta^2)/2,
    R = n1^2 (2 + delta)/(2 (1 - delta)), S = n1^2/(1 - delta)."""
    P = -CF.averaged_rate_eq4_12(1.0, 0.0, delta, chi)[0]
    S = -CF.averaged_rate_eq4_12(0.0, 1.0, delta, chi)[1]
    dwp, dw3, _ = CF.averaged_rate_eq4_12(1.0, 1.0, delta, chi)
    return P, -dwp - P, -dw3 - S, S


def truncated_coefficients(delta: float, chi: float) -> tuple[float, float, float, float]:
    """(P, Q, R, S) of the truncated averaged flow, spinviz's derivation from (2.5)
    (``asymptotics.truncated_averaged``, which states the flow through its late states:
    T4_A2 = 1/(2P), T4_beta = -R/(2P), T2_B2 = 1/(2S), T2_alpha = -Q/(2S))."""
    t = FM.truncated_averaged(delta, chi)
    P = 1.0 / (2.0 * t["T4_A2"])
    R = -2.0 * P * t["T4_beta"]
    if not math.isfinite(t["T2_B2"]):              # chi = 0: no n1, no S, no Q
        return P, 0.0, R, 0.0
    S = 1.0 / (2.0 * t["T2_B2"])
    return P, -2.0 * S * t["T2_alpha"], R, S
