"""The residual gas of a trap, meeting a spinning crystal: free-molecular flow (the molecules'
mean free path far beyond the body), each molecule hitting the surface once and leaving it.

The model, per surface element moving with velocity u = Omega x r (body frame; the gas at rest
in the world, Maxwellian at T_gas, number density n = p / k T_gas, molecular mass m):

* the molecules that arrive: a Maxwellian seen from the element, drifting at -u; those with a
  relative velocity w into the surface (w . n < 0).  In units of beta = sqrt(m / 2 k T), with
  s = beta u_n (u_n = u . n, the element moving into the gas when positive) and
  I_k(s) = int_0^oo y^k exp(-(y - s)^2) dy, the flux is Phi = n I_1(s) / (beta sqrt(pi)) and
  the incoming normal speed x = -w . n has E[x^j] = I_(j+1) / (I_1 beta^j); the tangential
  components are Gaussian about -u_t with variance k T / m, whatever x;
* how they leave: a share ``accommodation`` (alpha) diffusely, re-emitted from the surface at
  its own temperature T_b (a half-Maxwellian flux: normal speed Rayleigh, E = sqrt(pi/2) sigma_b,
  E[square] = 2 sigma_b^2; tangential Gaussian of variance sigma_b^2 = k T_b / m, in the
  surface's frame: they carry its velocity u away), the rest specularly (w_n -> -w_n);
* each molecule hands the body the momentum m (w - w'), an angular impulse J = m r x (w - w').

From this one model come the gas's mean torque (``GasModel.torque``: the drag), the rate of
collisions (``rate``), the second moment of their angular impulses per unit time
(``impulse_covariance``, the fluctuations: fluctuation and dissipation from the same gas), and
the single collisions of ``integrators.collisions``.  The drag is not linear in Omega once the
surface moves as fast as the molecules (the DAST cube's corners: ~2 km/s at pi 1e10 rad/s,
against v_bar = 476 m/s for N2 at 300 K); for slow surfaces it is, with per-area coefficients
(``linear_coefficients``)

    c_t = alpha m n v_bar / 4,
    c_n = m n v_bar [(2 - alpha) / 2 + alpha (pi / 8) sqrt(T_b / T_gas)],

(force per area -c_t u_t - c_n u_n n beyond the static pressure), which at alpha = 1,
T_b = T_gas are m n v_bar / 4 and m n v_bar (1/2 + pi/8).  On a sphere Omega x r is
tangential, so the drag is exactly linear at any speed: a spin's damping rate is
gamma = 10 p / (pi rho a v_bar) (a the radius; alpha = 1).  The linear drag tensors of a box
and a cylinder are written out in ``linear_drag_tensor``.

CGS throughout: pressure in dyn/cm^2, speeds cm/s, torques dyn cm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import units as U

# name -> (molecular mass in u, kinetic diameter in cm: the hard-sphere size of the mean free path)
GASES = {
    "H2": (2.01588, 2.89e-8),
    "He": (4.002602, 2.60e-8),
    "Ne": (20.1797, 2.75e-8),
    "N2": (28.0134, 3.64e-8),
    "O2": (31.9988, 3.46e-8),
    "Ar": (39.948, 3.40e-8),
    "CO2": (44.0095, 3.30e-8),
    "Xe": (131.293, 3.96e-8),
}
SQRT_PI = math.sqrt(math.pi)
_erfc = np.frompyfunc(math.erfc, 1, 1)          # the standard library's, element by element (NumPy has none)


@dataclass(frozen=True)
class Gas:
    """A trap's residual gas (CGS): ``name`` (a key of ``GASES``), pressure (dyn/cm^2), its
    temperature and the body's surface temperature (K), and the share of molecules re-emitted
    diffusely (``accommodation``, the rest specularly)."""

    name: str
    pressure: float
    temperature_k: float
    accommodation: float = 1.0
    body_temperature_k: float | None = None

    @property
    def mass(self) -> float:
        """One molecule's mass, g."""
        return GASES[self.name][0] * U.AMU

    @property
    def surface_temperature_k(self) -> float:
        """The body's surface temperature, K: given, or the gas's."""
        return self.temperature_k if self.body_temperature_k is None else self.body_temperature_k

    @property
    def density(self) -> float:
        """Number density n = p / k T, cm^-3."""
        return self.pressure / (U.K_BOLTZMANN * self.temperature_k)

    @property
    def beta(self) -> float:
        """sqrt(m / 2 k T), s/cm."""
        return math.sqrt(self.mass / (2.0 * U.K_BOLTZMANN * self.temperature_k))

    @property
    def sigma(self) -> float:
        """sqrt(k T / m), cm/s: one velocity component's spread."""
        return math.sqrt(U.K_BOLTZMANN * self.temperature_k / self.mass)

    @property
    def sigma_body(self) -> float:
        """sqrt(k T_b / m), cm/s: a re-emitted molecule's tangential spread."""
        return math.sqrt(U.K_BOLTZMANN * self.surface_temperature_k / self.mass)

    @property
    def mean_speed(self) -> float:
        """v_bar = sqrt(8 k T / pi m), cm/s."""
        return math.sqrt(8.0 * U.K_BOLTZMANN * self.temperature_k / (math.pi * self.mass))

    @property
    def mean_free_path(self) -> float:
        """lambda = k T / (sqrt(2) pi d^2 p), cm (hard spheres of the kinetic diameter d); inf in vacuum."""
        if self.pressure == 0.0:
            return math.inf
        d = GASES[self.name][1]
        return U.K_BOLTZMANN * self.temperature_k / (math.sqrt(2.0) * math.pi * d * d * self.pressure)

    @property
    def wall_flux(self) -> float:
        """Molecules hitting a resting surface, n v_bar / 4, per cm^2 per s."""
        return 0.25 * self.density * self.mean_speed

    def linear_coefficients(self) -> tuple[float, float]:
        """(c_t, c_n), g/(cm^2 s): the force per area -c_t u_t - c_n u_n n on an element moving
        slowly (|u| << v_bar) with velocity u (module docstring)."""
        a = self.accommodation
        mnv = self.mass * self.density * self.mean_speed
        ratio = math.sqrt(self.surface_temperature_k / self.temperature_k)
        return 0.25 * a * mnv, mnv * (0.5 * (2.0 - a) + a * math.pi / 8.0 * ratio)


