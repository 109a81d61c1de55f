"""How long to watch: the observation time after which a likelihood-ratio test on a stated
receiver's noisy estimates tells the two models apart at 5 sigma in 95 % of trials, with the
start unknown.

The crystal (a top with d along its axis, or a sphere: ``physics.longitudinal``) radiates one
line; its frequency and power over time are closed forms of the start, (5.2) reduced and (5.4)
truncated.  One trial:

1. A start drawn from the stated distribution (``START``): |Omega0| log-uniform over
   ``spin_range`` times the scene's |Omega0|, its direction in the body isotropic (cos of its
   angle to d uniform), the detector's direction from L isotropic (which sets the share of the
   power toward it, (1 + cos^2 alpha)/2, and the line's linear polarization fraction
   sin^2 alpha / (1 + cos^2 alpha)), the polarization angle uniform.
2. Each model in turn is the truth.  The observation time is cut into records: [0, t_int],
   then 12 a decade up to the horizon; a record merges the receiver's one-integration estimates
   it holds (``receiver``: frequency to sqrt(12)/(2 pi T_c sqrt(rho)), power to 2/sqrt(rho),
   polarization angle to 1/(p sqrt(rho)), rho = 2/N0 times the received energy), weighted by
   their inverse variances (the received power S), into one estimate of each with Gaussian
   noise.  A record counts where its line is detected in a coherent interval (rho_c above
   ``receiver.detection_threshold``) and the antenna is in the radiation zone (R >= lambda).
3. Each model's likelihood over the records up to a time T is maximised over its start --
   (omega_L0^2, sin^2 theta_L0), with tau0 the body's (``tau0 = "known"``) or fitted too
   (``"fitted"``) -- and over the unknown constants (the power's scale, the polarization
   angle): least squares on the records, the models' predictions merged with the same weights
   as the data (8-point Gauss-Legendre in each record).  Z = sqrt(2 Delta ln L^) = sqrt(chi2_other
   - chi2_true), negative when the wrong model fits better.  The polarization angle is the same
   constant in both models (L is fixed in space for these tops), so its term is common to both
   and cancels in Z.
4. The trial's decision time: the first T at which Z reaches 5, by bisection on the records
   (Z grows steadily with T; the noise moves it by about 1), interpolated in log T; infinite
   when Z < 5 at the horizon.

The answer is the 95 % quantile of the trials' decision times for each truth, with a
distribution-free interval from the order statistics (the number of trials decided before the
true quantile is binomial: the Monte Carlo's own uncertainty), and the fraction of trials
decided against observation time.  Trials are independent (each has its own seed from
``numpy.random.SeedSequence(seed).spawn``), so the result does not depend on how they are
batched or where they run: ``run`` takes any ``map``-like callable (in-process, a process pool,
or a Dask client: the command line chooses).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..physics import models as M
from . import receiver as RC

DECISION_Z = 5.0
SHARE = 0.95
RECORDS_PER_DECADE = 12
NODES = 8
FEWEST = 3                # records the first fit takes (two estimates each for two or three parameters and a scale)
START = ("|Omega0| log-uniform over spin_range x the scene's |Omega0|; its direction in the body isotropic; "
         "the detector's direction from L isotropic; the polarization angle uniform")


@dataclass(frozen=True)
class Setup:
    """What a trial needs (small, picklable): the body's tau0, the Larmor constant
    (2/3c^3) d^2 (erg s^2 -> erg/s with Omega_perp^2 omega_L^2), the receiver's numbers (CGS), the
    scene's |Omega0| (rad/s), the horizon (s), eps = I3/I1, ``spin_range`` and whether tau0 is
    "known" or "fitted"."""

    tau0: float
    larmor: float
    distance_cm: float
    noise_density: float
    integration_s: float
    bandwidth_hz: float
    gain: float | None
    area_cm2: float | None
    omega_ref: float
    horizon: float
    epsilon: float = 1.0
    spin_range: tuple = (0.5, 2.0)
    tau0_mode: str = "known"
    models: tuple = ("reduced", "truncated")
    nuisance: object = None              # analysis.nuisance.Nuisances: what must be known, and the trap

    def edges(self) -> np.ndarray:
        """Record edges (s): 0, t_int, then ``RECORDS_PER_DECADE`` a decade to the horizon, each
        on a whole number of integrations (a record merges whole estimates)."""
        t_int = min(self.integration_s, self.horizon)
        n = max(2, int(math.ceil(RECORDS_PER_DECADE * math.log10(max(self.horizon / t_int, 1.0)))) + 1)
        k = np.unique(np.floor(np.geomspace(1.0, self.horizon / t_int, n)))
        return np.concatenate([[0.0], k * t_int])

    def area(self, f_hz):
        """The antenna's effective area at f (cm^2): given, or G lambda^2 / 4 pi."""
        if self.area_cm2 is not None:
            return np.full_like(np.asarray(f_hz, dtype=float), self.area_cm2)
        return self.gain * U.wavelength_cm(f_hz) ** 2 / (4.0 * math.pi)


