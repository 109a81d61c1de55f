"""Convergence evidence for the atlas's labels: horizon, member count and tolerance.

    spinviz atlas evidence convergence [--members 32] [--horizons 1e10,1e12,1e14,1e16,1e20] [--out STORE] [--json]
    spinviz atlas evidence tolerance [--members 8]

For a validation subset -- the points of ``validate.POINTS`` (every domain of figure 2 and
the truncated types) and the four points where the paper is disputed -- each point's starts
are run by the atlas's engine (the hand-over engine, rtol 1e-10) to every horizon (1e10, 1e12,
1e14, 1e16, 1e20 by default), and with 4x the members at the first.  Per point the table says:

* the label shares at each horizon, and the share of the members that keep their label from
  tau_end to 1e4 tau_end;
* the share of the 4x members carrying the point's main label, against the base members';
* **coexistence**: two types each held by >= 10 % of the starts at every horizon (the starts
  stay apart as tau grows);
* **slow hand-over**: members still changing between the horizons (their label at the last
  horizon differs from the first's, or they are "approaching" a type at the last horizon);
* the "other" share per horizon and what those runs are (the classifier's reasons).

The rows are written as JSON (``--json``), into an atlas store as its ``convergence``
attribute (``--out STORE``: the figure atlas keeps the evidence it rests on), and as a Markdown
table for docs/atlas.md.

``tolerance`` asks the other question: on the quick atlas's 12 x 12 grid (every domain of
figure 2), how many labels does rtol change, and what does a looser one save?  Per model and
rtol: the share of labels equal to the tightest rtol's, the end states' relative difference
from it, and the integration and classification time per run (one thread).
"""

from __future__ import annotations

import math
import time
import warnings
from collections import Counter

import numpy as np

from ...inputs.atlas_spec import Settings, directions
from ...regimes.engine import classify as C
from ...regimes.engine.runs import classify_run, integrate_many

HORIZONS = (1e10, 1e12, 1e14, 1e16, 1e20)
COEXIST = 0.10            # a type held by at least this share of the starts at every horizon


def points() -> list[tuple]:
    """(name, model, delta, chi_deg, |omega0|): validate's points and the disputed ones."""
    from .validate import POINTS

    extra = [("4|5 coexistence below beta = -3/4", "reduced", 0.5, 42.0, 0.1),
             ("4|5 beyond beta = -3/4", "reduced", 0.5, 43.5, 0.1),
             ("near alpha = -1", "reduced", 0.5, 14.0, 0.1)]
    return list(POINTS) + extra


def run_point(model: str, delta: float, chi: float, starts: np.ndarray, horizon: float, rtol: float,
              base: float = HORIZONS[0]) -> list:
    """Records (``runs.Record``) of every start to ``horizon`` by the hand-over engine
    (``handover.cell_records``), whose cost does not grow with the horizon where the averaged
    flow holds, and which keeps the free spiral a brute-force run at rtol 1e-10 loses past
    ~1e12 near alpha = -1 (docs/atlas.md, "The hand-over engine against brute force")."""
    from ...regimes.engine.handover_engine import cell_records

    return cell_records(model, delta, chi, starts, Settings(tau_end=horizon, rtol=rtol))


def study(members: int = 32, horizons=HORIZONS, rtol: float = 1e-10, seed: int = 1, progress=None) -> list[dict]:
    """Per point: labels per horizon and with 4x members (see the module docstring).
    ``members`` and ``horizons`` are checked first (``inputs.options.EvidenceRequest``; the work against the cap by
    ``evidence.run``)."""
    from ...inputs.options import EvidenceRequest

    horizons = EvidenceRequest(members=members, horizons=horizons).horizons
    say = progress or (lambda m: None)
    rows = []
    for name, model, d, cdeg, w in points():
        chi = math.radians(cdeg)
        starts = directions(4 * members, seed) * w
        t0 = time.perf_counter()
        per_h = {}
        for h in horizons:
            say(f"{name}: tau_end = {h:g}")
            per_h[h] = run_point(model, d, chi, starts[:members], h, rtol, horizons[0])
        say(f"{name}: {4 * members} members")
        many = run_point(model, d, chi, starts, horizons[0], rtol, horizons[0])
        rows.append(summarize(name, model, d, cdeg, w, per_h, many, time.perf_counter() - t0))
    return rows


