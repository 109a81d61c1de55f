"""``decide`` with what must be known and what the trap does (``analysis.nuisance``): the same
trials, records and decision as ``analysis.decide``, with each trial's nuisances drawn from
their priors, the gas's walk, the clock and the field in the records, and a likelihood that
profiles the nuisances and carries the random parts in its covariance.

One trial, each model the truth in turn (``decide``'s steps, with):

1. beyond the start: the true tau0, gain slope, pressure (so the drag gamma and the walk's
   rate) and field geometry (E's direction and the antenna's azimuth about L), drawn from the
   priors; the gas's line at the start (``nuisance.gas_line``: quadrature and a pool of single
   collisions);
2. the records: the line at the 8 nodes of each record is the model's closed form with the drag
   (a change of time), plus the field's shift, the gas's collisions -- the located ones' jumps
   (``nuisance.located_jumps``), then the walk (exact collisions, or their Gaussian sum where
   many) -- times (1 + the clock's error); the power toward the antenna gets the share as L
   precesses about E and the gain slope; merged as ``decide`` merges them;
3. each model's fit: least squares on the records whitened by the Cholesky factor of their
   covariance (``nuisance.covariance``: measurement noise, the walk at the stated pressure, the
   clock, the share), over the start, ln tau0 (with its prior) and ln gamma (with the pressure's
   prior), the linear nuisances -- the power's constant, the gain's exponent, the field's
   shift kappa, each located collision's jump -- profiled in closed form with their priors
   (none for the jumps) at every step;
4. Z = sqrt(chi2_other - chi2_true), priors' penalties included; the decision time by bisection
   over the records as in ``decide`` (the records' covariance is Markov in time, so the first n
   records' whitening is the leading block of the whole: one factorisation a trial).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import units as U
from ..physics import models as M
from . import decide as DC
from . import nuisance as NU
from . import receiver as RC


@dataclass
class Truth:
    """A trial's true nuisances (step 1)."""

    tau0: float
    slope: float                 # the gain's exponent G
    factor: float                # the true pressure over the stated one
    kappa: float                 # Hz^2: the field's line shift is kappa cos(theta_L) / f
    line: object                 # nuisance.GasLine at the stated pressure, or None
    n_hat: np.ndarray            # the antenna's direction, in L's frame (L along z)
    e_hat: np.ndarray            # the field's direction, in L's frame
    field_rate: float            # d_par |E| / (2 pi I1): Omega_p = field_rate cos(theta_L) / f (rad/s)
    jump_t: np.ndarray = None    # the located collisions' instants (s) and the line's jumps (Hz)
    jump_v: np.ndarray = None
    t_switch: float = 0.0        # after it, the gas's smooth drag and its walk; before it, the located jumps alone

    @property
    def gamma(self) -> float:
        """The true drag of |L|, 1/s."""
        return 0.0 if self.line is None else self.factor * self.line.gamma


def _iso(rng) -> np.ndarray:
    v = rng.standard_normal(3)
    return v / np.linalg.norm(v)


def draw_truth(setup: DC.Setup, start: DC.Start, rng) -> Truth:
    """Step 1: the nuisances' true values, from the priors (``Nuisances``)."""
    nu = setup.nuisance
    tau0 = setup.tau0 * (math.exp(nu.tau0_width * rng.standard_normal()) if nu.tau0_width > 0 else 1.0)
    slope = nu.gain_width * rng.standard_normal() if nu.gain_slope_db > 0 else 0.0
    factor = math.exp(nu.pressure_width * rng.standard_normal()) if nu.gas is not None else 1.0
    ca = start.cos_alpha
    az = rng.uniform(0.0, 2.0 * math.pi)
    sa = math.sqrt(max(0.0, 1.0 - ca * ca))
    n_hat = np.array([sa * math.cos(az), sa * math.sin(az), ca])
    e_hat = _iso(rng)
    d = np.asarray(nu.dipole, dtype=float)
    d_par = float(np.linalg.norm(d))
    I1 = float(nu.inertia[0]) if nu.inertia else 1.0
    kappa = d_par * nu.field * float(e_hat[2]) / (4.0 * math.pi**2 * I1)
    line = None
    jump_t, jump_v, t_switch = np.zeros(0), np.zeros(0), 0.0
    if nu.gas is not None:
        omega = NU.start_omega(d, setup.epsilon, start.u0, start.b0, rng.uniform(0.0, 2.0 * math.pi))
        line = NU.gas_line(nu, omega, np.random.default_rng(rng.integers(2**63)))
        jump_t, jump_v, t_switch = NU.located_jumps(line, factor, setup.integration_s, setup.horizon, rng)
    return Truth(tau0=tau0, slope=slope, factor=factor, kappa=kappa, line=line, n_hat=n_hat, e_hat=e_hat,
                 field_rate=d_par * nu.field / (2.0 * math.pi * I1), jump_t=jump_t, jump_v=jump_v, t_switch=t_switch)