def setup_from_scene(sc, spec, horizon: float, spin_range=(0.5, 2.0), tau0_mode: str = "known") -> Setup:
    """The ``Setup`` of scene ``sc`` watched by receiver ``spec`` (``inputs.receiver.ReceiverSpec``)
    for ``horizon`` s; ``SceneError`` naming what the scene lacks (``Scene.require("decide")``)."""
    body = sc.require("decide").body
    gain = None if spec.antenna_area_cm2 is not None else float(U.gain_from_dbi(
        spec.record()["antenna_gain_dbi"]))
    return Setup(tau0=body.tau0, larmor=2.0 * body.dipole_magnitude**2 / (3.0 * U.C_LIGHT**3),
                 distance_cm=spec.distance_cm, noise_density=spec.noise_density, integration_s=spec.integration_s,
                 bandwidth_hz=spec.bandwidth_hz, gain=gain, area_cm2=spec.antenna_area_cm2,
                 omega_ref=float(np.linalg.norm(sc.omega0)), horizon=float(horizon), epsilon=body.epsilon,
                 spin_range=tuple(float(x) for x in spin_range), tau0_mode=tau0_mode,
                 models=tuple(sc.models))


# --- one trial --------------------------------------------------------------------------------
@dataclass
class Start:
    """A trial's start: u0 = Omega_perp^2, b0 = eps^2 Omega_par^2 (rad^2/s^2), cos alpha of the
    detector's direction from L, the polarization angle psi0 (rad)."""

    u0: float
    b0: float
    cos_alpha: float
    psi0: float

    @property
    def w0(self) -> float:
        """omega_L0^2 = u0 + b0."""
        return self.u0 + self.b0

    @property
    def share(self) -> float:
        """sin^2 theta_L0 = u0 / omega_L0^2."""
        return self.u0 / self.w0


def draw_start(setup: Setup, rng) -> Start:
    """A start from ``START``: (u0, b0) = (Omega_perp^2, eps^2 Omega_par^2) of the drawn Omega0."""
    lo, hi = setup.spin_range
    w = setup.omega_ref * math.exp(rng.uniform(math.log(lo), math.log(hi)))
    c = rng.uniform(-1.0, 1.0)
    ca = rng.uniform(-1.0, 1.0)
    return Start(u0=w * w * (1.0 - c * c), b0=setup.epsilon**2 * w * w * c * c, cos_alpha=ca,
                 psi0=rng.uniform(0, math.pi))


def _nodes(edges: np.ndarray):
    """Gauss-Legendre nodes (R, NODES) and weights in each record [e_j, e_j+1]."""
    x, w = np.polynomial.legendre.leggauss(NODES)
    a, b = edges[:-1, None], edges[1:, None]
    return 0.5 * (b - a) * x[None, :] + 0.5 * (a + b), 0.5 * (b - a) * w[None, :]


def _prediction(model: str, t, w0, share, tau0):
    """(f, y) at times t: the line frequency (Hz) and y = ln(Omega_perp^2 omega_L^2) from the start
    (omega_L0^2, sin^2 theta_L0); complex parameters allowed (complex-step derivatives)."""
    u, b = M.get(model).line.state(t, share * w0, (1.0 - share) * w0, tau0)
    w2 = u + b
    return np.sqrt(w2) / (2.0 * math.pi), np.log(u) + np.log(w2)


