"""Batches of Euler-only runs with the compiled kernel, each run classified where it ran.

One run integrates the dimensionless Euler equation (no orientation: ``with_q = False``) of a
symmetric top J = (1, 1, 1 - delta), d = (sin chi, 0, cos chi) from omega(0) to ``tau_end``,
sampled at log-spaced times, with ``kernels.lie_dop853`` called directly: the driver's
``simulate`` costs ~0.3 ms a call in checks and unit conversions and returns nothing when a
run fails, while a batch needs the partial series of a failed run and thousands of calls.

The run goes decade by decade (one kernel call per decade of samples, ~9 us each), which
buys three things: a step budget whose exhaustion still leaves the decades already done; a
stop as soon as a residual rotation is reached where the paper proves it is the end state
(reduced model at chi = 0 or pi/2 or delta = 0, (5.2), (5.6): there the explicit method is
held at the precession period by stability and the cost grows like tau, ~1e8 steps to 1e10);
and a stop flag looked at between decades.  The restart costs the DOP853 starting-step
estimate, ~2 right-hand sides, per decade.

``run_batch`` is what a Dask task executes: a block of the atlas (one model, a few cells,
some members), returned as small arrays; a run that fails is recorded with its reason and
never stops the batch.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass

import numpy as np

from ..integrators import status as ST
from . import classify as C

# status of a run (int8 in the store): the kernel's codes, and these
STOPPED_RESIDUAL = 10      # stopped early: residual rotation about d reached where it is the exact end state
SINGULAR_START = 11        # truncated (2.5) singular or nearly so at omega(0)
ERROR = 12                 # an exception (its message is the reason)
STATUS_TEXT = {ST.OK: "ok", ST.TOO_MANY_STEPS: "step budget exhausted", ST.STEP_UNDERFLOW: "step underflow",
               ST.NOT_FINITE: "not finite", ST.STIFF: "stiff", ST.TURN_TOO_LARGE: "turn too large",
               ST.INTERRUPTED: "interrupted", STOPPED_RESIDUAL: "stopped: residual rotation reached",
               SINGULAR_START: "singular start", ERROR: "error"}
METHOD = "lie-dop853"      # the one method used (the store's ``method`` variable names it per run)
METHOD_CODE = {METHOD: 0}
SINGULAR_MARGIN = 0.5      # truncated: refuse a start where 1 + (g x omega).J^-1 g < this


@dataclass(frozen=True)
class Settings:
    """How every run of an atlas is integrated and classified (part of the spec's identity).

    tau_end : horizon, tau = t/tau0.  tau_start : first sample after 0.  per_decade : samples
    a decade.  rtol, atol : DOP853 tolerances (atol absolute in omega).  max_steps : step
    budget of one run.  window : decades the classifier analyses.
    """

    tau_end: float = 1e10
    tau_start: float = 1e-2
    per_decade: int = 20
    rtol: float = 1e-8
    atol: float = 1e-20
    max_steps: int = 20_000_000
    window: float = 2.0

    def times(self) -> np.ndarray:
        """Output times [0, tau_start, ..., tau_end], ``per_decade`` log-spaced a decade."""
        return log_times(self.tau_start, self.tau_end, self.per_decade)


def log_times(tau_start: float, tau_end: float, per_decade: int) -> np.ndarray:
    """[0, tau_start, ..., tau_end] with ``per_decade`` samples a decade (shape (N,))."""
    n = int(round(per_decade * math.log10(tau_end / tau_start))) + 1
    return np.concatenate([[0.0], np.logspace(math.log10(tau_start), math.log10(tau_end), n)])


def residual_is_exact(model: str, delta: float, chi: float) -> bool:
    """Where the paper proves the reduced model ends in a residual rotation about d: chi = 0
    ((5.1), (5.2)), chi = pi/2 ((5.5), (5.6)) and the spherical top delta = 0 ((5.2), (6.7))."""
    return model == "reduced" and (chi == 0.0 or chi == 0.5 * math.pi or delta == 0.0)


@dataclass
class Run:
    """One integrated run: samples up to ``reached`` (tau, omega), why it ended, its cost."""

    tau: np.ndarray
    omega: np.ndarray
    status: int
    nsteps: int
    nfev: int
    seconds: float
    reason: str = ""
    verdict: C.Verdict | None = None     # the classification already made of exactly these samples


def integrate(model: str, delta: float, chi: float, omega0, settings: Settings, stop=None) -> Run:
    """One Euler-only run, decade by decade (see the module docstring).

    omega0 : shape (3,), body frame, dimensionless.  stop : optional int64 array of length 1;
    a nonzero value ends the run (status INTERRUPTED) at the next poll of the kernel.
    """
    # numba: the kernel is compiled, or loaded from its cache, on first use
    from ..integrators import kernels as KN
    from ..physics.equations import truncated_singularity

    J = (1.0, 1.0, 1.0 - float(delta))
    g = (math.sin(chi), 0.0, math.cos(chi))
    w0 = np.asarray(omega0, dtype=float)
    t = settings.times()
    out = np.empty((len(t), 3))
    out[0] = w0
    t0 = time.perf_counter()
    if model == "truncated":
        den = truncated_singularity(w0[0], w0[1], w0[2], J, g)
        if not den >= SINGULAR_MARGIN:
            return Run(t[:1], out[:1], SINGULAR_START, 0, 0, time.perf_counter() - t0,
                       f"truncated (2.5) near-singular at the start: 1 + (g x omega).J^-1 g = {den:.3g}; "
                       f"use a smaller |omega(0)| (below (1 - delta)/2)")
    stop = np.zeros(1, dtype=np.int64) if stop is None else stop
    exact_res = residual_is_exact(model, delta, chi)
    mid = KN.MODEL_ID[model]
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    nsteps = nfev = 0
    a = 0                                        # index of the segment's first sample (already known)
    status = ST.OK
    reason = ""
    per = settings.per_decade
    while a < len(t) - 1:
        b = min(len(t) - 1, (a // per + 1) * per)   # a decade of samples (the first segment adds 0 -> tau_start)
        seg = t[a:b + 1]
        w, _, nf, ns, _, st, _ = KN.lie_dop853(mid, J, g, out[a].copy(), q0, seg, settings.rtol, settings.atol, np.inf,
                                               False, max(1, settings.max_steps - nsteps), False, np.inf,
                                               *KN.DOP853_ARRAYS, stop)
        nsteps += int(ns)
        nfev += int(nf)
        if st != ST.OK:
            status = int(st)
            what = ST.MESSAGES.get(status, STATUS_TEXT.get(status, str(status)))
            reason = f"{what} between tau = {seg[0]:.3g} and {seg[-1]:.3g}"
            break
        out[a + 1:b + 1] = w[1:]
        a = b
        if exact_res and t[a] >= settings.tau_start * 10.0 ** (settings.window + 2):
            v = C.classify(t[:a + 1], out[:a + 1], delta, chi, model, settings.window)
            if v.label == "R" and v.confidence >= 0.9:
                status, reason = STOPPED_RESIDUAL, f"residual rotation about d reached by tau = {t[a]:.3g} (exact end state)"
                break
    return Run(t[:a + 1], out[:a + 1], status, nsteps, nfev, time.perf_counter() - t0, reason,
               v if status == STOPPED_RESIDUAL else None)


@dataclass
class Record:
    """What the store keeps of one run."""

    label: str
    label_early: str
    candidate: str
    confidence: float
    status: int
    reason: str
    evidence: np.ndarray          # shape (len(classify.EVIDENCE),)
    omega_final: np.ndarray       # shape (3,)
    tau_reached: float
    nsteps: int
    nfev: int
    seconds: float


def run_and_classify(model: str, delta: float, chi: float, omega0, settings: Settings, stop=None) -> Record:
    """``integrate`` then ``classify``, with the honest label for every way a run can end:

    * horizon reached (or the exact residual rotation reached early): the classifier's label;
    * step budget exhausted: "other", with the label the samples so far would get as the
      candidate (never a label the horizon was not reached for);
    * the solution left the finite numbers, the step underflowed, a singular truncated start,
      an exception: "failed" with its reason.

    ``label_early`` is the label of the same run cut ``window`` decades before its end: when it
    agrees with ``label`` the regime held over the last 2 x window decades."""
    nan_ev = np.full(len(C.EVIDENCE), np.nan)
    try:
        r = integrate(model, delta, chi, omega0, settings, stop)
    except Exception as e:                        # recorded, never raised: the batch goes on
        return Record("failed", "failed", "none", 0.0, ERROR, f"{type(e).__name__}: {e}", nan_ev, np.full(3, np.nan),
                      0.0, 0, 0, 0.0)
    if r.status == ST.INTERRUPTED:
        raise InterruptedError("stop flag set")
    reached = float(r.tau[-1])
    fin = r.omega[-1].copy()
    base = dict(omega_final=fin, tau_reached=reached, nsteps=r.nsteps, nfev=r.nfev, seconds=r.seconds)
    if r.status not in (ST.OK, STOPPED_RESIDUAL, ST.TOO_MANY_STEPS):
        return Record("failed", "failed", "none", 0.0, r.status, r.reason, nan_ev, **base)
    try:
        v = r.verdict if r.verdict is not None else C.classify(r.tau, r.omega, delta, chi, model, settings.window)
        cut = r.tau <= reached / 10.0**settings.window * (1.0 + 1e-9)
        early = C.classify(r.tau[cut], r.omega[cut], delta, chi, model, settings.window).label
    except Exception as e:
        return Record("failed", "failed", "none", 0.0, ERROR, f"classifier: {type(e).__name__}: {e}", nan_ev, **base)
    if r.status == ST.TOO_MANY_STEPS:
        return Record("other", early, v.label if v.label != "other" else v.candidate, min(v.confidence, 0.45), r.status,
                      f"{r.reason}; the samples so far say {v.label} ({v.confidence:.2f})", v.vector(), **base)
    reason = r.reason + "; " + v.reason if r.reason else v.reason
    return Record(v.label, early, v.candidate, v.confidence, r.status, reason, v.vector(), **base)


# --- a batch: what one Dask task computes -----------------------------------------------------
@dataclass(frozen=True)
class Batch:
    """A block of the atlas: one model, cells deltas x chis, members ``member_slice``.

    region : (model index, delta slice, chi slice, member slice) of the block in the store.
    omega0 : shape (n_members, 3), the block's initial conditions.
    """

    model: str
    deltas: tuple
    chis: tuple
    omega0: np.ndarray
    settings: Settings
    region: tuple

    @property
    def runs(self) -> int:
        return len(self.deltas) * len(self.chis) * len(self.omega0)


def run_batch(batch: Batch) -> dict:
    """Run and classify every run of ``batch``; arrays shaped (n_delta, n_chi, n_member[, k]).

    Also returns where and how it ran: ``worker_pid``, ``compute_s`` (wall time inside this
    function), ``cpu_s`` (the process's CPU time meanwhile: below ``compute_s`` when other
    work on the machine took the core) and ``max_rss_mb`` (the worker process's peak
    resident memory so far)."""
    start, cpu0 = time.perf_counter(), time.process_time()
    nd, nc, nm = len(batch.deltas), len(batch.chis), len(batch.omega0)
    shape = (nd, nc, nm)
    out = {
        "regime": np.empty(shape, dtype=np.int8), "regime_early": np.empty(shape, dtype=np.int8),
        "candidate": np.empty(shape, dtype=np.int8), "status": np.empty(shape, dtype=np.int8),
        "method": np.full(shape, METHOD_CODE[METHOD], dtype=np.int8),
        "confidence": np.empty(shape), "tau_reached": np.empty(shape), "run_seconds": np.empty(shape),
        "nsteps": np.empty(shape, dtype=np.int64), "nfev": np.empty(shape, dtype=np.int64),
        "evidence": np.empty(shape + (len(C.EVIDENCE),)), "omega_final": np.empty(shape + (3,)),
        "reason": np.empty(shape, dtype=f"<U{REASON_CHARS}"),
    }
    for i, d in enumerate(batch.deltas):
        for j, c in enumerate(batch.chis):
            for k in range(nm):
                r = run_and_classify(batch.model, float(d), float(c), batch.omega0[k], batch.settings)
                out["regime"][i, j, k] = code(r.label)
                out["regime_early"][i, j, k] = code(r.label_early)
                out["candidate"][i, j, k] = code(r.candidate)
                out["status"][i, j, k] = r.status
                out["confidence"][i, j, k] = r.confidence
                out["tau_reached"][i, j, k] = r.tau_reached
                out["run_seconds"][i, j, k] = r.seconds
                out["nsteps"][i, j, k] = r.nsteps
                out["nfev"][i, j, k] = r.nfev
                out["evidence"][i, j, k] = r.evidence
                out["omega_final"][i, j, k] = r.omega_final
                out["reason"][i, j, k] = r.reason[:REASON_CHARS]
    return {"region": batch.region, "data": out, "worker_pid": os.getpid(), "compute_s": time.perf_counter() - start,
            "cpu_s": time.process_time() - cpu0, "max_rss_mb": max_rss_mb()}


REASON_CHARS = 96


def code(label: str) -> int:
    """The int8 code of a label (mixtures and unknown candidates count as "other")."""
    return C.CODE.get(label, C.CODE["other"])


def max_rss_mb() -> float:
    """Peak resident memory of this process, MiB (Linux reports KiB, macOS bytes)."""
    import resource
    import sys

    kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return kb / (1024.0 * 1024.0) if sys.platform == "darwin" else kb / 1024.0


def warm() -> float:
    """Load (or compile, once, into numba's cache) the kernel; returns the seconds it took."""
    t0 = time.perf_counter()
    integrate("reduced", 0.3, 0.5, (0.05, 0.05, 0.05), Settings(tau_end=1.0, tau_start=0.1, per_decade=2))
    return time.perf_counter() - t0
