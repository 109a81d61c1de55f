"""The hand-over engine against brute force: the same starts at the validation points, run by
the engine and by brute-force Taylor integration to each horizon.

    spinviz atlas evidence handover [--members 16] [--horizons 1e12,1e14] [--out STORE] [--json]

Per point and horizon: the labels of both (same class -- an "approaching X" counted as X --,
compatible -- a mixture "1|2" or "4|5" against one of its types -- or different), and for
every handed-over run its averaged end amplitudes against the brute-force run's (read through
the same near-identity transform, ``physics.averaged.scaled_amplitudes``) measured against its
stated bound; on the reduced axial state the free/forced ratios of both.  Where they differ
(a label, an end state beyond the bound, or the free/forced ratio by more than 0.1 in
log10, where the free spiral is resolved), up to ``REFERENCE_RUNS`` of those starts are run
again by a scalar Taylor integrator at ``REFERENCE_TOL`` -- the tighter reference says which
of the two is wrong (past ~1e12 brute force at rtol 1e-10 loses the free spiral near
alpha = -1: it decides 1 versus 2 on its own truncation error).  Both are timed.
"""

from __future__ import annotations

import copy
import math
import time
from collections import Counter

import numpy as np

from ...inputs.atlas_spec import Settings, directions
from ...physics import averaged as AV
from ...regimes.engine import handover_engine as HO
from ...regimes.engine import runs as RN

HORIZONS = (1e12, 1e14)
REFERENCE_TOL = 1e-14          # near alpha = -1 the free spiral at 1e14 needs <= 1e-14 (1e-13 is off by 40 %)
REFERENCE_RUNS = 2


def points() -> list[tuple]:
    """(name, model, delta, chi_deg, |omega0|): the validation points, the disputed ones, and
    the truncated model's slow ones."""
    from .convergence import points as conv

    extra = [("T2 slow (alpha_T = -0.56)", "truncated", -0.6, math.degrees(0.3), 0.04),
             ("T2 (-0.5, 0.8)", "truncated", -0.5, math.degrees(0.8), 0.04),
             ("T4 (0.3, 0.72)", "truncated", 0.3, math.degrees(0.72), 0.04),
             ("T4 near TF (beta_T = -0.91)", "truncated", 0.6, math.degrees(1.0), 0.04)]
    return conv() + extra


def _class(r) -> str:
    return r.candidate if r.label == "approaching" else r.label


def agreement(bf, en) -> str:
    """"same", "compatible" (a mixture against one of its types), "undecided" (brute force
    "other": no class fits its samples yet) or "differ"."""
    if bf == en:
        return "same"
    if bf == "other":
        return "undecided"
    pairs = {("1|2", "1"), ("1|2", "2"), ("4|5", "4"), ("4|5", "5")}
    return "compatible" if (bf, en) in pairs or (en, bf) in pairs else "differ"


def full_run(model: str, delta: float, chi: float, omega0, taus, tol: float = REFERENCE_TOL) -> np.ndarray:
    """omega (N, 3) at ``taus`` by a scalar Taylor integrator at ``tol`` on the atlas's scaled
    variable u = omega / (|omega0| sqrt(1 + |omega0|^2 tau)), time |omega0| tau."""
    from ...integrators.taylor import template

    eps = float(np.linalg.norm(omega0))
    ta = copy.copy(template(model, "none", tol, "double", 0, symmetric=True, residual=False, runaway=False))
    ta.time = 0.0
    ta.state[:] = np.asarray(omega0) / eps
    k = math.sqrt(eps)
    ta.pars[:] = [delta, math.sin(chi) * k, math.cos(chi) * k, eps][:len(ta.pars)]
    taus = np.asarray(taus, dtype=float)
    u = np.asarray(ta.propagate_grid(np.concatenate([[0.0], taus * eps]))[-1])[1:]
    return eps * u / np.sqrt(1.0 + eps * eps * taus)[:, None]


def reference(model: str, delta: float, chi: float, omega0, tau: float, tol: float = REFERENCE_TOL):
    """omega at ``tau`` by a scalar Taylor integrator at ``tol`` (``full_run``)."""
    return full_run(model, delta, chi, omega0, [tau], tol)[-1]