@dataclass
class Records:
    """A trial's observations (only records where the line is detected in the radiation zone):
    end (s) of each record, and per record the weights (R, NODES) for merging the models'
    predictions, the estimates f (Hz), y (ln power + an unknown constant), psi (rad), and
    their errors."""

    end: np.ndarray
    t: np.ndarray
    weight: np.ndarray
    f: np.ndarray
    y: np.ndarray
    psi: np.ndarray
    sf: np.ndarray
    sy: np.ndarray
    spsi: np.ndarray

    def upto(self, n: int) -> Records:
        """The first ``n`` records."""
        return Records(*(getattr(self, k)[:n] for k in ("end", "t", "weight", "f", "y", "psi", "sf", "sy", "spsi")))


def observe_trial(setup: Setup, start: Start, truth: str, rng) -> Records:
    """The records a receiver makes of ``truth`` from ``start`` (module docstring, step 2)."""
    edges = setup.edges()
    t, w = _nodes(edges)
    f, y = _prediction(truth, t, start.w0, start.share, setup.tau0)
    ca2 = start.cos_alpha**2
    power_sr = setup.larmor * np.exp(y) * 3.0 / (8.0 * math.pi) * 0.5 * (1.0 + ca2)
    S = power_sr * setup.area(f) / setup.distance_cm**2
    energy = np.sum(S * w, axis=1)
    rho = 2.0 * energy / setup.noise_density
    weight = S * w / np.where(energy > 0, energy, 1.0)[:, None]
    fbar, ybar = np.sum(weight * f, axis=1), np.sum(weight * y, axis=1)
    tm = np.sum(weight * t, axis=1)
    line = M.get(truth).line
    u, b = line.state(tm, start.u0, start.b0, setup.tau0)
    fm = np.sqrt(u + b) / (2.0 * math.pi)
    rate, accel = line.drift(u, b, setup.tau0)
    fdot, fddot = rate * fm, accel * fm
    t_coh = RC.coherent_interval(fdot, fddot, setup.integration_s, setup.bandwidth_hz)
    s_mean = energy / (edges[1:] - edges[:-1])
    rho_c = 2.0 * s_mean * t_coh / setup.noise_density
    linear = (1.0 - ca2) / (1.0 + ca2)
    ok = (rho_c >= RC.detection_threshold(setup.bandwidth_hz * t_coh)) & (setup.distance_cm >= U.C_LIGHT / f[:, -1])
    with np.errstate(divide="ignore"):
        sf = RC.crb_tone(rho, t_coh)
        sy = 2.0 / np.sqrt(rho)
        spsi = 1.0 / (max(linear, 1e-12) * np.sqrt(rho))
    noise = rng.standard_normal((3, edges.size - 1))[:, ok]
    return Records(end=edges[1:][ok], t=t[ok], weight=weight[ok], f=fbar[ok] + sf[ok] * noise[0],
                   y=ybar[ok] + sy[ok] * noise[1], psi=start.psi0 + spsi[ok] * noise[2], sf=sf[ok], sy=sy[ok],
                   spsi=spsi[ok])


def _residuals(model: str, x, rec: Records, ref: Start, tau0: float, fitted: bool):
    """The weighted residuals of ``model`` with parameters x = (ln omega_L0^2 - ln ref, sin^2
    theta_L0[, ln tau0 - ln tau0_body]), the power's unknown scale profiled out; complex x allowed."""
    w0 = ref.w0 * np.exp(x[0])
    tz = tau0 * np.exp(x[2]) if fitted else tau0
    f, y = _prediction(model, rec.t, w0, x[1], tz)
    fb, yb = np.sum(rec.weight * f, axis=1), np.sum(rec.weight * y, axis=1)
    rf = (rec.f - fb) / rec.sf
    ry = (rec.y - yb) / rec.sy
    wy = 1.0 / rec.sy**2
    c = np.sum(wy * ry * rec.sy) / np.sum(wy)            # the best constant, in y units
    return np.concatenate([rf, ry - c / rec.sy])


