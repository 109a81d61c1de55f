"""Quaternion and SO(3) maths, in plain NumPy (numpy-quaternion for interchange, loaded lazily).

Conventions (docs/design.md, "Conventions"):

* quaternions are scalar-first float arrays, shape (..., 4), ordered (w, x, y, z);
  ``as_quaternion_array`` / ``as_float_quat`` convert to and from numpy-quaternion's
  ``quaternion`` dtype for callers who work with it;
* ``q`` represents O = R(q), the rotation that maps body-frame vectors to the world
  frame (r = O rho, as in section 2 of the paper), so ``world_from_body(q, v)`` = O v;
* q and -q are the same rotation: compare rotations with ``misorientation`` or
  ``allclose_up_to_sign``, never element by element;
* ZXZ Euler angles (phi, theta, psi) in radians with O = Rz(phi) Rx(theta) Rz(psi), the
  convention of the Poisson equations (6.4) (``tests/test_rotations.py`` checks it against them).

This module knows no physics and no rendering, and imports nothing but NumPy: the products,
matrices, exponentials and slerp below are a few vectorized lines each, while importing
numpy-quaternion loads numba and scipy (0.3-1.2 s), which the simulation path, the render
workers and ``import spinviz.physics`` must not pay.  numpy-quaternion is loaded only for
interchange and for the matrix -> quaternion conversion (its branch-free Shepperd method).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "as_quaternion_array",
    "as_float_quat",
    "normalize",
    "multiply",
    "conjugate",
    "exp_rotvec",
    "quat_from_axis_angle",
    "quat_from_euler_zxz",
    "euler_zxz_from_quat",
    "unwrap_euler_zxz",
    "matrix_from_quat",
    "quat_from_matrix",
    "world_from_body",
    "body_from_world",
    "misorientation",
    "quat_between",
    "angle_between",
    "euler_zxz_about",
    "allclose_up_to_sign",
    "unflip",
    "slerp_series",
]


def as_quaternion_array(q):
    """Float array (..., 4) (w, x, y, z) -> numpy-quaternion array (...) (loads numpy-quaternion)."""
    import quaternion as _nq

    q = np.asarray(q, dtype=float)
    if q.shape[-1] != 4:
        raise ValueError(f"quaternion array must have last axis of length 4 (w, x, y, z); got shape {q.shape}")
    return _nq.as_quat_array(np.ascontiguousarray(q))


def as_float_quat(qa) -> np.ndarray:
    """numpy-quaternion array (...) -> float array (..., 4), (w, x, y, z)."""
    import quaternion as _nq

    return _nq.as_float_array(qa)


def normalize(q) -> np.ndarray:
    """Unit quaternion(s) q / |q|; q shape (..., 4), (w, x, y, z).  Scaled by its largest
    component first, so |q| cannot overflow (1e308 components) or underflow (1e-320)."""
    q = np.asarray(q, dtype=float)
    q = q / np.max(np.abs(q), axis=-1, keepdims=True)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def multiply(a, b) -> np.ndarray:
    """Hamilton product a (x) b of float quaternions, shapes (..., 4) broadcast, (w, x, y, z)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    for q in (a, b):
        if q.shape[-1:] != (4,):
            raise ValueError(f"quaternion array must have last axis of length 4 (w, x, y, z); got shape {q.shape}")
    a0, a1, a2, a3 = np.moveaxis(a, -1, 0)
    b0, b1, b2, b3 = np.moveaxis(b, -1, 0)
    return np.stack([a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
                     a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
                     a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
                     a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0], axis=-1)


def conjugate(q) -> np.ndarray:
    """Conjugate (w, -x, -y, -z); the inverse rotation of a unit quaternion."""
    q = np.array(q, dtype=float, copy=True)
    q[..., 1:] *= -1.0
    return q


def exp_rotvec(rotvec) -> np.ndarray:
    """Unit quaternion exp(rotvec / 2): rotation by |rotvec| rad about rotvec.

    rotvec : array_like, shape (..., 3), rad.  Returns shape (..., 4), (w, x, y, z).
    Exact for any angle: sin(a/2)/a is taken from its Taylor series below a = 1e-4, where
    the division would lose digits (and at a = 0 would divide by zero).
    """
    rotvec = np.asarray(rotvec, dtype=float)
    a = np.linalg.norm(rotvec, axis=-1)
    small = a < 1e-4
    safe = np.where(small, 1.0, a)
    s = np.where(small, 0.5 - a * a / 48.0, np.sin(0.5 * safe) / safe)
    return np.concatenate([np.cos(0.5 * a)[..., None], s[..., None] * rotvec], axis=-1)


def quat_from_axis_angle(axis, angle) -> np.ndarray:
    """Rotation by ``angle`` (rad, shape (...)) about the fixed unit ``axis`` (shape (3,)).

    Returns shape (..., 4), (w, x, y, z).
    """
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    half = 0.5 * np.asarray(angle, dtype=float)
    out = np.empty(half.shape + (4,))
    out[..., 0] = np.cos(half)
    out[..., 1:] = np.sin(half)[..., None] * axis
    return out