def _type(r) -> str:
    return r.candidate if r.label == "approaching" else r.label


def _shown(r) -> str:
    """A label as the table shows it: an approaching run as "->X"."""
    return f"->{r.candidate}" if r.label == "approaching" else r.label


def summarize(name, model, d, cdeg, w, per_h: dict, many: list, seconds: float) -> dict:
    """One point's row: label shares per horizon, what kept its label, coexistence, slow hand-overs, 'other'."""
    hs = sorted(per_h)
    labels = {h: [_shown(r) for r in per_h[h]] for h in hs}
    types = {h: [_type(r) for r in per_h[h]] for h in hs}
    n = len(labels[hs[0]])
    keep = sum(types[hs[0]][k] == types[hs[-1]][k] for k in range(n)) / n
    changing = sum(types[hs[0]][k] != types[hs[-1]][k] or labels[hs[-1]][k].startswith("->") for k in range(n)) / n
    shares = {h: Counter(labels[h]) for h in hs}
    main = Counter(types[hs[-1]]).most_common(1)[0][0]
    coexist = sorted(t for t in set(types[hs[-1]]) if t not in ("other", "failed")
                     and all(Counter(types[h])[t] / n >= COEXIST for h in hs))
    reasons = Counter(r.reason.split(" (")[0] for r in per_h[hs[-1]] if r.label == "other")
    many_types = [_type(r) for r in many]
    names = {v: k for k, v in C.CODE.items()}
    limit = Counter(names.get((r.limit or {}).get("label_inf", C.CODE.get(r.label, 0)), r.label) for r in per_h[hs[-1]])
    settled = sum(int((r.limit or {}).get("limit_settled", 0)) for r in per_h[hs[-1]]) / n
    return {"point": name, "model": model, "delta": d, "chi_deg": cdeg, "omega0": w, "members": n,
            "shares": {f"{h:g}": dict(shares[h]) for h in hs}, "main": main,
            "keep_label": keep, "changing": changing, "coexisting": coexist if len(coexist) > 1 else [],
            "main_share": Counter(types[hs[0]])[main] / n, "main_share_4x": Counter(many_types)[main] / len(many_types),
            "other_share": {f"{h:g}": shares[h]["other"] / n for h in hs},
            "other_reasons": dict(reasons), "seconds": seconds, "limit": dict(limit), "settled_last": settled,
            "X2": {f"{h:g}": float(np.median([r.evidence[C.EVIDENCE.index("X2")] for r in per_h[h]])) for h in hs}}


def format_table(rows: list[dict]) -> str:
    """The convergence rows as a Markdown table."""
    hs = list(rows[0]["shares"])
    lines = [f"| point | model | delta | chi | labels at tau = {' / '.join(hs)} | keep label {hs[0]} -> {hs[-1]} | "
             f"changing | coexisting | main type share, {rows[0]['members']} / {4 * rows[0]['members']} members | "
             f"\"other\" | as tau -> oo (settled at {hs[-1]}) |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lab = " / ".join(", ".join(f"{k} {v}" for k, v in sorted(r["shares"][h].items(), key=lambda kv: -kv[1]))
                         for h in hs)
        oth = " / ".join(f"{100 * r['other_share'][h]:.0f} %" for h in hs)
        co = " + ".join(r["coexisting"]) or "no"
        lines.append(f"| {r['point']} | {r['model']} | {r['delta']:g} | {r['chi_deg']:.1f} | {lab} | "
                     f"{100 * r['keep_label']:.0f} % | {100 * r['changing']:.0f} % | {co} | "
                     f"{r['main']}: {100 * r['main_share']:.0f} % / {100 * r['main_share_4x']:.0f} % | {oth} | "
                     f"{', '.join(f'{k} {v}' for k, v in sorted(r.get('limit', {}).items(), key=lambda kv: -kv[1]))} "
                     f"({100 * r.get('settled_last', 0.0):.0f} %) |")
    return "\n".join(lines)


