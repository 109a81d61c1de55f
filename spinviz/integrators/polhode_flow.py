"""The averaged slow flow of any body under either model's torque: one polhode period at a time.

Under a torque that is weak against the spin (eps = tau0 |Omega| << 1) the body-frame state
keeps to a polhode of the free motion (``physics.polhode``) whose invariants drift slowly.
The slow variables are x = (ln X, ln p) -- X = |L|^2, p = |J_c 2E - X|, the polhode's size
about its encircled axis c, exact to the last digit as it shrinks onto the axis -- and the
fast ones are the polhode phase u (uniform in time for the free motion, rate omega_p) and the
turn about L, carried as the angle variable Sigma_bar = Sigma - W0(x, u) with W0 the free
motion's own periodic part of Sigma (so Sigma_bar, like u, advances uniformly when free).

First-order averaging (Arnold, Kozlov & Neishtadt, Mathematical Aspects, 6.1) over N nodes
evenly spaced in time along the polhode (the trapezoid rule: spectrally exact for these
analytic periodic functions, N set by the elliptic nome):

    d ln X / dt  = < 2 sum J_i^2 w_i a_i > / X,     d ln p / dt = < 2 sum J_i |J_c - J_i| w_i a_i > / p,
    d u / dt     = omega_p(x) + < grad u . a >,
    d Sigma_bar / dt = <Sigma_dot_free> + < sigma_rad - dW0/dx . x_dot_rad - Sigma~ gamma / omega_p >,

with a the model's radiation part of Omega_dot alone (``equations.reduced_terms`` /
``truncated_terms`` with free = 0: summed with the free part first it would drown in its
round-off), grad u . a by a central difference of the phase function along a, and
sigma_rad the radiation part of Sigma's rate.

The forcing.  Where the spin lies along c, the torque's transverse part F(w_c) does not
vanish (the reduced model with d askew; the paper's n1 n3 w3^3 for a symmetric top): it is
odd under the half-period shift u -> u + period/2 (w_o, w_m change sign, w_c does not), so
it averages out exactly and is taken out of every average before summing (``_forcing``),
which keeps its round-off out of the rates as p -> 0.  Its first-order response is the
forced offset x_f of the rotation axis from c ((4.9)'s B/tau for a symmetric top: type 1):
x_f = -(M + M_rad)^-1 (F - dx_f/dt) with M the free flow linearized about the axis.

The near-identity transform x = x_bar + U(x_bar, u), U the zero-mean part of the rates
integrated over u / omega_p, maps true and averaged slow variables into each other; with it
the slow variables are carried to O(eps^2) instead of O(eps).  Where the polhode is small
against the forced offset (|x_f| > ``SHIFT_RATIO`` x its size) the transform instead takes
the offset off first (the polhode is then about the shifted axis) and averages the rest.

Everything is in spin units (|omega(0)| = 1, |g|^2 = eps); NumPy over the nodes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..physics import polhode as PH
from ..physics.equations import free_rate
from ..physics.models import System, radiation_function

N_MIN = 32               # nodes at least (exact for products of Jacobi functions to degree ~30)
NODES_PER_K = 12.0       # and this many per quarter period K(m): the nome exp(-pi K'/K) -> 1 near the separatrix
N_MAX = 4096
SHIFT_RATIO = 0.1        # the forced offset taken off before averaging above this share of the polhode's size
FD_REL = 1e-6            # relative step of the central differences in x and along a
LN_P_MIN = -690.0        # ln(p / X) below which the polhode is taken as that size (float64 ends at -745)
NEAR_AXIS = 1e-6         # p/X below which the radiation is split by degree in omega_perp (``_radiation_nodes``)


def node_count(K: float) -> int:
    """N: a power of two >= N_MIN and NODES_PER_K K (at most N_MAX)."""
    n = max(N_MIN, NODES_PER_K * float(K))
    if not n < N_MAX:
        return N_MAX
    return int(2 ** math.ceil(math.log2(n)))


def spectral_integral(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(coefficients c_n, zero-mean antiderivative at the nodes) of samples f (..., N) of a
    periodic function of u over one period: F(u) = sum_{n != 0} c_n e^{i n u} / (i n)."""
    N = f.shape[-1]
    c = np.fft.rfft(f, axis=-1) / N
    n = np.arange(c.shape[-1])
    d = np.zeros_like(c)
    d[..., 1:] = c[..., 1:] / (1j * n[1:])
    if N % 2 == 0:
        d[..., -1] = 0.0                    # the Nyquist term has no antiderivative on the nodes
    return c, np.fft.irfft(d * N, n=N, axis=-1)