def _line(model: str, t, w0, share, tau0, gamma, t_switch: float = 0.0):
    """(f, y, cos theta_L) at times t of ``model``'s line with the drag gamma from ``t_switch`` on
    (a change of time, ``nuisance``; before it the located collisions stand for the gas): f (Hz),
    y = ln(Omega_perp^2 omega_L^2); complex parameters allowed."""
    law = M.get(model).line
    u0, b0 = share * w0, (1.0 - share) * w0
    if np.iscomplexobj(gamma) or gamma != 0.0:
        if t_switch > 0.0:
            u0, b0 = law.state(t_switch, u0, b0, tau0)
        dt = np.maximum(t - t_switch, 0.0)
        s = -np.expm1(-2.0 * gamma * dt) / (2.0 * gamma)
        decay = np.exp(-2.0 * gamma * dt)
        u, b = law.state(s, u0, b0, tau0)
        if t_switch > 0.0:                       # before the switch: the radiation alone
            early = t < t_switch
            ue, be = law.state(t, share * w0, (1.0 - share) * w0, tau0)
            u, b = np.where(early, ue, u), np.where(early, be, b)
            decay = np.where(early, 1.0, decay)
    else:
        u, b = law.state(t, u0, b0, tau0)
        decay = 1.0
    u, b = u * decay, b * decay
    w2 = u + b
    return np.sqrt(w2) / (2.0 * math.pi), np.log(u) + np.log(w2), np.sqrt(b / w2)


@dataclass
class RecordsEnv:
    """A trial's detected records (``decide.Records``' fields) and the fit's fixed parts: the
    Cholesky factor ``chol`` of their covariance (interleaved f, y), the measured ln f of each
    record (the gain's column), and the field's prior width (Hz^2) and the pressure's."""

    end: np.ndarray
    t: np.ndarray
    weight: np.ndarray
    f: np.ndarray
    y: np.ndarray
    sf: np.ndarray
    sy: np.ndarray
    chol: np.ndarray
    lnf: np.ndarray
    jumps: np.ndarray = None          # (R, K): each record's weight after each located collision
    jump_t: np.ndarray = None         # their instants (s)
    t_switch: float = 0.0

    def __post_init__(self):
        from scipy.linalg import solve_triangular

        # the inverse factor: its leading blocks whiten the first records (a lower triangle's inverse)
        n = self.chol.shape[0]
        self.white = (solve_triangular(self.chol, np.eye(n), lower=True, check_finite=False) if n else self.chol)
        self._fixed: dict = {}

    def fixed_columns(self, n: int, gain: bool) -> tuple[np.ndarray, int]:
        """The whitened columns of the power's constant (and the gain's exponent, and each
        located collision's jump of the line, 4 / f of it in the power) on the first n records,
        (2n, m), and how many of them have a prior (the gain's: it comes second)."""
        key = (n, gain)
        if key not in self._fixed:
            one = np.zeros(2 * n)
            one[1::2] = 1.0
            cols = [one]
            if gain:
                g = np.zeros(2 * n)
                g[1::2] = self.lnf[:n]
                cols.append(g)
            if self.jumps is not None and self.jumps.shape[1]:
                # collisions between the same two nodes are seen as one jump (their sum), one before
                # the first record is part of the start: each distinct, informative column once
                part = np.round(self.jumps[:n], 12)
                keep = np.any(part > 0.0, axis=0) & np.any(part < 1.0, axis=0)
                for col in np.unique(part[:, keep], axis=1).T:
                    c = np.zeros(2 * n)
                    c[0::2] = col
                    c[1::2] = 4.0 * col / self.f[:n]
                    cols.append(c)
            self._fixed[key] = self.white[:2 * n, :2 * n] @ np.stack(cols, axis=1)
        return self._fixed[key]