# --- the flux-weighted normal speeds --------------------------------------------------------
def flux_integrals(s, kmax: int = 4):
    """I_k(s) = int_0^oo y^k exp(-(y - s)^2) dy for k = 0..kmax, shape ``(kmax + 1, *s.shape)``.

    I_0 = (sqrt(pi)/2) erfc(-s), I_1 = exp(-s^2)/2 + s I_0, I_(k+1) = s I_k + (k/2) I_(k-1):
    erfc(-s) of a face receding from the gas (s < 0) is erfc(|s|), small and accurate, so its
    small flux keeps its relative accuracy (to ~s^2 of round-off in I_1's difference)."""
    s = np.asarray(s, dtype=float)
    e = np.exp(-s * s)
    i0 = 0.5 * SQRT_PI * np.asarray(_erfc(-s), dtype=float)
    i1 = np.maximum(0.5 * e + s * i0, 0.0)
    out = [i0, i1]
    for k in range(1, kmax):
        out.append(s * out[k] + 0.5 * k * out[k - 1])
    return np.stack(out)


def element_moments(gas: Gas, u, n, parts: bool = False):
    """What the gas does to surface elements moving with velocities u (..., 3) with outward
    normals n (..., 3), per unit area and time (module docstring):

    flux (...): molecules arriving, per cm^2 per s;
    mean (..., 3): E[w - w'] (cm/s), the velocity each molecule hands over on average;
    second (..., 3, 3): E[(w - w')(w - w')^T] (cm^2/s^2) -- or, with ``parts``, its pieces
    (tt, u_t, c_nn, c_x) of tt (1 - n n^T) + alpha u_t u_t^T + c_nn n n^T + c_x (u_t n^T + n u_t^T).
    """
    u = np.asarray(u, dtype=float)
    n = np.asarray(n, dtype=float)
    un = np.sum(u * n, axis=-1)
    ut = u - un[..., None] * n
    b = gas.beta
    I = flux_integrals(b * un)
    flux = gas.density * I[1] / (b * SQRT_PI)
    with np.errstate(invalid="ignore", divide="ignore"):
        safe = np.where(I[1] > 0.0, I[1], 1.0)
        ex = I[2] / safe / b                   # E[x], x = -w.n > 0
        ex2 = I[3] / safe / (b * b)            # E[x^2]
    a = gas.accommodation
    sb = gas.sigma_body
    ew, ew2 = math.sqrt(0.5 * math.pi) * sb, 2.0 * sb * sb
    mean_n = -((2.0 - a) * ex + a * ew)
    mean = -a * ut + mean_n[..., None] * n
    nn = n[..., :, None] * n[..., None, :]
    eye = np.eye(3)
    pt = eye - nn
    cnn = a * (ex2 + 2.0 * ex * ew + ew2) + (1.0 - a) * 4.0 * ex2
    cross = a * (ex + ew)
    tt = a * (gas.sigma**2 + sb * sb)
    if parts:
        return flux, mean, (np.broadcast_to(tt, cnn.shape), ut, cnn, cross)
    second = (a * (gas.sigma**2 + sb * sb) * pt + a * ut[..., :, None] * ut[..., None, :] + cnn[..., None, None] * nn
              + cross[..., None, None] * (ut[..., :, None] * n[..., None, :] + n[..., :, None] * ut[..., None, :]))
    return flux, mean, second