def eval_series(c: np.ndarray, u, integral: bool = False) -> np.ndarray:
    """The real periodic function with rfft coefficients c (..., M) at phases u (broadcast
    over the leading axes), or its zero-mean antiderivative (``integral``)."""
    n = np.arange(c.shape[-1])
    e = np.exp(1j * np.asarray(u, dtype=float)[..., None] * n)
    w = np.full(n.shape, 2.0)
    w[0] = 1.0
    if integral:
        coef = np.zeros_like(c)
        coef[..., 1:] = c[..., 1:] / (1j * n[1:])
        return np.real(np.sum(w * coef * e, axis=-1))
    return np.real(np.sum(w * c * e, axis=-1))


@dataclass
class Averages:
    """What one polhode contributes, at slow state x = (ln X, ln p) (spin units).

    rates : (d ln X/dt, d ln p/dt) averaged (to second order where asked).  omega_p : the polhode
    frequency; u_rate, sigma_rate : averaged phase rates (the free ones where the torque's
    corrections were not asked for).  osc : (2, M) rfft coefficients of the zero-mean slow rates
    (the transform U); vcoef : rfft coefficients of the phase's oscillation V (zero where not
    computed).  w0 : rfft coefficients of Sigma_dot_free's zero-mean part (W0 = its integral /
    omega_p).  shifted : the forced offset is taken off (``Flow.shift_mode``).
    mu_osc : largest oscillation of the slow variables over a period; mu_slope : its largest
    slope per radian of phase (what a phase error costs the slow variables); mu_ad : relative change of
    omega_p over one period; mu_sep : change of the separatrix distance over one period against
    that distance.  nodes : N.  pol : the ``Polhode``.
    """

    rates: np.ndarray
    omega_p: float
    u_rate: float
    sigma_rate: float
    osc: np.ndarray
    vcoef: np.ndarray
    w0: np.ndarray
    mu_osc: float
    mu_ad: float
    mu_sep: float
    nodes: int
    pol: PH.Polhode
    shifted: bool
    mu_slope: float


