"""What must be known to decide, and what the trap adds to the line: the nuisances of
``decide`` with their stated priors, each trial's draw of their true values, and the
covariance of the record estimates they make (the state-space part of the likelihood).

The nuisances (``Nuisances``), each with its prior and how it enters:

* tau0: log-normal about the body's, relative width ``tau0_width`` (0: known exactly);
  the true tau0 of a trial is drawn from it, the fit profiles ln tau0 with the prior;
* the antenna's gain slope: Gaussian, ``gain_slope_db`` dB per octave (1 sigma) about flat;
  the received power gains (f / f_ref)^G, G = slope / (10 log10 2); the fit profiles G;
* the reference clock: its fractional frequency error is a stationary Gauss-Markov process of
  standard deviation ``clock`` and correlation time ``clock_time`` (a reference stable to that
  over seconds to ``clock_time``, averaging down beyond); it multiplies the measured line;
* the gas: its pressure log-normal about the stated one, relative width ``pressure_width``.
  Its mean drag brakes |L| at gamma (``gas_line``: the gas's quadrature along L at the start),
  which enters the line's closed forms exactly as a change of time for a drag linear in Omega
  and the same for every component (a sphere-like top): with s = (1 - exp(-2 gamma t)) / 2
  gamma, (u, b)(t) = exp(-2 gamma t) (u, b)_radiation(s) (from the last located collision on,
  below); the fit profiles ln gamma.  Its
  collisions make the line walk: each changes |L| by L_hat . J, so the line jumps by
  L_hat . J / (2 pi I1).  Where they come rarely (fewer than ``RESOLVE_RATE`` an integration)
  each jump -- hundreds of Hz on the DAST cube's 7 GHz line, against a resolution of ~10 mHz --
  stands out of the 1 s estimates: an analysis locates it there and fits its size, so the
  first ``N_LOCATED`` are located (told to the fit by their instants) and the smooth drag
  starts only after them; the rest, and all of them where they come often, make the line's
  compensated walk, a random walk of intensity q = rate E[(L_hat . J)^2] / (2 pi I1)^2 (Hz^2/s,
  the mean squared included);
* a static field of the stated size, its direction unknown (isotropic): L precesses about E at
  Omega_p = d_par cos(theta_L) |E| / |L|, which moves the line by Omega_p (E_hat . L_hat) / 2 pi
  (``kappa cos(theta_L) / f``, kappa = d_par |E| (E_hat . L_hat) / 4 pi^2 I1: the fit profiles
  kappa, Gaussian of its isotropic RMS) and turns the antenna's share of the power as L
  sweeps its cone (ln share: a stationary process of variance ``SHARE_VARIANCE``, correlation
  time 1 / Omega_p).

Profiled, not marginalised: each nuisance is a parameter of the fit, with its prior as a
penalty term (the maximum of the posterior); Z is the likelihood ratio of the two models'
profiles.  The random parts (the gas's walk, the clock, the share) are not parameters: they
are Gaussian processes whose covariance enters the likelihood -- the Kalman filter's
likelihood of the records, computed in one piece (``covariance``: its Cholesky factor
whitens the residuals exactly as the filter's innovations do, ``kalman_loglike`` checks it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

CLOCK_TIME = 100.0               # s: the clock's correlation time (stable over seconds to this, averaging beyond)
SHARE_VARIANCE = 0.0372          # mean over isotropic E, antenna and L of the variance of ln((1 + cos^2)/2) over a precession
GAIN_PER_DB_OCTAVE = 1.0 / (10.0 * math.log10(2.0))     # the exponent G of (f/f_ref)^G per dB per octave
POOL = 2048                      # single collisions drawn per trial: the distribution of the line's jumps
EXACT_PER_STEP = 64              # collisions between two nodes drawn one by one; more: their Gaussian sum
RESOLVE_RATE = 0.2               # collisions an integration below which each is located in the 1 s estimates
N_LOCATED = 64                   # the located collisions an analysis profiles one by one; after them, a walk


@dataclass(frozen=True)
class Nuisances:
    """The stated priors (module docstring) and the trap: ``gas`` (``physics.gas.Gas`` at the
    stated pressure, or None), ``surface`` (``physics.surface.Surface``), the body's inertia
    (g cm^2) and dipole (statC cm, body frame), the field's size ``field`` (statV/cm), the gain's
    reference frequency ``f_ref`` (Hz); ``horizon_only``: only whether each trial decides within
    the horizon (``requirements``), not when."""

    tau0_width: float = 0.0
    gain_slope_db: float = 0.0
    clock: float = 0.0
    clock_time: float = CLOCK_TIME
    pressure_width: float = 1.0
    gas: object = None
    surface: object = None
    inertia: tuple = ()
    dipole: tuple = ()
    field: float = 0.0
    f_ref: float = 1.0
    horizon_only: bool = False

    @property
    def active(self) -> bool:
        """Anything beyond the perfect, perfectly known experiment."""
        return (self.tau0_width > 0.0 or self.gain_slope_db > 0.0 or self.clock > 0.0 or self.gas is not None
                or self.field > 0.0)

    @property
    def gain_width(self) -> float:
        """1 sigma of the gain's exponent G."""
        return self.gain_slope_db * GAIN_PER_DB_OCTAVE

    def record(self) -> dict:
        """The priors as plain numbers (JSON)."""
        from .. import units as U

        return {"tau0_relative_width": self.tau0_width, "gain_slope_db_per_octave": self.gain_slope_db,
                "clock_fractional_stability": self.clock, "clock_correlation_s": self.clock_time,
                "pressure_mbar": (self.gas.pressure / U.DYN_PER_CM2_IN_MBAR) if self.gas is not None else 0.0,
                "pressure_relative_width": self.pressure_width,
                "field_v_per_m": self.field * U.STATV_PER_CM_IN_V_PER_M, "treatment": "profiled (priors as penalties)"}


