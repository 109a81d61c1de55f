"""Compiled kernels (numba) for the geometric integrators.

The Euler-equation rates are the functions of ``physics.equations`` themselves, compiled
by numba: one source serves the Python paths and these loops.

Lie-group Runge-Kutta (Munthe-Kaas): within a step the orientation is written
q(t) = q_n (x) exp(u(t)) with u a rotation vector (u = 0 at the step's start), and the
pair (Omega, u) obeys an ODE in R^6,

    Omega_dot = model rate,   u_dot = dexp^-1_u(Omega) = Omega + u x Omega / 2
                                      + (1 - (|u|/2) cot(|u|/2)) / |u|^2 u x (u x Omega),

the inverse right Jacobian of SO(3), exact in closed form.  Any explicit RK tableau applied
to that ODE keeps its order, and q_{n+1} = q_n (x) exp(u_{n+1}) is a product of unit
quaternions: |q| = 1 by construction (up to round-off, which a renormalization per step
keeps at the 1e-16 level instead of letting it random-walk).

Set NUMBA_DISABLE_JIT=1 to run these loops as plain Python (debugging, coverage).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..physics import equations as E
from . import tableaus as T

_jit = nb.njit(cache=True)

MODEL_ID = {"free": 0, "reduced": 1, "truncated": 2}

_free = _jit(E.free_rate)
_reduced = _jit(E.reduced_terms)
_truncated = _jit(E.truncated_terms)


@_jit
def rate(model, w1, w2, w3, J, g):
    """Omega_dot components of model 0 (free), 1 (reduced) or 2 (truncated)."""
    if model == 1:
        return _reduced(w1, w2, w3, J, g, 1.0)
    if model == 2:
        return _truncated(w1, w2, w3, J, g, 1.0)
    return _free(w1, w2, w3, J, g)


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
def dexpinv(u1, u2, u3, w1, w2, w3):
    """u_dot = dexp^-1_u(Omega): inverse right Jacobian of SO(3) applied to Omega."""
    t2 = u1 * u1 + u2 * u2 + u3 * u3
    if t2 < 1e-4:
        # (1 - x cot x)/(4 x^2) with x = |u|/2, by its Taylor series (cancellation near 0)
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        th = math.sqrt(t2)
        c = (1.0 - 0.5 * th / math.tan(0.5 * th)) / t2
    a1, a2, a3 = u2 * w3 - u3 * w2, u3 * w1 - u1 * w3, u1 * w2 - u2 * w1
    b1, b2, b3 = u2 * a3 - u3 * a2, u3 * a1 - u1 * a3, u1 * a2 - u2 * a1
    return w1 + 0.5 * a1 + c * b1, w2 + 0.5 * a2 + c * b2, w3 + 0.5 * a3 + c * b3


@_jit
def lie_rhs(model, J, g, y, out, with_q):
    """out = f(y) for y = (Omega, u): model rate and dexp^-1_u(Omega)."""
    a = rate(model, y[0], y[1], y[2], J, g)
    out[0], out[1], out[2] = a[0], a[1], a[2]
    if with_q:
        d = dexpinv(y[3], y[4], y[5], y[0], y[1], y[2])
        out[3], out[4], out[5] = d[0], d[1], d[2]


@_jit
def apply_u(q, u1, u2, u3):
    """q <- q (x) exp(u), renormalized (round-off only)."""
    e = qexp(u1, u2, u3)
    r = qmul(q[0], q[1], q[2], q[3], e[0], e[1], e[2], e[3])
    n = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3])
    q[0], q[1], q[2], q[3] = r[0] / n, r[1] / n, r[2] / n, r[3] / n


@_jit
def _rms(v, n):
    s = 0.0
    for i in range(n):
        s += v[i] * v[i]
    return math.sqrt(s / n)


# status codes shared with the Python wrappers
OK, TOO_MANY_STEPS, STEP_UNDERFLOW, NOT_FINITE, STIFF = 0, 1, 2, 3, 4


@_jit
def lie_fixed(model, J, g, w0, q0, t_eval, h, A, b, c, with_q, max_steps):
    """Fixed-step Lie-group RK with tableau (A, b, c): each output interval is cut into
    ceil(dt/h) equal steps, so the outputs are hit exactly.  Returns
    (omega (N,3), q (N,4), nfev, nsteps, status)."""
    N = t_eval.shape[0]
    s = b.shape[0]
    n = 6 if with_q else 3
    out_w = np.empty((N, 3))
    out_q = np.empty((N, 4))
    K = np.zeros((s, 6))
    y = np.zeros(6)
    ys = np.zeros(6)
    q = q0.copy()
    y[0], y[1], y[2] = w0[0], w0[1], w0[2]
    out_w[0, :] = y[:3]
    out_q[0, :] = q
    nfev = 0
    nsteps = 0
    for j in range(N - 1):
        dt = t_eval[j + 1] - t_eval[j]
        m = max(1, int(math.ceil(dt / h - 1e-9)))
        hh = dt / m
        for _ in range(m):
            for i in range(s):
                for k in range(n):
                    acc = y[k]
                    for l in range(i):
                        acc += hh * A[i, l] * K[l, k]
                    ys[k] = acc
                lie_rhs(model, J, g, ys, K[i], with_q)
            nfev += s
            for k in range(n):
                acc = y[k]
                for l in range(s):
                    acc += hh * b[l] * K[l, k]
                y[k] = acc
            if with_q:
                apply_u(q, y[3], y[4], y[5])
                y[3] = 0.0
                y[4] = 0.0
                y[5] = 0.0
            nsteps += 1
            if not (math.isfinite(y[0]) and math.isfinite(y[1]) and math.isfinite(y[2])):
                return out_w, out_q, nfev, nsteps, NOT_FINITE
            if nsteps > max_steps:
                return out_w, out_q, nfev, nsteps, TOO_MANY_STEPS
        out_w[j + 1, :] = y[:3]
        out_q[j + 1, :] = q
    return out_w, out_q, nfev, nsteps, OK


@_jit
def lie_dop853(model, J, g, w0, q0, t_eval, rtol, atol, h_max, with_q, max_steps, stop_on_stiff,
               A, B, C, E3, E5, D):
    """Adaptive Lie-group DOP853 (error control and 7th-order dense output as in
    Hairer's DOP853 / SciPy), with Hairer's stiffness detection (15 stiff steps in a row:
    record the time, and return with status STIFF when ``stop_on_stiff``).

    Returns (omega (N,3), q (N,4), nfev, nsteps, nrejected, status, stiff_at)."""
    N = t_eval.shape[0]
    n = 6 if with_q else 3
    out_w = np.empty((N, 3))
    out_q = np.empty((N, 4))
    K = np.zeros((16, 6))
    y = np.zeros(6)
    y_new = np.zeros(6)
    ys = np.zeros(6)
    F = np.zeros((7, 6))
    q = q0.copy()
    y[0], y[1], y[2] = w0[0], w0[1], w0[2]
    t = t_eval[0]
    t_end = t_eval[-1]
    out_w[0, :] = y[:3]
    out_q[0, :] = q
    j_out = 1
    lie_rhs(model, J, g, y, K[0], with_q)
    nfev = 1
    # --- initial step (Hairer, Norsett & Wanner, II.4) ---
    sc = np.empty(6)
    for k in range(n):
        sc[k] = atol + abs(y[k]) * rtol
    d0 = 0.0
    d1 = 0.0
    for k in range(n):
        d0 += (y[k] / sc[k]) ** 2
        d1 += (K[0, k] / sc[k]) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, t_end - t)
    for k in range(n):
        ys[k] = y[k] + h0 * K[0, k]
    lie_rhs(model, J, g, ys, K[1], with_q)
    nfev += 1
    d2 = 0.0
    for k in range(n):
        d2 += ((K[1, k] - K[0, k]) / sc[k]) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    h = min(100.0 * h0, h1, h_max)
    nsteps = 0
    nrej = 0
    rejected = False
    n_stiff = 0
    n_nonstiff = 0
    stiff_at = -1.0
    err_exp = -1.0 / 8.0
    while t < t_end:
        if nsteps >= max_steps:
            return out_w, out_q, nfev, nsteps, nrej, TOO_MANY_STEPS, stiff_at
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h < min_step:
            return out_w, out_q, nfev, nsteps, nrej, STEP_UNDERFLOW, stiff_at
        if t + h > t_end:
            h = t_end - t
        # stages 1..11 and the new solution
        for i in range(1, 12):
            for k in range(n):
                acc = 0.0
                for l in range(i):
                    acc += A[i, l] * K[l, k]
                ys[k] = y[k] + h * acc
            lie_rhs(model, J, g, ys, K[i], with_q)
        for k in range(n):
            acc = 0.0
            for l in range(12):
                acc += B[l] * K[l, k]
            y_new[k] = y[k] + h * acc
        lie_rhs(model, J, g, y_new, K[12], with_q)
        nfev += 12
        # error estimate (5th and 3rd order embedded), SciPy's norm
        e5 = 0.0
        e3 = 0.0
        finite = True
        for k in range(n):
            s5 = 0.0
            s3 = 0.0
            for l in range(13):
                s5 += E5[l] * K[l, k]
                s3 += E3[l] * K[l, k]
            scale = atol + max(abs(y[k]), abs(y_new[k])) * rtol
            e5 += (s5 / scale) ** 2
            e3 += (s3 / scale) ** 2
            if not math.isfinite(y_new[k]):
                finite = False
        if not finite:
            return out_w, out_q, nfev, nsteps, nrej, NOT_FINITE, stiff_at
        if e5 == 0.0 and e3 == 0.0:
            err = 0.0
        else:
            err = h * e5 / math.sqrt((e5 + 0.01 * e3) * n)
        if err <= 1.0:
            # Hairer's stiffness test: h |lambda| estimated from the last two stages
            num = 0.0
            den = 0.0
            for k in range(n):
                num += (K[12, k] - K[11, k]) ** 2
                den += (y_new[k] - ys[k]) ** 2
            if den > 0.0:
                if h * math.sqrt(num / den) > 6.1:
                    n_nonstiff = 0
                    n_stiff += 1
                    if n_stiff == 15 and stiff_at < 0.0:
                        stiff_at = t
                        if stop_on_stiff:
                            return out_w, out_q, nfev, nsteps, nrej, STIFF, stiff_at
                else:
                    n_nonstiff += 1
                    if n_nonstiff == 6:
                        n_stiff = 0
            t_old = t
            t = t_old + h if t_old + h < t_end else t_end
            # dense output for every requested time in (t_old, t]
            if j_out < N and t_eval[j_out] <= t:
                for s in range(13, 16):
                    for k in range(n):
                        acc = 0.0
                        for l in range(s):
                            acc += A[s, l] * K[l, k]
                        ys[k] = y[k] + h * acc
                    lie_rhs(model, J, g, ys, K[s], with_q)
                nfev += 3
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
                while j_out < N and t_eval[j_out] <= t:
                    x = (t_eval[j_out] - t_old) / h
                    for k in range(n):
                        v = 0.0
                        for r in range(7):
                            v += F[6 - r, k]
                            if r % 2 == 0:
                                v *= x
                            else:
                                v *= 1.0 - x
                        ys[k] = y[k] + v
                    out_w[j_out, 0] = ys[0]
                    out_w[j_out, 1] = ys[1]
                    out_w[j_out, 2] = ys[2]
                    out_q[j_out, :] = q
                    if with_q:
                        apply_u(out_q[j_out], ys[3], ys[4], ys[5])
                    j_out += 1
            # accept: advance, move the orientation, restart the chart at u = 0
            for k in range(n):
                y[k] = y_new[k]
            if with_q:
                apply_u(q, y[3], y[4], y[5])
                y[3] = 0.0
                y[4] = 0.0
                y[5] = 0.0
            K[0, 0], K[0, 1], K[0, 2] = K[12, 0], K[12, 1], K[12, 2]   # FSAL for Omega
            if with_q:
                K[0, 3], K[0, 4], K[0, 5] = y[0], y[1], y[2]          # dexp^-1_0 = identity
            nsteps += 1
            if err == 0.0:
                factor = 10.0
            else:
                factor = min(10.0, 0.9 * err ** err_exp)
            if rejected:
                factor = min(1.0, factor)
            h = min(h * factor, h_max)
            rejected = False
        else:
            h = h * max(0.2, 0.9 * err ** err_exp)
            nrej += 1
            rejected = True
    return out_w, out_q, nfev, nsteps, nrej, OK, stiff_at


DOP853_ARRAYS = (T.DOP853_A, T.DOP853_B, T.DOP853_C, T.DOP853_E3, T.DOP853_E5, T.DOP853_D)