def compare_point(name, model, d, cdeg, w, members: int, horizon: float, rtol: float, seed: int = 1) -> dict:
    """One point at one horizon: engine and brute force on the same starts (see the module docstring)."""
    chi = math.radians(cdeg)
    starts = directions(members, seed) * w
    t0 = time.perf_counter()
    en = HO.cell_records(model, d, chi, starts, Settings(tau_end=horizon, rtol=rtol))
    t1 = time.perf_counter()
    st = Settings(tau_end=horizon, rtol=rtol, engine="taylor", max_steps=10**9)
    bf = [RN.classify_run(r, model, d, chi, st) for r in RN.integrate_many(model, [(d, chi)] * members, list(starts), st)]
    t2 = time.perf_counter()
    flow = AV.Flow(model, d, chi) if d != 0.0 and 0.0 < chi < 0.5 * math.pi else None
    verdict = [agreement(_class(b), _class(e)) for b, e in zip(bf, en)]
    diff, ratio_e, ratio_b, out, ratio_off = [], [], [], [], []
    for k, (b, e) in enumerate(zip(bf, en)):
        lim = e.limit or {}
        if not math.isfinite(lim.get("tau_handover", math.nan)) or flow is None:
            continue
        w_end = b.omega_final
        a, bb = AV.scaled_amplitudes(flow, w_end[0] + 1j * w_end[1], w_end[2], horizon)
        dd = max(abs(lim["abar_end"] - a), abs(abs(lim["bbar_end"]) - bb))
        diff.append(dd / lim["bound"])
        if dd > lim["bound"]:
            out.append(k)
        if math.isfinite(lim.get("free_forced_ratio", math.nan)) and not lim.get("spiral_unresolved", 0):
            ratio_e.append(lim["free_forced_ratio"])
            ratio_b.append(float(flow.free_forced_ratio(a * a, bb * bb, math.log(horizon))))
            if abs(math.log10(ratio_e[-1] / ratio_b[-1])) > 0.1:
                ratio_off.append(k)
    refs = []
    for k in list(dict.fromkeys([k for k, v in enumerate(verdict) if v == "differ"] + out + ratio_off))[:REFERENCE_RUNS]:
        if flow is None:
            break
        tr = time.perf_counter()
        wr = reference(model, d, chi, starts[k], horizon)
        a, bb = AV.scaled_amplitudes(flow, wr[0] + 1j * wr[1], wr[2], horizon)
        wb = bf[k].omega_final
        ab, bbb = AV.scaled_amplitudes(flow, wb[0] + 1j * wb[1], wb[2], horizon)
        lim = en[k].limit or {}
        refs.append({"member": k, "brute": _class(bf[k]), "engine": _class(en[k]), "seconds": time.perf_counter() - tr,
                     "engine_vs_ref": max(abs(lim.get("abar_end", math.nan) - a), abs(abs(lim.get("bbar_end", math.nan)) - bb)),
                     "brute_vs_ref": max(abs(ab - a), abs(bbb - bb)), "bound": lim.get("bound", math.nan),
                     "ratio_ref": float(flow.free_forced_ratio(a * a, bb * bb, math.log(horizon))) if flow.F else math.nan,
                     "ratio_engine": lim.get("free_forced_ratio", math.nan),
                     "ratio_brute": float(flow.free_forced_ratio(ab * ab, bbb * bbb, math.log(horizon))) if flow.F else math.nan})
    return {"point": name, "model": model, "delta": d, "chi_deg": cdeg, "omega0": w, "members": members,
            "horizon": horizon, "rtol": rtol,
            "brute": dict(Counter(_shown(b) for b in bf)), "engine": dict(Counter(_shown(e) for e in en)),
            "engine_limit": dict(Counter(_limit(e) for e in en)),
            "agreement": dict(Counter(verdict)), "handed_over": len(diff),
            "median_tau_handover": float(np.median([e.limit["tau_handover"] for e in en if e.limit and
                                                    math.isfinite(e.limit.get("tau_handover", math.nan))]))
            if diff else math.nan,
            "beyond_bound": len(out), "max_diff_over_bound": float(max(diff)) if diff else math.nan,
            "median_diff_over_bound": float(np.median(diff)) if diff else math.nan,
            "ratio_log10_diff": float(np.median(np.abs(np.log10(ratio_e) - np.log10(ratio_b)))) if ratio_e else math.nan,
            "ratio_compared": len(ratio_e),
            "references": refs, "engine_s": t1 - t0, "brute_s": t2 - t1}