def record(store: str, rows: list[dict], key: str = "convergence") -> None:
    """Keep the rows in an atlas store (root attribute ``key``, JSON), its metadata's
    checksums recorded again (the store stays verifiable)."""
    import json

    import zarr

    from ...regimes.store import integrity as IN

    def write():
        g = zarr.open_group(store, mode="r+", zarr_format=2)
        g.attrs[key] = json.dumps(rows, default=float)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*checksums is not recognized")   # our record, not Zarr's
            zarr.consolidate_metadata(store)

    IN.rewrite_metadata(store, [".zattrs", ".zmetadata"], write)


TOLERANCES = (1e-6, 1e-7, 1e-8, 1e-10)


def tolerance(members: int = 8, rtols=TOLERANCES, cells: int = 12, seed: int = 12, omega: float = 0.04,
              tau_end: float = 1e10, progress=None) -> list[dict]:
    """Labels and end states against rtol on a ``cells`` x ``cells`` grid (both models),
    against the tightest rtol of ``rtols``; see the module docstring.  ``members`` and
    ``tau_end`` are checked first (``inputs.options.EvidenceRequest``; the work against the cap by
    ``evidence.run``)."""
    from ...inputs.options import EvidenceRequest

    EvidenceRequest(members=members, tau_end=tau_end)
    from ...regimes.engine.runs import warm
    from ...regimes.store.levels import centres

    say = progress or (lambda m: None)
    grid = [(d, math.radians(c)) for d in centres(-1.0, 1.0, cells, 0) for c in centres(0.0, 90.0, cells, 0)]
    starts = directions(members, seed) * omega
    where = [cell for cell in grid for _ in range(members)]
    w0 = [w for _ in grid for w in starts]
    rows = []
    for model in ("reduced", "truncated"):
        found = {}
        for rt in sorted(rtols):
            st = Settings(tau_end=tau_end, rtol=rt)
            warm(st)
            say(f"{model}: rtol {rt:g}, {len(where)} runs")
            t0 = time.perf_counter()
            runs = integrate_many(model, where, w0, st)
            t1 = time.perf_counter()
            labels = [classify_run(r, model, d, c, st).label for r, (d, c) in zip(runs, where)]
            t2 = time.perf_counter()
            found[rt] = (labels, np.array([r.omega[-1] for r in runs]), t1 - t0, t2 - t1)
        ref_rt = min(rtols)
        ref_lab, ref_w = found[ref_rt][0], found[ref_rt][1]
        norm = np.linalg.norm(ref_w, axis=1)
        for rt in sorted(rtols, reverse=True):
            labels, w, t_int, t_cls = found[rt]
            diff = np.linalg.norm(w - ref_w, axis=1) / np.where(norm > 0, norm, 1.0)
            rows.append({"model": model, "rtol": rt, "reference_rtol": ref_rt, "runs": len(labels),
                         "same_label": float(np.mean([a == b for a, b in zip(labels, ref_lab)])),
                         "end_state_median": float(np.median(diff)), "end_state_max": float(np.max(diff)),
                         "ms_per_run": 1e3 * t_int / len(labels), "classify_ms_per_run": 1e3 * t_cls / len(labels)})
    return rows


def format_tolerance(rows: list[dict]) -> str:
    """The tolerance rows as a Markdown table."""
    out = ["| model | rtol | labels as at the tightest rtol | end state rel. diff. median / max | integration ms/run "
           "| classification ms/run |", "|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['model']} | {r['rtol']:g} | {100 * r['same_label']:.2f} % (rtol {r['reference_rtol']:g}) | "
                   f"{r['end_state_median']:.1e} / {r['end_state_max']:.1e} | {r['ms_per_run']:.2f} | "
                   f"{r['classify_ms_per_run']:.2f} |")
    return "\n".join(out)