class Flow:
    """The averaged flow of one body and model (spin units) about one encircled axis.

    system : a ``System`` (J, g, model); c, s_c : the encircled body axis and sign of w_c.
    """

    def __init__(self, system, c: int, s_c: float):
        self.system = system
        self.J = tuple(float(x) for x in system.inertia)
        self.Jv = np.asarray(self.J)
        self.g = tuple(float(x) for x in system.coupling)
        self.c, self.s_c = int(c), float(s_c)
        self.rad = radiation_function(system.model)
        self.free = system.model == "free"
        self.eps = float(np.dot(self.g, self.g))
        self._cache: dict = {}
        o, m, _ = PH.Polhode(self.J, self.c, self.s_c, 1.0, 1.0).labels
        Jm, Jc = self.J[m], self.J[self.c]
        self._ln_sep = math.log(abs(Jc - Jm) / Jm) if Jc != Jm else math.inf   # ln(p_sep / X)

    def polhode(self, x) -> PH.Polhode:
        """The free polhode at slow state x = (ln X, ln p) about this flow's axis."""
        return PH.Polhode(self.J, self.c, self.s_c, math.exp(x[0]), math.exp(x[1]))

    def x_of(self, omega) -> np.ndarray:
        """(ln X, ln p) of body-frame states (..., 3) about this flow's axis (p at least 1e-200 X)."""
        w = np.asarray(omega, dtype=float)
        J = self.Jv
        X = np.sum(J * J * w * w, axis=-1)
        p = np.sum(J * np.abs(J[self.c] - J) * w * w, axis=-1)
        # a spin exactly along the axis is the polhode of size 0: taken as one 1e-200 of |L|^2 (no
        # rate, and no output, can tell them apart; the logarithm stays finite)
        return np.stack([np.log(X), np.log(np.maximum(p, 1e-200 * X))], axis=-1)

    # --- the radiation along the polhode --------------------------------------------------------
    def _radiation(self, w) -> np.ndarray:
        if self.free:
            return np.zeros_like(w)
        return np.stack(np.broadcast_arrays(*self.rad(w[..., 0], w[..., 1], w[..., 2], self.J, self.g)), axis=-1)

    def _forcing(self, w) -> np.ndarray:
        """The transverse radiation at the state's projection on the axis, F(w_c) (..., 3)."""
        axis = np.zeros_like(w)
        axis[..., self.c] = w[..., self.c]
        F = self._radiation(axis)
        F[..., self.c] = 0.0
        return F

    def _slow_rates(self, w, a, X, p):
        J = self.Jv
        dX = 2.0 * np.sum(J * J * w * a, axis=-1)
        dp = 2.0 * np.sum(J * np.abs(J[self.c] - J) * w * a, axis=-1)
        return np.stack([dX / X, dp / p])

    def _phase(self, w) -> np.ndarray:
        """The polhode phase of states w (..., 3) on their own polhodes about this axis."""
        x = self.x_of(w)
        pol = PH.Polhode(self.J, self.c, self.s_c, np.exp(x[..., 0]), np.exp(x[..., 1]))
        return pol.phase(w)

    def _sigma_free(self, pol: PH.Polhode, u) -> np.ndarray:
        w = pol.omega(u)
        f = np.stack(free_rate(w[..., 0], w[..., 1], w[..., 2], self.J, None), axis=-1)
        return pol.sigma_rate(w, f)

    # --- the averages ------------------------------------------------------------------------
    def averages(self, x, phases: bool = True, order2: bool = False) -> Averages:
        """The averaged rates at slow state x = (ln X, ln p) (cached per state): ``phases``
        adds the torque's corrections to the phase rates, ``order2`` the second-order terms of
        the slow rates (``_second_order``)."""
        key = (float(x[0]), float(x[1]), phases, order2)
        hit = self._cache.get(key)
        if hit is not None:
            return hit
        if len(self._cache) > 64:
            self._cache.clear()
        lam, flow_n, x_n = self.normalized(x)
        raw = flow_n._averages(x_n, phases, order2)
        out = replace(raw, rates=raw.rates * lam, omega_p=raw.omega_p * lam, u_rate=raw.u_rate * lam,
                      sigma_rate=raw.sigma_rate * lam, osc=raw.osc * lam, w0=raw.w0 * lam, pol=self.polhode(x))
        self._cache[key] = out
        return out

    def normalized(self, x):
        """(lam, flow_n, x_n): the state x as |L| = 1 of the same body with coupling sqrt(lam) g,
        lam = |L|.  Both models obey a(lam w; g) = lam^2 a(w; sqrt(lam) g) exactly (the spin
        units' own rescaling), so every rate at x is lam times the rate at x_n = (0, ln p - ln X)
        and every ratio (mu, U, V) is the same: the flow keeps its digits however far the spin
        has braked (|omega| ~ 1e-100 of its start at 1e200 braking times)."""
        lam = math.exp(0.5 * float(x[0]))
        key = ("flow", lam)
        fn = self._cache.get(key)
        if fn is None:
            system = System(self.system.model, self.J, tuple(math.sqrt(lam) * gi for gi in self.g))
            fn = Flow(system, self.c, self.s_c)
            self._cache[key] = fn
        # a trial state of the solver beyond the separatrix (p > p_sep) is held just inside it, and a
        # polhode below e^-690 of |L|^2 (nothing in float64 tells it from the axis) at that size
        return lam, fn, np.array([0.0, min(max(float(x[1]) - float(x[0]), LN_P_MIN), self._ln_sep - 1e-12)])

    def rates(self, x) -> np.ndarray:
        """The averaged (d ln X/dt, d ln p/dt) at x alone, first order (a plan's quick look)."""
        lam, fn, x_n = self.normalized(x)
        pol = fn.polhode(x_n)
        N = node_count(float(pol.parameters()[3]))
        w, a, f = fn._state(x_n, pol.nodes(N), True)
        return lam * np.mean(f, axis=-1)

    def _state(self, x, u, shifted: bool):
        """(w, a, f) at slow state x and phases u: the free states, the radiation (the
        forcing taken off where ``shifted``), the slow rates."""
        pol = self.polhode(x)
        w = pol.omega(u)
        a, F = self._radiation_nodes(w, x)
        if not shifted:
            a = a + F
        return w, a, self._slow_rates(w, a, math.exp(x[0]), math.exp(x[1]))

    def _radiation_nodes(self, w, x):
        """(a - F, F), both (..., 3): the radiation a at states w less F, its transverse part at
        their projection on the axis (the forcing, which averages out).  Near the axis (p/X < ``NEAR_AXIS``) a's transverse part,
        O(sqrt(p/X)) of the whole, would carry the whole's round-off; there the reduced
        model's radiation, a homogeneous cubic in omega, is split by degree in omega_perp,
        a = F + t b1 + t^2 b2 + t^3 b3 (t = |omega_perp|), with b_k read off four evaluations at
        |omega_perp| ~ |omega_c| (exact for a cubic), so every digit of the transverse part
        stays.  The truncated model is cubic to O(tau0 |Omega|): the split is used where that
        is below 1e-12."""
        if self.free:
            z = np.zeros_like(w)
            return z, z
        c = self.c
        axis = np.zeros_like(w)
        axis[..., c] = w[..., c]
        A0 = self._radiation(axis)
        F = A0.copy()
        F[..., c] = 0.0
        near = math.exp(x[1] - x[0]) < NEAR_AXIS
        cubic = self.system.model == "reduced" or self.eps * math.exp(0.5 * x[0]) < 1e-12
        if not (near and cubic):
            return self._radiation(w) - F, F
        perp = w.copy()
        perp[..., c] = 0.0
        t = np.linalg.norm(perp, axis=-1)
        hat = perp / np.where(t > 0.0, t, 1.0)[..., None]
        h = 0.5 * np.abs(w[..., c])[..., None]
        ap, am = self._radiation(axis + h * hat), self._radiation(axis - h * hat)
        a2p, a2m = self._radiation(axis + 2.0 * h * hat), self._radiation(axis - 2.0 * h * hat)
        b1 = (8.0 * (ap - am) - (a2p - a2m)) / (12.0 * h)
        b2 = (ap + am - 2.0 * A0) / (2.0 * h * h)
        b3 = ((a2p - a2m) - 2.0 * (ap - am)) / (12.0 * h**3)
        tt = t[..., None]
        return (A0 - F) + tt * (b1 + tt * (b2 + tt * b3)), F

    def _averages(self, x, phases: bool, order2: bool) -> Averages:
        pol = self.polhode(x)
        _, _, _, K = pol.parameters()
        N = node_count(float(K))
        u = pol.nodes(N)
        shifted = self.shift_mode(x, self.s_c * float(pol.amplitudes[2]))
        w = pol.omega(u)
        a_hat, F = self._radiation_nodes(w, x)
        a = a_hat if shifted else a_hat + F
        f = self._slow_rates(w, a, math.exp(x[0]), math.exp(x[1]))
        # the means with the forcing taken off (it averages out exactly: only its round-off would stay)
        f_hat = f if shifted else self._slow_rates(w, a_hat, math.exp(x[0]), math.exp(x[1]))
        rates = np.mean(f_hat, axis=-1)
        omega_p = float(pol.frequency)
        f_osc = f - np.mean(f, axis=-1)[:, None]
        osc = np.fft.rfft(f_osc, axis=-1) / N
        U = np.fft.irfft(_antider(osc) * N, n=N, axis=-1) / omega_p
        mu_osc = float(np.max(np.abs(U)))
        grad = self._grad_ln_frequency(x)
        period = 2.0 * math.pi / omega_p
        mu_ad = period * abs(float(grad @ rates))
        sd = float(pol.separatrix_distance)
        mu_sep = period * abs((1.0 - sd) * (rates[1] - rates[0])) / sd if sd > 0.0 else math.inf
        ffree = np.stack(free_rate(w[..., 0], w[..., 1], w[..., 2], self.J, None), axis=-1)
        S = pol.sigma_rate(w, ffree)
        cS = np.fft.rfft(S) / N
        w0 = cS.copy()
        w0[0] = 0.0
        u_rate, sigma_rate = omega_p, float(np.real(cS[0]))
        vcoef = np.zeros_like(cS)
        if phases or order2:
            gamma = self._gamma(pol, w, a)
            g_osc = gamma - np.mean(gamma)
            # V: the phase's first-order oscillation, (grad omega_p . U + gamma~) / omega_p integrated
            dwp = omega_p * (grad[0] * U[0] + grad[1] * U[1])
            vcoef = _antider(np.fft.rfft(dwp + g_osc) / N) / omega_p
            if order2:
                rates = rates + self._second_order(x, u, shifted, f, f_osc, U, dwp + g_osc, omega_p)
            if phases:
                u_rate = omega_p + float(np.mean(gamma))
                sigma_rate = self._sigma_rate(pol, x, u, w, a, f, omega_p, ffree, S, gamma)
        mu_slope = float(np.max(np.abs(f_osc))) / omega_p
        return Averages(rates, omega_p, u_rate, sigma_rate, osc, vcoef, w0, mu_osc, mu_ad, mu_sep, N, pol, shifted,
                        mu_slope)

    def _grad_ln_frequency(self, x) -> np.ndarray:
        """d ln omega_p / dx (central differences)."""
        h = FD_REL * max(1.0, abs(x[0]), abs(x[1]))
        out = np.zeros(2)
        for k in range(2):
            e = np.zeros(2)
            e[k] = h
            out[k] = (math.log(float(self.polhode(x + e).frequency))
                      - math.log(float(self.polhode(x - e).frequency))) / (2.0 * h)
        return out

    def _gamma(self, pol, w, a) -> np.ndarray:
        """grad u . a at the nodes: the torque's part of the phase rate, by a central
        difference of the phase function along a."""
        amp = float(min(pol.amplitudes[0], pol.amplitudes[1]))
        an = float(np.max(np.linalg.norm(a, axis=-1)))
        if not (an > 0.0 and amp > 0.0):
            return np.zeros(w.shape[0])
        h = FD_REL * amp / an
        du = self._phase(w + h * a) - self._phase(w - h * a)
        return (np.mod(du + np.pi, 2.0 * np.pi) - np.pi) / (2.0 * h)

    def _second_order(self, x, u, shifted, f, f_osc, U, g_tot, omega_p) -> np.ndarray:
        """F2 = < df/dx . U > - < f~ (grad omega_p . U + gamma~) > / omega_p: the second-order
        averaged slow rates (x = y + U(y, v), u = v + V(y, v); Sanders, Verhulst & Murdock,
        Averaging Methods, 2.9), with df/dx at fixed u by central differences."""
        h = FD_REL * max(1.0, abs(x[0]), abs(x[1]))
        out = np.zeros(2)
        acc = np.zeros_like(f)
        for k in range(2):
            e = np.zeros(2)
            e[k] = h
            fp = self._state(x + e, u, shifted)[2]
            fm = self._state(x - e, u, shifted)[2]
            acc += (fp - fm) / (2.0 * h) * U[k]
        out += np.mean(acc, axis=-1)
        out -= np.mean(f_osc * g_tot, axis=-1) / omega_p
        return out

    def _sigma_rate(self, pol, x, u, w, a, f, omega_p, ffree, S, gamma) -> float:
        """d Sigma_bar / dt with the torque's first-order corrections (module docstring)."""
        N = u.size
        sig_rad = pol.sigma_rate(w, ffree + a) - S
        S_mean = float(np.mean(S))
        S_osc = S - S_mean
        # dW0/dx at fixed u: W0 = (zero-mean antiderivative of Sigma_dot_free) / omega_p
        hx = FD_REL * max(1.0, abs(x[0]), abs(x[1]))
        dW = np.zeros((2, N))
        for k in range(2):
            e = np.zeros(2)
            e[k] = hx
            Wp = spectral_integral(self._sigma_free(self.polhode(x + e), u))[1] / float(self.polhode(x + e).frequency)
            Wm = spectral_integral(self._sigma_free(self.polhode(x - e), u))[1] / float(self.polhode(x - e).frequency)
            dW[k] = (Wp - Wm) / (2.0 * hx)
        corr = sig_rad - dW[0] * f[0] - dW[1] * f[1] - S_osc * gamma / omega_p
        return S_mean + float(np.mean(corr))

    # --- the forced offset -------------------------------------------------------------------------
    def forced_offset(self, w_c: float) -> np.ndarray:
        """x_f (3,): the forced tilt of the rotation axis from c at w_c, to second order (zero
        component along c; zero where the model has no transverse forcing); evaluated at
        |w_c| = 1 with the coupling rescaled (``normalized``)."""
        if self.free or w_c == 0.0:
            return np.zeros(3)
        lam = abs(float(w_c)) * float(self.Jv[self.c])
        if abs(lam - 1.0) > 1e-12:
            _, fn, _ = self.normalized([2.0 * math.log(lam), 0.0])
            return lam * fn._forced_offset(float(w_c) / lam)
        return self._forced_offset(w_c)

    def _forced_offset(self, w_c: float) -> np.ndarray:
        """``forced_offset`` at this flow's own scale."""
        o, m, c = PH.Polhode(self.J, self.c, self.s_c, 1.0, 1.0).labels
        ax = np.zeros(3)
        ax[c] = w_c
        F = self._radiation(ax)
        Fv = np.array([F[o], F[m]])
        if not np.any(Fv != 0.0):
            return np.zeros(3)
        M = np.zeros((2, 2))
        Mr = np.zeros((2, 2))
        h = 1e-6 * abs(w_c)
        for j, idx in enumerate((o, m)):
            e = ax.copy()
            e[idx] = 1.0
            fr = free_rate(*e, self.J, None)            # exact: the free rate is quadratic, zero on an axis
            M[:, j] = (fr[o], fr[m])
            ep, em = ax.copy(), ax.copy()
            ep[idx] += h
            em[idx] -= h
            d = (self._radiation(ep) - self._radiation(em)) / (2.0 * h)
            Mr[:, j] = (d[o], d[m])
        x1 = -np.linalg.solve(M, Fv)
        # d x1/dt: x1 ~ w_c^2 (F ~ w_c^3, M ~ w_c), and w_c brakes at a_c(w_c e_c)
        dx1 = 2.0 * x1 / w_c * float(F[c])
        x2 = -np.linalg.solve(M + Mr, Fv - dx1)
        out = np.zeros(3)
        out[o], out[m] = x2
        return out

    def shift_mode(self, x, w_c: float) -> bool:
        """Whether the forced offset is taken off before averaging at this state (it is more
        than ``SHIFT_RATIO`` of the polhode's transverse size)."""
        if self.free or w_c == 0.0:
            return False
        if abs(float(x[0])) > 1e-12:
            lam, fn, x_n = self.normalized(x)
            return fn.shift_mode(x_n, float(w_c) / lam)
        pol = self.polhode(x)
        amp = float(min(pol.amplitudes[0], pol.amplitudes[1]))
        ax = np.zeros(3)
        ax[self.c] = w_c
        F = self._radiation(ax)
        F[self.c] = 0.0
        # |x_f| is about |F| / omega_p: far below the threshold, no need to solve for it
        if float(np.linalg.norm(F)) < 1e-3 * SHIFT_RATIO * amp * float(pol.frequency):
            return False
        xf = self.forced_offset(w_c)
        if not np.any(xf != 0.0):
            return False
        return float(np.linalg.norm(xf)) > SHIFT_RATIO * amp

    # --- the transform ----------------------------------------------------------------------------
    def transform(self, av: Averages, u: float) -> np.ndarray:
        """U (2,): the oscillating part of x at phase u of the polhode of ``av``."""
        return eval_series(av.osc, float(u), integral=True) / av.omega_p

    def phase_shift(self, av: Averages, u: float) -> float:
        """V: the phase's first-order oscillation at phase u (0 where not computed)."""
        return float(eval_series(av.vcoef, float(u)))

    def w0(self, av: Averages, u) -> np.ndarray:
        """W0 at phases u: the free motion's periodic part of Sigma."""
        return eval_series(av.w0, u, integral=True) / av.omega_p

    def to_averaged(self, omega, order2: bool = False) -> tuple[np.ndarray, float, bool, np.ndarray]:
        """(x_bar, u_bar, shifted, x_f) of the true body-frame state omega (3,): the forced
        offset taken off where it dominates, then the first-order inverse transform."""
        w = np.asarray(omega, dtype=float)
        x = self.x_of(w)
        shifted = self.shift_mode(x, float(w[self.c]))
        xf = self.forced_offset(float(w[self.c])) if shifted else np.zeros(3)
        if shifted:
            w = w - xf
            x = self.x_of(w)
        u = float(self._phase(w))
        av = self.averages(x, phases=False, order2=order2)
        return x - self.transform(av, u), u - self.phase_shift(av, u), av.shifted, xf

    def to_true(self, x_bar, u_bar, order2: bool = False) -> tuple[np.ndarray, np.ndarray, float]:
        """(omega (3,), x (2,), u) of the averaged state (x_bar, u_bar)."""
        x_bar = np.asarray(x_bar, dtype=float)
        av = self.averages(x_bar, phases=False, order2=order2)
        x = x_bar + self.transform(av, u_bar)
        u = float(u_bar) + self.phase_shift(av, u_bar)
        w = self.polhode(x).omega(u)
        if av.shifted:
            w = w + self.forced_offset(float(w[self.c]))
        return w, x, u