def _cross_matrix(r):
    """[r]_x (..., 3, 3): [r]_x v = r x v."""
    r = np.asarray(r, dtype=float)
    z = np.zeros(r.shape[:-1])
    return np.stack([np.stack([z, -r[..., 2], r[..., 1]], -1), np.stack([r[..., 2], z, -r[..., 0]], -1),
                     np.stack([-r[..., 1], r[..., 0], z], -1)], -2)


# --- a body in the gas ------------------------------------------------------------------------
@dataclass(frozen=True)
class GasModel:
    """The gas ``gas`` on the surface ``surface`` (``physics.surface``) of a body with principal
    moments ``inertia`` (g cm^2): rates, mean torque and impulse fluctuations at a body-frame
    angular velocity Omega (rad/s), by quadrature over the surface (module docstring)."""

    gas: Gas
    surface: object
    inertia: tuple

    def nodes_for(self, omega) -> int:
        """Gauss-Legendre nodes per flat coordinate for the state Omega: the flux changes from
        nothing to the ram flux n u_n over ~1 in s = beta u_n, so the faces need a few nodes per
        unit of s across them (the quadrature's error is checked against twice the nodes in the
        tests)."""
        s_max = self.gas.beta * float(np.linalg.norm(omega)) * self.surface.r_max
        return int(min(96, max(12, math.ceil(10 + 4.0 * s_max))))

    def _elements(self, omega, k=None):
        omega = np.asarray(omega, dtype=float)
        r, n, w = self.surface.nodes(k or self.nodes_for(omega))
        u = np.cross(np.broadcast_to(omega, r.shape), r)
        return r, n, w, element_moments(self.gas, u, n)

    def rate(self, omega, k=None) -> float:
        """Collisions per second at body-frame Omega (rad/s)."""
        _, _, w, (flux, _, _) = self._elements(omega, k)
        return float(np.sum(w * flux))

    def _static(self, r):
        """Phi E[w - w'] of a surface at rest (the static pressure, along -n): it exerts no torque
        on a closed surface, and taking it out before the sum keeps the drag of a slow spin from
        drowning in its round-off."""
        g = self.gas
        a = g.accommodation
        flux0 = g.density / (2.0 * g.beta * SQRT_PI)
        return flux0 * -((2.0 - a) * 0.5 * SQRT_PI / g.beta + a * math.sqrt(0.5 * math.pi) * g.sigma_body)

    def _torque(self, r, n, w, flux, mean) -> np.ndarray:
        force = flux[:, None] * mean - self._static(r) * n
        return self.gas.mass * np.sum(w[:, None] * np.cross(r, force), axis=0)

    def torque(self, omega, k=None) -> np.ndarray:
        """The gas's mean torque (3,), body frame, dyn cm: the drag, m sum Phi r x E[w - w'] dA."""
        r, n, w, (flux, mean, _) = self._elements(omega, k)
        return self._torque(r, n, w, flux, mean)

    def impulse_covariance(self, omega, k=None) -> np.ndarray:
        """sum over collisions per second of J J^T (3, 3), body frame, (g cm^2/s)^2 per s: the
        second moment of the angular impulses J = m r x (w - w') per unit time (their mean
        squared included: that is what a Poisson stream of them adds up to)."""
        return self.moments(omega, k)[2]

    def moments(self, omega, k=None) -> tuple[float, np.ndarray, np.ndarray]:
        """(rate, torque, impulse_covariance) at Omega in one quadrature."""
        omega = np.asarray(omega, dtype=float)
        r, n, w = self.surface.nodes(k or self.nodes_for(omega))
        u = np.cross(np.broadcast_to(omega, r.shape), r)
        flux, mean, parts = element_moments(self.gas, u, n, parts=True)
        wf = w * flux
        # [r]x E[dd^T] [r]x^T term by term (element_moments' parts): r x of each vector of the sum
        tt, ut, cnn, cross = parts
        rn, ru = np.cross(r, n), np.cross(r, ut)
        rr = np.einsum("k,ki,kj->ij", wf * tt, r, r)
        cov = np.eye(3) * np.sum(wf * tt * np.sum(r * r, axis=1)) - rr
        cov += np.einsum("k,ki,kj->ij", wf * (cnn - tt), rn, rn) + np.einsum("k,ki,kj->ij", wf * self.gas.accommodation, ru, ru)
        c = np.einsum("k,ki,kj->ij", wf * cross, ru, rn)
        cov += c + c.T
        return float(np.sum(wf)), self._torque(r, n, w, flux, mean), self.gas.mass**2 * cov

    def damping_rate(self, omega, k=None) -> float:
        """The gas's braking rate of |L| at Omega: -L . N / |L|^2 (1/s), L = I Omega."""
        omega = np.asarray(omega, dtype=float)
        L = np.asarray(self.inertia, dtype=float) * omega
        return float(-(L @ self.torque(omega, k)) / (L @ L))