def fit(model: str, rec: Records, ref: Start, tau0: float, fitted: bool, starts) -> tuple[float, np.ndarray]:
    """(chi2, x) of ``model``'s best fit to ``rec`` from the given starting points (x vectors),
    by ``scipy.optimize.least_squares`` with complex-step Jacobians."""
    from scipy.optimize import least_squares

    k = 3 if fitted else 2

    def fun(x):
        return _residuals(model, x, rec, ref, tau0, fitted).real

    def jac(x):
        h = 1e-30
        cols = []
        for i in range(k):
            z = np.asarray(x, dtype=complex).copy()
            z[i] += 1j * h
            cols.append(_residuals(model, z, rec, ref, tau0, fitted).imag / h)
        return np.stack(cols, axis=1)

    lo = [-np.inf, 1e-12] + ([-np.inf] if fitted else [])
    hi = [np.inf, 1.0] + ([np.inf] if fitted else [])
    best = (math.inf, None)
    for x0 in starts:
        x0 = np.clip(np.asarray(x0, dtype=float)[:k], np.array(lo) + 0.0, hi)
        x0[1] = min(max(x0[1], 1e-9), 1.0)
        try:
            r = least_squares(fun, x0, jac=jac, bounds=(lo, hi), x_scale="jac", method="trf", xtol=1e-14, ftol=1e-12,
                              gtol=1e-12, max_nfev=200)
        except (ValueError, FloatingPointError):
            continue
        chi2 = float(2.0 * r.cost)
        if np.isfinite(chi2) and chi2 < best[0]:
            best = (chi2, r.x)
    return best


def _polarization_chi2(rec: Records) -> float:
    """The polarization term of chi2, a constant angle fitted (the same for both models)."""
    w = 1.0 / rec.spsi**2
    m = np.sum(w * rec.psi) / np.sum(w)
    return float(np.sum(w * (rec.psi - m) ** 2))


def z_at(rec: Records, truth: str, start: Start, setup: Setup, warm: dict) -> float:
    """Z of ``truth`` against the other model on records ``rec`` (module docstring, step 3);
    ``warm`` {model: x} holds the last best fits (starting points for the next)."""
    first, second = setup.models
    other = second if truth == first else first
    fitted = setup.tau0_mode == "fitted"
    x_true = np.array([0.0, start.share, 0.0])
    chi = {}
    for m, starts in ((truth, [warm.get(truth, x_true), x_true]),
                      (other, [warm.get(other, x_true), x_true, np.array([0.0, 1.0, 0.0])])):
        chi[m], x = fit(m, rec, start, setup.tau0, fitted, starts)
        if x is not None:
            warm[m] = np.concatenate([x, [0.0]])[:3]
    pol = _polarization_chi2(rec)                      # common to both: cancels in the difference
    d = (chi[other] + pol) - (chi[truth] + pol)
    return math.copysign(math.sqrt(abs(d)), d)


def decision_time(rec: Records, truth: str, start: Start, setup: Setup) -> tuple[float, float]:
    """(T*, Z at the horizon): the first time Z reaches ``DECISION_Z`` (step 4; inf if never)."""
    n = rec.end.size
    if n < FEWEST:
        return math.inf, 0.0
    warm: dict = {}
    z_end = z_at(rec, truth, start, setup, warm)
    if z_end < DECISION_Z:
        return math.inf, z_end
    lo, hi = FEWEST, n                     # Z(lo records) < 5 assumed, Z(hi) >= 5
    zs = {n: z_end}
    z_lo = z_at(rec.upto(lo), truth, start, setup, dict(warm))
    if z_lo >= DECISION_Z:
        return float(rec.end[lo - 1]), z_end
    zs[lo] = z_lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        zs[mid] = z_at(rec.upto(mid), truth, start, setup, warm)
        lo, hi = (mid, hi) if zs[mid] < DECISION_Z else (lo, mid)
    t0, t1 = rec.end[lo - 1], rec.end[hi - 1]
    z0, z1 = zs[lo], zs[hi]
    frac = (DECISION_Z - z0) / (z1 - z0) if z1 > z0 else 1.0
    return float(math.exp(math.log(t0) + frac * (math.log(t1) - math.log(t0)))), z_end