# --- the gas along the line -----------------------------------------------------------------------
@dataclass(frozen=True)
class GasLine:
    """The gas's effect on the line at a trial's start (at the stated pressure): ``gamma`` the
    drag of |L| (1/s), ``rate`` collisions per s, ``q`` the walk's intensity (Hz^2/s), and their
    exponents against the line's frequency (``k_gamma``, ``k_rate``, ``k_q``: x ~ f^k), from the
    gas's quadrature at the start's Omega and at half of it; ``jumps`` (POOL,) the line's jumps of
    single collisions drawn at the start (Hz)."""

    gamma: float
    rate: float
    q: float
    k_gamma: float
    k_rate: float
    k_q: float
    jumps: np.ndarray


def start_omega(body_dipole, epsilon: float, u0: float, b0: float, azimuth: float) -> np.ndarray:
    """A start's body-frame Omega (rad/s) from (u0, b0) = (Omega_perp^2, eps^2 Omega_par^2) about
    the dipole and the azimuth of Omega_perp about it."""
    d = np.asarray(body_dipole, dtype=float)
    d = d / np.linalg.norm(d)
    a = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(d, a)
    return math.sqrt(b0) / epsilon * d + math.sqrt(u0) * (math.cos(azimuth) * a + math.sin(azimuth) * b)


def gas_line(nu: Nuisances, omega, rng) -> GasLine:
    """The gas along the line at body-frame Omega (rad/s), at the stated pressure."""
    from ..integrators.collisions import Collider
    from ..physics.gas import GasModel

    model = GasModel(nu.gas, nu.surface, tuple(nu.inertia))
    inertia = np.asarray(nu.inertia, dtype=float)
    two_pi_I1 = 2.0 * math.pi * float(inertia[0])

    def along(w):
        rate, N, Q = model.moments(w)
        L = inertia * w
        Lh = L / np.linalg.norm(L)
        return -float(Lh @ N) / float(np.linalg.norm(L)), rate, float(Lh @ Q @ Lh) / two_pi_I1**2

    g1, r1, q1 = along(np.asarray(omega, dtype=float))
    g2, r2, q2 = along(0.5 * np.asarray(omega, dtype=float))
    k = lambda a, b: math.log(a / b) / math.log(2.0) if a > 0 and b > 0 else 0.0     # noqa: E731
    J = Collider(nu.gas, nu.surface, rng).many(omega, POOL)
    L = inertia * np.asarray(omega, dtype=float)
    jumps = (J @ (L / np.linalg.norm(L))) / two_pi_I1
    return GasLine(gamma=g1, rate=r1, q=q1, k_gamma=k(g1, g2), k_rate=k(r1, r2), k_q=k(q1, q2), jumps=jumps)


