"""Batches of Euler-only runs through the one driver, each run classified where it ran.

One run integrates the dimensionless Euler equation (no orientation) of a symmetric top
J = (1, 1, 1 - delta), d = (sin chi, 0, cos chi) from omega(0) to ``tau_end``, sampled at
log-spaced times.  The runs of a batch go to ``driver.solve_many`` together, which hands them
to Taylor's method in heyoka's batch mode (``heyoka.recommended_simd_size()`` runs per SIMD
vector, 8 here) on the scaled variable omega sqrt(1 + tau/T) (T = 1/|omega0|^2), so the
tolerance keeps its meaning to the end of the run however far omega ~ 1/sqrt(tau) has fallen.

Early stops are terminal events, not restarts: a runaway (the reduction (2.3) breaking down)
and, where the paper proves the residual rotation about d is the end state (reduced model at
chi = 0 or pi/2 or delta = 0, (5.2), (5.6)), reaching it: |d x omega| < ``RESIDUAL_ETA`` |d|
|omega|.  There a resolving method would follow the steady rotation turn by turn to tau_end
(~1e8 steps); the samples after the stop are the rotation reached, held, and the reason says
so.  A run that fails keeps its samples so far and its reason; the batch goes on.

``plan`` cuts the runs a store lacks into ``Batch``es, each inside one storage chunk;
``run_batch`` is what a Dask task executes: a block of the atlas (one model, a few cells,
some members), returned as small arrays.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass

import numpy as np

from ...inputs.atlas_spec import AtlasSpec, Settings
from ...integrators import status as ST
from . import classify as C
from . import limit as LM

STOPPED_RESIDUAL = ST.STOPPED_RESIDUAL   # stopped early: residual rotation about d reached where it is the exact end state
SINGULAR_START = ST.SINGULAR_START       # truncated (2.5) singular or nearly so at omega(0)
ERROR = 12                 # an exception (its message is the reason)
STATUS_TEXT = {ST.OK: "ok", ST.TOO_MANY_STEPS: "step budget exhausted", ST.STEP_UNDERFLOW: "step underflow",
               ST.NOT_FINITE: "not finite", ST.STIFF: "stiff", ST.TURN_TOO_LARGE: "turn too large",
               ST.INTERRUPTED: "interrupted", ST.RUNAWAY: "runaway", STOPPED_RESIDUAL: "stopped: residual rotation reached",
               SINGULAR_START: "singular start", ERROR: "error"}
METHOD = "taylor"          # brute force: Taylor's method to tau_end (the store's ``method`` names it per run)
HANDED_OVER = "taylor+averaged"   # the hand-over engine's runs: Taylor's method, then the averaged flow
METHOD_CODE = {METHOD: 0, HANDED_OVER: 1}
RUNS_PER_TASK = 32          # a task of ~32 runs lasts ~0.2-10 s: scheduling (~ms) stays below 1 %
SINGULAR_MARGIN = 0.5      # truncated: refuse a start where 1 + (g x omega).J^-1 g < this
RESIDUAL_ETA = 1e-9        # rad: |d x omega|/(|d||omega|) at which a run in an exact-residual cell stops


def residual_is_exact(model: str, delta: float, chi: float) -> bool:
    """Where the paper proves the reduced model ends in a residual rotation about d: chi = 0
    ((5.1), (5.2)), chi = pi/2 ((5.5), (5.6)) and the spherical top delta = 0 ((5.2), (6.7))."""
    return model == "reduced" and (chi == 0.0 or chi == 0.5 * math.pi or delta == 0.0)


def integrate_many(model: str, cells: list, omega0: list, settings: Settings, stop=None) -> list:
    """Runs of ``model`` from omega0[i] at cells[i] = (delta, chi), through ``driver.solve_many``:
    a list of ``driver.Run`` (tau, omega (N, 3), status, reached, t_stop, reason, ...); after a
    residual stop the samples are the rotation reached, held."""
    from ...driver import solve_many

    t = settings.times()
    inertia = [(1.0, 1.0, 1.0 - float(d)) for d, _ in cells]
    coupling = [(math.sin(c), 0.0, math.cos(c)) for _, c in cells]
    eta = [RESIDUAL_ETA if residual_is_exact(model, float(d), float(c)) else 0.0 for d, c in cells]
    runs = solve_many(model, inertia, coupling, omega0, t, rtol=settings.rtol, max_steps=settings.max_steps,
                      residual_eta=eta, singular_margin=SINGULAR_MARGIN, stop=stop)
    for r in runs:
        if r.status == STOPPED_RESIDUAL and r.reached < len(t):
            r.omega[r.reached:] = r.omega[r.reached - 1]
    return runs


def integrate(model: str, delta: float, chi: float, omega0, settings: Settings, stop=None):
    """One run (``integrate_many`` of one)."""
    return integrate_many(model, [(delta, chi)], [np.asarray(omega0, dtype=float)], settings, stop)[0]


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
    limit: dict | None = None     # ``limit.RECORDS`` the run fills (the rest stay blank)
    method: str = METHOD
    series: np.ndarray | None = None   # (N, 3) on the spec's grid, when the engine made it another way than a Run


def classify_run(r, model: str, delta: float, chi: float, settings: Settings) -> Record:
    """The honest label for every way a run can end:

    * horizon reached (or the exact residual rotation reached early, held to the horizon):
      the classifier's label;
    * step budget exhausted: "other", with the label the samples so far would get as the
      candidate (never a label the horizon was not reached for);
    * a runaway, the solution leaving the finite numbers, a singular truncated start, an
      exception: "failed" with its reason.

    ``label_early`` is the label of the same run cut ``window`` decades before its end: when it
    agrees with ``label`` the regime held over the last 2 x window decades."""
    nan_ev = np.full(len(C.EVIDENCE), np.nan)
    held = r.status == STOPPED_RESIDUAL
    n = len(r.tau) if held else r.reached
    tau, omega = r.tau[:n], r.omega[:n]
    reached = float(r.tau[n - 1]) if not held else float(r.t_stop)
    fin = omega[n - 1].copy() if n else np.full(3, np.nan)
    base = dict(omega_final=fin, tau_reached=reached, nsteps=r.nsteps, nfev=0, seconds=r.seconds)
    if r.status not in (ST.OK, STOPPED_RESIDUAL, ST.TOO_MANY_STEPS):
        return Record("failed", "failed", "none", 0.0, r.status, r.reason, nan_ev, **base)
    try:
        v = C.classify(tau, omega, delta, chi, model, settings.window)
        cut = tau <= float(tau[-1]) / 10.0**settings.window * (1.0 + 1e-9)
        early = C.classify(tau[cut], omega[cut], delta, chi, model, settings.window).label
    except Exception as e:
        return Record("failed", "failed", "none", 0.0, ERROR, f"classifier: {type(e).__name__}: {e}", nan_ev, **base)
    if r.status == ST.TOO_MANY_STEPS:
        return Record("other", early, v.label if v.label != "other" else v.candidate, min(v.confidence, 0.45), r.status,
                      f"{r.reason}; the samples so far say {v.label} ({v.confidence:.2f})", v.vector(), **base)
    reason = r.reason + "; " + v.reason if r.reason else v.reason
    return Record(v.label, early, v.candidate, v.confidence, r.status, reason, v.vector(), **base)


def run_and_classify(model: str, delta: float, chi: float, omega0, settings: Settings, stop=None) -> Record:
    """``integrate`` then ``classify_run`` (an exception in the integration is a failed run)."""
    try:
        r = integrate(model, delta, chi, omega0, settings, stop)
    except InterruptedError:
        raise
    except Exception as e:                        # recorded, never raised: the batch goes on
        return _error_record(e)
    return classify_run(r, model, delta, chi, settings)


def _error_record(e: Exception) -> Record:
    return Record("failed", "failed", "none", 0.0, ERROR, f"{type(e).__name__}: {e}", np.full(len(C.EVIDENCE), np.nan),
                  np.full(3, np.nan), 0.0, 0, 0, 0.0)


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
    series: int = 0               # the store keeps the omega(tau) series of members 0 .. series - 1

    @property
    def runs(self) -> int:
        """Runs in the batch: cells x members."""
        return len(self.deltas) * len(self.chis) * len(self.omega0)

    @property
    def series_members(self) -> int:
        """How many of this batch's members (its first ones) have their series kept."""
        m0, m1 = self.region[3]
        return max(0, min(m1, self.series) - m0)


