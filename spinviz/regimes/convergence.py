"""Convergence evidence for the atlas's labels (issue 18.3): horizon and member count.

    python -m spinviz.regimes.convergence [--members 32] [--out atlas_convergence.zarr] [--json PATH]

For a validation subset -- the points of ``validate.POINTS`` (every domain of figure 2 and
the truncated types) and the four points where the paper is disputed -- each point's starts
are run to tau_end, 100 tau_end and 1e4 tau_end (1e10, 1e12, 1e14 by default), and with 4x the
members at tau_end.  Per point the table says:

* the label shares at each horizon, and the share of the members that keep their label from
  tau_end to 1e4 tau_end;
* the share of the 4x members carrying the point's main label, against the base members';
* **coexistence**: two types each held by >= 10 % of the starts at every horizon (the starts
  stay apart as tau grows);
* **slow hand-over**: members still changing between the horizons (their label at 1e4
  tau_end differs from tau_end's, or they are "approaching" a type at the last horizon);
* the "other" share per horizon and what those runs are (the classifier's reasons).

The rows are written as JSON (``--json``), into an atlas store as its ``convergence``
attribute (``--store``: the figure atlas keeps the evidence it rests on), and as a Markdown
table for docs/atlas.md.
"""

from __future__ import annotations

import math
import sys
import time
from collections import Counter

import numpy as np

from . import classify as C
from .runs import Settings, classify_run, integrate_many
from .spec import directions

HORIZONS = (1e10, 1e12, 1e14)
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
    """Records (``runs.Record``) of every start to ``horizon``.

    Beyond ``base`` the tolerance tightens as base/horizon and the step budget grows as
    sqrt(horizon/base) (the steps of a spiral do): heyoka holds the error of the scaled state
    as a whole, so a component falling faster than 1/sqrt(tau) -- type 1's omega_perp ~ 1/tau --
    sinks into the error of the dominant one (measured at (-0.6, 17.2 deg): type 1 at 1e12 is "other" at
    rtol 1e-8, type 1 at rtol 1e-10, and at 1e14 type 1 with omega_perp^2 tau = B^2/tau at 1e-12)."""
    scale = max(1.0, horizon / base)
    st = Settings(tau_end=horizon, rtol=rtol / scale, max_steps=int(Settings().max_steps * math.sqrt(scale)))
    runs = integrate_many(model, [(delta, chi)] * len(starts), list(starts), st)
    return [classify_run(r, model, delta, chi, st) for r in runs]


def study(members: int = 32, horizons=HORIZONS, rtol: float = 1e-8, seed: int = 1, progress=None) -> list[dict]:
    """Per point: labels per horizon and with 4x members (see the module docstring)."""
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
    return {"point": name, "model": model, "delta": d, "chi_deg": cdeg, "omega0": w, "members": n,
            "shares": {f"{h:g}": dict(shares[h]) for h in hs}, "main": main,
            "keep_label": keep, "changing": changing, "coexisting": coexist if len(coexist) > 1 else [],
            "main_share": Counter(types[hs[0]])[main] / n, "main_share_4x": Counter(many_types)[main] / len(many_types),
            "other_share": {f"{h:g}": shares[h]["other"] / n for h in hs},
            "other_reasons": dict(reasons), "seconds": seconds,
            "X2": {f"{h:g}": float(np.median([r.evidence[C.EVIDENCE.index("X2")] for r in per_h[h]])) for h in hs}}


def format_table(rows: list[dict]) -> str:
    hs = list(rows[0]["shares"])
    lines = [f"| point | model | delta | chi | labels at tau = {' / '.join(hs)} | keep label {hs[0]} -> {hs[-1]} | "
             f"changing | coexisting | main type share, {rows[0]['members']} / {4 * rows[0]['members']} members | "
             f"\"other\" |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lab = " / ".join(", ".join(f"{k} {v}" for k, v in sorted(r["shares"][h].items(), key=lambda kv: -kv[1]))
                         for h in hs)
        oth = " / ".join(f"{100 * r['other_share'][h]:.0f} %" for h in hs)
        co = " + ".join(r["coexisting"]) or "no"
        lines.append(f"| {r['point']} | {r['model']} | {r['delta']:g} | {r['chi_deg']:.1f} | {lab} | "
                     f"{100 * r['keep_label']:.0f} % | {100 * r['changing']:.0f} % | {co} | "
                     f"{r['main']}: {100 * r['main_share']:.0f} % / {100 * r['main_share_4x']:.0f} % | {oth} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    import argparse

    from ..atomic import write_json

    ap = argparse.ArgumentParser(prog="python -m spinviz.regimes.convergence")
    ap.add_argument("--members", type=int, default=32)
    ap.add_argument("--horizons", default=",".join(f"{h:g}" for h in HORIZONS))
    ap.add_argument("--json")
    ap.add_argument("--store", help="an atlas store to record the rows in (attribute 'convergence')")
    a = ap.parse_args(argv)
    rows = study(a.members, tuple(float(x) for x in a.horizons.split(",")),
                 progress=lambda m: print(f"  {m}", file=sys.stderr, flush=True))
    print(format_table(rows))
    if a.json:
        write_json(a.json, rows)
    if a.store:
        record(a.store, rows)
    return 0


def record(store: str, rows: list[dict]) -> None:
    """Keep the rows in an atlas store (root attribute ``convergence``, JSON)."""
    import json

    import zarr

    g = zarr.open_group(store, mode="r+", zarr_format=2)
    g.attrs["convergence"] = json.dumps(rows, default=float)
    zarr.consolidate_metadata(store)


if __name__ == "__main__":
    sys.exit(main())