def _antider(c: np.ndarray) -> np.ndarray:
    n = np.arange(c.shape[-1])
    d = np.zeros_like(c)
    d[..., 1:] = c[..., 1:] / (1j * n[1:])
    return d


def separatrix_odds(system, omega, axis, span: float = 40.0, n: int = 4001) -> dict:
    """Where a run leaving the lobe about (c, s_c) through the separatrix goes: the two lobes
    about the other extreme axis o, (o, +1) and (o, -1), with probabilities proportional to the
    flux of the torque out of the lobe through the separatrix branch each shares with it
    (Neishtadt's capture probabilities: each branch's integral of dh/dt along its homoclinic
    orbit, h = (X - J_m 2E) / X, at the |L| of ``omega``).  Returns {"to": [[o, +1, P+],
    [o, -1, P-]], "flux": [F+, F-]} (F per passage, relative), P = 0.5 each where neither flux
    leaves the lobe."""
    J = np.asarray(system.inertia, dtype=float)
    Jt = tuple(J)
    g = tuple(float(x) for x in system.coupling)
    c, s_c = int(axis[0]), float(axis[1])
    o, m, _ = PH.Polhode(Jt, c, s_c, 1.0, 1.0).labels
    w = np.asarray(omega, dtype=float)
    X = float(np.sum(J * J * w * w))
    Jo, Jm, Jc = J[o], J[m], J[c]
    p = abs(Jc - Jm) * X / Jm
    q = (abs(Jc - Jo) * X - Jo * p) / Jc
    lam = math.sqrt(abs(Jc - Jm) * q / (Jo * Jm * Jc))
    Ao, Am, Ac = math.sqrt(p / (Jo * abs(Jc - Jo))), math.sqrt(p / (Jm * abs(Jc - Jm))), math.sqrt(q / (Jc * abs(Jc - Jo)))
    tau = np.linspace(-span, span, n)
    sech, tanh = 1.0 / np.cosh(tau), np.tanh(tau)
    rad = radiation_function(system.model)
    sig_h = 1.0 if Jc > Jo else -1.0
    flux = []
    for so in (1.0, -1.0):
        e = np.zeros(3)
        e[o], e[c] = so, s_c
        s_m = 1.0 if free_rate(*e, Jt, None)[m] > 0.0 else -1.0
        ws = np.zeros((n, 3))
        ws[:, o], ws[:, m], ws[:, c] = so * Ao * sech, s_m * Am * tanh, s_c * Ac * sech
        a = np.stack(np.broadcast_arrays(*rad(ws[:, 0], ws[:, 1], ws[:, 2], Jt, g)), axis=-1)
        hdot = 2.0 * np.sum(J * (J - Jm) * ws * a, axis=-1) / X
        flux.append(-sig_h * float(np.trapezoid(hdot, tau)) / lam)
    pos = [max(f, 0.0) for f in flux]
    tot = sum(pos)
    probs = [f / tot for f in pos] if tot > 0.0 else [0.5, 0.5]
    return {"to": [[int(o), 1.0, probs[0]], [int(o), -1.0, probs[1]]], "flux": flux}