def located_jumps(line: GasLine, factor: float, integration_s: float, horizon: float, rng):
    """The collisions an analysis locates one by one in the 1 s estimates: where they come rarely
    (fewer than ``RESOLVE_RATE`` an integration) the first ``N_LOCATED`` of them, their instants
    (s) and the line's jumps (Hz, drawn from the pool), and the instant after which the rest are
    a random walk (the horizon when all are located); where they come often, none and 0."""
    rate = factor * line.rate
    if not rate * integration_s < RESOLVE_RATE:
        return np.zeros(0), np.zeros(0), 0.0
    times = np.cumsum(rng.exponential(1.0 / rate, N_LOCATED)) if rate > 0 else np.full(N_LOCATED, np.inf)
    times = times[times < horizon]
    t_switch = float(times[-1]) if times.size == N_LOCATED else float(horizon)
    return times, rng.choice(line.jumps, times.size), t_switch


def gas_walk(t_nodes, f_nodes, f0: float, line: GasLine, factor: float, rng, t_switch: float = 0.0) -> np.ndarray:
    """The gas's compensated walk of the line (Hz) at increasing node times ``t_nodes`` (M,)
    from ``t_switch`` on (before it the located jumps stand alone): between nodes a Poisson
    number of collisions at the rate ``factor`` x line.rate (f/f0)^k_rate, each a jump drawn
    from the pool scaled by (f/f0)^((k_q - k_rate)/2), less their mean; past
    ``EXACT_PER_STEP`` collisions the Gaussian of the same variance."""
    t = np.asarray(t_nodes, dtype=float)
    f = np.asarray(f_nodes, dtype=float)
    prev = np.concatenate([[0.0], t[:-1]])
    dt = np.maximum(0.0, t - np.maximum(prev, t_switch))
    ratio = np.maximum(f / f0, 1e-300)
    mu = factor * line.rate * ratio**line.k_rate * dt
    scale = ratio ** (0.5 * (line.k_q - line.k_rate))
    pool = line.jumps
    m1, m2 = float(np.mean(pool)), float(np.mean(pool * pool))
    counts = rng.poisson(mu)
    steps = np.empty(t.size)
    for i in range(t.size):
        if counts[i] <= EXACT_PER_STEP:
            steps[i] = float(np.sum(rng.choice(pool, counts[i])) - mu[i] * m1) if counts[i] else -mu[i] * m1
        else:
            steps[i] = rng.standard_normal() * math.sqrt(mu[i] * m2)
        steps[i] *= scale[i]
    return np.cumsum(steps)


def clock_path(t_nodes, sigma: float, tau: float, rng) -> np.ndarray:
    """The clock's fractional frequency error at increasing node times: a stationary Gauss-Markov
    (Ornstein-Uhlenbeck) process of standard deviation ``sigma`` and correlation time ``tau``."""
    t = np.asarray(t_nodes, dtype=float)
    out = np.empty(t.size)
    y = sigma * rng.standard_normal()
    prev = 0.0
    for i, ti in enumerate(t):
        a = math.exp(-(ti - prev) / tau)
        y = a * y + sigma * math.sqrt(max(0.0, 1.0 - a * a)) * rng.standard_normal()
        out[i] = y
        prev = ti
    return out


# --- the covariance of the records ------------------------------------------------------------------
def _pairs(w, K):
    """W K W^T of node kernel K (M, M) over records of nodes: w (R, NODES) the records'
    weights, nodes in record order."""
    R, n = w.shape
    Kr = K.reshape(R, n, R, n)
    return np.einsum("ja,jakb,kb->jk", w, Kr, w)


def covariance(t, w, f_rec, sf, sy, nu: Nuisances, walk_Q, share_rate: float) -> np.ndarray:
    """The covariance (2R, 2R) of a trial's record estimates, interleaved (f_1, y_1, f_2, ...):
    measurement noise (sf, sy), the gas's walk (node kernel Q(min(t, t')), Hz^2, ``walk_Q`` at
    the nodes), the clock (sigma^2 f f' exp(-|t - t'| / tau)) and the antenna's share under the
    field's precession (``SHARE_VARIANCE`` exp(-|t - t'| share_rate)); the power's walk is
    4 / f times the line's.  t, w (R, NODES) the records' nodes and weights."""
    R = t.shape[0]
    tn = t.reshape(-1)
    ff = np.diag(sf * sf)
    yy = np.diag(sy * sy)
    fy = np.zeros((R, R))
    if walk_Q is not None:
        Qn = np.asarray(walk_Q, dtype=float).reshape(-1)
        rw = _pairs(w, np.minimum.outer(Qn, Qn))
        g = 4.0 / f_rec
        ff = ff + rw
        yy = yy + rw * np.outer(g, g)
        fy = rw * g[None, :]
    lag = np.abs(np.subtract.outer(tn, tn))
    if nu.clock > 0.0:
        ff = ff + _pairs(w, np.exp(-lag / nu.clock_time)) * np.outer(f_rec, f_rec) * nu.clock**2
    if share_rate > 0.0:
        yy = yy + SHARE_VARIANCE * _pairs(w, np.exp(-lag * share_rate))
    out = np.empty((2 * R, 2 * R))
    out[0::2, 0::2], out[1::2, 1::2] = ff, yy
    out[0::2, 1::2], out[1::2, 0::2] = fy, fy.T
    return out