def observe_env(setup: DC.Setup, start: DC.Start, truth_model: str, tr: Truth, rng) -> RecordsEnv:
    """Step 2: the records a receiver makes of ``truth_model`` with the trial's nuisances."""
    nu = setup.nuisance
    edges = setup.edges()
    t, w = DC._nodes(edges)
    f_det, y_shape, cos = _line(truth_model, t, start.w0, start.share, tr.tau0, tr.gamma, tr.t_switch)
    tn, fn = t.reshape(-1), f_det.reshape(-1)
    f0 = float(fn[0])
    walk = np.zeros_like(fn)
    if tr.line is not None:
        walk = NU.gas_walk(tn, fn, f0, tr.line, tr.factor, rng, tr.t_switch)
        if tr.jump_t.size:                   # the located collisions: their jumps, uncompensated (the drag is theirs)
            walk = walk + (tn[:, None] > tr.jump_t[None, :]) @ tr.jump_v
    clock = NU.clock_path(tn, nu.clock, nu.clock_time, rng) if nu.clock > 0 else np.zeros_like(fn)
    walk, clock = walk.reshape(t.shape), clock.reshape(t.shape)
    f_true = f_det + tr.kappa * cos / f_det + walk + f_det * clock
    share = _share(tr, tn, fn, cos.reshape(-1), start).reshape(t.shape)
    gain = np.exp(tr.slope * np.log(f_det / nu.f_ref))
    y_true = y_shape + 4.0 * walk / f_det
    power_sr = setup.larmor * np.exp(y_true) * 3.0 / (8.0 * math.pi) * share
    S = power_sr * setup.area(f_det) * gain / setup.distance_cm**2
    energy = np.sum(S * w, axis=1)
    rho = 2.0 * energy / setup.noise_density
    weight = S * w / np.where(energy > 0, energy, 1.0)[:, None]
    fbar = np.sum(weight * f_true, axis=1)
    ybar = np.sum(weight * (y_true + np.log(share) + tr.slope * np.log(f_det / nu.f_ref)), axis=1)
    tm = np.sum(weight * t, axis=1)
    fm, _, _ = _line(truth_model, tm, start.w0, start.share, tr.tau0, tr.gamma, tr.t_switch)
    u, b = M.get(truth_model).line.state(tm, start.u0, start.b0, tr.tau0)
    rate, accel = M.get(truth_model).line.drift(u, b, tr.tau0)
    fdot, fddot = (rate - tr.gamma) * fm, accel * fm
    t_coh = RC.coherent_interval(fdot, fddot, setup.integration_s, setup.bandwidth_hz)
    rho_c = 2.0 * energy / (edges[1:] - edges[:-1]) * t_coh / setup.noise_density
    ok = (rho_c >= RC.detection_threshold(setup.bandwidth_hz * t_coh)) & (setup.distance_cm >= U.C_LIGHT / f_det[:, -1])
    with np.errstate(divide="ignore"):
        sf = RC.crb_tone(rho, t_coh)
        sy = 2.0 / np.sqrt(rho)
    noise = rng.standard_normal((2, edges.size - 1))
    fm_obs = fbar + sf * noise[0]
    ym_obs = ybar + sy * noise[1]
    chol = _whitening(setup, t[ok], w[ok], fm_obs[ok], sf[ok], sy[ok], tn, fn, f0, tr)
    jumps = None
    if tr.jump_t is not None and tr.jump_t.size:
        jumps = np.einsum("ja,jak->jk", weight[ok], (t[ok][:, :, None] > tr.jump_t[None, None, :]).astype(float))
    return RecordsEnv(end=edges[1:][ok], t=t[ok], weight=weight[ok], f=fm_obs[ok], y=ym_obs[ok], sf=sf[ok], sy=sy[ok],
                      chol=chol, lnf=np.log(fm_obs[ok] / nu.f_ref), jumps=jumps,
                      jump_t=tr.jump_t if jumps is not None else None, t_switch=tr.t_switch)


def _share(tr: Truth, tn, fn, cos, start) -> np.ndarray:
    """The antenna's share of the power, (1 + (n . L_hat)^2) / 2, at the nodes, L precessing
    about E by the angle int Omega_p dt (constant without a field)."""
    if tr.field_rate == 0.0:
        ca = start.cos_alpha
        return np.full(tn.shape, 0.5 * (1.0 + ca * ca))
    rate = tr.field_rate * cos / fn
    tt = np.concatenate([[0.0], tn])
    rr = np.concatenate([[rate[0]], rate])
    phase = np.cumsum(0.5 * (rr[1:] + rr[:-1]) * np.diff(tt))
    e = tr.e_hat
    L0 = np.array([0.0, 0.0, 1.0])
    par = float(e @ L0)
    perp = L0 - par * e
    cross = np.cross(e, L0)
    L = par * e[None, :] + np.cos(phase)[:, None] * perp[None, :] + np.sin(phase)[:, None] * cross[None, :]
    c = L @ tr.n_hat
    return 0.5 * (1.0 + c * c)