def linear_drag_tensor(kind: str, dims, c_t: float, c_n: float) -> np.ndarray:
    """The drag of a slowly spinning body, N = -K Omega (K (3, 3) in the shape's frame, g cm^2/s),
    from the per-area coefficients c_t, c_n (``Gas.linear_coefficients``), written out:

    N = -int r x (c_t u_t + c_n u_n n) dA = -(c_t S + (c_n - c_t) T) Omega, with the surface's
    second moment S = int (r^2 1 - r r^T) dA and T = int (r x n)(r x n)^T dA (u_n = Omega . (r x n));

    * "sphere" (dims: diameter 2a): T = 0, S = (8 pi / 3) a^4;
    * "box" (edges a, b, c along x, y, z): S_xx = 2 [a b^3/12 + a b c^2/4 + b^3 c/12 + b c^3/12
      + a c b^2/4 + a c^3/12] and cyclically, T = diag(a b^3 + a c^3, a^3 b + b c^3, a^3 c + b^3 c) / 6;
    * "rod" (a cylinder of length L and diameter 2R along z): S_xx = pi R^3 L + pi R L^3/6 +
      pi R^4/2 + pi R^2 L^2/2, S_zz = 2 pi R^3 L + pi R^4, T_xx = pi R L^3/12 + pi R^4/2, T_zz = 0.
    """
    if kind == "sphere":
        a = 0.5 * dims[0]
        return c_t * (8.0 * math.pi / 3.0) * a**4 * np.eye(3)
    if kind == "box":
        a, b, c = dims

        def s(a, b, c):           # S_xx of edges a (x), b (y), c (z)
            return 2.0 * (a * b**3 / 12 + a * b * c * c / 4 + b**3 * c / 12 + b * c**3 / 12 + a * c * b * b / 4
                          + a * c**3 / 12)

        S = np.diag([s(a, b, c), s(b, c, a), s(c, a, b)])
        T = np.diag([a * b**3 + a * c**3, a**3 * b + b * c**3, a**3 * c + b**3 * c]) / 6.0
        return c_t * S + (c_n - c_t) * T
    if kind == "rod":
        L, R = dims[0], 0.5 * dims[1]
        pi = math.pi
        sxx = pi * R**3 * L + pi * R * L**3 / 6 + pi * R**4 / 2 + pi * R * R * L * L / 2
        szz = 2 * pi * R**3 * L + pi * R**4
        txx = pi * R * L**3 / 12 + pi * R**4 / 2
        return c_t * np.diag([sxx, sxx, szz]) + (c_n - c_t) * np.diag([txx, txx, 0.0])
    raise ValueError(f"no drag tensor for a {kind!r}")
