"""What the spinning dipole sends out: the space-frame dipole and its derivatives, the Larmor
power, the angular momentum carried away (2.4a), the Schott-like term (2.4b), the energies, the
far field along a line of sight, and the line spectrum of a symmetric top.

Everything here is in the variables (4.1) (tau0 = 1, I1 = 1) and uses the coupling
g = sqrt(2/3c^3) d in place of d, so that no factor 2/3c^3 appears: (2/3c^3) d x ... = g x ...
and (2/3c^3) |d_ddot|^2 = |g_ddot|^2 (``units.radiation_from_dimensionless`` takes the results
back to CGS).  With O = R_world_from_body(q) and Omega the body-frame angular velocity, the
space-frame dipole and its derivatives are O times the body-frame vectors

    b0 = g,   b1 = Omega x g,   b2 = Omega_dot x g + Omega x b1,
    b3 = Omega_ddot x g + Omega_dot x b1 + 2 Omega x (Omega_dot x g) + Omega x (Omega x b1)

(d/dt (O v) = O (v_dot + Omega x v)), and

    Larmor power            P   = |b2|^2                 (2/3c^3) |d_ddot|^2
    flux of L (2.4a)        F   = -b1 x b2               -(2/3c^3) d_dot x d_ddot
    Schott-like term (2.4b) S   = b1 x b2 + g x b3       d/dt (2/3c^3) d x d_ddot
    the model's torque      N   = J Omega_dot + Omega x J Omega = dL/dt (body frame)
    energy                  E   = 1/2 Omega . J Omega
    Schott energy           E_S = b1 . b2                (2/3c^3) d_dot . d_ddot

Omega_dot is the model's own (its equation of motion), Omega_ddot = (dOmega_dot/dOmega) Omega_dot
by complex-step differentiation of the same formula: no finite differences.  N is computed as
J times the radiation part of Omega_dot alone, which for real particles is 1e-16 of the free
part and would be lost in the round-off of J Omega_dot + Omega x J Omega.

The balance laws these measure: (2.1) N = g x b3 = F + S (the reduced equation satisfies it
with Omega_dot, Omega_ddot inside b3 replaced by the free-motion values (2.3)); (2.4a) N = F
(the truncated equation (2.5), by construction); energy dE/dt = Omega . N, and for a torque
g x b3 this is b1 . b3 = -P + dE_S/dt (the Larmor power plus the Schott energy).

Rotation invariants (P, E, E_S, |F|, Omega . N) need only Omega, so they hold also where the
orientation's phase is beyond float64 (``secular`` runs of real particles).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import units as U
from ..rotations import unit_vector, world_from_body
from .equations import free_rate
from .models import radiation_function, rate_function


def _components(fn, w, J, g):
    """fn(w1, w2, w3, J, g) on an (..., 3) array, stacked back to (..., 3) (complex allowed)."""
    out = fn(w[..., 0], w[..., 1], w[..., 2], J, g)
    return np.stack(np.broadcast_arrays(*out), axis=-1)


def model_rates(model: str, omega_body, J, g, second: bool = True):
    """The model's Omega_dot, its radiation part, and Omega_ddot at body-frame states
    ``omega_body`` (..., 3).

    Dimensionless (4.1): J = (1, J2, J3), g the unit coupling.  Returns (omega_dot_body,
    omega_dot_radiation_body, omega_ddot_body), each (..., 3), body frame, 1/tau0^2 and
    1/tau0^3; omega_ddot_body is None unless ``second``.  Omega_ddot = D Omega_dot(Omega) . Omega_dot,
    the derivative along the model's own flow, by a complex step along Omega_dot:
    f(w + i h u) = f(w) + i h Df u + O(h^2) with no subtraction, so with h = 1e-30 |w| the
    imaginary part is the directional derivative to round-off.
    """
    w = np.asarray(omega_body, dtype=float)
    Jt, gt = tuple(float(x) for x in J), tuple(float(x) for x in g)
    wd = _components(rate_function(model), w, Jt, gt)
    wr = _components(radiation_function(model), w, Jt, gt)
    if not second:
        return wd, wr, None
    speed = np.linalg.norm(wd, axis=-1, keepdims=True)
    u = np.divide(wd, speed, out=np.zeros_like(wd), where=speed > 0)
    size = np.linalg.norm(w, axis=-1, keepdims=True)
    h = np.where(size > 0, 1e-30 * size, 1e-300)
    z = w + 1j * h * u
    wdd = _components(rate_function(model), z, Jt, gt).imag / h * speed
    return wd, wr, wdd


def dipole_derivatives(omega_body, omega_dot_body, g, omega_ddot_body=None):
    """Body-frame (b1, b2, b3) of the space dipole's first three derivatives (module docstring),
    for g (3,) and body-frame states, rates and second rates (..., 3) in (4.1) units; b3 is None
    without ``omega_ddot_body``.  O b_k is the k-th time derivative of the world-frame dipole g."""
    w = np.asarray(omega_body, dtype=float)
    wd = np.asarray(omega_dot_body, dtype=float)
    g = np.broadcast_to(np.asarray(g, dtype=float), w.shape)
    b1 = np.cross(w, g)
    wdg = np.cross(wd, g)
    b2 = wdg + np.cross(w, b1)
    if omega_ddot_body is None:
        return b1, b2, None
    b3 = (np.cross(np.asarray(omega_ddot_body, dtype=float), g) + np.cross(wd, b1) + 2.0 * np.cross(w, wdg)
          + np.cross(w, np.cross(w, b1)))
    return b1, b2, b3


@dataclass(frozen=True)
class Balance:
    """The radiation observables at body-frame states Omega, dimensionless (4.1) (module docstring).

    Vectors are (..., 3) in the body frame (``world_from_body(q, ...)`` takes them to the world):
    b1, b2, b3 (the dipole's derivatives), flux_body F (2.4a), schott_body S (2.4b),
    torque_body N = dL/dt of the model, L_body = J Omega, and the states' omega_body,
    omega_dot_body, omega_ddot_body.  Scalars (...): power P, energy E, schott_energy E_S.
    """

    omega_body: np.ndarray
    omega_dot_body: np.ndarray
    omega_ddot_body: np.ndarray
    b1: np.ndarray
    b2: np.ndarray
    b3: np.ndarray
    power: np.ndarray
    flux_body: np.ndarray
    schott_body: np.ndarray
    torque_body: np.ndarray
    energy: np.ndarray
    schott_energy: np.ndarray
    L_body: np.ndarray

    def dipole_torque(self, g) -> np.ndarray:
        """g x b3 = (2/3c^3) d x d_dddot: the right-hand side of (2.1) with the model's own
        Omega_dot, Omega_ddot (= flux + schott), (..., 3)."""
        return np.cross(np.broadcast_to(np.asarray(g, dtype=float), self.b3.shape), self.b3)

    @property
    def work(self) -> np.ndarray:
        """Omega . N = dE/dt, the power the torque takes from the rotation, (...)."""
        return np.sum(self.omega_body * self.torque_body, axis=-1)

    @property
    def dipole_work(self) -> np.ndarray:
        """b1 . b3 = -P + dE_S/dt: the work of (2.1)'s torque with the model's own derivatives."""
        return np.sum(self.b1 * self.b3, axis=-1)


def balance(model: str, omega_body, J, g) -> Balance:
    """All radiation observables of ``model`` at body-frame states ``omega_body`` (..., 3), in the
    variables (4.1): J = (1, J2, J3), g the unit coupling (``System.inertia``, ``.coupling``)."""
    w = np.asarray(omega_body, dtype=float)
    Jv = np.asarray(J, dtype=float)
    g = np.asarray(g, dtype=float)
    wd, wr, wdd = model_rates(model, w, J, g)
    b1, b2, b3 = dipole_derivatives(w, wd, g, wdd)
    b1xb2 = np.cross(b1, b2)
    return Balance(omega_body=w, omega_dot_body=wd, omega_ddot_body=wdd, b1=b1, b2=b2, b3=b3,
                   power=np.sum(b2 * b2, axis=-1), flux_body=-b1xb2,
                   schott_body=b1xb2 + np.cross(np.broadcast_to(g, b3.shape), b3), torque_body=Jv * wr,
                   energy=0.5 * np.sum(Jv * w * w, axis=-1), schott_energy=np.sum(b1 * b2, axis=-1), L_body=Jv * w)


def free_dipole_torque(omega_body, J, g) -> np.ndarray:
    """g x b3 with the free-motion Omega_dot (2.3a) and Omega_ddot (2.3b) (the latter by the same
    complex step): (2.1)'s right-hand side as the reduced equation (2.2)+(2.3) evaluates it.
    Body frame, (..., 3), at body-frame states ``omega_body`` (..., 3), (4.1) units."""
    w = np.asarray(omega_body, dtype=float)
    _, _, wdd = model_rates("free", w, J, g)
    Jt = tuple(float(x) for x in J)
    wd = _components(free_rate, w, Jt, tuple(float(x) for x in g))
    _, _, b3 = dipole_derivatives(w, wd, g, wdd)
    return np.cross(np.broadcast_to(np.asarray(g, dtype=float), b3.shape), b3)


def larmor_power(model: str, omega_body, J, g) -> np.ndarray:
    """P = |b2|^2 (Larmor, 2/3c^3 |d_ddot|^2), (...), I1/tau0^3, at body-frame states
    ``omega_body`` (..., 3) in (4.1) units, with the model's own Omega_dot."""
    w = np.asarray(omega_body, dtype=float)
    wd, _, _ = model_rates(model, w, J, g, second=False)
    _, b2, _ = dipole_derivatives(w, wd, g)
    return np.sum(b2 * b2, axis=-1)


def precession_phases(M: int) -> np.ndarray:
    """M evenly spaced precession phases on [0, 2 pi): averaging a trigonometric polynomial of
    degree < M over them is exact."""
    return 2.0 * np.pi * np.arange(M) / M


def about_e3(omega_body, angle) -> np.ndarray:
    """Omega rotated about e3 by ``-angle``: where the free precession of a symmetric top takes
    body-frame Omega after the phase ``angle`` = delta Omega3 t (rad).  omega_body (N, 3),
    angle (M,) -> (N, M, 3), body frame, the units of ``omega_body``."""
    w = np.asarray(omega_body, dtype=float)
    c, s = np.cos(angle)[None, :], np.sin(angle)[None, :]
    w1, w2, w3 = w[:, None, 0], w[:, None, 1], w[:, None, 2]
    return np.stack(np.broadcast_arrays(c * w1 + s * w2, c * w2 - s * w1, w3 + 0.0 * c), axis=-1)


def precession_rates(omega_body, J):
    """(phi_dot, psi_dot), each (...), of a symmetric top's free motion at body-frame states
    ``omega_body`` (..., 3): the turn about L at |L|/I1 and the body precession at delta Omega3
    (``Lines``), in the units of ``omega_body``."""
    w = np.asarray(omega_body, dtype=float)
    J = np.asarray(J, dtype=float)
    return np.linalg.norm(J * w, axis=-1) / J[0], (1.0 - J[2] / J[0]) * w[..., 2]


def precesses(omega_body, J) -> np.ndarray:
    """Whether the body frame precesses at a body-frame state, (...): |delta Omega3| above
    1e-12 |L|/I1 (a sphere, or a spin with Omega3 = 0 such as (3.9), keeps Omega fixed in the body)."""
    phi_dot, psi_dot = precession_rates(omega_body, J)
    return np.abs(psi_dot) > 1e-12 * phi_dot


def precession_averaged_power(model: str, omega_body, J, g, M: int = 16) -> np.ndarray:
    """P averaged over the free precession of a symmetric top (I1 = I2): Omega_perp turns about
    e3 at delta Omega3 in the body, |Omega_perp| and Omega3 stay (the slow variables).  What a
    detector integrating over many precession turns sees; needs no phase, so it is physical
    also for ``secular`` runs.  Exact for the free part (P is a trigonometric polynomial of
    degree 2 in the phase; M = 16 leaves the radiation part's degree-4 terms unaliased).  Where
    nothing precesses (``precesses`` False) it is the instantaneous P.  ``omega_body`` (..., 3)
    body frame, (4.1) units; returns (...), I1/tau0^3."""
    w = np.atleast_2d(np.asarray(omega_body, dtype=float))
    avg = larmor_power(model, about_e3(w, precession_phases(M)), J, g).mean(axis=-1)
    out = np.where(precesses(w, J), avg, larmor_power(model, w, J, g))
    return out.reshape(np.shape(omega_body)[:-1])


# --- the far field along a line of sight ----------------------------------------------------
def polarization_basis(line_of_sight) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(n, u1, u2): the unit line of sight (world) and two unit polarization axes across it,
    u1 = z x n / |z x n| (horizontal; x x n when n is along z), u2 = n x u1; a right-handed
    triad (u1, u2, n).  Polarization angles are measured from u1 towards u2."""
    try:
        n = unit_vector(line_of_sight)     # the schema's rule (inputs.base.Direction): any finite non-zero vector
    except ValueError as e:
        raise ValueError(f"line of sight: {e}") from None
    ref = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.99 else np.array([1.0, 0.0, 0.0])
    u1 = np.cross(ref, n)
    u1 /= np.linalg.norm(u1)
    return n, u1, np.cross(n, u1)


def far_field(ddot_world, line_of_sight) -> np.ndarray:
    """The radiation field's two polarizations along n, in units where E R c^2 = d_ddot:
    E = (d_ddot x n) x n = -(d_ddot across n), returned as (..., 2) components on (u1, u2) of
    ``polarization_basis`` (the retarded time is the caller's: add R/c to the times)."""
    _, u1, u2 = polarization_basis(line_of_sight)
    a = np.asarray(ddot_world)
    return -np.stack([a @ u1, a @ u2], axis=-1)


def power_per_sr(ddot_world, line_of_sight) -> np.ndarray:
    """dP/dOmega = |d_ddot x n|^2 / (4 pi c^3) = (3/8 pi) |b2 across n|^2 in g units (...);
    integrates to P over the sphere."""
    e = far_field(ddot_world, line_of_sight)
    return 3.0 / (8.0 * math.pi) * np.sum(np.abs(e) ** 2, axis=-1)


# --- the line spectrum of a symmetric top ---------------------------------------------------
@dataclass(frozen=True)
class Lines:
    """The spectral lines of d_ddot(t) near each state of a symmetric top, dimensionless.

    The free symmetric top moves as O(t) = R_L(Phi_dot t) O0 R_e3(Psi_dot t): a turn about the
    fixed L at Phi_dot = |L|/I1 (the rotation seen from outside) composed with the body's
    precession about e3 at Psi_dot = delta Omega3 (I1 - I3 = delta I1).  So d_ddot(t) is
    sum_k 2 Re(amplitude_k exp(i omega_k t)) with omega_k = m Phi_dot + kappa Psi_dot.

    angular_frequency : (N, K) signed angular frequencies of the lines, 1/tau0 (also read as
    ``omega``, its earlier name: a rate, not a vector).
    amplitude : (N, K, 3) complex world-frame amplitudes of d_ddot (g units); the phases are
    those of the state at each sample (true where the orientation's phase is resolved).
    phi_dot, psi_dot : (N,) the rotation and the body precession rates.
    """

    angular_frequency: np.ndarray
    amplitude: np.ndarray
    phi_dot: np.ndarray
    psi_dot: np.ndarray

    @property
    def omega(self) -> np.ndarray:
        """``angular_frequency`` under its earlier name (kept for existing callers)."""
        return self.angular_frequency

    @property
    def power(self) -> np.ndarray:
        """Each line's share of the time-averaged Larmor power, (N, K): 2 |amplitude|^2."""
        return 2.0 * np.sum(np.abs(self.amplitude) ** 2, axis=-1)

    def toward(self, line_of_sight):
        """(e, power_per_sr): each line's complex field amplitudes on (u1, u2), (N, K, 2) (with
        E(t) = 2 Re(e exp(i omega t)) in the units of ``far_field``), and its dP/dOmega toward n,
        (N, K), time-averaged."""
        _, u1, u2 = polarization_basis(line_of_sight)
        e = -np.stack([self.amplitude @ u1, self.amplitude @ u2], axis=-1)
        return e, 3.0 / (8.0 * math.pi) * 2.0 * np.sum(np.abs(e) ** 2, axis=-1)

    def stokes(self, line_of_sight) -> np.ndarray:
        """Time-averaged Stokes parameters (I, Q, U, V) of the field toward n, summed over the
        lines (incoherent: lines of different frequency do not interfere on average), (N, 4),
        in the units of ``far_field`` squared.  V > 0: the field turns from u1 towards u2."""
        e, _ = self.toward(line_of_sight)
        e = np.where((self.angular_frequency < 0)[..., None], np.conj(e), e)    # a negative frequency is its conjugate's
        e1, e2 = e[..., 0], e[..., 1]
        i = 2.0 * (np.abs(e1) ** 2 + np.abs(e2) ** 2)
        q = 2.0 * (np.abs(e1) ** 2 - np.abs(e2) ** 2)
        u = 4.0 * np.real(e1 * np.conj(e2))
        v = 4.0 * np.imag(np.conj(e1) * e2)
        return np.stack([i.sum(-1), q.sum(-1), u.sum(-1), v.sum(-1)], axis=-1)

    def signal(self, line_of_sight, t) -> np.ndarray:
        """The two polarizations of the field at times ``t`` (M,) after each sample (seconds of
        the lines' own time unit), synthesized from the lines: (N, M, 2)."""
        e, _ = self.toward(line_of_sight)
        ph = np.exp(1j * self.angular_frequency[:, :, None] * np.asarray(t, dtype=float)[None, None, :])   # (N, K, M)
        return 2.0 * np.real(np.einsum("nkp,nkm->nmp", e, ph))


def symmetric_top_lines(model: str, omega_body, q, J, g, M: int = 16) -> Lines:
    """The spectral lines of d_ddot near each state (``Lines``) of a symmetric top (J1 = J2).

    omega_body (N, 3) body frame, q (N, 4) (w, x, y, z), dimensionless (4.1).  Over the body-frame
    precession phase Psi the state is rotated about e3 (``about_e3``), d_ddot = O b2 is formed
    with the model's own Omega_dot at each phase, and its harmonics in Psi (FFT over M phases)
    and in the turn about L (analytic: R_L(Phi) A = A_par + cos Phi A_perp + sin Phi L x A) give
    the lines.  Where Psi_dot = 0 (a sphere, or Omega3 = 0) nothing precesses: the state's own
    phase is kept and all its harmonics fall on Phi_dot.
    """
    J = tuple(float(x) for x in J)
    if abs(J[0] - J[1]) > 1e-12 * max(abs(J[0]), abs(J[1])):
        raise ValueError("the line spectrum needs a symmetric top (I1 = I2)")
    w = np.atleast_2d(np.asarray(omega_body, dtype=float))
    q = np.atleast_2d(np.asarray(q, dtype=float))
    n = w.shape[0]
    L_world = world_from_body(q, np.asarray(J) * w)
    size = np.linalg.norm(L_world, axis=-1)
    L_hat = np.divide(L_world, size[:, None], out=np.tile([0.0, 0.0, 1.0], (n, 1)), where=size[:, None] > 0)
    phi_dot, psi_dot = precession_rates(w, J)
    psi = precession_phases(M)
    ws = about_e3(w, psi)                                               # (N, M, 3)
    wd, _, _ = model_rates(model, ws, J, g, second=False)
    _, b2, _ = dipole_derivatives(ws, wd, g)
    # back to the state's own body frame (undo the rotation about e3), then to the world
    c, s = np.cos(psi)[None, :], np.sin(psi)[None, :]
    b2 = np.stack([c * b2[..., 0] - s * b2[..., 1], s * b2[..., 0] + c * b2[..., 1], b2[..., 2]], axis=-1)
    A = world_from_body(q[:, None, :], b2)                              # (N, M, 3): d_ddot at Phi = 0
    a_par = np.sum(A * L_hat[:, None, :], axis=-1)                      # (N, M)
    A_perp = A - a_par[..., None] * L_hat[:, None, :]
    rot = 0.5 * (A_perp - 1j * np.cross(L_hat[:, None, :], A))          # coefficient of exp(i Phi)
    kappa = np.fft.fftfreq(M, 1.0 / M)                                  # 0, 1, .., M/2-1, -M/2, .., -1
    c1 = np.fft.fft(rot, axis=1) / M                                    # (N, M, 3): m = 1, kappa
    c0 = np.fft.fft(a_par, axis=1) / M                                  # (N, M): m = 0
    pos = np.arange(1, M // 2)
    amp = np.concatenate([c1, c0[:, pos, None] * L_hat[:, None, :]], axis=1)
    freq = np.concatenate([phi_dot[:, None] + kappa[None, :] * psi_dot[:, None], pos[None, :] * psi_dot[:, None]], axis=1)
    still = ~precesses(w, J)
    if np.any(still):
        # no precession: the state's phase (column 0 of the grid, the stored state) is the phase
        amp[still] = 0.0
        amp[still, 0] = rot[still, 0]
        freq[still] = phi_dot[still, None]
    return Lines(angular_frequency=freq, amplitude=amp, phi_dot=phi_dot, psi_dot=psi_dot)


# --- a run's observables, in its body's units -----------------------------------------------
def observables(body, model: str, omega_body, q=None, line_of_sight=None) -> dict:
    """The radiation observables of states of ``body`` under ``model``, in the body's units.

    omega_body (N, 3) body frame (rad/s for "cgs" bodies, 1/tau0 for dimensionless ones); q (N, 4)
    (w, x, y, z) or None.  Returns {name: (dims, values, attrs)} ready for ``xarray.Dataset``:
    the invariants power (Larmor), power_precession_averaged (symmetric tops), energy,
    schott_energy and work (= dE/dt) always; with q the world-frame vectors dipole, dipole_dot,
    dipole_ddot, dipole_dddot, flux_2_4a, schott_2_4b, torque (= dL/dt) and L; with q and a
    ``line_of_sight`` (world) the far field's two polarizations (E R, on u1, u2 of
    ``polarization_basis``) and the power per solid angle toward it.
    """
    s = body.system(model)
    tau0, I1, cgs = body.tau0, body.I1, body.units == "cgs"
    w = U.omega_to_dimensionless(np.atleast_2d(omega_body), tau0)
    b = balance(model, w, s.inertia, s.coupling)

    def conv(x, kind):
        return U.radiation_from_dimensionless(x, kind, I1, tau0)

    def attrs(kind, name):
        return {"units": U.radiation_unit(kind, body.units), "long_name": name}

    out = {
        "power": (("time",), conv(b.power, "power"), attrs("power", "Larmor power (2/3c^3)|d_ddot|^2, instantaneous")),
        "energy": (("time",), conv(b.energy, "energy"), attrs("energy", "kinetic energy 1/2 Omega.I Omega")),
        "schott_energy": (("time",), conv(b.schott_energy, "energy"),
                          attrs("energy", "Schott energy (2/3c^3) d_dot.d_ddot")),
        "work": (("time",), conv(b.work, "power"), attrs("power", "dE/dt = Omega.N, the model's torque times Omega")),
    }
    if body.is_symmetric:
        out["power_precession_averaged"] = (("time",), conv(precession_averaged_power(model, w, s.inertia, s.coupling),
                                                            "power"),
                                            attrs("power", "Larmor power averaged over the free precession"))
    if q is None:
        return out
    q = np.atleast_2d(np.asarray(q, dtype=float))
    d = body.dipole_magnitude if cgs else 1.0
    g = np.broadcast_to(np.asarray(s.coupling), w.shape)
    dip_unit = U.DIPOLE_UNITS if cgs else ("|d|", "|d|/tau0", "|d|/tau0^2", "|d|/tau0^3")
    names = ("dipole", "dipole_dot", "dipole_ddot", "dipole_dddot")
    for k, (name, vec) in enumerate(zip(names, (g, b.b1, b.b2, b.b3))):
        out[name] = (("time", "xyz"), d * world_from_body(q, vec) / tau0**k,
                     {"units": dip_unit[k], "long_name": f"space-frame dipole, derivative {k} (world frame)"})
    # the saved names ("torque", "L", ...) stay as they are in files written before; their
    # long_name says the frame
    for name, vec, kind, long in (("flux_2_4a", b.flux_body, "torque", "-(2/3c^3) d_dot x d_ddot, (2.4a)"),
                                  ("schott_2_4b", b.schott_body, "torque", "d/dt (2/3c^3) d x d_ddot, (2.4b)"),
                                  ("torque", b.torque_body, "torque", "dL/dt of the model (world frame)"),
                                  ("L", b.L_body, "angular_momentum", "angular momentum (world frame)")):
        out[name] = (("time", "xyz"), conv(world_from_body(q, vec), kind), attrs(kind, long))
    if line_of_sight is not None:
        n, u1, u2 = polarization_basis(line_of_sight)
        ddot = out["dipole_ddot"][1]
        c2 = U.C_LIGHT**2 if cgs else 1.0
        out["field"] = (("time", "polarization"), far_field(ddot, n) / c2,
                        {"units": "statV" if cgs else "|d|/tau0^2 (c = 1)",
                         "long_name": "far field times distance, E R = (d_ddot x n) x n / c^2, on u1, u2",
                         "line_of_sight": n.tolist(), "u1": u1.tolist(), "u2": u2.tolist()})
        out["power_per_sr"] = (("time",), conv(power_per_sr(world_from_body(q, b.b2), n), "power_per_sr"),
                               attrs("power_per_sr", "dP/dOmega toward the line of sight"))
    return out