def _shown(r) -> str:
    return f"->{r.candidate}" if r.label == "approaching" else r.label


def _limit(r) -> str:
    code = (r.limit or {}).get("label_inf")
    names = {v: k for k, v in RN.C.CODE.items()}
    return names.get(code, r.label) if code is not None else r.label


def run(members: int = 16, horizons=HORIZONS, rtol: float = 1e-10, progress=None) -> list[dict]:
    """Every point of ``points`` at every horizon (``compare_point``)."""
    say = progress or (lambda m: None)
    rows = []
    for p in points():
        for h in horizons:
            say(f"{p[0]}: tau_end = {h:g}")
            rows.append(compare_point(*p, members, h, rtol))
    return rows


def format_table(rows: list[dict]) -> str:
    """The rows as a Markdown table, and the references below it."""
    out = ["| point | model | tau_end | brute force | engine at tau_end (limit) | agreement | handed over (median tau_h) | "
           "end state: beyond bound, max diff/bound | 1-vs-2 ratio: median log10 diff | time engine / brute |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    refs = []
    for r in rows:
        lab = lambda c: ", ".join(f"{k} {v}" for k, v in sorted(c.items(), key=lambda kv: -kv[1]))  # noqa: E731
        ho = f"{r['handed_over']}/{r['members']}" + (f" ({r['median_tau_handover']:.2g})" if r["handed_over"] else "")
        es = f"{r['beyond_bound']}, {r['max_diff_over_bound']:.2f}" if r["handed_over"] else "-"
        rat = f"{r['ratio_log10_diff']:.1e}" if math.isfinite(r["ratio_log10_diff"]) else "-"
        out.append(f"| {r['point']} | {r['model']} | {r['horizon']:.0e} | {lab(r['brute'])} | {lab(r['engine'])} "
                   f"({lab(r['engine_limit'])}) | {lab(r['agreement'])} | {ho} | {es} | {rat} | "
                   f"{r['engine_s']:.2f} s / {r['brute_s']:.1f} s |")
        for f in r["references"]:
            refs.append(f"* {r['point']}, tau_end {r['horizon']:.0e}, start {f['member']} (brute {f['brute']}, engine "
                        f"{f['engine']}): against tol {REFERENCE_TOL:g}, engine {f['engine_vs_ref']:.2e} (bound "
                        f"{f['bound']:.2e}), brute force {f['brute_vs_ref']:.2e}; free/forced ratio reference "
                        f"{f['ratio_ref']:.4g}, engine {f['ratio_engine']:.4g}, brute {f['ratio_brute']:.4g} "
                        f"({f['seconds']:.0f} s)")
    return "\n".join(out + ([""] + refs if refs else []))


# --- the stated bound against tight references ---------------------------------------------------
MARGIN_TOL = 1e-15             # the references' tolerance (scalar Taylor on the scaled variable)


SCAN_DELTA = (0.3, 0.5, 0.7, 0.9, 0.95, 0.98)
SCAN_BETA = (-0.52, -0.55, -0.6, -0.65, -0.7)


def bound_points() -> list[tuple]:
    """(name, model, delta, chi_deg, |omega0|): the validation and disputed points; the
    audit's (0.7, 29 deg) and two cells beside it (the balanced state just inside (4.17), the
    transverse one where mu falls slowest); and a scan of the reduced transverse state between
    the 3|4 boundary beta(4.18) = -1/2 and the 4|5 band (``SCAN_BETA`` at each of ``SCAN_DELTA``),
    where omega3 dies as tau^(beta + 1/2), slowest by the boundary, so the smaller amplitude b
    stays large against the bound's |(a, b)| term for decades."""
    from ...physics import asymptotics as FM
    from .convergence import points as conv

    scan = [(f"scan beta = {b:g}", "reduced", d, round(math.degrees(chi_at_beta(d, b)), 2), 0.1)
            for d in SCAN_DELTA for b in SCAN_BETA]
    near = [("4 by 3|4: b slow", "reduced", 0.7, 29.0, 0.1), ("4 by 4|5: mu slow", "reduced", 0.7, 31.0, 0.1),
            ("3 by 3|4", "reduced", 0.7, 25.0, 0.1)]
    near = [(f"{n} (beta = {FM.type4_eq4_18(d, math.radians(c))['beta']:.2f})", m, d, c, w) for n, m, d, c, w in near]
    return conv() + near + scan


def margins(members: int = 8, tau_end: float = 1e12, points=None, seed: int = 1, progress=None) -> list[dict]:
    """The hand-over engine's stated bound where it was measured: per point, ``members`` starts
    run by the engine (rtol 1e-8, as the atlases) to ``tau_end``, and each handed-over one again
    by a scalar Taylor integrator at ``MARGIN_TOL`` (``full_run``), both read through the same
    near-identity transform.  Per point: how many handed over, the largest and median error
    over the bound, how many beyond it, and the error of the smaller amplitude as a share of
    itself over mu_h^2 (signed: its largest magnitude, and how many are positive)."""
    say = progress or (lambda m: None)
    rows = []
    for name, model, d, cdeg, w in (points or bound_points()):
        say(f"bound: {name}")
        chi = math.radians(cdeg)
        starts = directions(members, seed) * w
        t0 = time.perf_counter()
        en = HO.cell_records(model, d, chi, starts, Settings(tau_end=tau_end, rtol=1e-8))
        flow = AV.Flow(model, d, chi) if d != 0.0 and 0.0 < chi < 0.5 * math.pi else None
        over, first, small = [], [], []
        state = flow.stable_state() if flow is not None else None
        axial = state is None or (model == "reduced" and state.name == "axial")
        for k, e in enumerate(en):
            lim = e.limit or {}
            if flow is None or not math.isfinite(lim.get("tau_handover", math.nan)):
                continue
            wr = full_run(model, d, chi, starts[k], [tau_end], MARGIN_TOL)[-1]
            a, b = (float(x) for x in AV.scaled_amplitudes(flow, wr[0] + 1j * wr[1], wr[2], tau_end))
            ea, eb = lim["abar_end"] - a, abs(lim["bbar_end"]) - b
            over.append(max(abs(ea), abs(eb)) / lim["bound"])
            if not axial:               # the first term alone (+ the floor): the bound without the smaller one's share
                floor = lim.get("noise_floor", math.nan)
                alone = HO.BOUND_C * lim["mu_handover"] ** 2 * math.hypot(lim["abar_end"], lim["bbar_end"])
                first.append(max(abs(ea), abs(eb)) / (alone + (floor if math.isfinite(floor) else 0.0)))
            if not lim.get("spiral_unresolved", 0):         # a free spiral below the noise: no share of its own
                small.append((eb / b if b < a else ea / a) / lim["mu_handover"] ** 2)
        rows.append({"point": name, "model": model, "delta": d, "chi_deg": cdeg, "omega0": w, "members": members,
                     "tau_end": tau_end, "handed_over": len(over),
                     "max_over_bound": float(max(over)) if over else math.nan,
                     "median_over_bound": float(np.median(over)) if over else math.nan,
                     "beyond_bound": int(sum(x > 1.0 for x in over)),
                     "max_over_first_term": float(max(first)) if first else math.nan,
                     "small_share_mu2": float(max(small, key=abs)) if small else math.nan,
                     "small_positive": int(sum(x > 0.0 for x in small)), "seconds": time.perf_counter() - t0})
    return rows


def format_margins(rows: list[dict]) -> str:
    """The bound rows as a Markdown table."""
    out = ["| point | model | δ | χ | handed over | error / bound: largest, median | beyond | error / first term "
           "alone: largest | smaller amplitude's error / (itself × μ_h²): largest, positive |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        n = r["handed_over"]
        err = f"{r['max_over_bound']:.2f}, {r['median_over_bound']:.2f}" if n else "-"
        sm = f"{r['small_share_mu2']:+.2f}, {r['small_positive']}/{n}" if n and math.isfinite(r["small_share_mu2"]) else "-"
        ft = f"{r['max_over_first_term']:.2f}" if n and math.isfinite(r["max_over_first_term"]) else "-"
        out.append(f"| {r['point']} | {r['model']} | {r['delta']:g} | {r['chi_deg']:.2f}° | {n}/{r['members']} | {err} | "
                   f"{r['beyond_bound'] if n else '-'} | {ft} | {sm} |")
    return "\n".join(out)


# --- the 4|5 band: basin fractions against beta -------------------------------------------------
BAND_DELTA = 0.5
BAND_CHI_DEG = (39.0, 40.0, 41.0, 42.0, 43.0, 44.0)  # delta = 0.5: beta(4.18) = -0.617 ... -0.795
OTHER_DELTA = 0.4                                   # the same betas at another delta
AUDIT_CHI_DEG = 47.0                                # (0.4, 47 deg), beta = -0.730: the independent audit's point
SPREAD_DELTA = (0.2, 0.8)                           # the audit's beta at deltas farther apart
CONFIDENCE = 0.95


def chi_at_beta(delta: float, beta: float) -> float:
    """chi (rad) where beta of (4.18), -(2 + delta) xi / (2 (1 - delta)(xi + 2)), equals ``beta``."""
    xi = -4.0 * (1.0 - delta) * beta / (2.0 + delta + 2.0 * (1.0 - delta) * beta)
    return math.atan(math.sqrt(xi))


def band_points() -> list[tuple]:
    """(delta, chi_deg) across the 4|5 band: ``BAND_CHI_DEG`` at ``BAND_DELTA``, then the same
    betas of (4.18) at ``OTHER_DELTA`` (whether the shares follow beta alone), then the
    audit's point (``OTHER_DELTA``, ``AUDIT_CHI_DEG``) and its beta at ``BAND_DELTA`` and at
    ``SPREAD_DELTA``."""
    from ...physics import asymptotics as FM

    pts = [(BAND_DELTA, c) for c in BAND_CHI_DEG]
    betas = [FM.type4_eq4_18(BAND_DELTA, math.radians(c))["beta"] for c in BAND_CHI_DEG]
    pts += [(OTHER_DELTA, round(math.degrees(chi_at_beta(OTHER_DELTA, b)), 2)) for b in betas]
    audit = FM.type4_eq4_18(OTHER_DELTA, math.radians(AUDIT_CHI_DEG))["beta"]
    return pts + [(OTHER_DELTA, AUDIT_CHI_DEG)] + [(d, round(math.degrees(chi_at_beta(d, audit)), 2))
                                                   for d in (BAND_DELTA,) + SPREAD_DELTA]


def share_interval(k: int, n: int, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """The Clopper-Pearson interval of a share k/n, by its closed form in the beta
    distribution's quantiles (lower B^-1(a/2; k, n - k + 1), upper B^-1(1 - a/2; k + 1, n - k),
    a = 1 - ``confidence``; 0 and 1 at k = 0, n): its coverage is at least ``confidence`` for
    every true share, where Wilson's dips below it (to ~0.83 at 32 starts near shares of 0
    and 1) -- and the table's claims are of both kinds, a type absent from a cell and two
    types sharing it."""
    from scipy.stats import beta

    a, k, n = 1.0 - confidence, int(k), int(n)
    lo = float(beta.ppf(0.5 * a, k, n - k + 1)) if k > 0 else 0.0
    hi = float(beta.ppf(1.0 - 0.5 * a, k + 1, n - k)) if k < n else 1.0
    return lo, hi


def starts_needed(half_width: float, confidence: float = CONFIDENCE) -> int:
    """The fewest starts whose Clopper-Pearson interval at a share of 1/2 (the widest) is at
    most +-``half_width``."""
    n = 4
    while True:
        lo, hi = share_interval(n // 2, n, confidence)
        if 0.5 * (hi - lo) <= half_width:
            return n
        n += 2


def basins(members: int = 128, tau_end: float = 1e16, points=None, rtol: float = 1e-8, seed: int = 1,
           omega: float = 0.1, threads: int | None = None, progress=None) -> list[dict]:
    """Across the 4|5 band (``band_points``): per point, beta of (4.18) and the shares of the
    starts whose limit is type 4 and type 5, with their Clopper-Pearson intervals (the
    hand-over engine: beyond beta = -3/4 the spiral is captured, a type-4 run counting as 5
    with its ``lock_to_5_at_tau``; before it both are attractors and the shares are the basins'
    fractions among starts uniform on the sphere at |omega0| = ``omega``), and what is still
    unsettled.  The points run in ``threads`` threads (the cores)."""
    from concurrent.futures import ThreadPoolExecutor

    from ...executors.processes import usable_cores
    from ...physics import asymptotics as FM

    say = progress or (lambda m: None)
    starts = directions(members, seed) * omega
    pts = list(points or band_points())

    def one(p):
        d, cdeg = p
        say(f"basins: delta {d:g}, chi {cdeg:g} deg")
        return HO.cell_records("reduced", d, math.radians(cdeg), starts, Settings(tau_end=tau_end, rtol=rtol))

    with ThreadPoolExecutor(threads or usable_cores(), thread_name_prefix="spinviz-basins") as pool:
        per = list(pool.map(one, pts))
    rows = []
    for (d, cdeg), recs in zip(pts, per):
        lim = Counter(_limit(r) for r in recs)
        lock = [r.evidence[RN.C.EVIDENCE.index("lock_to_5_at_tau")] for r in recs if _limit(r) == "5" and r.label == "4"]
        k4, k5 = lim.get("4", 0), lim.get("5", 0)
        rows.append({"delta": d, "chi_deg": float(cdeg), "beta": FM.type4_eq4_18(d, math.radians(cdeg))["beta"],
                     "members": members, "tau_end": tau_end, "omega0": omega, "limit": dict(lim),
                     "at_tau_end": dict(Counter(_shown(r) for r in recs)),
                     "share_4": k4 / members, "ci_4": share_interval(k4, members),
                     "share_5": k5 / members, "ci_5": share_interval(k5, members), "other": members - k4 - k5,
                     "captured_later": len(lock), "median_lock_tau": float(np.nanmedian(lock)) if lock else math.nan})
    return rows


def format_basins(rows: list[dict]) -> str:
    """The basin rows as a Markdown table (95 % Clopper-Pearson intervals in brackets)."""
    out = ["| δ | χ | β (4.18) | as τ → ∞: type 4 | type 5 | other | at τ_end | type 4 at τ_end captured later "
           "(median τ) |", "|---|---|---|---|---|---|---|---|"]
    pc = lambda x, ci: f"{100 * x:.0f} % [{100 * ci[0]:.0f}, {100 * ci[1]:.0f}]"  # noqa: E731
    for r in sorted(rows, key=lambda r: (-r["beta"], r["delta"])):
        at = ", ".join(f"{k} {v}" for k, v in sorted(r["at_tau_end"].items(), key=lambda kv: -kv[1]))
        lock = f"{r['captured_later']} ({r['median_lock_tau']:.1e})" if r["captured_later"] else "0"
        out.append(f"| {r['delta']:g} | {r['chi_deg']:.2f}° | {r['beta']:.3f} | {pc(r['share_4'], r['ci_4'])} | "
                   f"{pc(r['share_5'], r['ci_5'])} | {r['other']} | {at} | {lock} |")
    n = rows[0]["members"] if rows else 0
    out += ["", f"{n} starts per point (|ω0| = {rows[0]['omega0'] if rows else 0:g}, τ_end = "
                f"{rows[0]['tau_end'] if rows else 0:.0e}); brackets: 95 % Clopper–Pearson intervals."]
    pairs = equal_beta(rows)
    if pairs:
        out += ["", "At equal β, type 4's share against δ = "
                f"{BAND_DELTA:g}'s (Fisher's exact test: p, the chance of counts as far apart from one share):", ""]
        out += [f"* β = {q['beta']:.3f}: δ = {q['delta']:g} {100 * q['share']:.0f} % against {100 * q['share_band']:.0f} %, "
                f"p = {q['p']:.2g}" for q in pairs]
    return "\n".join(out)


def equal_beta(rows: list[dict]) -> list[dict]:
    """Each row off ``BAND_DELTA`` against the ``BAND_DELTA`` row of the same beta (within 1e-3):
    type 4's two shares and Fisher's exact test of their counts -- whether the share is a
    function of beta alone."""
    from scipy.stats import fisher_exact

    band = [r for r in rows if r["delta"] == BAND_DELTA]
    out = []
    for r in sorted((r for r in rows if r["delta"] != BAND_DELTA), key=lambda r: (-r["beta"], r["delta"])):
        same = [b for b in band if abs(b["beta"] - r["beta"]) < 1e-3]
        if not same:
            continue
        b = same[0]
        k, kb = r["limit"].get("4", 0), b["limit"].get("4", 0)
        p = float(fisher_exact([[k, r["members"] - k], [kb, b["members"] - kb]]).pvalue)
        out.append({"beta": r["beta"], "delta": r["delta"], "share": k / r["members"], "share_band": kb / b["members"], "p": p})
    return out


# --- the averaged flows against full integration -------------------------------------------------
FLOW_CELLS = (("reduced", 0.3, 0.72, "3"), ("reduced", -0.6, math.radians(77.0), "3 below delta = -1/2"),
              ("reduced", 0.5, math.radians(39.0), "4"), ("reduced", 0.5, math.radians(20.0), "2"),
              ("reduced", 0.5, math.radians(14.0), "2 -> 1"), ("reduced", -0.6, 0.3, "1"),
              ("truncated", -0.5, 0.8, "T2"), ("truncated", 0.3, 0.72, "T4"))
FLOW_MU = (1e-1, 5e-2, 3e-2, 1e-2, 3e-3, 1e-3)


def flows(cells=FLOW_CELLS, mus=FLOW_MU, tau_f: float = 1e10, tol: float = 1e-15, progress=None) -> list[dict]:
    """The averaged flow against full integration: per cell one start (omega0 = (0.06, -0.05,
    0.05)) run by a scalar Taylor integrator at ``tol`` to ``tau_f`` on 40 samples a decade,
    handed over at the first sample below each mu of ``mus``; the averaged amplitudes at tau_f
    against the full run's (read through the same transform): the error, the engine's stated
    bound (``handover_engine.stated_bound`` without the noise floor), the error / mu_h^2, and the
    order fitted over ``mus``."""
    say = progress or (lambda m: None)
    rows = []
    for model, d, chi, what in cells:
        say(f"flows: {model} ({d:g}, {math.degrees(chi):.1f} deg)")
        f = AV.Flow(model, d, chi)
        w0 = np.array([0.06, -0.05, 0.05])
        tau = np.logspace(3, math.log10(tau_f), int(round(40 * (math.log10(tau_f) - 3))) + 1)
        t0 = time.perf_counter()
        w = full_run(model, d, chi, w0, tau, tol)
        mu = f.small_parameter(np.hypot(w[:, 0], w[:, 1]), w[:, 2])
        a_ref, b_ref = AV.scaled_amplitudes(f, w[-1, 0] + 1j * w[-1, 1], w[-1, 2], tau[-1])
        pts = []
        for target in mus:
            if not (mu[:-40] < target).any():                 # not reached a decade before tau_f
                continue
            i = int(np.argmax(mu < target))
            r = HO.averaged_stage([f], tau, [i], [w[i]], math.inf)[0]
            a, b = math.exp(0.5 * r["lnA"][-1]), math.exp(0.5 * r["lnB"][-1])
            err = max(abs(a - a_ref), abs(b - b_ref))
            pts.append({"mu_h": float(mu[i]), "tau_h": float(tau[i]), "error": err,
                        "bound": HO.stated_bound(float(mu[i]), a, b, r["mu2_int"], delta=d), "error_over_mu2": err / mu[i] ** 2})
        order = float(np.polyfit(np.log([p["mu_h"] for p in pts]), np.log([p["error"] for p in pts]), 1)[0])
        rows.append({"model": model, "delta": d, "chi_deg": math.degrees(chi), "type": what, "tau_f": tau_f,
                     "order": order, "points": pts, "seconds": time.perf_counter() - t0,
                     "within_bound": all(p["error"] <= p["bound"] for p in pts),
                     "max_error_over_bound": max(p["error"] / p["bound"] for p in pts)})
    return rows


def format_flows(rows: list[dict]) -> str:
    """The flow rows as a Markdown table."""
    out = ["| cell | type | error at mu_h = " + " / ".join(f"{m:.0e}".replace("e-0", "e-") for m in FLOW_MU)
           + " | largest error / bound | order in mu_h |", "|---|---|---|---|---|"]
    for r in rows:
        errs = " / ".join(f"{p['error']:.1e}" for p in r["points"]) + " / -" * (len(FLOW_MU) - len(r["points"]))
        out.append(f"| {r['model']} ({r['delta']:g}, {r['chi_deg']:.1f}°) | {r['type']} | {errs} | "
                   f"{r['max_error_over_bound']:.2f} | {r['order']:.2f} |")
    return "\n".join(out)