def _whitening(setup, t, w, f_rec, sf, sy, tn_all, fn_all, f0, tr: Truth) -> np.ndarray:
    """The Cholesky factor of the detected records' covariance (``nuisance.covariance``), from
    the stated values (the fit does not know the trial's truths)."""
    nu = setup.nuisance
    Q = None
    if tr.line is not None:
        # the walk's intensity along the whole run (undetected stretches included), from the
        # measured line where there is one
        f_at = np.interp(tn_all, t.reshape(-1), np.repeat(f_rec, t.shape[1])) if f_rec.size else fn_all
        Q_all = NU.cumulative_intensity(tn_all, f_at, f0, tr.line.q, tr.line.k_q, tr.t_switch)
        Q = np.interp(t.reshape(-1), tn_all, Q_all)
    share_rate = tr.field_rate / max(float(f_rec[0]), 1e-300) if (tr.field_rate > 0 and f_rec.size) else 0.0
    C = NU.covariance(t, w, f_rec, sf, sy, nu, Q, share_rate)
    return np.linalg.cholesky(C) if C.size else C


# --- the fits --------------------------------------------------------------------------------------
def _layout(setup: DC.Setup, tr: Truth | None = None):
    """Which nonlinear parameters the fits carry: (k, tau0 index or None, gamma index or None);
    the drag only where the gas walks (after the located collisions)."""
    nu = setup.nuisance
    k = 2
    i_tau = i_gam = None
    if setup.tau0_mode == "fitted" or nu.tau0_width > 0:
        i_tau, k = k, k + 1
    if nu.gas is not None and (tr is None or tr.t_switch < setup.horizon):
        i_gam, k = k, k + 1
    return k, i_tau, i_gam


def _apply(W, v):
    """W v for a real matrix and a real or complex vector (a complex product would copy W to
    complex at every call)."""
    if np.iscomplexobj(v):
        return W @ v.real + 1j * (W @ v.imag)
    return W @ v


def _residuals(setup, model, x, rec: RecordsEnv, n: int, ref: DC.Start, tr: Truth, layout):
    """The whitened, profiled residuals of ``model`` on the first ``n`` records (step 3)."""
    nu = setup.nuisance
    k, i_tau, i_gam = layout
    w0 = ref.w0 * np.exp(x[0])
    tau0 = setup.tau0 * (np.exp(x[i_tau]) if i_tau is not None else 1.0)
    gamma = (tr.line.gamma * np.exp(x[i_gam])) if i_gam is not None else 0.0
    t, wt = rec.t[:n], rec.weight[:n]
    f, y, cos = _line(model, t, w0, x[1], tau0, gamma, rec.t_switch)
    fb, yb = np.sum(wt * f, axis=1), np.sum(wt * y, axis=1)
    r = np.empty(2 * n, dtype=np.result_type(fb, float))
    r[0::2], r[1::2] = rec.f[:n] - fb, rec.y[:n] - yb
    Wn = rec.white[:2 * n, :2 * n]
    z = _apply(Wn, r)
    gain = nu.gain_slope_db > 0
    A = rec.fixed_columns(n, gain)
    widths = [math.inf] + ([nu.gain_width] if gain else []) + [math.inf] * (A.shape[1] - 1 - int(gain))
    if nu.field > 0 and tr.field_rate > 0:
        kc = np.zeros(2 * n, dtype=np.result_type(cos, float))
        kc[0::2] = np.sum(wt * cos / f, axis=1)
        A = np.concatenate([A, _apply(Wn, kc)[:, None]], axis=1)
        widths.append(tr.field_rate / (2.0 * math.pi * math.sqrt(3.0)))     # kappa's isotropic RMS
    prior = np.array([0.0 if math.isinf(s) else 1.0 / (s * s) for s in widths])
    G = A.T @ A + np.diag(prior)
    G += np.diag(1e-12 * np.diag(G))                 # a ridge far below the data: nearly collinear jumps stay solvable
    beta = np.linalg.solve(G, A.T @ z)
    out = [z - A @ beta, np.sqrt(prior) * beta]
    if i_tau is not None and nu.tau0_width > 0 and setup.tau0_mode != "fitted":
        out.append(np.atleast_1d(x[i_tau] / nu.tau0_width))
    if i_gam is not None:
        out.append(np.atleast_1d(x[i_gam] / nu.pressure_width))
    return np.concatenate([np.asarray(o) for o in out])


