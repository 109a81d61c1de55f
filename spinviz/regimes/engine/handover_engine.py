"""The hand-over engine: each run integrated in full until the averaged flow holds, then carried
by the averaged flow to tau_end; its type as tau -> oo is the attractor it is in, its label at
tau_end what its state shows there.

Same contract as ``runs.run_batch`` (``run_batch(batch) -> dict``), chosen by the spec's
``[run] engine = "handover"`` (the default).  Per run of a symmetric top
J = (1, 1, 1 - delta), d = (sin chi, 0, cos chi) (dimensionless (4.1)):

1. **Full stage.**  Taylor's method (heyoka's batch integrator on the scaled variable
   omega sqrt(1 + tau/T), the template the brute-force engine uses) on the spec's output grid,
   one run per SIMD lane; a lane whose run is done is refilled from the batch's queue at once.
   After every stretch of samples the lane restarts from its own last sample (time and state
   from the dense output), so a run's numbers never depend on which runs share its batch.
   At each sample the small parameter mu of the averaged flow (``physics.averaged``) is
   computed; the run hands over when mu < ``MU_STAR`` has held at every sample of the last
   ``HOLD_DECADES`` and tau >= ``MIN_BRAKING_TIMES`` T (T = 1/|omega0|^2).
2. **Averaged stage.**  The state at hand-over is read through the near-identity transform
   (``Flow.to_averaged``: the forced response -- type 1 -- kept apart) as the scaled amplitudes
   A = omega_perp^2 tau, B = omega3^2 tau, and carried by (LV) in s = ln tau to tau_end: one
   DOP853 solve for every handed-over run of the batch (in ln A, ln B: no underflow, every
   decade costs the same).  mu is checked along it: a run whose mu exceeds ``MU_BACK`` x
   ``MU_STAR`` before tau_end goes back to full integration from its start, without hand-over
   (``returned_to_full``).
3. **Where averaging cannot last** -- the cell's stable averaged state makes mu grow (the
   reduced transverse spiral with beta < -3/4: captured into the libration "5"; beyond beta =
   -1 the domain "?"; the truncated TF), the state is not unique or degenerate (delta = 0,
   chi = 0 or pi/2), a truncated start too near its singular surface, |omega0| past the
   runaway risk -- the runs go through the brute-force engine (``runs``) to tau_end and its
   classifier: cheap per decade there (the libration's steps grow as tau^(1/4)).
4. **Noise floor.**  Taylor's error control is local; the global error of the full stage is
   measured per cell by rerunning its first ``NOISE_PROBES`` handed-over runs at rtol/100 to
   their hand-over and comparing the averaged amplitudes.  The stated bound of a run is
   ``stated_bound``: ``BOUND_C`` mu_h^2 |(a, b)|_end (the averaged flow's error with the
   transform: O(mu_h^2), measured, docs/atlas.md) + ``SMALL_C`` min(a, b)_end (mu_h^2 + int mu^2
   d ln tau) / min(1, 1 - delta) (the smaller amplitude's own share, below) + that floor (+ on the axial state of
   the reduced model the ln tau drift of type 1, ``TYPE1_DRIFT_C`` mu_end^2 |b| ln(tau_end/tau_h)).
   The second term: (LV) carries ln A and ln B, so the hand-over's O(mu_h^2) reading error and
   the second-order drift first-order averaging omits (O(mu^2) per unit ln tau, integrated
   along the averaged run) are shares of each amplitude, and the smaller one -- dying or slow
   along the attractor, omega3 on the transverse state, where b ~ tau^(beta + 1/2) stays ~0.1 a
   for decades -- keeps its share undamped.  On the reduced transverse state by the 3|4
   boundary that share is b high by up to 0.4 mu_h^2 b at delta = 0.3, 0.9 at 0.5, 1.7 at 0.7,
   6.7 at 0.9 (``validation.atlas.against_brute_force.margins``): ~0.3-0.7 mu_h^2 b / (1 - delta),
   the torque's change of omega3 being divided by J3 = 1 - delta, so the term carries that
   factor (measured, not derived: docs/atlas.md).  Where the free
   spiral -- the component that decides 1 versus 2 -- is below ``NOISE_FACTOR`` x the floor
   (or x the transform's own residual, 5 mu_h^2 |z_f|), the run says "spiral unresolved" and
   is not evidence for that decision.

Labels, two of them: ``label_inf`` (the store's ``limit_label``) is the type as tau -> oo, the
attractor -- the stable state of (LV), unique in every cell where the engine hands over: "3",
"4", "T2", "T4", and on the reduced axial state "1" iff alpha(4.14) < -1, else "2";
``limit_settled`` and ``decades_to_settle`` say how near it the run is.  ``regime`` (``label``)
is what the run's state shows at tau_end: the classifier's label on its samples, the averaged
flow's after the hand-over (a slow run still on its way -- a truncated cone drifting to T2, a
type-3 run creeping as tau^-0.04 -- says so there, "Tcone" or "approaching 3").  Runs that stay
in full keep the classifier's label; in cells with beta < -3/4 a type-4 run's limit is "5"
(the spiral is captured into the libration, ``lock_to_5_at_tau``).
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

from ...integrators.cache import working
from ...physics import averaged as AV
from ...physics.equations import truncated_singularity
from . import classify as C
from . import runs as RN
from .averaged_stage import averaged_stage, lv_template
from .limit import crossing, limit_of, reconstruct

MU_STAR = 1e-2              # hand over below this mu: the averaged flow's error 0.2 mu^2 ~ 2e-5 of the amplitudes
HOLD_DECADES = 0.25         # ... held at every sample of this last stretch
MIN_BRAKING_TIMES = 10.0    # never before tau = 10 T: the braking has to have begun
MU_BACK = 3.0               # the averaged flow is trusted to MU_BACK x MU_STAR (hysteresis); beyond: back to full
BOUND_C = 0.2               # error of the averaged amplitudes <= BOUND_C mu_h^2 |(a, b)| ...
SMALL_C = 1.0               # ... + SMALL_C min(a, b) (mu_h^2 + int mu^2 d ln tau) / min(1, 1 - delta)
TYPE1_DRIFT_C = 1.3         # type 1's (k1 + k2 ln tau)/tau drift of b, missed by first-order averaging (measured)
NOISE_PROBES = 4            # handed-over runs per cell rerun at rtol/100 for the noise floor
NOISE_FACTOR = 10.0         # a component below this x the floor is not resolved
RESIDUAL_C = 5.0            # the transform's own residual on the forced response: 5 mu^2 |z_f| (measured)
CHUNK_MAX = 40              # samples a lane advances at most between looks


# --- where the engine hands over -------------------------------------------------------------
def handover_sample(tau: np.ndarray, mu: np.ndarray, mu_star: float, tau_min: float, since: float | None):
    """The first sample (index into ``tau``) at which a run hands over -- mu < ``mu_star`` at
    every sample since tau / 10^HOLD_DECADES (``since``: where the current stretch below
    mu_star began, carried between calls) and tau >= ``tau_min`` -- or -1; and the new ``since``."""
    hold = 10.0 ** HOLD_DECADES * (1.0 - 1e-12)
    for i in range(len(tau)):
        if mu[i] < mu_star:
            if since is None:
                since = float(tau[i])
            if tau[i] >= tau_min and tau[i] >= since * hold:
                return i, since
        else:
            since = None
    return -1, since


class _Job:
    """One run in the full stage: its grid (tau and spin-unit t), parameters, samples so far,
    and the hand-over bookkeeping.  ``stop_at``: end at that sample (the noise floor's reruns)."""

    def __init__(self, model: str, delta: float, chi: float, omega0, tau: np.ndarray, per_decade: int,
                 flow=None, stop_at: int | None = None):
        self.model, self.delta, self.chi = model, float(delta), float(chi)
        self.omega0 = np.asarray(omega0, dtype=float)
        self.eps = float(np.linalg.norm(self.omega0))
        self.tau = tau
        self.t = tau * self.eps                    # spin units: time x |omega0|
        k = math.sqrt(self.eps)
        self.pars = np.array([self.delta, math.sin(chi) * k, math.cos(chi) * k, self.eps])
        self.u0 = self.omega0 / self.eps
        self.flow = flow
        self.per_decade = per_decade
        self.end = len(tau) if stop_at is None else stop_at + 1
        self.omega = np.full((len(tau), 3), np.nan)
        self.omega[0] = self.omega0
        self.nxt, self.status, self.nsteps, self.handed = 1, 0, 0, -1
        self.t_stop = float(tau[self.end - 1])
        self.tau_min = MIN_BRAKING_TIMES / self.eps**2
        self.since, self.last_mu = None, math.inf
        self.mu_h = math.nan

    @property
    def reached(self) -> int:
        """Samples obtained (the first is the start)."""
        return self.nxt

    def rows_wanted(self) -> int:
        """How many samples the lane advances next: up to where a hand-over can happen
        (predicted from mu ~ tau^-1/2, the spirals' law), at most ``CHUNK_MAX``."""
        left = self.end - self.nxt
        k = CHUNK_MAX
        if self.flow is not None:
            hold = int(math.ceil(HOLD_DECADES * self.per_decade))
            tau = self.tau[self.nxt]
            if tau < self.tau_min:
                k = int(math.ceil(self.per_decade * math.log10(self.tau_min / tau))) + hold
            elif self.since is None:
                ratio = self.last_mu / MU_STAR
                k = (int(math.ceil(2.0 * self.per_decade * math.log10(ratio))) if math.isfinite(ratio) and ratio > 1.0
                     else 0) + hold
            else:
                k = int(math.ceil(self.per_decade * math.log10(self.since * 10.0 ** HOLD_DECADES / tau))) + 1
        return max(1, min(k, CHUNK_MAX, left))

    def take(self, u: np.ndarray, mu_star: float) -> bool:
        """Samples u (k, 3) (scaled, spin units) for grid indices nxt.. ; True when the run is
        done (handed over, or at its end)."""
        idx = np.arange(self.nxt, self.nxt + len(u))
        w = self.eps * u / np.sqrt(1.0 + self.eps * self.t[idx])[:, None]
        self.omega[idx] = w
        if self.flow is not None:
            mu = self.flow.small_parameter(np.hypot(w[:, 0], w[:, 1]), w[:, 2])
            i, self.since = handover_sample(self.tau[idx], mu, mu_star, self.tau_min, self.since)
            self.last_mu = float(mu[-1])
            if i >= 0:
                self.handed, self.mu_h = int(idx[i]), float(mu[i])
                self.omega[idx[i] + 1:] = np.nan
                self.nxt = int(idx[i]) + 1
                return True
        self.nxt += len(u)
        return self.nxt >= self.end


def integrate(jobs: list, model: str, tol: float, max_steps: int, mu_star: float = MU_STAR) -> None:
    """The full stage of ``jobs`` (one model): heyoka's batch integrator, one job per lane, a
    finished lane refilled at once; each job's samples, status, steps and hand-over filled in."""
    # Long on purpose: the lane loop (refill, grid, propagate, take, restart) reads as one story
    from ...integrators import status as ST
    from ...integrators.taylor import _status, template, width

    if not jobs:
        return
    n = width()
    ta = working(template(model, "none", tol, "double", n, symmetric=True, residual=False, runaway=False))
    npar = ta.pars.shape[0]
    pars, state, times = np.zeros((npar, n)), np.zeros((3, n)), np.zeros(n)
    lane: list = [None] * n
    queue = list(range(len(jobs)))[::-1]
    while True:
        for j in range(n):
            if lane[j] is None and queue:
                job = jobs[queue.pop()]
                lane[j] = job
                pars[:, j], state[:, j], times[j] = job.pars[:npar], job.u0, 0.0
        live = [j for j in range(n) if lane[j] is not None]
        if not live:
            return
        ks = {j: lane[j].rows_wanted() for j in live}
        M = 1 + max(ks.values())
        grid = np.empty((M, n))
        for j in range(n):
            if lane[j] is None:
                grid[:, j] = np.arange(M, dtype=float)         # idle: at rest from t = 0 (a fixed point)
                continue
            job, k = lane[j], ks[j]
            col = np.concatenate([[times[j]], job.t[job.nxt:job.nxt + k]])
            end = col[-1]
            grid[:, j] = np.concatenate([col, end + max(abs(end), 1.0) * 1e-9 * np.arange(1, M - k)])
        ta.set_time(times.copy())
        ta.state[:] = state
        ta.pars[:] = pars
        _, res = ta.propagate_grid(grid)
        res = np.asarray(res)
        pr = ta.propagate_res
        for j in live:
            job, k = lane[j], ks[j]
            job.nsteps += int(pr[j][3])
            rows = res[1:k + 1, :, j]
            good = np.all(np.isfinite(rows), axis=1)
            m = int(np.argmin(good)) if not good.all() else k
            st = _status(pr[j][0], None, False)
            done = job.take(rows[:m], mu_star) if m else False
            if not done and (st != ST.OK or m < k):
                job.status, job.t_stop = st if st != ST.OK else ST.NOT_FINITE, float(job.tau[job.nxt - 1])
                done = True
            elif not done and job.nsteps >= max_steps:
                job.status, job.t_stop, done = ST.TOO_MANY_STEPS, float(job.tau[job.nxt - 1]), True
            if done:
                lane[j] = None
                state[:, j], times[j] = 0.0, 0.0
            else:                                      # restart from its own last sample
                times[j], state[:, j] = job.t[job.nxt - 1], rows[m - 1]


# --- the noise floor ---------------------------------------------------------------------------
def noise_floor(jobs: list, model: str, rtol: float, max_steps: int) -> float:
    """The global error of the full stage at hand-over, in the scaled averaged amplitudes: the
    largest |d abar|, |d bbar| between ``jobs`` (handed-over runs) and the same starts
    integrated again at rtol/100 to the same sample.  NaN without jobs."""
    from ...integrators.taylor import tolerance

    if not jobs:
        return math.nan
    tight = [_Job(j.model, j.delta, j.chi, j.omega0, j.tau, j.per_decade, None, stop_at=j.handed) for j in jobs]
    tol, _ = tolerance(rtol / 100.0, rtol / 100.0)
    integrate(tight, model, tol, max_steps)
    worst = 0.0
    for j, t in zip(jobs, tight):
        if t.nxt <= j.handed:
            return math.nan                         # the tighter run did not get there: no floor measured
        tau = j.tau[j.handed]
        a0, b0 = AV.scaled_amplitudes(j.flow, *_zw(j.omega[j.handed]), tau)
        a1, b1 = AV.scaled_amplitudes(j.flow, *_zw(t.omega[j.handed]), tau)
        worst = max(worst, float(abs(a0 - a1)), float(abs(b0 - b1)))
    return worst


def _zw(w):
    return w[0] + 1j * w[1], w[2]


# --- a batch ----------------------------------------------------------------------------------
def startable(model: str, delta: float, chi: float, omega0) -> bool:
    """Whether a start may go through the full stage here: |omega0| within the runaway-free
    range of the compiled integrator (``taylor.RUNAWAY_RISK``) and, truncated, away from the
    singular surface (``runs.SINGULAR_MARGIN``); the brute-force engine handles the others
    (and says why they fail)."""
    from ...integrators.taylor import RUNAWAY_RISK

    w = np.asarray(omega0, dtype=float)
    if not 0.0 < float(np.linalg.norm(w)) <= RUNAWAY_RISK:
        return False
    if model == "truncated":
        J, g = (1.0, 1.0, 1.0 - delta), (math.sin(chi), 0.0, math.cos(chi))
        return float(truncated_singularity(w[0], w[1], w[2], J, g)) >= RN.SINGULAR_MARGIN
    return True


def run_batch(batch) -> dict:
    """Every run of ``batch`` (``runs.Batch``) through the hand-over engine (module docstring);
    the same arrays as ``runs.run_batch``, with the ``limit.RECORDS`` filled."""
    start, cpu0 = time.perf_counter(), time.process_time()
    out = RN.outputs(batch)
    cells, starts = RN.flat_runs(batch)
    classify_s = 0.0
    try:
        records, classify_s = _records(batch, cells, starts)
    except InterruptedError:
        raise
    except Exception as e:                        # the whole batch failed: every run says why
        records = [RN._error_record(e)] * len(cells)
    share = (time.perf_counter() - start) / max(1, len(cells))
    for n, r in enumerate(records):
        r.seconds = share
        RN.put(out, batch, n, r)
    return {"region": batch.region, "data": out, "worker_pid": os.getpid(), "compute_s": time.perf_counter() - start,
            "classify_s": classify_s, "cpu_s": time.process_time() - cpu0, "max_rss_mb": RN.max_rss_mb()}


def _records(batch, cells: list, starts: list) -> tuple[list, float]:
    """(a ``runs.Record`` per run, seconds spent labelling)."""
    from ...integrators.taylor import tolerance

    st, model = batch.settings, batch.model
    tau = st.times()
    info = {cell: AV.averaging_holds(model, *cell) for cell in dict.fromkeys(cells)}
    jobs, brute = {}, []
    for i, (cell, w0) in enumerate(zip(cells, starts)):
        ok, flow, _ = info[cell]
        if ok and startable(model, *cell, w0):
            jobs[i] = _Job(model, *cell, w0, tau, st.per_decade, flow)
        else:
            brute.append(i)
    records: list = [None] * len(cells)
    t_cls = 0.0
    if brute:
        runs = RN.integrate_many(model, [cells[i] for i in brute], [starts[i] for i in brute], st)
        t0 = time.perf_counter()
        for i, r in zip(brute, runs):
            rec = RN.classify_run(r, model, *cells[i], st)
            rec.series, rec.limit = r.omega, full_limit(model, *cells[i], rec, info[cells[i]])
            records[i] = rec
        t_cls += time.perf_counter() - t0
    tol, _ = tolerance(st.rtol, st.rtol)
    integrate(list(jobs.values()), model, tol, st.max_steps)
    handed = [i for i, j in jobs.items() if j.handed >= 0]
    av = dict(zip(handed, averaged_stage([jobs[i].flow for i in handed], tau, [jobs[i].handed for i in handed],
                                         [jobs[i].omega[jobs[i].handed] for i in handed], MU_BACK * MU_STAR)))
    back = [i for i in handed if math.isfinite(av[i]["tau_back"])]
    if back:                                      # the averaged flow stopped holding: in full from the start
        again = {i: _Job(model, *cells[i], starts[i], tau, st.per_decade, None) for i in back}
        integrate(list(again.values()), model, tol, st.max_steps)
        jobs.update(again)
        handed = [i for i in handed if i not in again]
    floors = {}
    for cell in dict.fromkeys(cells[i] for i in handed):
        probes = [jobs[i] for i in handed if cells[i] == cell][:NOISE_PROBES]
        floors[cell] = noise_floor(probes, model, st.rtol, st.max_steps)
    t0 = time.perf_counter()
    keep = batch.series_members
    for i in handed:
        records[i] = handed_record(jobs[i], av[i], info[cells[i]][2], floors[cells[i]], st,
                                   series=i % len(batch.omega0) < keep)
    for i, job in jobs.items():
        if records[i] is None:
            records[i] = full_record(job, st, info[cells[i]], returned=i in back)
    return records, t_cls + time.perf_counter() - t0


def stated_bound(mu_h: float, a: float, b: float, mu2_int: float = 0.0, floor: float = math.nan,
                 drift: tuple | None = None, delta: float = 0.0) -> float:
    """The stated bound on the error of a handed-over run's averaged end amplitudes (a, b) =
    (abar, |bbar|) (module docstring): ``BOUND_C`` mu_h^2 |(a, b)| + ``SMALL_C`` min(a, b) (mu_h^2 +
    ``mu2_int``) / min(1, 1 - ``delta``) (``mu2_int``: int mu^2 d ln tau along the averaged run,
    ``averaged_stage``; 1 - delta = J3, which divides the torque's change of omega3) + the noise
    ``floor`` (NaN: not measured, 0) + type 1's drift ``TYPE1_DRIFT_C`` mu_end^2 b ln(tau_end
    / tau_h) when ``drift`` = (mu_end, ln(tau_end / tau_h)) is given (the reduced axial state)."""
    bound = BOUND_C * mu_h**2 * math.hypot(a, b) + SMALL_C * min(a, b) * (mu_h**2 + mu2_int) / min(1.0, 1.0 - delta)
    bound += floor if math.isfinite(floor) else 0.0
    if drift is not None:
        bound += TYPE1_DRIFT_C * drift[0] ** 2 * b * drift[1]
    return bound


def handed_record(job: _Job, r: dict, state, floor: float, st, series: bool = True) -> RN.Record:
    """The record of a handed-over run.  Its limit (``label_inf``: the attractor, module
    docstring) and the limit records from the averaged flow; its label at tau_end -- what its
    state shows there, not where it goes -- by the classifier, on its samples: the full stage's,
    then ``reconstruct``'s (the averaged amplitudes, to the stated bound, with the free spiral's
    unresolved phase spread round the circle: ``reconstruct(spread=True)``), as a run
    integrated in full is labelled, with the classifier's evidence; ``series``: also its omega
    series on the output grid (after the hand-over with the averaged phase)."""
    flow, tau = job.flow, job.tau
    t = tau[r["idx"]]
    s = np.log(t)
    end, tau_end = len(t) - 1, float(t[-1])
    lnA, lnB = float(r["lnA"][end]), float(r["lnB"][end])
    lim = limit_of(flow, state, lnA, lnB, float(s[end]))
    a_h = math.exp(0.5 * r["lnA"][0])
    zf_h = abs(complex(flow.forced_response(job.omega[job.handed][2]))) * math.sqrt(t[0])
    thr = NOISE_FACTOR * max(floor if math.isfinite(floor) else 0.0, RESIDUAL_C * job.mu_h**2 * zf_h)
    unresolved = state.name == "axial" and flow.model == "reduced" and flow.F != 0.0 and a_h < thr
    seen = job.omega.copy()
    seen[r["idx"]] = reconstruct(flow, r, tau, spread=True)
    v = C.classify(tau, seen, flow.delta, flow.chi, flow.model, st.window)
    cut = tau <= tau_end / 10.0**st.window * (1.0 + 1e-9)
    label, candidate, confidence = v.label, v.candidate, v.confidence
    early = C.classify(tau[cut], seen[cut], flow.delta, flow.chi, flow.model, st.window).label
    reason = f"averaged from tau {t[0]:.2g} (mu {job.mu_h:.1g}); basin of {state.label}"
    if unresolved:
        # the free spiral -- what tells 1 from 2 -- is noise: only type 1 is decided, where the
        # noise's upper bound on the spiral decides it
        lim = limit_of(flow, state, lnA, lnB, float(s[end]), thr / max(a_h, 1e-300))
        lim["label_inf"] = "1" if flow.ratio_exponent < 0.0 else "other"
        if lim["label"] != "1" or label != "1":            # 1 and 2 not told apart: the mixture
            candidate, label, confidence = "1|2", "other", min(confidence, 0.3)
        early = early if early == "1" else "other"
        reason += ", spiral unresolved (noise floor)"
    reason += ("" if lim["settled"] else f", {lim['decades']:.2g} decades to settle") + f"; at tau_end {v.reason}"
    A, B = math.exp(lnA), math.exp(lnB)
    mu_end = float(flow.small_parameter_scaled(A, B, s[end]))
    drift = (mu_end, math.log(tau_end / t[0])) if state.name == "axial" and flow.model == "reduced" else None
    bound = stated_bound(job.mu_h, math.sqrt(A), math.sqrt(B), r["mu2_int"], floor, drift, flow.delta)
    limit = {"tau_handover": float(t[0]), "mu_handover": job.mu_h, "bound": bound, "abar_end": math.sqrt(A),
             "bbar_end": r["sign_b"] * math.sqrt(B), "free_forced_ratio": lim["ratio"], "tau_1_2": crossing(flow, r, tau),
             "limit_settled": int(lim["settled"] and lim["label_inf"] != "other"), "decades_to_settle": lim["decades"],
             "label_inf": RN.code(lim["label_inf"]), "noise_floor": floor, "spiral_unresolved": int(unresolved)}
    omega = job.omega.copy()
    if series:
        omega[r["idx"]] = reconstruct(flow, r, tau)
    else:
        omega[-1] = reconstruct(flow, r, tau, last_only=True)[-1]
    ev = C.Verdict(label, confidence, candidate, reason, v.evidence).vector()
    return RN.Record(label, early, candidate, float(confidence), 0, reason, ev, omega[-1].copy(),
                     tau_end, job.nsteps, 0, 0.0, limit=limit, method=RN.HANDED_OVER, series=omega if series else None)


def full_record(job: _Job, st, info: tuple, returned: bool = False) -> RN.Record:
    """The record of a run of a hand-over cell that stayed in full (or went back to it): the
    classifier's label on its samples, as the brute-force engine gives it."""
    from ...driver import Run
    from ...integrators import status as ST

    reason = "" if job.status == ST.OK else \
        f"{ST.MESSAGES.get(job.status, f'status {job.status}')} at tau = {job.t_stop:.3g}"
    run = Run(job.tau, job.omega, job.status, job.nxt, job.t_stop, job.nsteps, 0.0, reason)
    rec = RN.classify_run(run, job.model, job.delta, job.chi, st)
    rec.series = job.omega
    rec.limit = full_limit(job.model, job.delta, job.chi, rec, info)
    rec.limit["returned_to_full"] = int(returned)
    return rec


def full_limit(model: str, delta: float, chi: float, rec: RN.Record, info: tuple) -> dict:
    """The limit records of a run integrated in full, from its label, its evidence and its
    cell's averaged flow (``limit_inf``), and where the averaged flow's transform holds at its
    end, its averaged amplitudes and free/forced ratio there."""
    _, flow, state = info
    if flow is None and delta != 0.0 and 0.0 < chi < 0.5 * math.pi:
        flow = AV.Flow(model, delta, chi)
        state = flow.stable_state()
    inf, decades = limit_inf(model, state, rec)
    out = {"label_inf": RN.code(inf), "decades_to_settle": decades,
           "limit_settled": int(inf == rec.label and rec.label == rec.label_early
                                and rec.label not in ("approaching", "other", "failed", "1|2", "4|5"))}
    w = rec.omega_final
    if state is not None and np.all(np.isfinite(w)) and rec.tau_reached > 0.0:
        wp = math.hypot(w[0], w[1])
        if float(flow.small_parameter(wp, w[2])) < MU_BACK * MU_STAR:
            a, b = AV.scaled_amplitudes(flow, w[0] + 1j * w[1], w[2], rec.tau_reached)
            out.update(abar_end=float(a), bbar_end=float(math.copysign(b, w[2])))
            if state.name == "axial":
                out["free_forced_ratio"] = float(flow.free_forced_ratio(a * a, b * b, math.log(rec.tau_reached)))
    return out


UNSETTLED = ("other", "approaching", "1|2", "4|5")


def limit_inf(model: str, state, rec: RN.Record) -> tuple[str, float]:
    """(the type as tau -> oo, decades still needed, NaN if unknown) of a run integrated in
    full, labelled ``rec.label`` at tau_end.

    * Where the cell's stable averaged state is transverse and averaging cannot last there
      (reduced beta < -3/4, the domain "?"; truncated beta_T < -1): a run in its basin --
      labelled 4 / T4, or not yet labelled with omega_perp dominant (reduced: and falling as
      tau^-1/2) -- ends in the libration "5" (its rotating phase is captured,
      ``lock_to_5_at_tau``) or with the frozen phase "TF" (its remaining phase falls as
      tau^(1 + beta_T)).
    * Where averaging holds and the stable state is the only attractor (every such cell but
      the reduced transverse ones, where the libration competes): a run not yet labelled whose
      amplitudes already lean to that state ends there ((LV) has one stable state, attracting
      every start).
    * Otherwise its label."""
    ev = dict(zip(C.EVIDENCE, rec.evidence))
    X, Y, p = ev.get("X2", math.nan), ev.get("Y2", math.nan), ev.get("slope_perp", math.nan)
    if state is None or rec.label == "failed" or not (math.isfinite(X) and math.isfinite(Y)):
        return rec.label, math.nan
    transverse = X > 4.0 * Y and (model == "truncated" or abs(p + 0.5) < 0.1)
    if state.name == "transverse" and not state.holds:
        end = "5" if model == "reduced" else "TF"
        if rec.label == end:
            return end, 0.0
        if rec.label in ("4", "T4", *UNSETTLED) and transverse:
            lock, turns = ev.get("lock_to_5_at_tau", math.nan), ev.get("turns", math.nan)
            if end == "5":
                return end, math.log10(lock / rec.tau_reached) if math.isfinite(lock) and lock > rec.tau_reached \
                    else math.nan
            rate = -1.0 - state.exponent                  # the remaining phase ~ tau^(1 + beta_T)
            return end, math.log10(turns / 0.01) / rate if math.isfinite(turns) and turns > 0.01 else 0.0
        return rec.label, math.nan
    if state.holds and rec.label in UNSETTLED and not (model == "reduced" and state.name == "transverse"):
        lean = {"axial": Y > 4.0 * X, "transverse": transverse, "balanced": X > 0.05 * Y and Y > 0.05 * X}
        if lean[state.name]:
            return state.label, math.nan
    return rec.label, (0.0 if rec.label not in UNSETTLED else math.nan)


def cell_records(model: str, delta: float, chi: float, starts, settings, series: bool = False) -> list:
    """The ``runs.Record`` of each start at one cell through this engine (one batch; the
    evidence commands compare them with brute force; ``series``: with every run's omega
    series on the output grid, as the store keeps them)."""
    starts = np.asarray(starts, dtype=float)
    b = RN.Batch(model, (float(delta),), (float(chi),), starts, settings, (0, (0, 1), (0, 1), (0, len(starts))),
                 len(starts) if series else 0)
    cells, omega0 = RN.flat_runs(b)
    return _records(b, cells, omega0)[0]


def warm(settings, tol: float) -> None:
    """Load (or compile once) this engine's integrators beside the brute-force ones
    (``runs.warm``): the full stage's at ``tol`` and at a hundredth of it (the noise floor's
    reruns), and the averaged stage's."""
    from ...integrators.taylor import template, tolerance, width

    tight, _ = tolerance(settings.rtol / 100.0, settings.rtol / 100.0)
    for model in ("reduced", "truncated"):
        for t in (tol, tight):
            template(model, "none", t, "double", width(), symmetric=True, residual=False, runaway=False)
    lv_template(width())


RN.ENGINES["handover"] = sys.modules[__name__]