def plan(spec: AtlasSpec, chunks: tuple, done: np.ndarray, runs_per_task: int = RUNS_PER_TASK):
    """Batches covering exactly the runs not yet done, each inside one storage chunk, in store
    order (a block that is partly done is cut into the missing stretches of members).

    Returns (batches, the storage chunk of each -- its Zarr chunk index (model, delta, chi
    block, member block) --, expected batches per chunk)."""
    _, _, cc, cm = chunks
    tm = min(cm, max(1, runs_per_task))
    tc = max(1, min(cc, runs_per_task // tm))
    batches, keys, expected = [], [], {}
    nd, nc, nm = len(spec.deltas), len(spec.chis), spec.members
    for mi, model in enumerate(spec.models):
        for di in range(nd):
            for c0 in range(0, nc, cc):
                for a in range(c0, min(c0 + cc, nc), tc):
                    b = min(a + tc, c0 + cc, nc)
                    for m0 in range(0, nm, cm):
                        key = (mi, di, c0 // cc, m0 // cm)
                        for ma in range(m0, min(m0 + cm, nm), tm):
                            mb = min(ma + tm, m0 + cm, nm)
                            block = done[mi, di, a:b, ma:mb]
                            if block.all():
                                continue
                            if not block.any():
                                parts = [(a, b, ma, mb)]
                            else:                    # partly done: only the missing runs, cell by cell
                                parts = [(a + j, a + j + 1, ma + s0, ma + s1) for j in range(b - a)
                                         for s0, s1 in _runs_of(~block[j])]
                            for pa, pb, pma, pmb in parts:
                                batches.append(Batch(model, (float(spec.deltas[di]),),
                                                        tuple(float(x) for x in spec.chis[pa:pb]),
                                                        np.asarray(spec.omega0[pma:pmb]), spec.settings,
                                                        (mi, (di, di + 1), (pa, pb), (pma, pmb)), spec.series))
                                keys.append(key)
                                expected[key] = expected.get(key, 0) + 1
    return batches, keys, expected


def _runs_of(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) of each stretch of True in a 1-D mask."""
    out, start = [], None
    for i, m in enumerate(mask):
        if m and start is None:
            start = i
        elif not m and start is not None:
            out.append((start, i))
            start = None
    if start is not None:
        out.append((start, len(mask)))
    return out


# [run] engine -> the module that runs it, beside the brute force here ("taylor"): each
# registers itself when imported, and the package imports it (engine/__init__.py), so a Dask
# worker that unpickles a Batch has it
ENGINES: dict = {}


def run_batch(batch: Batch) -> dict:
    """Run and classify every run of ``batch``; arrays shaped (n_delta, n_chi, n_member[, k]).

    The spec's ``[run].engine`` chooses how: "handover" (``handover.run_batch``, registered in
    ``ENGINES``: full integration until the averaged flow holds, then the averaged flow) or
    "taylor" (brute force: every run integrated to tau_end, here).

    Also returns where and how it ran: ``worker_pid``, ``compute_s`` (wall time inside this
    function), ``classify_s`` (of which: classifying the runs), ``cpu_s`` (the process's CPU
    time meanwhile: below ``compute_s`` when other work on the machine took the core) and
    ``max_rss_mb`` (the worker process's peak resident memory so far)."""
    if batch.settings.engine != "taylor":
        return ENGINES[batch.settings.engine].run_batch(batch)
    start, cpu0 = time.perf_counter(), time.process_time()
    out = outputs(batch)
    cells, starts = flat_runs(batch)
    classify_s = 0.0
    try:
        runs = integrate_many(batch.model, cells, starts, batch.settings)
        t_cls = time.perf_counter()
        records = [classify_run(r, batch.model, d, c, batch.settings) for r, (d, c) in zip(runs, cells)]
        classify_s = time.perf_counter() - t_cls
    except InterruptedError:
        raise
    except Exception as e:                        # the whole batch failed: every run says why
        runs, records = [], [_error_record(e)] * len(cells)
    for n, run in enumerate(runs):
        records[n].series = run.omega
    for n, r in enumerate(records):
        put(out, batch, n, r)
    return {"region": batch.region, "data": out, "worker_pid": os.getpid(), "compute_s": time.perf_counter() - start,
            "classify_s": classify_s, "cpu_s": time.process_time() - cpu0, "max_rss_mb": max_rss_mb()}


def flat_runs(batch: Batch) -> tuple[list, list]:
    """The batch's runs in store order (delta, chi, member): ([(delta, chi)], [omega0])."""
    nm = len(batch.omega0)
    cells = [(float(d), float(c)) for d in batch.deltas for c in batch.chis for _ in range(nm)]
    starts = [np.asarray(batch.omega0[k], dtype=float) for _ in batch.deltas for _ in batch.chis for k in range(nm)]
    return cells, starts


def outputs(batch: Batch) -> dict:
    """The arrays a batch returns, shaped (n_delta, n_chi, n_member[, k]), before any run."""
    shape = (len(batch.deltas), len(batch.chis), len(batch.omega0))
    out = {
        "regime": np.empty(shape, dtype=np.int8), "regime_early": np.empty(shape, dtype=np.int8),
        "candidate": np.empty(shape, dtype=np.int8), "status": np.empty(shape, dtype=np.int8),
        "method": np.full(shape, METHOD_CODE[METHOD], dtype=np.int8),
        "confidence": np.empty(shape), "tau_reached": np.empty(shape), "run_seconds": np.empty(shape),
        "nsteps": np.empty(shape, dtype=np.int64), "nfev": np.empty(shape, dtype=np.int64),
        "evidence": np.empty(shape + (len(C.EVIDENCE),)), "omega_final": np.empty(shape + (3,)),
        "reason": np.empty(shape, dtype=f"<U{REASON_CHARS}"),
        **LM.blank(shape),
    }
    if batch.series_members:
        out["series"] = np.full(shape[:2] + (batch.series_members, len(batch.settings.times()), 3), np.nan,
                                dtype=np.float32)
    return out


def put(out: dict, batch: Batch, n: int, r: Record) -> None:
    """Run ``n`` of the batch (store order) into ``out``."""
    nc, nm = len(batch.chis), len(batch.omega0)
    i, rest = divmod(n, nc * nm)
    j, k = divmod(rest, nm)
    out["regime"][i, j, k] = code(r.label)
    out["regime_early"][i, j, k] = code(r.label_early)
    out["candidate"][i, j, k] = code(r.candidate)
    out["status"][i, j, k] = r.status
    out["method"][i, j, k] = METHOD_CODE[r.method]
    out["confidence"][i, j, k] = r.confidence
    out["tau_reached"][i, j, k] = r.tau_reached
    out["run_seconds"][i, j, k] = r.seconds
    out["nsteps"][i, j, k] = r.nsteps
    out["nfev"][i, j, k] = r.nfev
    out["evidence"][i, j, k] = r.evidence
    out["omega_final"][i, j, k] = r.omega_final
    out["reason"][i, j, k] = r.reason[:REASON_CHARS]
    out["label_inf"][i, j, k] = code(r.label)
    for name, value in (r.limit or {}).items():
        out[name][i, j, k] = value
    if "series" in out and k < out["series"].shape[2] and r.series is not None:
        out["series"][i, j, k] = r.series


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


def warm(settings: Settings | None = None) -> float:
    """Load (or compile, once, into heyoka's on-disk cache) the batch integrators of both models
    at the atlas's tolerance -- and for the hand-over engine at a hundredth of it (the noise
    floor's reruns) and the averaged stage's -- returns the seconds it took."""
    from ...integrators.taylor import template, tolerance, width

    t0 = time.perf_counter()
    st = settings or Settings()
    tol, _ = tolerance(st.rtol, st.rtol)
    for model in ("reduced", "truncated"):
        template(model, "none", tol, "double", width())
    if st.engine != "taylor":
        ENGINES[st.engine].warm(st, tol)
    return time.perf_counter() - t0