def fit(setup, model, rec: RecordsEnv, n: int, ref: DC.Start, tr: Truth, starts) -> tuple[float, np.ndarray]:
    """(chi2, x) of ``model``'s best fit to the first ``n`` records from the starting points."""
    from scipy.optimize import least_squares

    layout = _layout(setup, tr)
    k = layout[0]

    def fun(x):
        return _residuals(setup, model, x, rec, n, ref, tr, layout).real

    def jac(x):
        h = 1e-30
        cols = []
        for i in range(k):
            z = np.asarray(x, dtype=complex).copy()
            z[i] += 1j * h
            cols.append(_residuals(setup, model, z, rec, n, ref, tr, layout).imag / h)
        return np.stack(cols, axis=1)

    lo = np.array([-np.inf, 1e-12] + [-np.inf] * (k - 2))
    hi = np.array([np.inf, 1.0] + [np.inf] * (k - 2))
    best = (math.inf, None)
    for x0 in starts:
        x0 = np.clip(np.resize(np.asarray(x0, dtype=float), k), lo, hi)
        x0[1] = min(max(x0[1], 1e-9), 1.0)
        try:
            r = least_squares(fun, x0, jac=jac, bounds=(lo, hi), x_scale="jac", method="trf", xtol=1e-14, ftol=1e-12,
                              gtol=1e-12, max_nfev=200)
        except (ValueError, FloatingPointError, np.linalg.LinAlgError):
            continue
        chi2 = float(2.0 * r.cost)
        if np.isfinite(chi2) and chi2 < best[0]:
            best = (chi2, r.x)
    return best


def z_at(setup, rec: RecordsEnv, n: int, truth: str, start: DC.Start, tr: Truth, warm: dict) -> float:
    """Z of ``truth`` against the other model on the first ``n`` records (step 4)."""
    first, second = setup.models
    other = second if truth == first else first
    k = _layout(setup, tr)[0]
    x_true = np.zeros(k)
    x_true[1] = start.share
    across = x_true.copy()
    across[1] = 1.0
    chi = {}
    for m, starts in ((truth, [warm.get(truth, x_true), x_true]), (other, [warm.get(other, x_true), x_true, across])):
        chi[m], x = fit(setup, m, rec, n, start, tr, starts)
        if x is not None:
            warm[m] = x
    d = chi[other] - chi[truth]
    return math.copysign(math.sqrt(abs(d)), d) if math.isfinite(d) else 0.0


def decision_time(setup, rec: RecordsEnv, truth: str, start: DC.Start, tr: Truth) -> tuple[float, float]:
    """(T*, Z at the horizon), as ``decide.decision_time``."""
    n = rec.end.size
    if n < DC.FEWEST:
        return math.inf, 0.0
    warm: dict = {}
    z_end = z_at(setup, rec, n, truth, start, tr, warm)
    if z_end < DC.DECISION_Z or setup.nuisance.horizon_only:
        return (math.inf if z_end < DC.DECISION_Z else float(rec.end[-1])), z_end
    lo, hi = DC.FEWEST, n
    zs = {n: z_end}
    z_lo = z_at(setup, rec, lo, truth, start, tr, dict(warm))
    if z_lo >= DC.DECISION_Z:
        return float(rec.end[lo - 1]), z_end
    zs[lo] = z_lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        zs[mid] = z_at(setup, rec, mid, truth, start, tr, warm)
        lo, hi = (mid, hi) if zs[mid] < DC.DECISION_Z else (lo, mid)
    t0, t1 = rec.end[lo - 1], rec.end[hi - 1]
    z0, z1 = zs[lo], zs[hi]
    frac = (DC.DECISION_Z - z0) / (z1 - z0) if z1 > z0 else 1.0
    return float(math.exp(math.log(t0) + frac * (math.log(t1) - math.log(t0)))), z_end


def run_trials(setup: DC.Setup, seed: int, indices) -> list[dict]:
    """``decide.run_trials`` with the nuisances (module docstring): the same starts, seeds and
    rows (plus each trial's true nuisances)."""
    seqs = np.random.SeedSequence(seed).spawn(max(indices) + 1)
    out = []
    for i in indices:
        rng = np.random.default_rng(seqs[i])
        start = DC.draw_start(setup, rng)
        tr = draw_truth(setup, start, rng)
        row = {"trial": int(i), "u0": start.u0, "b0": start.b0, "cos_alpha": start.cos_alpha,
               "truth": {"tau0_ratio": tr.tau0 / setup.tau0, "gain_exponent": tr.slope, "pressure_ratio": tr.factor,
                         "gamma": tr.gamma, "kappa": tr.kappa}}
        for truth in setup.models:
            rec = observe_env(setup, start, truth, tr, rng)
            t_star, z_end = decision_time(setup, rec, truth, start, tr)
            row[truth] = {"t": t_star, "z_end": z_end, "records": int(rec.end.size)}
        out.append(row)
    return out