def run_trials(setup: Setup, seed: int, indices) -> list[dict]:
    """Trials ``indices`` of the Monte Carlo seeded by ``seed``: per trial its start and, per
    truth, the decision time and the final Z (a top-level function: any map can run it).
    With nuisances (``Setup.nuisance``), ``decide_env.run_trials``."""
    if setup.nuisance is not None and setup.nuisance.active:
        from . import decide_env

        return decide_env.run_trials(setup, seed, indices)
    seqs = np.random.SeedSequence(seed).spawn(max(indices) + 1)
    out = []
    for i in indices:
        rng = np.random.default_rng(seqs[i])
        start = draw_start(setup, rng)
        row = {"trial": int(i), "u0": start.u0, "b0": start.b0, "cos_alpha": start.cos_alpha}
        for truth in setup.models:
            rec = observe_trial(setup, start, truth, rng)
            t_star, z_end = decision_time(rec, truth, start, setup)
            row[truth] = {"t": t_star, "z_end": z_end, "records": int(rec.end.size)}
        out.append(row)
    return out


# --- many trials ------------------------------------------------------------------------------
@dataclass
class Outcome:
    """The Monte Carlo's answer: per truth the trials' decision times (s, inf = never within
    the horizon), the 95 % quantile ``t95`` with its 68 % interval, and the setup."""

    setup: Setup
    trials: int
    seed: int
    rows: list
    t95: dict = field(default_factory=dict)
    interval: dict = field(default_factory=dict)
    title: str = ""
    receiver: object = None          # inputs.receiver.ReceiverSpec the trials were watched by

    def table(self) -> str:
        """The answer for people (``format_outcome``)."""
        return format_outcome(self, self.title, self.receiver)

    def times(self, truth: str) -> np.ndarray:
        """The trials' decision times under ``truth`` (s; inf where Z < 5 at the horizon)."""
        return np.array([r[truth]["t"] for r in self.rows], dtype=float)

    def fraction(self, truth: str, T) -> np.ndarray:
        """The share of trials decided by observation times T."""
        t = self.times(truth)
        return np.mean(t[None, :] <= np.asarray(T, dtype=float)[:, None], axis=1)

    def record(self) -> dict:
        """JSON-ready: the setup, the start distribution, per truth t95 and its interval, the
        share decided at the horizon, and every trial's decision time."""
        s = self.setup
        return {"trials": self.trials, "seed": self.seed, "start_distribution": START, "spin_range": list(s.spin_range),
                "tau0": s.tau0_mode, "horizon_s": s.horizon, "decision_z": DECISION_Z, "share": SHARE,
                "t95_s": {k: _num(v) for k, v in self.t95.items()},
                "t95_interval_s": {k: [_num(x) for x in v] for k, v in self.interval.items()},
                "decided_at_horizon": {m: float(np.mean(np.isfinite(self.times(m)))) for m in s.models},
                "decision_times_s": {m: [_num(x) for x in self.times(m)] for m in s.models},
                **({"nuisances": s.nuisance.record()} if s.nuisance is not None else {})}


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


def quantile_time(times: np.ndarray, share: float = SHARE) -> float:
    """The time by which ``share`` of the trials are decided (inf when more than 1 - share never are)."""
    t = np.sort(np.asarray(times, dtype=float))
    k = int(math.ceil(share * t.size)) - 1
    return float(t[max(k, 0)])


def quantile_interval(times: np.ndarray, share: float = SHARE, level: float = 0.68) -> tuple[float, float]:
    """A distribution-free ``level`` interval of the ``share`` quantile of the trials' times: the
    order statistics between which the true quantile lies with at least that probability (the
    number of trials below it is binomial(n, share)); the upper end is inf where it lies beyond
    the largest time (too few trials to bound it) or among the trials never decided."""
    t = np.sort(np.asarray(times, dtype=float))
    n = t.size
    k = np.arange(n + 1)
    logpmf = (np.array([math.lgamma(n + 1) - math.lgamma(j + 1) - math.lgamma(n - j + 1) for j in k])
              + k * math.log(share) + (n - k) * math.log1p(-share))
    cdf = np.cumsum(np.exp(logpmf - logpmf.max()))
    cdf /= cdf[-1]
    lo = int(np.searchsorted(cdf, 0.5 * (1.0 - level)))            # trials below the quantile, low end
    hi = int(np.searchsorted(cdf, 0.5 * (1.0 + level)))
    return float(t[max(lo - 1, 0)]), (float(t[hi]) if hi < n else math.inf)