def quat_from_euler_zxz(angles) -> np.ndarray:
    """Quaternion of O = Rz(phi) Rx(theta) Rz(psi), the ZXZ convention of (6.4).

    angles : array_like, shape (..., 3) -- (phi, theta, psi) in rad.
    Returns shape (..., 4), (w, x, y, z), with
    q = (cos(theta/2) cos((phi+psi)/2), sin(theta/2) cos((phi-psi)/2),
         sin(theta/2) sin((phi-psi)/2), cos(theta/2) sin((phi+psi)/2)).
    """
    a = np.asarray(angles, dtype=float)
    if a.shape[-1:] != (3,):
        raise ValueError(f"Euler angles must have last axis of length 3 (phi, theta, psi); got shape {a.shape}")
    phi, theta, psi = a[..., 0], a[..., 1], a[..., 2]
    qz_phi = quat_from_axis_angle((0.0, 0.0, 1.0), phi)
    qx_theta = quat_from_axis_angle((1.0, 0.0, 0.0), theta)
    qz_psi = quat_from_axis_angle((0.0, 0.0, 1.0), psi)
    return multiply(multiply(qz_phi, qx_theta), qz_psi)


def euler_zxz_from_quat(q) -> np.ndarray:
    """ZXZ Euler angles (phi, theta, psi), rad, of O = R(q); inverse of ``quat_from_euler_zxz``.

    q : array_like, shape (..., 4), (w, x, y, z); need not be normalized.
    Returns shape (..., 3) with theta in [0, pi] and phi, psi in (-pi, pi].

    Uses atan2 on the closed form of ``quat_from_euler_zxz`` (no arccos, so theta keeps
    full precision near 0 and pi).  At theta = 0 only phi + psi is defined and at
    theta = pi only phi - psi: there psi is set to 0 -- the singularity of the
    angles themselves, the reason (6.4) breaks down there and quaternions do not.
    """
    q = np.asarray(q, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    c = np.hypot(w, z)                    # |cos(theta/2)|
    s = np.hypot(x, y)                    # |sin(theta/2)|
    theta = 2.0 * np.arctan2(s, c)
    sum_ = 2.0 * np.arctan2(z, w)         # phi + psi  (mod 2 pi, up to the q -> -q sign)
    diff = 2.0 * np.arctan2(y, x)         # phi - psi
    tiny = 1e-15 * np.hypot(c, s)
    sum_ = np.where(c > tiny, sum_, diff)   # theta = pi: put everything in phi
    diff = np.where(s > tiny, diff, sum_)   # theta = 0:  put everything in phi
    phi = 0.5 * (sum_ + diff)
    psi = 0.5 * (sum_ - diff)
    out = np.stack([phi, theta, psi], axis=-1)
    # wrap phi, psi into (-pi, pi]
    out[..., 0] = _wrap(out[..., 0])
    out[..., 2] = _wrap(out[..., 2])
    return out


def _wrap(a):
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


def unwrap_euler_zxz(angles) -> np.ndarray:
    """Unwrap phi and psi of a time series of ZXZ angles, shape (N, 3), along axis 0."""
    out = np.array(angles, dtype=float, copy=True)
    out[:, 0] = np.unwrap(out[:, 0])
    out[:, 2] = np.unwrap(out[:, 2])
    return out


def matrix_from_quat(q) -> np.ndarray:
    """Rotation matrix O = R(q), shape (..., 3, 3); q shape (..., 4), (w, x, y, z), normalized here."""
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] != (4,):
        raise ValueError(f"quaternion array must have last axis of length 4 (w, x, y, z); got shape {q.shape}")
    w, x, y, z = np.moveaxis(q, -1, 0)
    s = 2.0 / (w * w + x * x + y * y + z * z)
    m = np.empty(q.shape[:-1] + (3, 3))
    m[..., 0, 0] = 1.0 - s * (y * y + z * z)
    m[..., 0, 1] = s * (x * y - w * z)
    m[..., 0, 2] = s * (x * z + w * y)
    m[..., 1, 0] = s * (x * y + w * z)
    m[..., 1, 1] = 1.0 - s * (x * x + z * z)
    m[..., 1, 2] = s * (y * z - w * x)
    m[..., 2, 0] = s * (x * z - w * y)
    m[..., 2, 1] = s * (y * z + w * x)
    m[..., 2, 2] = 1.0 - s * (x * x + y * y)
    return m


