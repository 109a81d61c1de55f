"""Single collisions of gas molecules with a spinning body, drawn one by one from the kinetic
theory of ``physics.gas`` (compiled; NumPy's ``Generator`` drives them, so a seed reproduces
every one).

A collision at body-frame Omega: a point of the surface (``physics.surface``) and a molecule
arriving there, drawn by thinning -- candidates uniform over the surface at the rate
Lambda = Phi(s_bound) A (A the area, Phi the flux of ``physics.gas`` and s_bound = beta |Omega|
r_max, above every element's s = beta u_n), each kept with probability I_1(s) / I_1(s_bound):
so kept collisions arrive at the surface's true rate, sum of Phi(s) dA, wherever they land.
The molecule: its normal speed x from the flux-weighted density x exp(-(x - u_n)^2 beta^2)
(exact rejection, ``_normal_speed``), its tangential velocity Gaussian about -u_t with k T / m a
component; it leaves diffusely with probability alpha (Rayleigh normal speed and Gaussian
tangential velocity at the surface's temperature, in the surface's frame), specularly
otherwise.  The body receives the angular impulse J = m r x (w - w') (body frame, g cm^2/s).

The gas's mean torque, rate and impulse covariance are not used here: they are the
quadratures of ``physics.gas.GasModel``, against which these draws are checked.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..physics.surface import DISK, RECT, SIDE

_jit = nb.njit(cache=True, nogil=True, error_model="numpy")
SQRT_PI = math.sqrt(math.pi)


@_jit
def flux_shape(s):
    """I_1(s) = exp(-s^2)/2 + s (sqrt(pi)/2) erfc(-s): the flux of a surface element moving
    into the gas at s = beta u_n, in units of n / (beta sqrt(pi)); never negative."""
    if s >= 0.0:
        return 0.5 * math.exp(-s * s) + s * 0.5 * SQRT_PI * math.erfc(-s)
    v = 0.5 * math.exp(-s * s) - (-s) * 0.5 * SQRT_PI * math.erfc(-s)
    return v if v > 0.0 else 0.0


@_jit
def _normal_speed(rng, s):
    """y > 0 from the density proportional to y exp(-(y - s)^2) (x = y / beta: the normal speed
    of the molecules that arrive on an element moving at s = beta u_n), by exact rejection:
    for s >= 0 from the envelope (|z| + s) exp(-z^2), z = y - s, a mixture of a two-sided
    Rayleigh and a Gaussian; for s < 0 from y exp(-y^2), kept with probability exp(-2 y |s|)."""
    if s >= 0.0:
        p1 = 1.0 / (1.0 + s * SQRT_PI)
        while True:
            if rng.random() < p1:
                z = math.sqrt(-math.log(1.0 - rng.random()))
                if rng.random() < 0.5:
                    z = -z
            else:
                z = rng.standard_normal() * math.sqrt(0.5)
            y = s + z
            if y > 0.0 and rng.random() * (abs(z) + s) < y:
                return y
    while True:
        y = math.sqrt(-math.log(1.0 - rng.random()))
        if rng.random() < math.exp(2.0 * s * y):
            return y


@_jit
def _point(kinds, geo, cum, u0, u1, u2, out):
    """A point uniform over the surface by area: out = (r, n, t1, t2), (12,) body frame."""
    total = cum[-1]
    x = u0 * total
    p = 0
    while p < kinds.shape[0] - 1 and cum[p] < x:
        p += 1
    g = geo[p]
    kind = kinds[p]
    for i in range(3):
        c, n, e1, e2 = g[i], g[3 + i], g[6 + i], g[9 + i]
        if kind == RECT:
            out[i] = c + (2.0 * u1 - 1.0) * g[12] * e1 + (2.0 * u2 - 1.0) * g[13] * e2
            out[3 + i], out[6 + i], out[9 + i] = n, e1, e2
        elif kind == SIDE:
            ph = 2.0 * math.pi * u1
            radial = math.cos(ph) * e1 + math.sin(ph) * e2
            out[i] = c + g[13] * radial + (2.0 * u2 - 1.0) * g[12] * n
            out[3 + i] = radial
            out[6 + i] = -math.sin(ph) * e1 + math.cos(ph) * e2
            out[9 + i] = n
        elif kind == DISK:
            rho = g[13] * math.sqrt(u1)
            ph = 2.0 * math.pi * u2
            out[i] = c + rho * (math.cos(ph) * e1 + math.sin(ph) * e2)
            out[3 + i], out[6 + i], out[9 + i] = n, e1, e2
    if kind != RECT and kind != SIDE and kind != DISK:          # a sphere
        z = 2.0 * u1 - 1.0
        ph = 2.0 * math.pi * u2
        sn = math.sqrt(max(0.0, 1.0 - z * z))
        nx, ny, nz = sn * math.cos(ph), sn * math.sin(ph), z
        out[3], out[4], out[5] = nx, ny, nz
        out[0], out[1], out[2] = g[0] + g[13] * nx, g[1] + g[13] * ny, g[2] + g[13] * nz
        # a tangent basis: e_theta, e_phi
        out[6], out[7], out[8] = z * math.cos(ph), z * math.sin(ph), -sn
        out[9], out[10], out[11] = -math.sin(ph), math.cos(ph), 0.0


@_jit
def attempt(rng, omega, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass, s_bound, J):
    """One candidate of the thinned stream at body-frame ``omega`` (rad/s): True with the
    angular impulse in J (3,) if it is kept (module docstring), False otherwise."""
    pt = np.empty(12)
    _point(kinds, geo, cum, rng.random(), rng.random(), rng.random(), pt)
    r0, r1, r2 = pt[0], pt[1], pt[2]
    n0, n1, n2 = pt[3], pt[4], pt[5]
    u0 = omega[1] * r2 - omega[2] * r1
    u1 = omega[2] * r0 - omega[0] * r2
    u2 = omega[0] * r1 - omega[1] * r0
    un = u0 * n0 + u1 * n1 + u2 * n2
    s = beta * un
    top = flux_shape(s_bound)
    if top <= 0.0 or rng.random() * top >= flux_shape(s):
        return False
    x = _normal_speed(rng, s) / beta
    a1, a2 = rng.standard_normal() * sigma, rng.standard_normal() * sigma
    # w = v - u: tangential -u_t plus thermal spread, normal -x
    w = np.empty(3)
    for i in range(3):
        ui = (u0, u1, u2)[i]
        ni = pt[3 + i]
        w[i] = -(ui - un * ni) + a1 * pt[6 + i] + a2 * pt[9 + i] - x * ni
    d = np.empty(3)
    if rng.random() < alpha:
        vn = sigma_b * math.sqrt(-2.0 * math.log(1.0 - rng.random()))
        b1, b2 = rng.standard_normal() * sigma_b, rng.standard_normal() * sigma_b
        for i in range(3):
            d[i] = w[i] - (vn * pt[3 + i] + b1 * pt[6 + i] + b2 * pt[9 + i])
    else:
        for i in range(3):
            d[i] = -2.0 * x * pt[3 + i]            # w - w' of a specular bounce: twice the normal part
    J[0] = mass * (r1 * d[2] - r2 * d[1])
    J[1] = mass * (r2 * d[0] - r0 * d[2])
    J[2] = mass * (r0 * d[1] - r1 * d[0])
    return True


@_jit
def many(rng, omega, count, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass):
    """``count`` collisions at a fixed body-frame ``omega``: (J (count, 3), candidates drawn)."""
    out = np.empty((count, 3))
    J = np.empty(3)
    s_bound = beta * math.sqrt(omega[0] ** 2 + omega[1] ** 2 + omega[2] ** 2) * r_max
    k = 0
    tries = 0
    while k < count:
        tries += 1
        if attempt(rng, omega, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass, s_bound, J):
            out[k, 0], out[k, 1], out[k, 2] = J[0], J[1], J[2]
            k += 1
    return out, tries


class Collider:
    """Single collisions of ``gas`` (``physics.gas.Gas``) with ``surface``
    (``physics.surface.Surface``), drawn with ``rng`` (a NumPy ``Generator``)."""

    def __init__(self, gas, surface, rng):
        self.gas, self.surface, self.rng = gas, surface, rng
        self.kinds = np.asarray(surface.kind, dtype=np.int64)
        self.geo = np.ascontiguousarray(surface.geometry, dtype=float)
        self.cum = np.cumsum(surface.area)
        self.args = (self.kinds, self.geo, self.cum, float(surface.r_max), gas.beta, gas.sigma, gas.sigma_body,
                     float(gas.accommodation), gas.mass)
        self.J = np.empty(3)

    def bound(self, omega_norm: float) -> tuple[float, float]:
        """(s_bound, Lambda): the thinning's bound for any state with |Omega| <= ``omega_norm``
        and its candidate rate (per second)."""
        g = self.gas
        s = g.beta * omega_norm * self.surface.r_max
        return s, g.density / (g.beta * SQRT_PI) * flux_shape(s) * self.surface.total_area

    def attempt(self, omega, s_bound: float):
        """One candidate at ``omega`` (rad/s, body frame): the angular impulse J (3,) or None."""
        if attempt(self.rng, np.asarray(omega, dtype=float), *self.args, s_bound, self.J):
            return self.J.copy()
        return None

    def many(self, omega, count: int) -> np.ndarray:
        """``count`` collisions at a fixed ``omega``: J (count, 3)."""
        return many(self.rng, np.asarray(omega, dtype=float), int(count), *self.args)[0]


@_jit
def first_kept(rng, omegas, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass, s_bound):
    """The thinned stream's candidates at the states ``omegas`` (B, 3) (rad/s), in order, until
    one is kept: (its index or -1, J (3,), candidates looked at, whether a state's |Omega|
    exceeded the bound -- then nothing is kept and the caller redraws with a larger one)."""
    J = np.zeros(3)
    for i in range(omegas.shape[0]):
        w = omegas[i]
        if beta * math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2) * r_max > s_bound:
            return -1, J, i, True
        if attempt(rng, w, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass, s_bound, J):
            return i, J, i + 1, False
    return -1, J, omegas.shape[0], False


@_jit
def _rotate(axis, angle, v, out):
    """Rodrigues: ``v`` turned by ``angle`` about the unit ``axis``, into ``out``."""
    c, s = math.cos(angle), math.sin(angle)
    d = axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2]
    x0 = axis[1] * v[2] - axis[2] * v[1]
    x1 = axis[2] * v[0] - axis[0] * v[2]
    x2 = axis[0] * v[1] - axis[1] * v[0]
    out[0] = v[0] * c + x0 * s + axis[0] * d * (1.0 - c)
    out[1] = v[1] * c + x1 * s + axis[1] * d * (1.0 - c)
    out[2] = v[2] * c + x2 * s + axis[2] * d * (1.0 - c)


@_jit
def chunk_exact(rng, omega, inertia, O, Lw_hat, w_L, prec, dt, count, kinds, geo, cum, r_max, beta, sigma, sigma_b,
                alpha, mass, s_bound):
    """The collisions of a chunk of length ``dt`` (s) that ends at the body-frame state
    ``omega`` (rad/s) and orientation O (3, 3, body to world), one by one: ``count`` candidates of
    the thinned stream, each at a uniform instant t_end - tau on the free motion through the
    end state (the body's precession ``prec`` = delta omega3 about e3, the spin ``w_L`` about
    L_world, direction ``Lw_hat``; ``integrators.secular_env``).  Returns (dL_body (3,), in the
    end state's body frame; dL_world (3,); collisions kept; candidates whose state outran the
    bound)."""
    w = omega.copy()
    dLb = np.zeros(3)
    dLw = np.zeros(3)
    J = np.zeros(3)
    Jend = np.zeros(3)
    wp = np.zeros(3)
    tmp = np.zeros(3)
    ez = np.array([0.0, 0.0, 1.0])
    kept = 0
    bumped = 0
    for _ in range(count):
        tau = rng.random() * dt
        psi = prec * tau
        _rotate(ez, psi, w, wp)
        if beta * math.sqrt(wp[0] ** 2 + wp[1] ** 2 + wp[2] ** 2) * r_max > s_bound:
            bumped += 1
        if not attempt(rng, wp, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass, s_bound, J):
            continue
        kept += 1
        _rotate(ez, -psi, J, Jend)
        for i in range(3):
            dLb[i] += Jend[i]
            w[i] += Jend[i] / inertia[i]
        for i in range(3):
            tmp[i] = O[i, 0] * Jend[0] + O[i, 1] * Jend[1] + O[i, 2] * Jend[2]
        _rotate(Lw_hat, -w_L * tau, tmp, J)
        for i in range(3):
            dLw[i] += J[i]
    return dLb, dLw, kept, bumped


@_jit
def uniformized_walk(rng, omega0, inertia, n, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass, s_bound):
    """A spherical top (I1 = I2 = I3: between collisions its body-frame Omega stays) in the gas
    alone, seen at ``n`` candidates of the thinned stream at the fixed bound ``s_bound``: the
    process uniformized, so averages over the candidates are averages over time.  Returns
    (the mean of 1/2 Omega . I Omega over them, erg; the candidates whose state outran the bound)."""
    w = omega0.copy()
    J = np.zeros(3)
    total = 0.0
    out = 0
    for _ in range(n):
        if beta * math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2) * r_max > s_bound:
            out += 1
        if attempt(rng, w, kinds, geo, cum, r_max, beta, sigma, sigma_b, alpha, mass, s_bound, J):
            for i in range(3):
                w[i] += J[i] / inertia[i]
        total += 0.5 * (inertia[0] * w[0] ** 2 + inertia[1] * w[1] ** 2 + inertia[2] * w[2] ** 2)
    return total / n, out