def summarize(out: Outcome) -> Outcome:
    """Fill ``t95`` and its 68 % interval (``quantile_interval``: the Monte Carlo's own spread)."""
    for m in out.setup.models:
        t = out.times(m)
        out.t95[m] = quantile_time(t)
        out.interval[m] = quantile_interval(t)
    return out


def work_seconds(setup: Setup, trials: int, workers: int = 1) -> float:
    """The estimated wall time of ``trials`` trials of ``setup`` on ``workers`` processes, s:
    the measured cost of a trial (``inputs.options.DECIDE_S_PER_TRIAL``, by tau0 mode and
    nuisances, for a
    trial that is decided: the dearest) times the share of records beyond the measured ones."""
    from ..inputs.options import DECIDE_RECORDS, DECIDE_S_PER_TRIAL

    records = setup.edges().size - 1
    nu = setup.nuisance
    kind = setup.tau0_mode
    if nu is not None and nu.active:
        kind = "gas" if nu.gas is not None else "nuisances"
    each = max(DECIDE_S_PER_TRIAL[kind], DECIDE_S_PER_TRIAL[setup.tau0_mode]) * max(1.0, records / DECIDE_RECORDS)
    return trials * each / max(1, int(workers))


def check_work(setup: Setup, trials: int, workers: int) -> float:
    """Refuse, before any trial, a Monte Carlo estimated above the cap on one command's work
    (``SPINVIZ_MAX_DAYS``; ``SpecError`` naming ``trials``); returns the estimate, s."""
    from ..inputs.options import check_units

    return check_units("trials", trials, work_seconds(setup, 1), f"{trials} trials (tau0 {setup.tau0_mode}, "
                                                                  f"{setup.edges().size - 1} records a trial)", workers)


def run(setup: Setup, trials: int, seed: int = 1, mapper=None, batch: int = 8) -> Outcome:
    """``trials`` trials in batches of ``batch``, by ``mapper(fn, list_of_batches)`` (default:
    in this process), summarized."""
    batches = [list(range(i, min(i + batch, trials))) for i in range(0, trials, batch)]
    from functools import partial

    fn = partial(run_trials, setup, seed)
    results = (mapper or (lambda f, xs: list(map(f, xs))))(fn, batches)
    rows = sorted((r for part in results for r in part), key=lambda r: r["trial"])
    return summarize(Outcome(setup=setup, trials=trials, seed=seed, rows=rows))


def format_outcome(out: Outcome, title: str, receiver) -> str:
    """The answer for people: the setup, the start distribution, and per truth the time by which
    95 % of the trials are decided at 5 sigma (with the Monte Carlo's interval)."""
    s = out.setup
    lines = [title, "", f"receiver: {receiver.describe()}",
             f"start: {START}; spin_range {s.spin_range[0]:g}..{s.spin_range[1]:g}",
             f"tau0: {'the body' + chr(39) + 's (known)' if s.tau0_mode == 'known' else 'fitted with the start'}; "
             f"{out.trials} trials (seed {out.seed}); watched for at most {U.human_time(s.horizon)}"]
    if s.nuisance is not None:
        from .nuisance import describe

        lines.append(f"what must be known, and the trap: {describe(s.nuisance)}")
    lines.append("")
    lines.append(f"how long to watch: the time by which {100 * SHARE:g} % of the trials reach Z = {DECISION_Z:g}")
    for m in s.models:
        t = out.times(m)
        decided = float(np.mean(np.isfinite(t)))
        t95 = out.t95[m]
        if math.isfinite(t95):
            lo, hi = out.interval[m]
            text = (f"{U.human_time(t95)} (Monte Carlo 68 % interval {U.human_time(lo)} .. {U.human_time(hi)}); "
                    f"median {U.human_time(float(np.median(t)))}")
        else:
            text = f"not within {U.human_time(s.horizon)}: {100 * decided:.1f} % of the trials decided"
        lines.append(f"  truth {m:<10} {text}")
    worst = max(out.t95.values())
    lines.append("")
    lines.append("both ways: " + (U.human_time(worst) if math.isfinite(worst) else "not within the horizon"))
    return "\n".join(lines)
