"""The torque-free symmetric top (I1 = I2): its motion written about the fixed L_world.

In ZXZ angles taken from a frame whose z axis is L_world, the free symmetric top
(J3 = I3/I1, delta = 1 - J3) moves as

    theta_L = const,  phi_L_dot = |L|/I1 = sqrt(w_perp^2 + J3^2 w3^2),  psi_L_dot = delta w3,

with body-frame angular velocity (w_perp sin psi_L, w_perp cos psi_L, w3).  ``secular``
builds its orientation from these angles and the display re-times them (slowed spin).
"""

from __future__ import annotations

import numpy as np

from .. import rotations as R


def pose_about_L(q_L, phi, theta_L, psi, wp, w3, q_frame, with_q=True):
    """(Omega_body, q) of a symmetric top from its ZXZ angles about L (arrays over time).

    q = q_L (x) ZXZ(phi, theta_L, psi) (x) q_frame and Omega = (wp sin psi, wp cos psi, w3)
    -- the free top's p = pi/2 - psi -- taken back from the frame q_frame (e3 along d for a
    sphere; identity otherwise) to the body.  q is None unless ``with_q``.
    """
    q_frame = np.asarray(q_frame, dtype=float)
    omega = R.body_from_world(q_frame, np.stack([wp * np.sin(psi), wp * np.cos(psi), w3], axis=-1))
    if not with_q:
        return omega, None
    q = R.multiply(np.asarray(q_L, dtype=float), R.quat_from_euler_zxz(np.stack([phi, theta_L, psi], axis=-1)))
    return omega, R.multiply(q, q_frame[None, :])
