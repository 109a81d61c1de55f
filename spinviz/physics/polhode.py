"""The torque-free asymmetric top (Euler-Poinsot): its polhode, its phases and its pose.

A body with principal moments J = (J1, J2, J3) (any order, any unit) turns freely with
|L|^2 = X = sum J_i^2 w_i^2 and 2E = Y = sum J_i w_i^2 fixed.  In the body frame L runs
round a polhode about one of the two extreme axes -- the *encircled* axis c (the largest
moment where X > J_m Y, the smallest where X < J_m Y, J_m the middle one) -- periodically,
in Jacobi elliptic functions of lambda t (Landau & Lifshitz, Mechanics, section 37): with o
the other extreme axis and m the middle one,

    w_o = A_o cn(lambda t | m),   w_m = s_m A_m sn(lambda t | m),   w_c = s_c A_c dn(lambda t | m),

    A_o^2 = p / (J_o |J_c - J_o|),   A_m^2 = p / (J_m |J_c - J_m|),   A_c^2 = q / (J_c |J_c - J_o|),
    lambda^2 = |J_c - J_m| q / (J_o J_m J_c),   m = k^2 = |J_m - J_o| p / (|J_c - J_m| q),

where p = |J_c Y - X| and q = |X - J_o Y| are written as sums of non-negative terms,
p = sum J_i |J_c - J_i| w_i^2 (so that p -> 0 at the axis keeps its digits).  The polhode's
period is 4 K(m) / lambda; its phase u = 2 pi t / period runs over [0, 2 pi), u = 0 where
w_m = 0 and w_o > 0.  The separatrix, the polhode through the middle axis, is m = 1:
p = |J_c - J_m| X / J_m; the period diverges there logarithmically.

A symmetric top is the case J_o = J_m (m = 0: a circle, u the precession phase of
omega_perp); a sphere has no polhode (every axis is fixed) and is not handled here.

In space L_world is fixed.  Written in ZXZ angles about it, in the right-handed frame
(e_a, e_b, e_c) = a cyclic relabelling of the body axes with e_c the encircled axis, the
body sits at O = R(q_L) Rz(phi) Rx(theta) Rz(psi) (then back from that frame to the
body's), with L's direction in the body (sin theta sin psi, sin theta cos psi, cos theta)
and phi the turn about L.  Sigma = phi + s_c psi (s_c = sign of L_c) is regular where the
polhode shrinks onto e_c (theta -> 0); its rate is w . L/|L| + psi_dot (s_c - cos theta).

Quaternions are scalar-first (w, x, y, z).  Pure NumPy (``elliptic``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .. import rotations as R
from . import elliptic as EL
from .equations import free_rate

# R(q_frame) takes body components to those of the frame (e_a, e_b, e_c), a cyclic relabelling
# with e_c the encircled axis: c = 0 -> (1, 2, 0), c = 1 -> (2, 0, 1), c = 2 -> identity
_Q_FRAME = {0: (0.5, -0.5, -0.5, -0.5), 1: (0.5, 0.5, 0.5, 0.5), 2: (1.0, 0.0, 0.0, 0.0)}


class NoPolhode(ValueError):
    """The state has no polhode to average over (a sphere, or a rotation about an axis of a
    degenerate pair); the message says why."""


def extreme_axes(J) -> tuple[int, int, int]:
    """(s, m, l): body indices of the smallest, middle and largest moment.  Ties keep the
    unique moment extreme (a symmetric top's axis is s or l); ``NoPolhode`` for a sphere."""
    J = np.asarray(J, dtype=float)
    s, m, l = (int(i) for i in np.argsort(J, kind="stable"))
    if J[s] == J[l]:
        raise NoPolhode("a sphere (I1 = I2 = I3) has no polhode: every axis is fixed")
    if J[s] == J[m]:                      # oblate symmetric: the unique axis is the largest
        return s, m, l
    if J[m] == J[l]:                      # prolate symmetric: the unique axis is the smallest
        return s, m, l
    return s, m, l


def separatrix_function(J, omega) -> np.ndarray:
    """h = X - J_m Y = sum J_i (J_i - J_m) w_i^2 at body-frame states omega (..., 3): > 0 on
    polhodes about the largest axis, < 0 about the smallest, 0 on the separatrix."""
    J = np.asarray(J, dtype=float)
    _, m, _ = extreme_axes(J)
    w = np.asarray(omega, dtype=float)
    return np.sum(J * (J - J[m]) * w * w, axis=-1)


def encircled_axis(J, omega) -> tuple[int, float]:
    """(c, s_c): the body axis the polhode through ``omega`` (3,) runs round and the sign of
    w_c on it.  ``NoPolhode`` on a rotation the free motion leaves fixed or cannot tell
    (exactly on the separatrix, or in the plane of a degenerate pair)."""
    J = np.asarray(J, dtype=float)
    s, m, l = extreme_axes(J)
    h = float(separatrix_function(J, omega))
    w = np.asarray(omega, dtype=float)
    if h > 0.0 and J[m] < J[l]:
        c = l
    elif h < 0.0 and J[s] < J[m]:
        c = s
    else:
        raise NoPolhode("the rotation is on the separatrix or about an axis of a degenerate pair: no fast polhode "
                        "to average over")
    if w[c] == 0.0:
        raise NoPolhode("the rotation is on the separatrix: no polhode to average over")
    return c, (1.0 if w[c] > 0.0 else -1.0)


@dataclass(frozen=True)
class Polhode:
    """One polhode: body moments J (3,), encircled axis c with the sign s_c of w_c, the
    invariants X = |L|^2 and p = |J_c Y - X| (units of J^2 omega^2).  Arrays X, p of one
    shape describe many polhodes of the same body and axis at once."""

    J: tuple
    c: int
    s_c: float
    X: object
    p: object

    # --- the labels ---------------------------------------------------------------------------
    @cached_property
    def labels(self) -> tuple[int, int, int]:
        """(o, m, c): the other extreme axis, the middle one, the encircled one (body indices)."""
        s, m, l = extreme_axes(self.J)
        return (l if self.c == s else s), m, self.c

    @property
    def frame(self) -> tuple[int, int, int]:
        """(a, b, c): the cyclic relabelling with e_c last (a right-handed frame)."""
        return (self.c + 1) % 3, (self.c + 2) % 3, self.c

    @property
    def q_frame(self) -> np.ndarray:
        """(w, x, y, z) of the rotation taking body components to the frame's (``frame``)."""
        return np.array(_Q_FRAME[self.c])

    @cached_property
    def s_m(self) -> float:
        """The sign of w_m' where w_m = 0 and w_o > 0 (the sense the polhode is run)."""
        o, m, c = self.labels
        J = self.J
        w = np.zeros(3)
        w[o], w[c] = 1.0, self.s_c
        return 1.0 if free_rate(*w, J, None)[m] > 0.0 else -1.0

    # --- the free motion's constants ------------------------------------------------------------
    def _moments(self):
        o, m, c = self.labels
        return float(self.J[o]), float(self.J[m]), float(self.J[c])

    @property
    def q(self):
        """q = |X - J_o Y| = (|J_c - J_o| X - J_o p) / J_c."""
        Jo, _, Jc = self._moments()
        return (abs(Jc - Jo) * np.asarray(self.X) - Jo * np.asarray(self.p)) / Jc

    @property
    def Y(self):
        """2E = (X +- p) / J_c (+ about the largest axis, - about the smallest)."""
        Jo, _, Jc = self._moments()
        sig = 1.0 if Jc > Jo else -1.0
        return (np.asarray(self.X) + sig * np.asarray(self.p)) / Jc

    @property
    def separatrix_distance(self):
        """1 - p / p_sep, p_sep = |J_c - J_m| X / J_m: 1 on the axis, 0 on the separatrix."""
        _, Jm, Jc = self._moments()
        return 1.0 - Jm * np.asarray(self.p) / (abs(Jc - Jm) * np.asarray(self.X))

    def parameters(self):
        """(m, m1 = 1 - m, lambda, K(m)) of the elliptic solution."""
        return self._parameters

    @cached_property
    def _parameters(self):
        Jo, Jm, Jc = self._moments()
        p, q = np.asarray(self.p, dtype=float), np.asarray(self.q, dtype=float)
        den = abs(Jc - Jm) * q
        with np.errstate(divide="ignore", invalid="ignore"):
            m = abs(Jm - Jo) * p / den
            # 1 - m = |J_c - J_o| (|J_c - J_m| X - J_m p) / (J_c |J_c - J_m| q): no 1 - m cancellation
            m1 = abs(Jc - Jo) * (abs(Jc - Jm) * np.asarray(self.X) - Jm * p) / (Jc * den)
        lam = np.sqrt(np.maximum(abs(Jc - Jm) * q / (Jo * Jm * Jc), 0.0))
        return m, m1, lam, EL.ellipk(m, m1)

    @property
    def frequency(self):
        """omega_p = 2 pi / period = pi lambda / (2 K): the polhode's angular frequency."""
        _, _, lam, K = self.parameters()
        return 0.5 * np.pi * lam / K

    @property
    def amplitudes(self):
        """(A_o, A_m, A_c)."""
        Jo, Jm, Jc = self._moments()
        p, q = np.asarray(self.p, dtype=float), np.asarray(self.q, dtype=float)
        return (np.sqrt(p / (Jo * abs(Jc - Jo))), np.sqrt(p / (Jm * abs(Jc - Jm))),
                np.sqrt(np.maximum(q, 0.0) / (Jc * abs(Jc - Jo))))

    # --- states on it ----------------------------------------------------------------------------
    def omega(self, u) -> np.ndarray:
        """Body-frame omega at polhode phases u (rad; broadcast against X, p), shape (..., 3)."""
        o, m, c = self.labels
        mm, m1, _, K = self.parameters()
        u = np.asarray(u, dtype=float)
        sn, cn, dn, _ = EL.ellipj(2.0 * K * u / np.pi, mm, m1)
        Ao, Am, Ac = self.amplitudes
        shape = np.broadcast(sn, Ao).shape
        out = np.empty(shape + (3,))
        out[..., o] = Ao * cn
        out[..., m] = self.s_m * Am * sn
        out[..., c] = self.s_c * Ac * dn
        return out

    def phase(self, omega) -> np.ndarray:
        """The phase u in [0, 2 pi) of body-frame states ``omega`` (..., 3) on this polhode
        (read from the ratio w_m / w_o only: states off it get the phase of their projection)."""
        o, m, _ = self.labels
        mm, m1, _, K = self.parameters()
        Ao, Am, _ = self.amplitudes
        w = np.asarray(omega, dtype=float)
        am = np.mod(np.arctan2(self.s_m * w[..., m] / Am, w[..., o] / Ao), 2.0 * np.pi)
        return np.mod(0.5 * np.pi * EL.ellipkinc(am, mm, m1) / K, 2.0 * np.pi)

    def nodes(self, n: int) -> np.ndarray:
        """n phases evenly spaced in time over one period (the quadrature nodes)."""
        return 2.0 * np.pi * np.arange(n) / n

    def L_angles(self, omega):
        """(theta, psi, s_c - cos theta) of L's direction in the frame, at states (..., 3)."""
        a, b, c = self.frame
        L = np.asarray(self.J, dtype=float) * np.asarray(omega, dtype=float)
        La, Lb, Lc = L[..., a], L[..., b], L[..., c]
        rho = np.hypot(La, Lb)
        Lm = np.hypot(rho, Lc)
        theta = np.arctan2(rho, Lc)
        # s_c - cos theta = s_c (|L| - |L_c|) / |L| = s_c rho^2 / (|L| (|L| + |L_c|)): no cancellation
        return theta, np.arctan2(La, Lb), self.s_c * rho * rho / (Lm * (Lm + np.abs(Lc)))

    def sigma_rate(self, omega, omega_dot) -> np.ndarray:
        """d Sigma / dt at states omega (..., 3) moving at omega_dot (body frame): the ZXZ
        angles about a fixed L, Sigma = phi + s_c psi, phi_dot = w . L/|L| - psi_dot cos theta."""
        a, b, c = self.frame
        J = np.asarray(self.J, dtype=float)
        w = np.asarray(omega, dtype=float)
        L = J * w
        dL = J * np.asarray(omega_dot, dtype=float)
        La, Lb = L[..., a], L[..., b]
        rho2 = La * La + Lb * Lb
        Lm = np.sqrt(np.sum(L * L, axis=-1))
        psidot = (Lb * dL[..., a] - La * dL[..., b]) / rho2
        _, _, k = self.L_angles(w)
        return np.sum(w * L, axis=-1) / Lm + psidot * k

    def pose(self, q_L, Sigma, u) -> tuple[np.ndarray, np.ndarray]:
        """(omega_body (..., 3), q (..., 4)): the body on this polhode at phase u with
        Sigma = phi + s_c psi about L_world = R(q_L) z (arrays broadcast)."""
        w = self.omega(u)
        theta, psi, _ = self.L_angles(w)
        phi = np.asarray(Sigma, dtype=float) - self.s_c * psi
        qz = R.quat_from_euler_zxz(np.stack(np.broadcast_arrays(phi, theta, psi), axis=-1))
        q = R.multiply(R.multiply(np.asarray(q_L, dtype=float), qz), self.q_frame)
        return w, q


def polhode_of(J, omega) -> Polhode:
    """The polhode through the body-frame state ``omega`` (3,) (``NoPolhode`` where there is none)."""
    J = tuple(float(x) for x in J)
    w = np.asarray(omega, dtype=float)
    c, s_c = encircled_axis(J, w)
    Jv = np.asarray(J)
    X = float(np.sum(Jv * Jv * w * w))
    p = float(np.sum(Jv * np.abs(Jv[c] - Jv) * w * w))
    return Polhode(J, c, s_c, X, p)


def sigma_of(pol: Polhode, q_L, q) -> float:
    """Sigma = phi + s_c psi of the orientation q (4,) about L_world = R(q_L) z on polhode
    ``pol``: the ZXZ angles of q (x) q_frame* in the frame of q_L."""
    qf = R.multiply(R.multiply(R.conjugate(np.asarray(q_L, dtype=float)), np.asarray(q, dtype=float)),
                    R.conjugate(pol.q_frame))
    # Sigma is what stays defined where theta -> 0: 2 atan2(z, w) of the quaternion is phi + psi
    # (theta -> pi, s_c = -1: phi - psi = 2 atan2(y, x))
    if pol.s_c > 0.0:
        return float(2.0 * math.atan2(qf[3], qf[0]))
    return float(2.0 * math.atan2(qf[2], qf[1]))


def mean_sigma_rate(pol: Polhode, n: int = 256) -> float:
    """The mean rate of Sigma over one period of the free motion (the precession about L
    plus s_c times the winding of psi)."""
    u = pol.nodes(n)
    w = pol.omega(u)
    f = np.stack(free_rate(w[:, 0], w[:, 1], w[:, 2], pol.J, None), axis=-1)
    return float(np.mean(pol.sigma_rate(w, f)))


def angle_range(pol: Polhode, d_body, n: int = 256) -> tuple[float, float]:
    """(lowest, highest) angle between the body-frame direction ``d_body`` and L over the
    polhode, rad: what the angle d-L sweeps in one period whatever the phase."""
    w = pol.omega(pol.nodes(n))
    L = np.asarray(pol.J, dtype=float) * w
    a = R.angle_between(np.broadcast_to(np.asarray(d_body, dtype=float), L.shape), L)
    return float(np.min(a)), float(np.max(a))


def angle_variables(pol: Polhode, n: int = 64) -> tuple[float, float, np.ndarray]:
    """(omega_p, nu_Sigma, c): the free motion's two frequencies -- the polhode's and Sigma's
    mean rate -- and the rfft coefficients c (n // 2 + 1,) of Sigma_dot's zero-mean part over
    one period, from which ``sigma_periodic`` gives Sigma - nu_Sigma t - const at any phase."""
    u = pol.nodes(n)
    w = pol.omega(u)
    f = np.stack(free_rate(w[:, 0], w[:, 1], w[:, 2], pol.J, None), axis=-1)
    c = np.fft.rfft(pol.sigma_rate(w, f)) / n
    nu = float(np.real(c[0]))
    c[0] = 0.0
    return float(pol.frequency), nu, c


def sigma_periodic(c: np.ndarray, omega_p: float, u) -> np.ndarray:
    """W0(u): the periodic part of Sigma along the free motion at phases u (``angle_variables``'
    coefficients c integrated over the phase, divided by omega_p); Sigma = Sigma_bar + W0(u)
    with Sigma_bar advancing uniformly at nu_Sigma."""
    u = np.asarray(u, dtype=float)
    k = np.arange(1, c.size)
    coef = 2.0 * c[1:] / (1j * k)
    return np.real(np.sum(coef * np.exp(1j * u[..., None] * k), axis=-1)) / omega_p
