"""The averaged (secular) flows of the symmetric top, both models, and what they say as tau -> oo.

Everything is dimensionless (4.1): J = (1, 1, 1 - delta), d = (n1, 0, n3), n1 = sin chi,
n3 = cos chi, xi = tan^2 chi; z = omega1 + i omega2 = omega_perp e^{i phi}.  Pure NumPy.

**Harmonics.**  The radiation part of each model's rate (the rate less the free precession
(delta omega2 omega3, -delta omega1 omega3, 0)) is a sum of monomials c z^j zb^k w3^l (zb the
complex conjugate; reduced (4.2)-(4.4): exactly cubic; truncated (2.5): its cubic, leading
order in |omega| -- the Sherman-Morrison denominator 1 + n1 n3 delta omega2/(1 - delta) adds
terms smaller by O(|omega|)).  A monomial turns as e^{i m phi}, m = j - k, while the free
precession turns z as e^{i nu tau}, nu = -delta omega3.  Each model's ``Averaged.harmonics``
(``physics.harmonics``) lists them (``tests/test_averaged.py`` rebuilds them from the models'
rates by a Fourier transform over phi, so a change of either rate cannot leave them behind).

**The averaged flows.**  First-order averaging keeps the m = 1 terms of z' and the m = 0 terms
of omega3':

    d wp/dtau = -wp (P wp^2 + Q w3^2),      d w3/dtau = -w3 (R wp^2 + S w3^2),     d phi/dtau = -delta w3

reduced, (4.12):  P = n3^2 + n1^2/2,  Q = n3^2 (1 - delta)^2 + n1^2 (1 + delta + delta^2)/2,
                  R = n1^2 (2 + delta) / (2 (1 - delta)),  S = n1^2 / (1 - delta);
truncated, spinviz's derived equation (``asymptotics.truncated_averaged``):
                  P_T = n3^2 + n1^2/2,  Q_T = n1^2 (2 + delta)/2,
                  R_T = n3^2 + n1^2 / (2 (1 - delta)),  S_T = n1^2 / (1 - delta).

In s = ln tau, with the scaled amplitudes a = wp sqrt(tau), b = w3 sqrt(tau), A = a^2, B = b^2,
both are the competitive Lotka-Volterra system

    dA/ds = A (1 - 2 P A - 2 Q B),      dB/ds = B (1 - 2 R A - 2 S B)                  (LV)

whose fixed points are the paper's spiral types: axial (0, 1/(2S)) = "2" (exponent across
alpha = -Q/(2S) = (4.14)), transverse (1/(2P), 0) = "4" (beta = -R/(2P) = (4.18), A = the
corrected (1 + xi)/(2 + xi)), balanced = "3" = (4.16).  A state's eigenvalues say how fast it
attracts (the deviation goes as tau^lambda).

**Type 1 is the forced response.**  The one z-independent term of z', n1 n3 w3^3 (reduced
only: the truncated omega_perp = 0 is invariant), drives omega_perp at a fixed phase:
z_f = -i n1 n3 w3^2/delta - n1 n3 w3^3 [n1^2 (1 + delta^3) - n3^2 (1 - delta)^3]/(delta^2 (1 - delta)),
whose two orders are B/tau and A tau^-3/2 of (4.9) on type 1 (w3^2 tau = C^2).  On the axial
state the free spiral falls as tau^alpha and z_f as 1/tau, so their ratio goes as
tau^(alpha + 1): the late state is type 1 iff alpha < -1.

**The near-identity transform.**  z = zbar + U_z(zbar, w3bar) + z_f(w3bar), w3 = w3bar + U_3
with U_z = sum_{m != 1} i T / ((m - 1) delta w3) over the z-dependent terms and
U_3 = sum_{m != 0} i T / (m delta w3): the homological equation of the free rotation.  With it
the averaged flow carries the slow variables to O(mu^2) (without it, O(mu)); mu, the small
parameter, is the radiation rate against the precession, |omega|^2/|delta w3|, times
max(1, |omega|/|w3|) in the reduced model (its omega3' has terms without w3, so U_3/w3 ~
wp^3/(delta w3^2) where w3 << omega).  Where the stable state makes mu grow (reduced
transverse state with beta < -3/4: the phase is captured into the libration "5", beyond
beta = -1 the domain "?" (4.20); truncated beta_T < -1, the frozen phase "TF"), averaging
cannot last, and the state says so (``State.holds``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import models as M


@dataclass(frozen=True)
class State:
    """A fixed point of (LV) in the scaled amplitudes A = omega_perp^2 tau, B = omega3^2 tau.

    name : "axial", "transverse" or "balanced".  A, B : its amplitudes.
    eigenvalues : of (LV)'s Jacobian there (in s = ln tau: a deviation goes as tau^lambda).
    stable : both eigenvalues negative.  label : the type it is as tau -> oo ("1" or "2" on
    the reduced axial state by the sign of alpha + 1, "3", "4", "4->5" for a transverse
    spiral captured into the libration (beta < -3/4), "?" beyond beta = -1 (4.20); truncated
    "T2", "T4", "TF", "Tcone").  exponent : alpha (axial: omega_perp ~ tau^alpha) or beta
    (transverse: omega3 ~ tau^beta); NaN for the balanced state.  mu_exponent : mu ~
    tau^mu_exponent there.  holds : averaging can last there (mu falls).
    """

    name: str
    A: float
    B: float
    eigenvalues: tuple
    stable: bool
    label: str
    exponent: float
    mu_exponent: float

    @property
    def holds(self) -> bool:
        """mu falls along the state, so a hand-over to the averaged flow lasts."""
        return self.mu_exponent < 0.0

    @property
    def slowest(self) -> float:
        """The eigenvalue closest to 0 (the approach goes as tau^slowest)."""
        return float(max(self.eigenvalues))


class Flow:
    """The averaged flow of one (model, delta, chi): coefficients, fixed points, the stable
    state, the forced response, the near-identity transform and the small parameter.
    Arrays broadcast; z complex (omega1 + i omega2), omega3 real."""

    def __init__(self, model: str, delta: float, chi: float):
        av = M.get(model).averaged
        if av is None:
            raise ValueError(f"the model {model!r} has no averaged flow")
        self.model, self.delta, self.chi = model, float(delta), float(chi)
        d, n1, n3 = self.delta, math.sin(chi), math.cos(chi)
        self.n1, self.n3 = n1, n3
        self.z_terms = tuple((m, j, k, l, f(d, n1, n3)) for m, j, k, l, f in av.harmonics["z"])
        self.w3_terms = tuple((m, j, k, l, f(d, n1, n3)) for m, j, k, l, f in av.harmonics["w3"])
        self.P, self.Q, self.R, self.S = av.coefficients(d, chi)
        # the forcing of z at z = 0: reduced n1 n3 w3^3, truncated none
        self.F = sum(c for m, j, k, l, c in self.z_terms if (j, k) == (0, 0))

    # --- the flow ---------------------------------------------------------------------------
    def rates(self, wp, w3):
        """(d omega_perp/dtau, d omega3/dtau) of the averaged flow."""
        wp, w3 = np.asarray(wp, dtype=float), np.asarray(w3, dtype=float)
        return -wp * (self.P * wp * wp + self.Q * w3 * w3), -w3 * (self.R * wp * wp + self.S * w3 * w3)

    def lv(self, lnA, lnB):
        """(LV) in ln A, ln B: (d ln A/ds, d ln B/ds), s = ln tau (no underflow however fast a
        component dies)."""
        A, B = np.exp(lnA), np.exp(lnB)
        return 1.0 - 2.0 * (self.P * A + self.Q * B), 1.0 - 2.0 * (self.R * A + self.S * B)

    # --- fixed points ---------------------------------------------------------------------
    def fixed_points(self) -> dict:
        """The fixed points of (LV) with A, B >= 0 other than the origin: name -> ``State``."""
        P, Q, R, S = self.P, self.Q, self.R, self.S
        red = self.model == "reduced"
        out = {}
        if S > 0.0:
            alpha = -Q / (2.0 * S)
            lab = ("1" if alpha < -1.0 else "2" if alpha > -1.0 else "1|2") if red else "T2"
            out["axial"] = State("axial", 0.0, 1.0 / (2.0 * S), (2.0 * alpha + 1.0, -1.0), alpha < -0.5, lab, alpha,
                                 -0.5 if self.delta != 0.0 else math.inf)
        if P > 0.0:
            beta = -R / (2.0 * P)
            if red:
                lab, mu_e = ("?" if beta < -1.0 else "4->5" if beta < -0.75 else "4"), -1.5 - 2.0 * beta
            else:
                lab, mu_e = ("TF" if beta < -1.0 else "T4"), -1.0 - beta
            out["transverse"] = State("transverse", 1.0 / (2.0 * P), 0.0, (2.0 * beta + 1.0, -1.0), beta < -0.5, lab, beta,
                                      mu_e if self.delta != 0.0 else math.inf)
        det = P * S - Q * R
        if det != 0.0:
            A, B = 0.5 * (S - Q) / det, 0.5 * (P - R) / det
            if A > 0.0 and B > 0.0:
                ev = np.linalg.eigvals(np.array([[-2.0 * P * A, -2.0 * Q * A], [-2.0 * R * B, -2.0 * S * B]]))
                ev = tuple(float(x) for x in np.sort(ev.real))
                out["balanced"] = State("balanced", A, B, ev, bool(max(ev) < 0.0), "3" if red else "Tcone", math.nan,
                                        -0.5 if self.delta != 0.0 else math.inf)
        return out

    def stable_state(self) -> State | None:
        """The one stable fixed point of (LV), or None where there is none or more than one
        (then the start decides and the atlas integrates in full)."""
        st = [s for s in self.fixed_points().values() if s.stable]
        return st[0] if len(st) == 1 else None

    # --- the forced response and the free/forced ratio ---------------------------------------
    def forced_response(self, w3, order: int = 2):
        """z_f(w3): the quasi-static response of omega_perp to the forcing n1 n3 w3^3 (reduced;
        0 truncated).  order 1: -i n1 n3 w3^2/delta (omega2 = B/tau of (4.9) on type 1);
        order 2 adds the real omega1 = A tau^-3/2 of (4.9)."""
        w3 = np.asarray(w3, dtype=float)
        if self.F == 0.0 or self.delta == 0.0:
            return np.zeros(w3.shape, dtype=complex)
        d, n1, n3 = self.delta, self.n1, self.n3
        z = -1j * self.F * w3**2 / d
        if order >= 2:
            z = z - n1 * n3 * w3**3 * (n1 * n1 * (1.0 + d**3) - n3 * n3 * (1.0 - d) ** 3) / (d * d * (1.0 - d))
        return z

    def free_forced_ratio(self, A, B, s):
        """|zbar| / |z_f|: the free spiral against the forced response (order 1) at
        (A, B) of (LV) at s = ln tau: sqrt(A) |delta| sqrt(tau) / (|F| B).  NaN where there is
        no forcing (truncated, chi = 0 or pi/2)."""
        A, B, s = (np.asarray(x, dtype=float) for x in (A, B, s))
        if self.F == 0.0 or self.delta == 0.0:
            return np.full(np.broadcast(A, B, s).shape, np.nan)
        with np.errstate(divide="ignore"):
            return np.sqrt(A) * abs(self.delta) * np.exp(0.5 * s) / (abs(self.F) * B)

    @property
    def ratio_exponent(self) -> float:
        """alpha + 1 of (4.14): on the axial state the free/forced ratio goes as tau^(alpha + 1)
        (NaN where there is no forced response)."""
        if self.F == 0.0 or self.S <= 0.0:
            return math.nan
        return -self.Q / (2.0 * self.S) + 1.0

    # --- the near-identity transform -------------------------------------------------------------
    def oscillating(self, z, w3):
        """(U_z, U_3) at (z, w3): the first-order oscillating terms (the forced response, which
        the transforms treat apart, excluded)."""
        z = np.asarray(z, dtype=complex)
        w3 = np.asarray(w3, dtype=float)
        zb = np.conj(z)
        dw = self.delta * w3
        Uz = np.zeros(np.broadcast(z, w3).shape, dtype=complex)
        U3 = np.zeros(Uz.shape, dtype=complex)
        with np.errstate(divide="ignore", invalid="ignore"):
            for m, j, k, l, c in self.z_terms:
                if m != 1 and (j, k) != (0, 0):
                    Uz = Uz + 1j * c * z**j * zb**k * w3**l / ((m - 1) * dw)
            for m, j, k, l, c in self.w3_terms:
                if m != 0:
                    U3 = U3 + 1j * c * z**j * zb**k * w3**l / (m * dw)
        return Uz, U3.real

    def to_averaged(self, z, w3):
        """True (z, w3) -> averaged (zbar, w3bar): the forced response taken off, then the
        oscillating terms inverted to first order (exact to O(mu^2))."""
        zeta = np.asarray(z, dtype=complex) - self.forced_response(w3)
        Uz, U3 = self.oscillating(zeta, w3)
        return zeta - Uz, np.asarray(w3, dtype=float) - U3

    def to_true(self, zbar, w3bar):
        """Averaged (zbar, w3bar) -> true (z, w3) (the phase of zbar is the averaged phase)."""
        Uz, U3 = self.oscillating(zbar, w3bar)
        return np.asarray(zbar, dtype=complex) + Uz + self.forced_response(w3bar), np.asarray(w3bar, dtype=float) + U3

    # --- validity ----------------------------------------------------------------------------
    def small_parameter(self, wp, w3):
        """mu: |omega|^2/|delta w3| (the radiation rate against the precession), times
        max(1, |omega|/|w3|) in the reduced model."""
        wp, w3 = np.asarray(wp, dtype=float), np.asarray(w3, dtype=float)
        w2 = wp * wp + w3 * w3
        a3 = np.abs(w3)
        ok = a3 > 0.0
        mu = np.divide(w2, abs(self.delta) * a3, out=np.full(np.shape(w2), np.inf), where=ok & (self.delta != 0.0))
        if self.model == "reduced":
            mu = mu * np.maximum(1.0, np.divide(np.sqrt(w2), a3, out=np.full(np.shape(w2), np.inf), where=ok))
        return mu

    def small_parameter_scaled(self, A, B, s):
        """mu at (A, B) of (LV) at s = ln tau."""
        e = np.exp(-0.5 * np.asarray(s, dtype=float))
        return self.small_parameter(np.sqrt(A) * e, np.sqrt(B) * e)


def averaging_holds(model: str, delta: float, chi: float):
    """(holds, flow, state): whether the averaged flow can carry the runs of this cell to
    tau -> oo -- a unique stable state of (LV) along which mu falls, delta != 0 (there is no
    precession at delta = 0), 0 < chi < pi/2 (at chi = 0 or pi/2 the reduced model ends in a
    residual rotation, (5.2), (5.6)) -- with the cell's ``Flow`` and its stable ``State``
    (None where there is none)."""
    if delta == 0.0 or not 0.0 < chi < 0.5 * math.pi:
        return False, None, None
    f = Flow(model, delta, chi)
    state = f.stable_state()
    return bool(state is not None and state.holds), f, state


def flow(model: str, delta: float, chi: float) -> Flow:
    """The averaged flow of one (model, delta, chi) (``Flow``)."""
    return Flow(model, delta, chi)


def scaled_amplitudes(flow_: Flow, z, w3, tau):
    """(abar, bbar): the averaged amplitudes omega_perp_bar sqrt(tau), |omega3_bar| sqrt(tau) of the
    true state (z, w3) at tau, through ``Flow.to_averaged`` (what a full run and the averaged
    flow are compared on: no phase needed)."""
    zb, w3b = flow_.to_averaged(z, w3)
    sq = np.sqrt(np.asarray(tau, dtype=float))
    return np.abs(zb) * sq, np.abs(w3b) * sq
