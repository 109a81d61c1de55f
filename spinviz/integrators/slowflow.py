"""The compiled hybrid slow flow behind ``secular``: the body-frame Euler equation of a
symmetric top, in full where its precession is slow, averaged over the precession where it
is fast, with the spin about the fixed L_world integrated as a phase.

The body-frame equation does not involve the orientation.  Its only fast motion is the
precession of omega_perp about e3 at the rate delta w3; its slow motion is the braking, at
the rate eps |w|^2 (spin units, eps = tau0 |Omega0|).  Two modes, one loop of
Dormand-Prince 8(5,3) steps (``tableaus.DP853``):

* FULL: y = (w1, w2, w3, Sigma), the equation itself -- cheap wherever the precession is
  slow, exact wherever it stops (the domain "?" of (4.20), where w3 changes sign again and
  again, the oscillating solution "5");
* AVG: y = (w_perp, w3, p, Sigma), the flow averaged over the precession phase p ((4.12)
  for the reduced model; here the model's own radiation rate averaged on M phase nodes).

The hand-over follows mu_ad = eps |w|^3 / (|delta| w3^2) -- how much the precession rate
itself changes over one radian of precession (the plain ratio eps |w|^2 / |delta w3| misses
the slowing of w3; measured: 100x larger errors): FULL above ``mu_star``, AVG below half of
it.  At the start, at each switch and at each output the first-order near-identity
transform x = xbar + U(xbar, p) maps averaged and true variables into each other; without
it first-order averaging is off by O(eps) in the slow variables and by O(1) in the phases
after O(1/eps) of time (measured), with it by O(eps^2) and O(eps) respectively.

Sigma = phi + sign(w3) psi, the ZXZ angles about L (psi = pi/2 - p), is what is integrated
for the orientation: regular where e3 lines up with +-L, unlike phi and psi separately.
Its rate includes the radiation part of the precession (``sigma_rate``).

Units: spin units of spinviz (|omega(0)| = 1, coupling g with |g|^2 = eps).  J = (1, 1, J3).
Ported from a research prototype; the measurements are in docs/integrators.md ("secular").
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from . import kernels as KN
from .status import INTERRUPTED, NOT_FINITE, OK, STEP_UNDERFLOW, STOP_POLL, TOO_MANY_STEPS

_jit = nb.njit(cache=True, nogil=True, error_model="numpy")

FULL, AVG = 0, 1
M_PHASES = 32          # phase-average nodes: exact for trigonometric polynomials of degree < 32
HYST = 0.5             # AVG again only below HYST * mu_star: no chattering
NIT_MAX = 0.1          # the transform is applied only where it is a small correction
MAX_SWITCHES = 100_000
MAX_CROSSINGS = 100_000
RESONANCES = (1.0, 2.0, -1.0, -2.0)   # m of |L|/I1 = m delta w3: the torque across L has only these harmonics


@_jit
def detunings(mode, y, J3, delta, F):
    """F_m = |L| - m delta w3 for the m of RESONANCES at the state y (either mode)."""
    if mode == FULL:
        wp = math.hypot(y[0], y[1])
        w3 = y[2]
    else:
        wp = y[0]
        w3 = y[1]
    L = math.sqrt(wp * wp + J3 * J3 * w3 * w3)
    for i in range(4):
        F[i] = L - RESONANCES[i] * delta * w3
    return wp, w3


@_jit
def forced_z(model, J, g, w3):
    """(z_f1, z_f2): the forced response of omega_perp to the torque's omega_perp-independent
    part F = a_perp(0, 0, w3) (the paper's n1 n3 w3^3 of (4.2): type "1", (4.9)), to second
    order: x1 = -M^-1 F with M = [[0, delta w3], [-delta w3, 0]] the free precession, then
    x2 = -(M + M_rad)^-1 (F - dx1/dt), M_rad the radiation's own linear part in omega_perp and
    dx1/dt = 2 x1 a3(0, 0, w3) / w3 (x1 ~ w3^2).  The free precession is linear in omega_perp,
    so omega_perp = z_f + a free circle exactly at first order, whatever the circle's size:
    secular carries the circle averaged and z_f apart (order 1: -i n1 n3 w3^2 / delta, the
    B / tau of (4.9); order 2 its real A tau^-3/2)."""
    delta = 1.0 - J[2]
    if w3 == 0.0 or delta == 0.0:
        return 0.0, 0.0
    a0 = KN.radiation(model, 0.0, 0.0, w3, J, g)
    F1, F2 = a0[0], a0[1]
    if F1 == 0.0 and F2 == 0.0:
        return 0.0, 0.0
    nu = delta * w3
    # M x = (nu x2, -nu x1) = -F  ->  x1 = F2 / nu, x2 = -F1 / nu
    x1, x2 = F2 / nu, -F1 / nu
    h = 1e-6 * abs(w3)
    ap = KN.radiation(model, h, 0.0, w3, J, g)
    am = KN.radiation(model, -h, 0.0, w3, J, g)
    bp = KN.radiation(model, 0.0, h, w3, J, g)
    bm = KN.radiation(model, 0.0, -h, w3, J, g)
    m11, m21 = (ap[0] - am[0]) / (2.0 * h), (ap[1] - am[1]) / (2.0 * h)
    m12, m22 = (bp[0] - bm[0]) / (2.0 * h), (bp[1] - bm[1]) / (2.0 * h)
    r1 = F1 - 2.0 * x1 / w3 * a0[2]
    r2 = F2 - 2.0 * x2 / w3 * a0[2]
    # (M + M_rad) x = -r, M = [[0, nu], [-nu, 0]]
    A11, A12, A21, A22 = m11, nu + m12, -nu + m21, m22
    det = A11 * A22 - A12 * A21
    return -(A22 * r1 - A12 * r2) / det, -(-A21 * r1 + A11 * r2) / det


@_jit
def forced_response(model, J, g, wp, w3, mu):
    """What carrying the forced response apart leaves: its third-order residual, 5 mu^2 |z_f|
    (the atlas engine's measured residual of the same transform), mu = eps |w|^2 / |delta w3|."""
    z1, z2 = forced_z(model, J, g, w3)
    return 5.0 * mu * mu * math.hypot(z1, z2)


@_jit
def avg_rates(model, J, g, wp, w3, cM, sM, equiv):
    """The radiation part of (d w_perp, d w3, d p) averaged over the precession phase p, and
    the mean of N = w1 a2 - w2 a1 (w_perp^2 x the radiation part of p_dot); exact, with no
    average, where the torque commutes with rotations about e3 (``equiv``)."""
    if equiv or wp == 0.0:
        a = KN.radiation(model, wp, 0.0, w3, J, g)
        return a[0], a[2], (a[1] / wp if wp != 0.0 else 0.0), wp * a[1]
    M = cM.shape[0]
    s1 = 0.0
    s2 = 0.0
    s3 = 0.0
    # the p-independent part a(0, 0, w3) averages out of s1 and s3 exactly; taking it out first
    # keeps its round-off out of s3 / w_perp^2 as w_perp -> 0 (types "1" and "2")
    a0 = KN.radiation(model, 0.0, 0.0, w3, J, g)
    for k in range(M):
        w1 = wp * cM[k]
        w2 = wp * sM[k]
        a = KN.radiation(model, w1, w2, w3, J, g)
        b1 = a[0] - a0[0]
        b2 = a[1] - a0[1]
        s1 += w1 * b1 + w2 * b2
        s2 += a[2]
        s3 += w1 * b2 - w2 * b1
    return s1 / (M * wp), s2 / M, s3 / (M * wp * wp), s3 / M


@_jit
def sigma_rate(wp2, w3, J3, sgn, N):
    """d/dt (phi + sgn psi), sgn = sign(w3), ZXZ angles about a fixed L (J1 = 1):
    phi_dot = |L| - r cos(theta), psi_dot = delta w3 + r with r = -N / w_perp^2 the radiation
    part of psi_dot and cos(theta) = J3 w3 / |L|; the sum is regular where w_perp -> 0."""
    L = math.sqrt(wp2 + J3 * J3 * w3 * w3)
    return L + sgn * (1.0 - J3) * w3 - sgn * N / (L * (L + J3 * abs(w3)))


@_jit
def rhs(mode, sgn, model, J, g, cM, sM, equiv, y, out):
    """The slow flow's right-hand side into ``out`` (4,): in FULL mode y = (w1, w2, w3, Sigma),
    the body-frame Euler equation of the symmetric top J = (1, 1, J3); in AVG mode
    y = (w_perp, w3, p, Sigma), its average over the precession phase p on the M nodes
    (cM, sM) ((4.12) for the reduced model).  Spin units; ``sgn`` the sign of w3 in Sigma."""
    J3 = J[2]
    if mode == FULL:
        w1, w2, w3 = y[0], y[1], y[2]
        a = KN.radiation(model, w1, w2, w3, J, g)
        d = 1.0 - J3
        # the free part of a symmetric top (J1 = J2 = 1): (delta w2 w3, -delta w1 w3, 0)
        out[0] = a[0] + d * w2 * w3
        out[1] = a[1] - d * w1 * w3
        out[2] = a[2]
        out[3] = sigma_rate(w1 * w1 + w2 * w2, w3, J3, sgn, w1 * a[1] - w2 * a[0])
    else:
        dwp, dw3, dp, N = avg_rates(model, J, g, y[0], y[1], cM, sM, equiv)
        out[0] = dwp
        out[1] = dw3
        out[2] = dp - (1.0 - J3) * y[1]
        out[3] = sigma_rate(y[0] * y[0], y[1], J3, sgn, N)


@_jit
def mu_ad(mode, y, eps, delta):
    """eps |w|^3 / (|delta| w3^2) (for |w3| < |w|; eps |w|^2 / |delta w3| otherwise): the
    relative change of the precession rate over one radian of precession.  inf where it stops."""
    if mode == FULL:
        w2 = y[0] * y[0] + y[1] * y[1] + y[2] * y[2]
        w3 = y[2]
    else:
        w2 = y[0] * y[0] + y[1] * y[1]
        w3 = y[1]
    den = abs(delta * w3)
    if den == 0.0:
        return np.inf
    mu = eps * w2 / den
    r = math.sqrt(w2) / abs(w3)
    return mu * r if r > 1.0 else mu


@_jit
def nit(model, J, g, cM, sM, wp, w3, p):
    """First-order near-identity transform at (w_perp, w3, p): (U_wp, U_w3, V_p, V_phi) with
    x = xbar + U(xbar, p), p = pbar + V_p, phi = phibar + V_phi.  U = int F~ dp / p0dot with F~
    the zero-mean part of the radiation rates along the precession; V_p and V_phi from the
    phase rates likewise.  Zero where it would not be a small correction."""
    M = cM.shape[0]
    delta = 1.0 - J[2]
    p0dot = -delta * w3
    Fwp = np.empty(M)
    Fw3 = np.empty(M)
    G = np.empty(M)
    # the forcing a_perp(0, 0, w3) is carried apart as z_f (``forced_z``): out of the transform
    a0 = KN.radiation(model, 0.0, 0.0, w3, J, g)
    for k in range(M):
        w1 = wp * cM[k]
        w2 = wp * sM[k]
        a = KN.radiation(model, w1, w2, w3, J, g)
        b1, b2 = a[0] - a0[0], a[1] - a0[1]
        Fwp[k] = (w1 * b1 + w2 * b2) / wp
        Fw3[k] = a[2]
        G[k] = (w1 * b2 - w2 * b1) / (wp * wp)
    Uwp = 0.0
    Uw3 = 0.0
    Vp = 0.0
    A2wp = 0.0
    A2w3 = 0.0
    AG = 0.0
    for j in range(1, M // 2):
        # c_j = (1/M) sum_k f_k e^{-i j p_k}; the antiderivative term is 2 Re(c_j e^{ijp} / (ij))
        cr_wp = ci_wp = cr_w3 = ci_w3 = cr_g = ci_g = 0.0
        for k in range(M):
            ck, sk = cM[(j * k) % M], sM[(j * k) % M]     # cos, sin of j p_k, from the table
            cr_wp += Fwp[k] * ck
            ci_wp -= Fwp[k] * sk
            cr_w3 += Fw3[k] * ck
            ci_w3 -= Fw3[k] * sk
            cr_g += G[k] * ck
            ci_g -= G[k] * sk
        cj, sj = math.cos(j * p), math.sin(j * p)
        im_wp = (cr_wp * sj + ci_wp * cj) / M
        im_w3 = (cr_w3 * sj + ci_w3 * cj) / M
        im_g = (cr_g * sj + ci_g * cj) / M
        re_w3 = (cr_w3 * cj - ci_w3 * sj) / M
        re_wp = (cr_wp * cj - ci_wp * sj) / M
        A2wp += -2.0 * re_wp / (j * j)
        A2w3 += -2.0 * re_w3 / (j * j)
        AG += 2.0 * im_g / j
        Uwp += 2.0 * im_wp / j
        Uw3 += 2.0 * im_w3 / j
        Vp += 2.0 * im_g / j + delta / p0dot * 2.0 * re_w3 / (j * j)
    Uwp, Uw3, Vp = Uwp / p0dot, Uw3 / p0dot, Vp / p0dot
    J3 = J[2]
    L = math.sqrt(wp * wp + J3 * J3 * w3 * w3)
    Vphi = ((wp / L) * A2wp / p0dot + (J3 * J3 * w3 / L) * A2w3 / p0dot + (J3 * w3 / L) * AG) / p0dot
    if not (abs(Uwp) <= NIT_MAX * wp and abs(Uw3) <= NIT_MAX * abs(w3) and abs(Vp) <= NIT_MAX
            and abs(Vphi) <= NIT_MAX):
        return 0.0, 0.0, 0.0, 0.0
    return Uwp, Uw3, Vp, Vphi


@_jit
def initial_step(mode, sgn, model, J, g, cM, sM, equiv, y, f0, rtol, atol, n, h_max):
    """The first step of a mode (II.4), as for the other kernels (one extra evaluation)."""
    sc = np.empty(n)
    ys = np.empty(n)
    f1 = np.empty(n)
    h0, d1 = KN.first_guess(y, f0, n, rtol, atol, h_max, sc, ys)
    rhs(mode, sgn, model, J, g, cM, sM, equiv, ys, f1)
    return KN.second_guess(f0, f1, n, sc, h0, d1, h_max)


@_jit
def to_avg(model, J, g, cM, sM, y, p_unw, use_nit):
    """FULL state -> AVG state in place: the forced response z_f taken off, then the transform
    inverted to first order; returns (the shift of phi, the shift of the phase by taking z_f off).
    The caller adds sgn x the second to phi: Sigma = phi + sgn psi, the spin angle about e3, stays
    what it was (where omega_perp is mostly z_f the body spins about e3 at omega3, and Sigma carries
    that; the free circle's phase is then not omega_perp's)."""
    w3 = y[2]
    z1, z2 = forced_z(model, J, g, w3)
    v1, v2 = y[0] - z1, y[1] - z2
    wp = math.hypot(v1, v2)
    # the free circle's phase, on the branch of the unwrapped phase of omega_perp
    p = p_unw + (math.atan2(v2, v1) - p_unw + math.pi) % (2.0 * math.pi) - math.pi
    dsplit = p - p_unw
    dphi = 0.0
    if use_nit:
        u = nit(model, J, g, cM, sM, wp, w3, p)
        wp, w3, p = wp - u[0], w3 - u[1], p - u[2]
        dphi = -u[3]
    y[0], y[1], y[2] = wp, w3, p
    return dphi, dsplit


@_jit
def to_full(model, J, g, cM, sM, y, use_nit):
    """AVG state -> FULL state in place (the forced response z_f added back); returns (unwrapped
    phase of omega_perp, shift of phi, shift of the phase by adding z_f: the caller adds sgn x it
    to phi, as for ``to_avg``)."""
    wp, w3, p = y[0], y[1], y[2]
    dphi = 0.0
    if use_nit:
        u = nit(model, J, g, cM, sM, wp, w3, p)
        wp, w3, p = wp + u[0], w3 + u[1], p + u[2]
        dphi = u[3]
    z1, z2 = forced_z(model, J, g, w3)
    y[0], y[1], y[2] = wp * math.cos(p) + z1, wp * math.sin(p) + z2, w3
    # the unwrapped phase of omega_perp itself, on the free circle's branch
    p_true = p + (math.atan2(y[1], y[0]) - p + math.pi) % (2.0 * math.pi) - math.pi
    return p_true, dphi, p_true - p


@_jit
def phase_nodes(M):
    """(cos p_k, sin p_k) at the M equally spaced phases p_k = 2 pi k / M the averages sample."""
    cM = np.empty(M)
    sM = np.empty(M)
    for k in range(M):
        cM[k] = math.cos(2.0 * math.pi * k / M)
        sM[k] = math.sin(2.0 * math.pi * k / M)
    return cM, sM


@_jit
def integrate_hybrid(model, J, g, w0, t_eval, rtol, atol, mu_star, equiv, max_steps, phi0, A, B, E3, E5, D, stop):
    """Integrate from the body-frame w0 (spin units) over t_eval.

    Returns (out (N, 7): w1, w2, w3 (the forced response included), phi, p, mode and the free
    circle's radius (the pose's nutation: in FULL mode |omega_perp|) at each output; counters (16,); switches
    (K, 2): time and new mode; crossings (K, 4): time, w_perp, w3 and m of every passage
    through a resonance |L|/I1 = m delta w3; status).  phi: the ZXZ precession angle about the
    fixed L, from phi0; p: the unwrapped body-frame phase of omega_perp (psi = pi/2 - p).
    counters: 0 steps FULL, 1 steps AVG, 2 evaluations FULL, 3 evaluations AVG, 4 rejected
    steps, 5 switches, 6 the largest mu_ad met in AVG, 7 precession turns in FULL, 8 sign
    changes of w3, 13 the time of the first, 14 the time reached (9, 15 unused), 10 the integral of mu^2 dt over
    AVG (mu = eps |w|^2 / |delta w3|), 11 the phase Sigma covered in FULL, 12 the largest
    forced-response error met in AVG."""
    # Long on purpose: one compiled loop whose step, hand-over and dense output share ~20 local arrays and counters.
    N = t_eval.shape[0]
    n = 4
    out = np.empty((N, 7))
    cnt = np.zeros(16)
    cnt[13] = -1.0
    sw = np.zeros((MAX_SWITCHES, 2))
    nsw = 0
    cross = np.zeros((MAX_CROSSINGS, 4))
    ncross = 0
    Fold = np.empty(4)
    Fnew = np.empty(4)
    cM, sM = phase_nodes(M_PHASES)
    eps = g[0] * g[0] + g[1] * g[1] + g[2] * g[2]
    delta = 1.0 - J[2]
    K = np.zeros((16, n))
    y = np.zeros(n)
    y_new = np.zeros(n)
    ys = np.zeros(n)
    F = np.zeros((7, n))
    y[0], y[1], y[2], y[3] = w0[0], w0[1], w0[2], 0.0
    p_unw = math.atan2(w0[1], w0[0])
    if equiv:
        mode = AVG
    else:
        mode = FULL if mu_ad(FULL, y, eps, delta) > mu_star else AVG
    dphi = 0.0
    dsplit = 0.0
    if mode == AVG:
        dphi, dsplit = to_avg(model, J, g, cM, sM, y, p_unw, not equiv)
    sgn = 1.0 if w0[2] >= 0.0 else -1.0
    y[3] = phi0 + dphi + sgn * dsplit + sgn * (0.5 * math.pi - (y[2] if mode == AVG else p_unw))
    detunings(mode, y, J[2], delta, Fold)
    t = t_eval[0]
    t_end = t_eval[-1]
    out[0, 0], out[0, 1], out[0, 2] = w0[0], w0[1], w0[2]
    out[0, 3] = phi0
    out[0, 4] = p_unw
    out[0, 5] = mode
    out[0, 6] = math.hypot(w0[0], w0[1])
    j_out = 1
    rhs(mode, sgn, model, J, g, cM, sM, equiv, y, K[0])
    nf = 1
    h = initial_step(mode, sgn, model, J, g, cM, sM, equiv, y, K[0], rtol, atol, n, t_end - t)
    nf += 1
    nsteps = 0
    rejected = False
    err_exp = -1.0 / 8.0
    while t < t_end:
        if nsteps >= max_steps:
            cnt[14] = t
            return out, cnt, sw[:nsw], cross[:ncross], TOO_MANY_STEPS
        if (nsteps + int(cnt[4])) % STOP_POLL == 0 and stop[0] != 0:
            cnt[14] = t
            return out, cnt, sw[:nsw], cross[:ncross], INTERRUPTED
        if h < 10.0 * abs(np.nextafter(t, np.inf) - t):
            cnt[14] = t
            return out, cnt, sw[:nsw], cross[:ncross], STEP_UNDERFLOW
        if t + h > t_end:
            h = t_end - t
        for i in range(1, 12):
            KN.stage_point(A, K, y, h, i, n, ys)
            rhs(mode, sgn, model, J, g, cM, sM, equiv, ys, K[i])
        for k in range(n):
            acc = 0.0
            for l in range(12):
                acc += B[l] * K[l, k]
            y_new[k] = y[k] + h * acc
        rhs(mode, sgn, model, J, g, cM, sM, equiv, y_new, K[12])
        nf += 12
        # the phase Sigma (index 3) is held to rtol x its increment
        err, finite = KN.error_norm(K, y, y_new, h, n, rtol, atol, E3, E5, 3)
        if not finite:
            cnt[14] = t
            return out, cnt, sw[:nsw], cross[:ncross], NOT_FINITE
        if not err <= 1.0:
            h = h * max(0.2, 0.9 * err ** err_exp)
            cnt[4] += 1
            rejected = True
            continue
        t_old = t
        t = t_old + h if t_old + h < t_end else t_end
        p_old = p_unw
        if mode == FULL:
            p_unw = p_old + (math.atan2(y_new[1], y_new[0]) - p_old + math.pi) % (2.0 * math.pi) - math.pi
            cnt[7] += abs(p_unw - p_old) / (2.0 * math.pi)
        if j_out < N and t_eval[j_out] <= t:
            for s in range(13, 16):
                KN.stage_point(A, K, y, h, s, n, ys)
                rhs(mode, sgn, model, J, g, cM, sM, equiv, ys, K[s])
            nf += 3
            KN.dense_assemble(D, K, y, y_new, h, n, F)
            while j_out < N and t_eval[j_out] <= t:
                KN.dense_eval(F, y, (t_eval[j_out] - t_old) / h, n, ys)
                if mode == FULL:
                    out[j_out, 0], out[j_out, 1], out[j_out, 2] = ys[0], ys[1], ys[2]
                    out[j_out, 4] = p_old + (math.atan2(ys[1], ys[0]) - p_old + math.pi) % (2.0 * math.pi) - math.pi
                    out[j_out, 6] = math.hypot(ys[0], ys[1])
                    out[j_out, 3] = ys[3] - sgn * (0.5 * math.pi - out[j_out, 4])
                else:
                    out[j_out, 3] = ys[3] - sgn * (0.5 * math.pi - ys[2])
                    wp_o, w3_o, p_o = ys[0], ys[1], ys[2]
                    z1 = z2 = 0.0
                    if not equiv:
                        u = nit(model, J, g, cM, sM, wp_o, w3_o, p_o)
                        wp_o, w3_o, p_o = wp_o + u[0], w3_o + u[1], p_o + u[2]
                        out[j_out, 3] += u[3]
                        z1, z2 = forced_z(model, J, g, w3_o)
                    out[j_out, 0] = wp_o * math.cos(p_o) + z1
                    out[j_out, 1] = wp_o * math.sin(p_o) + z2
                    out[j_out, 2] = w3_o
                    out[j_out, 4] = p_o
                    out[j_out, 6] = wp_o
                out[j_out, 5] = mode
                j_out += 1
        if mode == FULL:
            cnt[11] += abs(y_new[3] - y[3])
        for k in range(n):
            y[k] = y_new[k]
            K[0, k] = K[12, k]
        nsteps += 1
        if mode == FULL:
            cnt[0] += 1
            cnt[2] += nf
        else:
            cnt[1] += 1
            cnt[3] += nf
        # resonances crossed in this step, and what the error statements need
        wp_n, w3_n = detunings(mode, y, J[2], delta, Fnew)
        for i in range(4):
            if Fnew[i] * Fold[i] < 0.0 and ncross < MAX_CROSSINGS:
                cross[ncross, 0], cross[ncross, 1], cross[ncross, 2], cross[ncross, 3] = t, wp_n, w3_n, RESONANCES[i]
                ncross += 1
            Fold[i] = Fnew[i]
        if mode == AVG and not equiv:
            mu_now = 0.0
            if delta * w3_n != 0.0:
                mu_now = eps * (wp_n * wp_n + w3_n * w3_n) / abs(delta * w3_n)
                cnt[10] += mu_now * mu_now * (t - t_old)
            fr = forced_response(model, J, g, wp_n, w3_n, mu_now)
            if fr > cnt[12]:
                cnt[12] = fr
        nf = 0
        factor = 10.0 if err == 0.0 else min(10.0, 0.9 * err ** err_exp)
        if rejected:
            factor = min(1.0, factor)
        h = h * factor
        rejected = False
        # Sigma = phi + sgn psi is re-based when w3 changes sign
        w3_now = y[2] if mode == FULL else y[1]
        s_new = 1.0 if w3_now >= 0.0 else -1.0
        if s_new != sgn:
            psi_now = 0.5 * math.pi - (y[2] if mode == AVG else p_unw)
            y[3] += (s_new - sgn) * psi_now
            sgn = s_new
            cnt[8] += 1
            if cnt[13] < 0.0:
                cnt[13] = t
            rhs(mode, sgn, model, J, g, cM, sM, equiv, y, K[0])
            nf += 1
        # the hand-over
        if not equiv:
            mu = mu_ad(mode, y, eps, delta)
            switch = False
            phi_now = y[3] - sgn * (0.5 * math.pi - (y[2] if mode == AVG else p_unw))
            if mode == FULL and mu < HYST * mu_star:
                dphi, dsplit = to_avg(model, J, g, cM, sM, y, p_unw, True)
                phi_now += dphi + sgn * dsplit
                mode = AVG
                switch = True
            elif mode == AVG:
                if mu > cnt[6]:
                    cnt[6] = mu
                if mu > mu_star:
                    p_unw, dphi, dsplit = to_full(model, J, g, cM, sM, y, True)
                    phi_now += dphi + sgn * dsplit
                    mode = FULL
                    switch = True
            if switch:
                y[3] = phi_now + sgn * (0.5 * math.pi - (y[2] if mode == AVG else p_unw))
                if nsw < MAX_SWITCHES:
                    sw[nsw, 0] = t
                    sw[nsw, 1] = mode
                    nsw += 1
                cnt[5] += 1
                rhs(mode, sgn, model, J, g, cM, sM, equiv, y, K[0])
                h = initial_step(mode, sgn, model, J, g, cM, sM, equiv, y, K[0], rtol, atol, n, t_end - t)
                nf = 2
    cnt[14] = t
    return out, cnt, sw[:nsw], cross[:ncross], OK


@_jit
def torque_harmonic(model, J, g, wp, w3, m, M):
    """|c_m|: harmonic m of the world-frame radiation torque across L in the body-frame phase
    p (the component that does not average out over the spin where |L|/I1 = m delta w3)."""
    delta = 1.0 - J[2]
    theta = math.atan2(wp, (1.0 - delta) * w3)
    ct, st = math.cos(theta), math.sin(theta)
    re = 0.0
    im = 0.0
    for k in range(M):
        p = 2.0 * math.pi * k / M
        a = KN.radiation(model, wp * math.cos(p), wp * math.sin(p), w3, J, g)
        n1, n2, n3 = J[0] * a[0], J[1] * a[1], J[2] * a[2]
        psi = 0.5 * math.pi - p
        x = math.cos(psi) * n1 - math.sin(psi) * n2
        yy = math.sin(psi) * n1 + math.cos(psi) * n2
        y2 = ct * yy - st * n3
        # Z(p) = x + i y2; c_m = (1/M) sum Z e^{-i m p}
        c, s = math.cos(m * p), math.sin(m * p)
        re += x * c + y2 * s
        im += y2 * c - x * s
    return math.hypot(re, im) / M