def quat_from_matrix(m) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation matrix, shape (..., 3, 3) -> (..., 4)
    (numpy-quaternion's conversion, loaded here)."""
    import quaternion as _nq

    return as_float_quat(_nq.from_rotation_matrix(np.asarray(m, dtype=float)))


def world_from_body(q, v_body) -> np.ndarray:
    """O v: body-frame vectors to the world frame.

    q : shape (..., 4), (w, x, y, z); v_body : shape (..., 3); leading axes broadcast
    pairwise (one quaternion per vector), unlike ``quaternion.rotate_vectors``.
    """
    m = matrix_from_quat(q)
    return np.einsum("...ij,...j->...i", m, np.asarray(v_body, dtype=float))


def body_from_world(q, v_world) -> np.ndarray:
    """O^T v: world-frame vectors to the body frame (pairwise broadcasting as above)."""
    m = matrix_from_quat(q)
    return np.einsum("...ji,...j->...i", m, np.asarray(v_world, dtype=float))


def quat_between(a, b) -> np.ndarray:
    """The smallest rotation (w, x, y, z) taking the direction of ``a`` to that of ``b`` (shape (3,)).

    Antiparallel vectors: a half turn about an axis perpendicular to ``a``.
    """
    a = np.asarray(a, dtype=float) / np.linalg.norm(a)
    b = np.asarray(b, dtype=float) / np.linalg.norm(b)
    v = np.cross(a, b)
    s = float(np.linalg.norm(v))
    c = float(a @ b)
    if s < 1e-15:
        if c > 0:
            return np.array([1.0, 0.0, 0.0, 0.0])
        perp = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        return quat_from_axis_angle(perp, np.pi)
    return exp_rotvec(v / s * np.arctan2(s, c))


def angle_between(a, b) -> np.ndarray:
    """Angle (rad, [0, pi]) between vectors, shapes (..., 3) broadcast; atan2 of |a x b| and
    a . b, so small angles keep full precision (arccos of a dot product does not)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def euler_zxz_about(axis, q):
    """ZXZ angles of R(q) in a frame whose z axis is ``axis`` (world, shape (3,)).

    Returns (q_axis, angles): q_axis (w, x, y, z) takes the world z axis to ``axis`` and
    R(q) = R(q_axis) Rz(phi) Rx(theta) Rz(psi); theta is the angle of the body e3 from
    ``axis`` (for axis = L: the nutation of a symmetric top)."""
    q_axis = quat_between((0.0, 0.0, 1.0), axis)
    return q_axis, euler_zxz_from_quat(multiply(conjugate(q_axis), q))


def misorientation(q1, q2) -> np.ndarray:
    """Angle (rad, in [0, pi]) of the rotation taking R(q1) to R(q2); sign-blind.

    q1, q2 : shape (..., 4), (w, x, y, z), unit.  Uses atan2 of the vector and scalar parts
    of q1* (x) q2, accurate also for tiny angles (arccos of a dot product is not).
    """
    r = multiply(conjugate(q1), q2)
    return 2.0 * np.arctan2(np.linalg.norm(r[..., 1:], axis=-1), np.abs(r[..., 0]))


def allclose_up_to_sign(q1, q2, atol: float = 1e-12) -> bool:
    """True when q1 and q2 (shape (..., 4), (w, x, y, z)) are the same rotations within atol rad."""
    return bool(np.all(misorientation(q1, q2) <= atol))


def unflip(q) -> np.ndarray:
    """Choose signs along a time series q, shape (N, 4), so that neighbours are continuous
    (each sample's sign flipped where its dot product with the previous one is negative)."""
    q = np.array(q, dtype=float, copy=True)
    if q.ndim < 2 or len(q) < 2:
        return q
    flips = np.sum(q[1:] * q[:-1], axis=-1) < 0.0
    sign = np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)
    q[1:] *= sign[:, None]
    return q


def slerp_series(t_src, q_src, t_dst) -> np.ndarray:
    """Orientation at times ``t_dst`` by slerp between stored orientations.

    t_src : shape (N,), increasing; q_src : shape (N, 4), (w, x, y, z), unit;
    t_dst : shape (M,) within [t_src[0], t_src[-1]].  Returns shape (M, 4).
    Each interval is interpolated along its shortest geodesic (neighbours are unflipped
    first), so the stored samples must be closer than half a turn apart.
    """
    t_src = np.asarray(t_src, dtype=float)
    t_dst = np.atleast_1d(np.asarray(t_dst, dtype=float))
    q_src = unflip(np.asarray(q_src, dtype=float))
    if t_src.size == 1:
        return np.repeat(q_src[:1], t_dst.size, axis=0)
    i = np.clip(np.searchsorted(t_src, t_dst, side="right") - 1, 0, t_src.size - 2)
    span = t_src[i + 1] - t_src[i]
    tau = np.clip((t_dst - t_src[i]) / np.where(span > 0, span, 1.0), 0.0, 1.0)
    qa, qb = q_src[i], q_src[i + 1]
    rel = multiply(conjugate(qa), qb)                       # qa^-1 qb, w >= 0 after unflip
    ang = np.arctan2(np.linalg.norm(rel[:, 1:], axis=-1), rel[:, 0])   # half the angle between them
    v = rel[:, 1:]
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    axis = np.divide(v, n, out=np.zeros_like(v), where=n > 0)
    return multiply(qa, exp_rotvec(2.0 * (tau * ang)[:, None] * axis))
