"""Compiled kernels (numba): the splitting integrators and the shared Dormand-Prince 8(5,3)
pieces (``tableaus.DP853``) of the secular slow flow.

They stay compiled where ``spinviz bench`` shows they win: the splitting (``split2`` ..
``split8``) takes steps set by the braking, not the spin, where the torque commutes with the
free flow ((6.10), (3.9): 1e6 turns in milliseconds, where a resolving method needs ~3e6
steps), and ``secular`` averages the free precession over 1e6 .. 1e25 turns, which no
resolving method can follow.  Every run that resolves each turn goes to Taylor's method
(``taylor``, heyoka) instead.

The Euler-equation rates are the functions of ``physics.equations`` themselves, compiled
by numba: one source serves the Python paths, these loops and heyoka's expressions.

Compensated summation.  Over 1e6 turns the spin phase is 6e6 rad; to hold it to 1e-8 rad,
the state must stay right to ~1e-15 relative over millions of updates.  Plain additions lose
~1e-16 at each update and the losses random-walk into the phase (measured: ~5e-8 rad after
1e4 turns), so the splitting's polar state is updated by compensated summation (Hairer,
Lubich & Wanner, Geometric Numerical Integration, VIII.5): the rounding error of each addition
is carried into the next increment.

Set NUMBA_DISABLE_JIT=1 to run these loops as plain Python (debugging, coverage).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..physics import equations as E
from . import tableaus as T
from .status import (  # noqa: F401
    INTERRUPTED,
    NOT_FINITE,
    OK,
    STEP_UNDERFLOW,
    STOP_POLL,
    TOO_MANY_STEPS,
)

_jit = nb.njit(cache=True, nogil=True)    # nogil: interrupt.call_stoppable runs them in a thread

_free = _jit(E.free_rate)
_reduced = _jit(E.reduced_terms)
_truncated = _jit(E.truncated_terms)


@_jit
def terms(model, w1, w2, w3, J, g, free):
    """Omega_dot of the model whose ``kernel_id`` (``physics.models``) is ``model``: 0 free, 1
    reduced, 2 truncated; ``free`` = 0 keeps only the radiation part (see
    physics.equations.reduced_terms).  numba dispatches on a number, not on the registry: a
    model with a compiled kernel adds its branch here."""
    if model == 1:
        return _reduced(w1, w2, w3, J, g, free)
    if model == 2:
        return _truncated(w1, w2, w3, J, g, free)
    a = _free(w1, w2, w3, J, g)
    return free * a[0], free * a[1], free * a[2]


@_jit
def rate(model, w1, w2, w3, J, g):
    """The whole Omega_dot."""
    return terms(model, w1, w2, w3, J, g, 1.0)


@_jit
def qmul(a0, a1, a2, a3, b0, b1, b2, b3):
    """Hamilton product of scalar-first quaternions."""
    return (
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    )


@_jit
def qexp(u1, u2, u3):
    """Unit quaternion (w, x, y, z) of the rotation vector u (angle |u| about u/|u|)."""
    th = math.sqrt(u1 * u1 + u2 * u2 + u3 * u3)
    if th < 1e-4:
        # sin(th/2)/th = 1/2 - th^2/48 + th^4/3840: the division loses digits near 0
        t2 = th * th
        s = 0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    else:
        s = math.sin(0.5 * th) / th
    return math.cos(0.5 * th), s * u1, s * u2, s * u3


@_jit
def compensated(x, increment, err):
    """(x + increment, new carry), the rounding error of the sum carried in ``err``
    (compensated summation: Omega and t over millions of steps keep ~1 ulp)."""
    d = increment + err
    s = x + d
    return s, (x - s) + d


@_jit
def add_compensated(y, k, increment, err):
    """y[k] += increment with the rounding error carried in err[k]."""
    y[k], err[k] = compensated(y[k], increment, err[k])


@_jit
def stage_point(A, K, y, h, i, n, ys):
    """ys = y + h sum_{l < i} A[i, l] K[l] (first n components): the point of RK stage i."""
    for k in range(n):
        acc = 0.0
        for l in range(i):
            acc += A[i, l] * K[l, k]
        ys[k] = y[k] + h * acc


@_jit
def substeps(dt, h):
    """Fixed-step methods cut an output interval dt into m equal steps of at most h: (m, dt/m)."""
    m = max(1, int(math.ceil(dt / h - 1e-9)))
    return m, dt / m


@_jit
def first_guess(y, f0, n, rtol, atol, span, sc, ys):
    """Hairer, Norsett & Wanner (II.4), first half: the trial step h0 from y and f(y) = f0, the
    error scales ``sc`` and the trial point ``ys`` = y + h0 f0 (where the caller evaluates f1).
    Returns (h0, d1)."""
    d0 = 0.0
    d1 = 0.0
    for k in range(n):
        sc[k] = atol + abs(y[k]) * rtol
        d0 += (y[k] / sc[k]) ** 2
        d1 += (f0[k] / sc[k]) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, span)
    for k in range(n):
        ys[k] = y[k] + h0 * f0[k]
    return h0, d1


@_jit
def second_guess(f0, f1, n, sc, h0, d1, h_max):
    """II.4, second half: the first step from the change f1 - f0 over the trial step (order 8)."""
    d2 = 0.0
    for k in range(n):
        d2 += ((f1[k] - f0[k]) / sc[k]) ** 2
    d2 = math.sqrt(d2 / n) / h0
    h1 = max(1e-6, h0 * 1e-3) if (d1 <= 1e-15 and d2 <= 1e-15) else (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, h_max)


@_jit
def error_norm(K, y, y_new, h, n, rtol, atol, E3, E5, by_increment=-1):
    """The Dormand-Prince 8(5,3) pair's scaled error of the step (5th- and 3rd-order embedded estimates, SciPy's norm),
    and whether y_new is finite.  Component ``by_increment`` (if >= 0), a phase that grows to
    2 pi x the turns, is held to rtol x its increment rather than rtol x its size."""
    e5 = 0.0
    e3 = 0.0
    finite = True
    for k in range(n):
        s5 = 0.0
        s3 = 0.0
        for l in range(13):
            s5 += E5[l] * K[l, k]
            s3 += E3[l] * K[l, k]
        if k == by_increment:
            scale = atol + abs(y_new[k] - y[k]) * rtol
        else:
            scale = atol + max(abs(y[k]), abs(y_new[k])) * rtol
        e5 += (s5 / scale) ** 2
        e3 += (s3 / scale) ** 2
        if not math.isfinite(y_new[k]):
            finite = False
    if e5 == 0.0 and e3 == 0.0:
        return 0.0, finite
    return h * e5 / math.sqrt((e5 + 0.01 * e3) * n), finite


@_jit
def dense_assemble(D, K, y, y_new, h, n, F):
    """The 7 x n dense-output coefficients F from the 16 stages in K (after the 3 extra ones)."""
    for k in range(n):
        dy = y_new[k] - y[k]
        F[0, k] = dy
        F[1, k] = h * K[0, k] - dy
        F[2, k] = 2.0 * dy - h * (K[12, k] + K[0, k])
        for r in range(4):
            acc = 0.0
            for l in range(16):
                acc += D[r, l] * K[l, k]
            F[3 + r, k] = h * acc


@_jit
def dense_eval(F, y, x, n, out):
    """out = the dense-output state at the fraction x in [0, 1] of the step."""
    for k in range(n):
        v = 0.0
        for r in range(7):
            v += F[6 - r, k]
            if r % 2 == 0:
                v *= x
            else:
                v *= 1.0 - x
        out[k] = y[k] + v


DP853_ARRAYS = (T.DP853_A, T.DP853_B, T.DP853_E3, T.DP853_E5, T.DP853_D)   # the system is autonomous: no c


# --- splitting: exact torque-free flow of a symmetric top + radiation torque ------------
@_jit
def radiation(model, w1, w2, w3, J, g):
    """The radiation part of Omega_dot alone (no free part to cancel against)."""
    return terms(model, w1, w2, w3, J, g, 0.0)


@_jit
def free_flow(st, q, tau, J, with_q, ec):
    """Exact torque-free motion of a symmetric top (I1 = I2) over time tau, in place.

    State st = (rho, phi, Omega3): Omega_perp = rho (cos phi, sin phi).  Body form of
    O(t) = R_L(|L| t / I1) O(0) R_e3(delta Omega3 t): q <- q (x) exp(L_body tau / I1) (x)
    exp(e3 delta Omega3 tau); Omega_perp turns by -delta Omega3 tau, i.e. phi changes and rho
    does not -- held in polar form so that no rounding ever touches |Omega_perp| here."""
    J1, J3 = J[0], J[2]
    ang = (1.0 - J3 / J1) * st[2] * tau
    if with_q:
        w1, w2 = st[0] * math.cos(st[1]), st[0] * math.sin(st[1])
        a = qexp(w1 * tau, w2 * tau, J3 / J1 * st[2] * tau)
        b = qexp(0.0, 0.0, ang)
        r = qmul(q[0], q[1], q[2], q[3], a[0], a[1], a[2], a[3])
        r = qmul(r[0], r[1], r[2], r[3], b[0], b[1], b[2], b[3])
        n = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3])
        q[0], q[1], q[2], q[3] = r[0] / n, r[1] / n, r[2] / n, r[3] / n
    if ang != 0.0:
        add_compensated(st, 1, -ang, ec)


@_jit
def radiation_flow(model, st, tau, J, g, A, b, rh_max, ec):
    """Omega under the radiation torque alone over time tau (q does not move), by the 8th-order
    Dormand-Prince formula (``tableaus.DP853``) in substeps of at most rh_max in units of the local decay time.

    The increment dOmega is accumulated on its own (it is small) and then turned into
    increments of rho, phi and Omega3 without cancellation, each added with compensation."""
    # Long on purpose: a numba kernel on scalars; helpers returning the increments would cost a tuple per stage.
    c, s_ = math.cos(st[1]), math.sin(st[1])
    w1, w2, w3 = st[0] * c, st[0] * s_, st[2]
    r = radiation(model, w1, w2, w3, J, g)
    wn = math.sqrt(w1 * w1 + w2 * w2 + w3 * w3)
    rate = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) / wn if wn > 0.0 else 0.0
    x = abs(tau) * rate                      # relative change of Omega over the sub-flow
    nfev = 1
    d1 = d2 = d3 = 0.0                       # the increment of Omega over the whole sub-flow
    if x < 1e-6:
        # RK4's error relative to the increment is ~1e3 x^4 (measured): < 1e-21 here.  At
        # x ~ 1e-4 it is ~1e-15, systematic, and adds up to ~1e-9 rad of phase over 1e4
        # turns -- so larger changes take the 8th-order formula below.
        k1 = r
        k2 = radiation(model, w1 + 0.5 * tau * k1[0], w2 + 0.5 * tau * k1[1], w3 + 0.5 * tau * k1[2], J, g)
        k3 = radiation(model, w1 + 0.5 * tau * k2[0], w2 + 0.5 * tau * k2[1], w3 + 0.5 * tau * k2[2], J, g)
        k4 = radiation(model, w1 + tau * k3[0], w2 + tau * k3[1], w3 + tau * k3[2], J, g)
        d1 = tau * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]) / 6.0
        d2 = tau * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]) / 6.0
        d3 = tau * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]) / 6.0
        nfev += 3
        n = 0
    else:
        n = max(1, int(math.ceil(x / rh_max)))
    hh = tau / n if n > 0 else 0.0
    s = b.shape[0]
    K = np.empty((s, 3))
    for _ in range(n):
        for i in range(s):
            y1, y2, y3 = w1 + d1, w2 + d2, w3 + d3
            for l in range(i):
                y1 += hh * A[i, l] * K[l, 0]
                y2 += hh * A[i, l] * K[l, 1]
                y3 += hh * A[i, l] * K[l, 2]
            k = radiation(model, y1, y2, y3, J, g)
            K[i, 0], K[i, 1], K[i, 2] = k[0], k[1], k[2]
        nfev += s
        a1 = a2 = a3 = 0.0
        for i in range(s):
            a1 += b[i] * K[i, 0]
            a2 += b[i] * K[i, 1]
            a3 += b[i] * K[i, 2]
        d1 += hh * a1
        d2 += hh * a2
        d3 += hh * a3
    rho = st[0]
    if rho > 0.0:
        # exact algebra: rho' - rho = (2 w.d + |d|^2) / (rho' + rho); dphi = angle from w to w + d
        rho_new = math.hypot(w1 + d1, w2 + d2)
        drho = (2.0 * (w1 * d1 + w2 * d2) + d1 * d1 + d2 * d2) / (rho_new + rho)
        dphi = math.atan2(w1 * d2 - w2 * d1, rho * rho + w1 * d1 + w2 * d2)
        add_compensated(st, 0, drho, ec)
        add_compensated(st, 1, dphi, ec)
    else:
        st[0] = math.hypot(d1, d2)
        st[1] = math.atan2(d2, d1)
    add_compensated(st, 2, d3, ec)
    return nfev


@_jit
def split_symmetric(model, J, g, w0, q0, t_eval, h, gammas, with_q, max_steps, rh_max, A, b, stop):
    """Fixed-step composition of Strang steps A(h/2) B(h) A(h/2) with weights ``gammas``
    (orders 2, 4, 6, 8).  Returns (omega (N,3), q (N,4), nfev, nsteps, status)."""
    N = t_eval.shape[0]
    out_w = np.empty((N, 3))
    out_q = np.empty((N, 4))
    st = np.array([math.hypot(w0[0], w0[1]), math.atan2(w0[1], w0[0]), w0[2]])   # (rho, phi, Omega3)
    q = q0.copy()
    ec = np.zeros(3)                       # compensated-summation carries of (rho, phi, Omega3)
    out_w[0, :] = w0
    out_q[0, :] = q
    nfev = 0
    nsteps = 0
    for j in range(N - 1):
        m, hh = substeps(t_eval[j + 1] - t_eval[j], h)
        ns = gammas.shape[0]
        for step in range(m):
            # A(g1 h/2) B(g1 h) A((g1+g2) h/2) B(g2 h) ... B(gs h) A(gs h/2): neighbouring half
            # free flows merged (the free flow is a one-parameter group), also across steps
            if step == 0:
                free_flow(st, q, 0.5 * gammas[0] * hh, J, with_q, ec)
            for k in range(ns):
                nfev += radiation_flow(model, st, gammas[k] * hh, J, g, A, b, rh_max, ec)
                if k < ns - 1:
                    free_flow(st, q, 0.5 * (gammas[k] + gammas[k + 1]) * hh, J, with_q, ec)
                elif step < m - 1:
                    free_flow(st, q, 0.5 * (gammas[k] + gammas[0]) * hh, J, with_q, ec)
                else:
                    free_flow(st, q, 0.5 * gammas[k] * hh, J, with_q, ec)
            nsteps += 1
            if not (math.isfinite(st[0]) and math.isfinite(st[1]) and math.isfinite(st[2])):
                return out_w, out_q, nfev, nsteps, NOT_FINITE
            if nsteps > max_steps:
                return out_w, out_q, nfev, nsteps, TOO_MANY_STEPS
            if nsteps % STOP_POLL == 0 and stop[0] != 0:
                return out_w, out_q, nfev, nsteps, INTERRUPTED
        out_w[j + 1, 0] = st[0] * math.cos(st[1])
        out_w[j + 1, 1] = st[0] * math.sin(st[1])
        out_w[j + 1, 2] = st[2]
        out_q[j + 1, :] = q
    return out_w, out_q, nfev, nsteps, OK