def cumulative_intensity(t_nodes, f_nodes, f0: float, q0: float, k_q: float, t_switch: float = 0.0) -> np.ndarray:
    """Q(t) = int_t_switch^t q dt' at increasing node times (0 before t_switch), q = q0
    (f/f0)^k_q (trapezoid; Hz^2)."""
    t = np.asarray(t_nodes, dtype=float)
    q = q0 * np.maximum(np.asarray(f_nodes, dtype=float) / f0, 1e-300) ** k_q
    tt = np.maximum(np.concatenate([[0.0], t]), t_switch)
    qq = np.concatenate([[q[0]], q])
    return np.cumsum(0.5 * (qq[1:] + qq[:-1]) * np.diff(tt))


def kalman_loglike(y, t, sigma, q) -> float:
    """-2 ln L of measurements y (M,) at increasing times t of a random walk from 0 (intensity
    q, per unit time) seen with white noise sigma (M,): the scalar Kalman filter's innovations,
    sum (nu^2 / S + ln S) (the reference ``covariance``'s Cholesky form is checked against)."""
    x, P, prev, out = 0.0, 0.0, 0.0, 0.0
    for yk, tk, sk in zip(y, t, sigma):
        P += q * (tk - prev)
        S = P + sk * sk
        nu = yk - x
        out += nu * nu / S + math.log(S)
        K = P / S
        x += K * nu
        P *= 1.0 - K
        prev = tk
    return out


def from_scene(sc, tau0_width: float = 0.0, gain_slope_db: float = 0.0, clock: float = 0.0,
               pressure_width: float = 1.0, horizon_only: bool = False) -> Nuisances:
    """The nuisances of scene ``sc`` (its ``[environment]``: the gas and the field) with the
    stated priors."""
    from ..physics import longitudinal as LG

    body = sc.body
    env = sc.environment
    gas = env.gas_model()
    surface = None
    if gas is not None:
        from ..physics.surface import surface_of

        surface = surface_of(body)
    u0, b0 = LG.start_state(sc.omega0, body.dipole_direction, body.epsilon)
    return Nuisances(tau0_width=float(tau0_width), gain_slope_db=float(gain_slope_db), clock=float(clock),
                     pressure_width=float(pressure_width), gas=gas, surface=surface, inertia=tuple(body.inertia),
                     dipole=tuple(body.dipole), field=float(np.linalg.norm(env.field_cgs())),
                     f_ref=math.sqrt(u0 + b0) / (2.0 * math.pi), horizon_only=bool(horizon_only))


def describe(nu: Nuisances) -> str:
    """The priors and the trap in one line (profiled nuisances)."""
    from .. import units as U

    parts = []
    if nu.tau0_width > 0:
        parts.append(f"tau0 to {nu.tau0_width:.3g} (relative)")
    if nu.gain_slope_db > 0:
        parts.append(f"gain slope {nu.gain_slope_db:.3g} dB/octave (1 sigma)")
    if nu.clock > 0:
        parts.append(f"clock stable to {nu.clock:.3g} over seconds to {nu.clock_time:g} s")
    if nu.gas is not None:
        parts.append(f"{nu.gas.name} at {nu.gas.pressure / U.DYN_PER_CM2_IN_MBAR:.3g} mbar, {nu.gas.temperature_k:g} K "
                     f"(known to a factor e^{nu.pressure_width:g}): its drag and its collisions' walk of the line")
    if nu.field > 0:
        parts.append(f"a static field of {nu.field * U.STATV_PER_CM_IN_V_PER_M:.3g} V/m, direction unknown")
    return "; ".join(parts) + " -- profiled, priors as penalties; the walk, the clock and the field's sweep of the " \
                              "antenna's share in the records' covariance"
