"""The one rotation the drawing side needs beyond ``spinviz.rotations`` (which it uses for
everything else): turning the +x glyph of an arrow onto a direction.  Quaternions are
(w, x, y, z), scalar first, unit, body -> world, as everywhere in spinviz.
"""

from __future__ import annotations

import numpy as np

from ..rotations import matrix_from_quat

__all__ = ["matrix_from_quat", "rotation_x_to"]


def rotation_x_to(v) -> np.ndarray:
    """The smallest rotation (3x3) taking +x to the direction of ``v`` (identity for v = 0;
    a half turn about z for v along -x)."""
    v = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(v))
    if n == 0.0:
        return np.eye(3)
    b = v / n
    c = float(b[0])                                   # cos of the angle from +x
    axis = np.array([0.0, -b[2], b[1]])               # x cross b
    s = float(np.linalg.norm(axis))
    if s < 1e-12:
        return np.eye(3) if c > 0 else np.diag([-1.0, -1.0, 1.0])
    k = axis / s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)    # Rodrigues
