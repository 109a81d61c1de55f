"""Small rotation helpers in plain NumPy for the drawing side.

The render workers import only what drawing needs: ``spinviz.rotations`` wraps
numpy-quaternion, whose import pulls in numba and scipy (about 1.5 s per worker on this
machine), so the few formulas the session uses are written out here.  Quaternions are
(w, x, y, z), scalar first, unit, body -> world, as everywhere in spinviz.
"""

from __future__ import annotations

import numpy as np


def matrix_from_quat(q) -> np.ndarray:
    """Rotation matrix of a unit quaternion (w, x, y, z): shape (..., 4) -> (..., 3, 3)."""
    q = np.asarray(q, dtype=float)
    w, x, y, z = np.moveaxis(q, -1, 0)
    m = np.empty(q.shape[:-1] + (3, 3))
    m[..., 0, 0] = 1 - 2 * (y * y + z * z)
    m[..., 0, 1] = 2 * (x * y - w * z)
    m[..., 0, 2] = 2 * (x * z + w * y)
    m[..., 1, 0] = 2 * (x * y + w * z)
    m[..., 1, 1] = 1 - 2 * (x * x + z * z)
    m[..., 1, 2] = 2 * (y * z - w * x)
    m[..., 2, 0] = 2 * (x * z - w * y)
    m[..., 2, 1] = 2 * (y * z + w * x)
    m[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return m


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