def precession_harmonics(flow: Flow, x) -> tuple[float, float, np.ndarray, float]:
    """(nu_phi, omega_p, c, |L|) at slow state x: the mean rate of phi (the free turn about L),
    the polhode frequency, and the Fourier coefficients c_n (n = -N/2 .. N/2 - 1, numpy's FFT
    order) of the torque across L along the free motion, Z(u) e^{i phi~(u)}, where
    Z = N_x + i N_y in the L frame before the turn phi and phi~ the periodic part of phi: the
    world-frame torque across L turns as sum_n c_n e^{i (nu_phi + n omega_p) t}."""
    lam, fn, x_n = flow.normalized(x)
    nu, wp, c, L = _precession_harmonics(fn, x_n)
    # rates scale with lam, the torque J a with lam^2, |L| with lam
    return nu * lam, wp * lam, c * lam * lam, L * lam


def _precession_harmonics(flow: Flow, x):
    av = flow._averages(np.asarray(x, dtype=float), False, False)
    pol = av.pol
    N = av.nodes
    u = pol.nodes(N)
    w = pol.omega(u)
    omega_p = av.omega_p
    t = u / omega_p
    ffree = np.stack(free_rate(w[..., 0], w[..., 1], w[..., 2], flow.J, None), axis=-1)
    S = pol.sigma_rate(w, ffree)
    cS, W0 = spectral_integral(S)
    Sm = float(np.real(cS[0]))
    theta, psi, _ = pol.L_angles(w)
    psi = np.unwrap(psi)
    wind = round((psi[-1] - psi[0] + (psi[1] - psi[0])) / (2.0 * np.pi))
    nu_phi = Sm - pol.s_c * wind * omega_p
    phi = Sm * t + W0 / omega_p - pol.s_c * psi
    phi_t = phi - nu_phi * t
    a = flow._radiation(w)
    Nb = flow.Jv * a
    fa, fb, fc = pol.frame
    Nf = np.stack([Nb[:, fa], Nb[:, fb], Nb[:, fc]], axis=-1)
    # V = Rx(theta) Rz(psi) N_frame: the torque in the L frame before the turn phi
    cp, sp = np.cos(psi), np.sin(psi)
    v1, v2, v3 = cp * Nf[:, 0] - sp * Nf[:, 1], sp * Nf[:, 0] + cp * Nf[:, 1], Nf[:, 2]
    ct, st = np.cos(theta), np.sin(theta)
    V1, V2 = v1, ct * v2 - st * v3
    Z = (V1 + 1j * V2) * np.exp(1j * phi_t)
    return nu_phi, omega_p, np.fft.fft(Z) / N, math.sqrt(float(pol.X))
