"""The atlas at single points inside each domain: label shares, exponents and amplitudes
against the paper's formulas (docs/atlas.md's validation table).

    spinviz atlas evidence validate [--members 32] [--workers 2] [--json]

Each point is an atlas of one cell (built with ``parse_spec``, run with ``atlas`` into a
temporary store, the default engine, tau_end = 1e16 as the shipped atlases), so the table is
made by exactly the code that makes the diagrams.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
from collections import Counter

import numpy as np

from ...inputs.atlas_spec import parse_spec
from ...physics import asymptotics as FM
from ...regimes.api import atlas
from ...regimes.engine import classify as C

# (name, model, delta, chi_deg, |omega0|)
POINTS = [
    ("2: alpha above -1", "reduced", 0.5, 22.0, 0.1),
    ("2 -> 1: alpha = -21.7", "reduced", -0.6, math.degrees(0.3), 0.1),
    ("3 deep", "reduced", 0.8, 11.4, 0.1),
    ("3 slow", "reduced", 0.3, math.degrees(0.72), 0.1),
    ("3 at delta < -1/2", "reduced", -0.6, 77.0, 0.1),
    ("4, beta > -3/4", "reduced", 0.5, 39.0, 0.1),
    ("4 -> 5: beta = -0.83", "reduced", 0.5, 45.0, 0.1),
    ("5 in '?' and (4.43)", "reduced", 0.8, math.degrees(1.2), 0.1),
    ("5 outside (4.43)", "reduced", 0.2, 70.0, 0.1),
    ("T4", "truncated", 0.5, 22.0, 0.04),
    ("T2", "truncated", -0.6, 60.0, 0.04),
    ("TF", "truncated", 0.8, math.degrees(1.2), 0.04),
]


def run(members: int = 32, workers: int | None = None, tau_end: float = 1e16, points=POINTS, progress: bool = False):
    """A single-cell atlas at each validation point; one row per point with its labels and formulas.
    ``members``, ``workers`` and ``tau_end`` are checked first (``inputs.options.EvidenceRequest``; the work against the cap by
    ``evidence.run``)."""
    from ...inputs.options import EvidenceRequest

    EvidenceRequest(members=members, workers=workers, tau_end=tau_end)
    rows = []
    tmp = tempfile.mkdtemp(prefix="spinviz-atlas-validate-")
    try:
        for i, (name, model, d, cdeg, w) in enumerate(points):
            spec = parse_spec({"title": name, "models": [model], "grid": {"delta": [d], "chi_deg": [cdeg]},
                               "members": {"count": members, "seed": 1, "omega": w}, "run": {"tau_end": tau_end}},
                              f"<validation point {name}>")
            out = os.path.join(tmp, f"p{i}.zarr")
            res = atlas(spec, out, workers=workers, progress=progress)
            from ...regimes.store.dataset import open_atlas

            ds = open_atlas(out).isel(model=0, delta=0, chi=0)
            labels = [str(x) for x in ds["label"].values]
            shares = Counter(labels)
            top = shares.most_common(1)[0][0]
            sel = np.array([lab == top for lab in labels])
            vals = {q: ds[q].values for q in C.EVIDENCE}        # read from the store once
            ev = {q: v[sel] for q, v in vals.items()}
            devs = {}
            for k in range(members):
                if sel[k]:
                    e = {q: float(v[k]) for q, v in vals.items()}
                    for key, val in C.deviations(top, e, d, math.radians(cdeg), model).items():
                        devs.setdefault(key, []).append(val)
            rows.append({"point": name, "model": model, "delta": d, "chi_deg": cdeg, "omega0": w, "members": members,
                         "shares": dict(shares), "label": top,
                         "median": {q: float(np.median(ev[q])) for q in ("slope_perp", "slope_3", "X2", "Y2", "w2_tau",
                                                                         "libration_A2", "h_mean")
                                    if q in ev},
                         "deviations": {k: (float(np.median(v)), float(np.min(v)), float(np.max(v))) for k, v in devs.items()},
                         "seconds": res.seconds,
                         "median_run_s": float(np.nanmedian(ds["run_seconds"].values))})
            shutil.rmtree(out, ignore_errors=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return rows


def format_table(rows) -> str:
    """The validation rows as a Markdown table."""
    lines = ["| point | model | δ | χ | labels | median measured | deviation from the formula, median [min, max] |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        sh = ", ".join(f"{k} {v}/{r['members']}" for k, v in sorted(r["shares"].items(), key=lambda x: -x[1]))
        m = r["median"]
        meas = f"p {m['slope_perp']:.4f}, q {m['slope_3']:.4f}, X² {m['X2']:.4g}, Y² {m['Y2']:.4g}"
        if r["label"] == "1":
            meas += f", ω₂τ {m['w2_tau']:.4g}"
        if r["label"] == "5":
            meas += f", A²(4.23) {m['libration_A2']:.4g}, h {m['h_mean']:.4f}"
        dev = "; ".join(f"{k} {100 * v[0]:+.2f} % [{100 * v[1]:+.2f}, {100 * v[2]:+.2f}]" for k, v in r["deviations"].items())
        if not dev and r["label"] == "5":
            a2 = FM.type5_eq4_42(r["delta"], math.radians(r["chi_deg"]))["A2"]
            dev = f"(4.42) has no real solution here (A² = {a2:.3g})"
        lines.append(f"| {r['point']} | {r['model']} | {r['delta']:g} | {r['chi_deg']:.1f}° | {sh} | {meas} | {dev or '—'} |")
    return "\n".join(lines)


# --- (4.42) read as peak and as r.m.s. ----------------------------------------------------------
LIBRATION = ("5 in '?' and (4.43)", 0.8, 1.2)     # the type-5 point where (4.42) is real


def libration_readings(members: int = 8, delta: float = LIBRATION[1], chi: float = LIBRATION[2], omega: float = 0.1,
                       tau: float = 1e10, span: float = 2.0, samples: int = 40001, seed: int = 1) -> dict:
    """(4.42)'s A^2 and M^2 read both ways the paper allows.  (4.33) writes the swing as
    omega_angle = f cos(phi), omega3 = v sin(phi) + w cos(phi) with f = A tau^-1/2, v = M tau^-3/4:
    A, M are amplitudes, the peaks of omega_angle sqrt(tau), omega3 tau^(3/4) over a swing; for the
    harmonic swing (4.33) assumes, the same as sqrt(2) x their r.m.s.  The measured swing is
    anharmonic (~40 deg), so the two readings differ.  Each of ``members`` starts (|omega0| =
    ``omega``, ``seed``) is integrated by a scalar Taylor integrator at tol 1e-12 to ``tau`` and
    sampled ``samples`` times evenly over [tau, span tau] (~20 swings at (0.8, 1.2)); per
    start the relative deviations from (4.42) of the peak readings (max A^2 = max omega_angle^2
    tau, max M^2 = max omega3^2 tau^(3/2)), of the r.m.s. readings (2 <...>), and of B (mean
    omega2 sqrt(tau): a mean either way).  Returns {"point", "delta", "chi", "members", "tau",
    name: (median, min, max)}."""
    from ...inputs.atlas_spec import directions
    from .against_brute_force import full_run

    f = FM.type5_eq4_42(delta, chi)
    n1, n3 = math.sin(chi), math.cos(chi)
    t = np.linspace(tau, span * tau, samples)
    per: dict = {}
    for w0 in directions(members, seed) * omega:
        w = full_run("reduced", delta, chi, w0, t, tol=1e-12)
        a2 = (w[:, 0] + (n3 / n1) * (1.0 - delta) * w[:, 2]) ** 2 * t          # omega_angle (4.23)^2 tau
        m2 = w[:, 2] ** 2 * t**1.5
        got = {"A^2 peak": (a2.max(), f["A2"]), "A^2 r.m.s.": (2.0 * a2.mean(), f["A2"]),
               "M^2 peak": (m2.max(), f["M2"]), "M^2 r.m.s.": (2.0 * m2.mean(), f["M2"]),
               "B": (float(np.mean(w[:, 1] * np.sqrt(t))), f["B"])}
        for k, (meas, pred) in got.items():
            per.setdefault(k, []).append((meas - pred) / abs(pred))
    out = {"point": LIBRATION[0], "delta": delta, "chi": chi, "members": members, "tau": tau, "span": span}
    out.update({k: (float(np.median(v)), float(np.min(v)), float(np.max(v))) for k, v in per.items()})
    return out


def format_libration(r: dict) -> str:
    """The two readings of (4.42) as a Markdown table."""
    lines = [f"(4.42) at {r['point']} (δ = {r['delta']:g}, χ = {math.degrees(r['chi']):.2f}°), {r['members']} starts, "
             f"dense samples over τ = {r['tau']:.0e} … {r['span'] * r['tau']:.0e}: deviation from (4.42), median [min, max]", "",
             "| quantity | peak (the classifier's) | r.m.s. (2 × mean square) |", "|---|---|---|"]
    fmt = lambda v: f"{100 * v[0]:+.1f} % [{100 * v[1]:+.1f}, {100 * v[2]:+.1f}]"  # noqa: E731
    for q in ("A^2", "M^2"):
        lines.append(f"| {q} | {fmt(r[q + ' peak'])} | {fmt(r[q + ' r.m.s.'])} |")
    lines.append(f"| B (a mean) | {fmt(r['B'])} | {fmt(r['B'])} |")
    return "\n".join(lines)


# --- the diagram against the domains ---------------------------------------------------------
def paper_domain(delta: float, chi: float) -> str:
    """The type figure 2 assigns to a cell: (4.15) "2", (4.17) "3", (4.19) "4", (4.20) "?",
    or "none" (delta <= -1/2 above (4.15): no domain of the paper)."""
    xi = math.tan(chi) ** 2
    if xi < FM.xi_eq4_15(delta):
        return "2"
    if delta > -0.5 and xi <= FM.xi_eq4_17(delta):
        return "3"
    if delta > 0.0 and xi > FM.xi_eq4_20(delta):
        return "?"
    if delta > -0.5:
        return "4"
    return "none"


def spinviz_domain(delta: float, chi: float) -> str:
    """The late state spinviz's reading of the averaged flow predicts: "1" below alpha = -1,
    "2" up to (4.15), "3" where (4.16) is positive, "5" beyond beta = -3/4 (delta > -1/5),
    else "4"."""
    xi = math.tan(chi) ** 2
    if xi < FM.xi_spinviz_alpha_minus_one(delta):
        return "1"
    if xi < FM.xi_eq4_15(delta):
        return "2"
    if FM.type3_eq4_16(delta, chi)["positive"]:
        return "3"
    if delta > -0.2 and xi > FM.xi_spinviz_beta_minus_three_quarters(delta):
        return "5"
    return "4"


def compare_domains(ds, model: str = "reduced") -> dict:
    """``ds``: ``store.open_atlas(path)``.  Majority label of each cell against ``paper_domain`` and ``spinviz_domain``:
    {"paper": {domain: Counter of majority labels}, "spinviz": {...}, "cells": n, "agree_spinviz": k}."""
    lab = ds["label"].sel(model=model).values
    out = {"paper": {}, "spinviz": {}, "cells": 0, "agree_spinviz": 0, "agree_paper": 0, "share_other": 0.0}
    for i, d in enumerate(ds["delta"].values):
        for j, c in enumerate(ds["chi"].values):
            maj = Counter(str(x) for x in lab[i, j]).most_common(1)[0][0]
            p, s = paper_domain(float(d), float(c)), spinviz_domain(float(d), float(c))
            out["paper"].setdefault(p, Counter())[maj] += 1
            out["spinviz"].setdefault(s, Counter())[maj] += 1
            out["cells"] += 1
            out["agree_spinviz"] += maj == s
            out["agree_paper"] += maj == p
    out["share_other"] = float(np.isin(lab, ["other", "1|2", "4|5"]).mean())
    return out

