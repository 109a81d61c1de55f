"""Jacobi elliptic functions and elliptic integrals of the first kind, in plain NumPy.

The torque-free asymmetric top moves in these functions (``polhode``).  Physics stays free
of scipy (its import contract), so they are computed here by the textbook algorithms,
vectorized, each a few lines and checked against ``scipy.special`` in
``tests/test_polhode.py``:

* K(m) by the arithmetic-geometric mean, K = pi / (2 AGM(1, sqrt(1 - m))) (DLMF 19.8.5);
  the complementary parameter m1 = 1 - m may be passed on its own, so that K near the
  separatrix (m -> 1) keeps its digits;
* sn, cn, dn by the descending Landen (AGM) sequence and its back-substitution of the
  amplitude (Abramowitz & Stegun 16.4; the Cephes ``ellpj`` algorithm);
* F(phi | m) by Carlson's symmetric integral R_F (DLMF 19.25.5, 19.36.1) on the reduced
  amplitude, extended by F(phi + j pi) = F(phi) + 2 j K.

The parameter is m = k^2 in [0, 1) throughout (scipy's convention).
"""

from __future__ import annotations

import math

import numpy as np

_TOL = 1e-16
_MAX_ITER = 40


def _m1_of(m, m1):
    m = np.asarray(m, dtype=float)
    m1 = 1.0 - m if m1 is None else np.asarray(m1, dtype=float)
    return m, m1


def _agm_scalar(a: float, b: float) -> float:
    for _ in range(_MAX_ITER):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
        if abs(a - b) <= _TOL * a:
            break
    return 0.5 * (a + b)


def agm(a, b) -> np.ndarray:
    """The arithmetic-geometric mean of a, b >= 0 (arrays broadcast)."""
    if np.ndim(a) == 0 and np.ndim(b) == 0:
        return np.float64(_agm_scalar(float(a), float(b)))
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    a, b = a.copy(), b.copy()
    for _ in range(_MAX_ITER):
        a, b = 0.5 * (a + b), np.sqrt(a * b)
        if np.all(np.abs(a - b) <= _TOL * a):
            break
    return 0.5 * (a + b)


def ellipk(m, m1=None) -> np.ndarray:
    """K(m) = F(pi/2 | m), the quarter period, for 0 <= m < 1; ``m1`` = 1 - m when known
    more precisely than 1 - m (near the separatrix).  inf at m1 = 0."""
    if np.ndim(m) == 0 and np.ndim(m1) == 0:
        k1 = 1.0 - float(m) if m1 is None else float(m1)
        return np.float64(0.5 * math.pi / _agm_scalar(1.0, math.sqrt(k1)) if k1 > 0.0 else math.inf)
    _, m1 = _m1_of(m, m1)
    with np.errstate(divide="ignore"):
        return np.where(m1 > 0.0, 0.5 * np.pi / agm(1.0, np.sqrt(np.maximum(m1, 0.0))), np.inf)


def ellipj(u, m, m1=None):
    """(sn, cn, dn, am) of u with parameter m (0 <= m < 1), arrays broadcast.

    Descending Landen sequence a_{n+1} = (a_n + b_n)/2, b_{n+1} = sqrt(a_n b_n),
    c_{n+1} = (a_n - b_n)/2 from (1, sqrt(m1), sqrt(m)), then phi_N = 2^N a_N u and
    phi_{n-1} = (phi_n + asin(c_n sin(phi_n) / a_n)) / 2; am = phi_0, sn = sin am, cn = cos am
    (A&S 16.4.3) and dn = sqrt(m1 + m cn^2).
    """
    u = np.asarray(u, dtype=float)
    m, m1 = _m1_of(m, m1)
    if m.ndim == 0 and m1.ndim == 0:
        # one parameter for all u (a polhode's nodes): the Landen sequence once, in floats
        a, b, c = 1.0, math.sqrt(max(float(m1), 0.0)), math.sqrt(max(float(m), 0.0))
        as_, cs = [a], [c]
        while len(as_) < _MAX_ITER:
            a, b, c = 0.5 * (a + b), math.sqrt(a * b), 0.5 * (a - b)
            as_.append(a)
            cs.append(c)
            if abs(c) <= _TOL * a:
                break
        n = len(as_) - 1
    else:
        u, m, m1 = np.broadcast_arrays(u, m, m1)
        a = np.ones(u.shape)
        b = np.sqrt(np.maximum(m1, 0.0))
        c = np.sqrt(np.maximum(m, 0.0))
        cs = [c]
        as_ = [a]
        while len(as_) < _MAX_ITER:
            a, b, c = 0.5 * (a + b), np.sqrt(a * b), 0.5 * (a - b)
            as_.append(a)
            cs.append(c)
            if np.all(np.abs(c) <= _TOL * a):
                break
        n = len(as_) - 1
    phi = (2.0 ** n) * a * u
    for i in range(n, 0, -1):
        phi = 0.5 * (phi + np.arcsin(np.clip(cs[i] * np.sin(phi) / as_[i], -1.0, 1.0)))
    sn, cn = np.sin(phi), np.cos(phi)
    # dn^2 = 1 - m sn^2 = m1 + m cn^2: two non-negative terms (A&S's cos(phi_0)/cos(phi_1 - phi_0) is 0/0 at sn = +-1)
    dn = np.sqrt(np.maximum(m1, 0.0) + m * cn * cn)
    return sn, cn, dn, phi


def carlson_rf(x, y, z) -> np.ndarray:
    """Carlson's R_F(x, y, z) for x, y, z >= 0, at most one of them 0 (DLMF 19.36.1,
    duplication to |1 - x/A| < 3e-3, then the fifth-order series)."""
    x, y, z = (np.asarray(v, dtype=float) for v in (x, y, z))
    x, y, z = np.broadcast_arrays(x, y, z)
    x, y, z = x.copy(), y.copy(), z.copy()
    for _ in range(_MAX_ITER):
        A = (x + y + z) / 3.0
        dev = np.max(np.abs(np.stack([A - x, A - y, A - z])), axis=0) / A
        if np.all(dev < 3e-3):
            break
        sx, sy, sz = np.sqrt(x), np.sqrt(y), np.sqrt(z)
        lam = sx * sy + sx * sz + sy * sz
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
    A = (x + y + z) / 3.0
    X, Y = 1.0 - x / A, 1.0 - y / A
    Z = -(X + Y)
    E2 = X * Y - Z * Z
    E3 = X * Y * Z
    return (1.0 - E2 / 10.0 + E3 / 14.0 + E2 * E2 / 24.0 - 3.0 * E2 * E3 / 44.0) / np.sqrt(A)


def ellipkinc(phi, m, m1=None) -> np.ndarray:
    """F(phi | m), the incomplete integral of the first kind, for any real phi (odd in phi,
    F(phi + j pi) = F(phi) + 2 j K(m))."""
    phi = np.asarray(phi, dtype=float)
    m, m1 = _m1_of(m, m1)
    j = np.round(phi / np.pi)
    r = phi - j * np.pi                                   # in [-pi/2, pi/2]
    s, c = np.sin(r), np.cos(r)
    f = s * carlson_rf(c * c, 1.0 - m * s * s, 1.0)
    return f + 2.0 * j * np.where(j != 0.0, ellipk(m, m1), 0.0)
