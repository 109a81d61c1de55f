"""Pictures of an atlas: the delta-chi diagram (figures 2, 3.D and 5) and the hodographs (figure 3).

* ``diagram``: one panel per model; each cell is split into bars whose widths are the shares
  of the types among its members (computed, not yet computed, failed and "other" included),
  with the paper's boundaries (4.15), (4.17), (4.19), (4.20), (4.43) drawn over it (black),
  spinviz's derived lines (blue: alpha = -1, red: beta = -3/4; see ``formulas``) and the two
  DAST families of figure 5 (grey: family 1 solid, family 2 dash-dotted).
* ``hodographs``: one small panel per type found, the run with the highest confidence of that
  type re-integrated (the store keeps summaries, not series; the runs are deterministic), as
  omega scaled by sqrt(tau + 1/|omega0|^2): the unit sphere at the start, omega sqrt(tau) at
  the end, where the asymptotic types are fixed points (1), circles (3, 4), spirals onto an
  axis (2) or arcs (5).
"""

from __future__ import annotations

import math
import os
import textwrap

import numpy as np

from ..atomic import Outputs, check_outputs
from ..errors import UsageError
from ..plotting import pyplot
from . import classify as C
from . import formulas as FM

# Okabe & Ito's colour-blind-safe palette; a truncated type shares the colour of the reduced
# type it resembles (T2 ~ 2, Tcone ~ 3, T4 ~ 4, TF ~ the frozen 3.9).
COLORS = {"1": "#0072B2", "2": "#56B4E9", "3": "#009E73", "4": "#E69F00", "5": "#D55E00", "3.9": "#CC79A7",
          "R": "#F0E442", "T2": "#56B4E9", "Tcone": "#009E73", "T4": "#E69F00", "TF": "#CC79A7", "T1": "#0072B2",
          "T5": "#D55E00", "other": "#dddddd", "1|2": "#dddddd", "4|5": "#dddddd", "approaching": "#bbbbbb",
          "failed": "#000000", "missing": "#ffffff"}
ORDER = ("1", "2", "3", "4", "5", "3.9", "R", "T2", "Tcone", "T4", "TF", "approaching", "other", "failed", "missing")
# what each type is, in plain words (the diagram's legend; the paper's section 4 for the formulas)
WORDS = {
    "1": "1: spin about the symmetry axis, the cross spin dies as 1/\u03c4",
    "2": "2: spiral onto the symmetry axis",
    "3": "3: balanced spiral, both parts fall as 1/\u221a\u03c4",
    "4": "4: spiral with the cross spin dominant",
    "5": "5: wobble about a cross axis (libration)",
    "3.9": "(3.9): rotation about e\u2082 itself",
    "R": "R: keeps spinning about the dipole",
    "T2": "T2: slows to rest, spin gathering on the axis",
    "Tcone": "Tcone: slows to rest on a fixed cone",
    "T4": "T4: slows to rest, cross spin dominant",
    "TF": "TF: slows to rest, turning about a fixed cross axis",
}
COEXIST = 0.10             # a type "coexists" in a cell when it holds at least this share next to another


def hodograph_path(path: str) -> str:
    stem, ext = os.path.splitext(path)
    return f"{stem}_hodographs{ext}"


def page_path(path: str) -> str:
    """The interactive page drawn beside the diagram ``path``: ``<stem>.html``."""
    return f"{os.path.splitext(path)[0]}.html"


def check_plot_paths(path: str, out: str, spec=None) -> list[str]:
    """The three output paths of ``--plot PATH`` -- the diagram, the hodographs and the
    page -- checked before any work."""
    if os.path.splitext(path)[1].lower() != ".png":
        raise UsageError(f"--plot: {path}: the pictures are PNG; give a path ending in .png")
    paths = [path, hodograph_path(path), page_path(path)]
    for p in paths:
        if os.path.abspath(p).startswith(os.path.abspath(out) + os.sep) or os.path.abspath(p) == os.path.abspath(out):
            raise UsageError(f"--plot: {p}: inside the store {out}")
    inputs = [spec.path] if spec is not None and os.path.exists(spec.path) else []
    check_outputs(paths, inputs)
    return paths


def open_levels(store_path: str) -> list:
    """The atlas at ``store_path`` and its refinement levels (``store.stored_levels``), each
    opened with ``store.open_atlas``: the coarse grid first."""
    from .store import open_atlas, stored_levels

    return [open_atlas(p) for p in stored_levels(store_path)]


def draw(store_path: str, paths: list[str]) -> list[str]:
    """The pictures of the store -- diagram (every refinement level), hodographs and, when a
    third path is given, the interactive page -- landed together (atomically)."""
    levels = open_levels(store_path)
    with Outputs(paths) as tmps:
        diagram(levels, tmps[0])
        hodographs(levels[0], tmps[1])
        if len(paths) > 2:
            from .html import page_of

            with open(tmps[2], "w", encoding="utf-8") as f:
                f.write(page_of(levels))
    return list(paths)


def cell_types(ds, model: str):
    """(types, approaching): per (delta, chi, member) the type a run counts for in the diagram
    (an "approaching X" run counts for X) as label strings, and whether it is still approaching."""
    lab = ds["label"].sel(model=model).values
    appr = lab == "approaching"
    if appr.any():
        names = {v: k for k, v in C.CODE.items()}
        cand = np.vectorize(lambda c: names.get(int(c), "other"))(ds["candidate"].sel(model=model).values)
        lab = np.where(appr, cand, lab)
    lab = np.where(np.isin(lab, ["1|2", "4|5"]), "other", lab)
    return lab, appr


def shares(ds, model: str) -> dict:
    """type -> array (delta, chi) of the share of the members of that type (an approaching run
    counted for the type it approaches; how many are still approaching: ``cell_types``).
    The shares of a cell add up to 1."""
    lab, _ = cell_types(ds, model)
    n = lab.shape[-1]
    out = {}
    for name in ORDER:
        s = (lab == name).sum(axis=-1) / n
        if np.any(s > 0):
            out[name] = s
    return out


def coexisting(ds, model: str) -> np.ndarray:
    """(delta, chi) bool: cells where two settled types each hold >= ``COEXIST`` of the members."""
    lab, appr = cell_types(ds, model)
    settled = np.where(appr | np.isin(lab, ["other", "failed", "missing"]), "", lab)
    n = lab.shape[-1]
    count = np.zeros(lab.shape[:-1], dtype=int)
    for name in ORDER:
        if name in WORDS:
            count += ((settled == name).sum(axis=-1) / n >= COEXIST)
    return count >= 2


def _edges(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Cell edges around the centres ``v`` (midpoints; the outer ones reflected, clipped to [lo, hi])."""
    if len(v) == 1:
        w = 0.1 * (hi - lo)
        return np.array([max(lo, v[0] - w / 2), min(hi, v[0] + w / 2)])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[max(lo, 2 * v[0] - mid[0])], mid, [min(hi, 2 * v[-1] - mid[-1])]])


def diagram(levels, path: str, title: str | None = None):
    """The delta-chi diagram, one panel per model, like the paper's figures 2, 3.D and 5: each
    cell split into bars, one per type, as wide as that type's share of the cell's members
    (hatched: the share still approaching it at tau_end, a slow hand-over), a dot where two
    types coexist among the starts; the analytic boundaries labelled with their equations; the
    DAST families of figure 5; a legend in words.  ``levels``: one atlas Dataset or the list of
    its refinement levels (``open_levels``), each finer level drawn over the coarser."""
    levels = levels if isinstance(levels, (list, tuple)) else [levels]
    ds = levels[0]
    plt = pyplot()
    models = [str(m) for m in ds["model"].values]
    one = len(models) == 1                  # one panel: the legend in 2 columns below, taller
    fig, axes = plt.subplots(1, len(models), figsize=(9.0, 8.8) if one else (7.2 * len(models), 7.6), squeeze=False)
    seen = set()
    for ax, model in zip(axes[0], models):
        seen |= _cells(ax, compose_levels(levels, model))
        _lines(ax, model)
        n = ds.sizes["member"]
        ax.set_xlim(-1, 1)
        ax.set_ylim(0, 90)
        ax.set_xlabel("\u03b4 = 1 \u2212 I\u2083/I\u2081   (prolate \u2190 0 \u2192 oblate)")
        ax.set_ylabel("\u03c7 = angle of the dipole from the symmetry axis (deg)")
        ax.set_title(f"{model} model: type of each of {n} starts per cell", fontsize=11)
    _legend(fig, seen, ncol=2 if one else 3)
    s = _spec(ds)
    w0 = s["members"]["omega"]
    starts = f"|\u03c9\u2080| = {w0}" if w0 else "explicit starts"
    grid = f"{ds.sizes['delta']} \u00d7 {ds.sizes['chi']} cells"
    if len(levels) > 1:
        fine = levels[-1]
        grid += f", refined {len(levels) - 1}\u00d7 near the boundaries to {fine.sizes['delta']} \u00d7 {fine.sizes['chi']}"
    head = title or f"{ds.attrs.get('title', 'atlas')}   ({grid}; \u03c4_end = {s['run']['tau_end']:.0e}, {starts})"
    fig.suptitle("\n".join(textwrap.wrap(head, 95 if one else 150)), y=0.985, fontsize=11)
    fig.tight_layout(rect=(0, 0.2 if one else 0.13, 1, 0.95))
    _save_small(fig, path, dpi=110)


def compose(ds, model: str, level: int = 0) -> list[dict]:
    """The diagram's cells of one model, as plain data for the PNG and the HTML page: each a
    dict with ``i``, ``j``, ``level``, ``id`` ("model:level:i:j"), the rectangle ``x0, x1``
    (delta) and ``y0, y1`` (chi, deg), the ``bars`` -- (type, width fraction, hatched) left to
    right in ``ORDER`` -- ``coexist`` and ``counts`` (type or "->type" -> members).  On a
    refinement level (``level`` > 0) only the cells it computed."""
    deltas, chis = ds["delta"].values, np.degrees(ds["chi"].values)
    de, ce = _edges(deltas, -1.0, 1.0), _edges(chis, 0.0, 90.0)
    lab, appr = cell_types(ds, model)
    co = coexisting(ds, model)
    n = lab.shape[-1]
    cells = []
    for i in range(len(deltas)):
        for j in range(len(chis)):
            if level and (lab[i, j] == "missing").all():
                continue
            bars, counts = [], {}
            for name in ORDER:
                m = lab[i, j] == name
                k = int(m.sum())
                if name == "approaching" or not k:
                    continue
                ka = int((m & appr[i, j]).sum())
                if k - ka:
                    bars.append((name, (k - ka) / n, False))
                    counts[name] = k - ka
                if ka:
                    bars.append((name, ka / n, True))
                    counts["->" + name] = ka
            cells.append({"i": i, "j": j, "level": level, "id": f"{model}:{level}:{i}:{j}", "delta": float(deltas[i]),
                          "chi_deg": float(chis[j]), "x0": float(de[i]), "x1": float(de[i + 1]), "y0": float(ce[j]),
                          "y1": float(ce[j + 1]), "bars": bars, "coexist": bool(co[i, j]), "counts": counts})
    return cells


def compose_levels(levels: list, model: str) -> list[dict]:
    """``compose`` of every refinement level, coarse first, without the cells a finer level
    computed again (its four children cover each of them whole)."""
    per = [compose(ds, model, level=k) for k, ds in enumerate(levels)]
    out = []
    for k, cells in enumerate(per):
        finer = {(c["i"], c["j"]) for c in per[k + 1]} if k + 1 < len(per) else set()
        out += [c for c in cells if (2 * c["i"], 2 * c["j"]) not in finer]
    return out


def _cells(ax, cells: list[dict]) -> set:
    """The bars of every cell (one PatchCollection per level, type and hatching, finer levels
    on top) and the coexistence dots."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    rects: dict = {}
    seen = set()
    dots = []
    for c in cells:
        x, w, h = c["x0"], c["x1"] - c["x0"], c["y1"] - c["y0"]
        for name, frac, hatched in c["bars"]:
            rects.setdefault((c["level"], name, hatched), []).append(Rectangle((x, c["y0"]), w * frac, h))
            x += w * frac
            seen.add("approaching" if hatched else name)
            seen.add(name)
        if c["coexist"]:
            dots.append((c["delta"], c["chi_deg"], c["level"]))
    for (level, name, hatched), rs in sorted(rects.items(), key=lambda kv: kv[0][0]):
        ax.add_collection(PatchCollection(rs, facecolor=COLORS[name], edgecolor="white" if hatched else "none",
                                          hatch="////" if hatched else None, linewidth=0.0, zorder=1 + 0.01 * level))
    if dots:
        d, c, lv = zip(*dots)
        ax.scatter(d, c, s=7.0 / 2.0 ** np.asarray(lv), color="black", edgecolors="white", linewidths=0.4, zorder=5)
        seen.add("coexisting")
    return seen


LINE_STYLE = {  # name prefix -> (colour, style, where to write its label: delta)
    "(4.15)": ("k", "-", -0.72), "(4.17)": ("k", "--", -0.38), "(4.20)": ("k", ":", 0.62),
    "(4.43) as printed": ("k", "-.", 0.93), "(4.43) corrected": ("#a3001b", "-.", 0.72),
    "alpha": ("#0b3d91", "-", -0.62), "beta = -3/4": ("#a3001b", "-", 0.3),
    "delta = 0": ("#0b3d91", "-", 0.0), "beta_T": ("#a3001b", "-", 0.75),
}


def _lines(ax, model: str) -> None:
    """The analytic boundaries, each labelled with its equation, and the DAST families."""
    for line in FM.boundaries(model):
        key = next(k for k in sorted(LINE_STYLE, key=len, reverse=True) if line["name"].startswith(k))
        color, ls, at = LINE_STYLE[key]
        d, c = line["delta"], np.degrees(line["chi"])
        ax.plot(d, c, color=color, ls=ls, lw=1.6)
        ok = np.isfinite(c) & (c > 2) & (c < 88)
        if np.ptp(d) == 0.0:  # a vertical line (delta = 0): its label half way up
            ax.annotate(line["label"], (d[0], 47.0), fontsize=7.5, color=color, ha="center", va="bottom", **_BOX)
        elif ok.any():
            k = int(np.argmin(np.where(ok, np.abs(d - at), np.inf)))
            ax.annotate(line["label"], (d[k], c[k]), fontsize=7.5, color=color, ha="center", va="bottom", **_BOX)
    for fam in FM.dast_families():
        ax.plot(fam["delta"], np.degrees(fam["chi"]), color="0.25", ls=fam["style"], lw=1.2, alpha=0.9)
        ax.text(-0.98, np.degrees(fam["chi"][0]) + 0.8, fam["short"], fontsize=7, color="0.2", **_BOX)


# Labels above the cells' bars, hatching and coexistence dots (zorder 5), on a white box.
_BOX = {"zorder": 6, "bbox": {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85}}


def _legend(fig, seen: set, ncol: int = 3) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=COLORS[k], edgecolor="0.5", label=WORDS[k]) for k in ORDER if k in seen and k in WORDS]
    extra = []
    if "approaching" in seen:
        extra.append(Patch(facecolor="0.75", edgecolor="white", hatch="////",
                           label="hatched: still approaching that type at \u03c4_end (a slow hand-over)"))
    if "coexisting" in seen:
        extra.append(Line2D([], [], marker="o", ls="", color="black", markersize=4,
                            label="dot: two types coexist among the cell's starts (each \u2265 10 %)"))
    if "other" in seen:
        extra.append(Patch(facecolor=COLORS["other"], edgecolor="0.5", label="other: no type fits (yet)"))
    if "failed" in seen:
        extra.append(Patch(facecolor=COLORS["failed"], label="failed run (see its reason in the store)"))
    extra += [Line2D([], [], color="k", lw=1.6, label="black: the paper's domain boundaries"),
              Line2D([], [], color="#0b3d91", lw=1.6, label="blue, red: lines spinviz derived (labelled)"),
              Line2D([], [], color="0.25", lw=1.2, label="grey: the DAST crystal families of figure 5")]
    fig.legend(handles=handles + extra, loc="lower center", ncol=ncol, fontsize=8, frameon=False, bbox_to_anchor=(0.5, 0.0))


def _save_small(fig, path: str, dpi: int) -> None:
    """PNG with a 256-colour palette (flat colours and thin lines lose nothing visible; the
    file is ~3x smaller, small enough for the repository's gallery)."""
    import io

    from PIL import Image

    plt = pyplot()
    buf = io.BytesIO()
    fig.savefig(buf, dpi=dpi, format="png")
    plt.close(fig)
    buf.seek(0)
    Image.open(buf).convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(path, format="PNG",
                                                                                             optimize=True)


def _spec(ds) -> dict:
    import json

    return json.loads(ds.attrs["spec"])


def representatives(ds) -> list[tuple]:
    """(model, label, delta, chi, member index, confidence) for each type found, per model:
    the cell where the type has its largest share (ties: the one nearest the centre of that
    type's cells), and there the member labelled so with the highest confidence -- preferring
    the members whose series the store keeps (``[output].series``), so that drawing needs no
    integration unless a type was met only among the others."""
    out = []
    d_all, c_all = ds["delta"].values, ds["chi"].values
    kept = ds.sizes["start"] if "series" in ds else 0
    for model in [str(m) for m in ds["model"].values]:
        lab_all = ds["label"].sel(model=model).values
        conf_all = ds["confidence"].sel(model=model).values
        for name in ORDER:
            if name in ("other", "failed", "missing", "approaching"):
                continue
            width = kept if (lab_all[..., :kept] == name).any() else lab_all.shape[-1]
            m, conf = lab_all[..., :width] == name, conf_all[..., :width]
            if not m.any():
                continue
            share = m.mean(axis=-1)
            ii, jj = np.nonzero(share > 0)
            cd, cc = np.average(d_all[ii], weights=share[ii, jj]), np.average(c_all[jj], weights=share[ii, jj])
            dist = (d_all[:, None] - cd) ** 2 + ((c_all[None, :] - cc) / (0.5 * math.pi)) ** 2
            i, j = min(zip(ii, jj), key=lambda ij: (-share[ij], dist[ij]))
            k = int(np.argmax(np.where(m[i, j], conf[i, j], -1.0)))
            out.append((model, name, float(d_all[i]), float(c_all[j]), k, float(conf[i, j, k])))
    return out


def series_of(ds, model: str, i: int, j: int, k: int):
    """(tau, omega (N, 3)) of member ``k`` of cell (i, j): read from the store when it kept
    that series, else integrated again (the runs are deterministic)."""
    if "series" in ds and k < ds.sizes["start"]:
        w = ds["series"].sel(model=model).isel(delta=i, chi=j, start=k).values.astype(float)
        if np.isfinite(w).any():
            return ds["tau"].values, w
    from .runs import integrate
    from .spec import settings_from_canonical

    st = settings_from_canonical(_spec(ds))
    r = integrate(model, float(ds["delta"].values[i]), float(ds["chi"].values[j]), ds["omega0"].values[k], st)
    return r.tau, r.omega


def hodographs(ds, path: str):
    """One panel per type found (per model), the most confident run of that type, its series
    read from the store."""
    plt = pyplot()
    reps = representatives(ds)
    n = max(1, len(reps))
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig = plt.figure(figsize=(3.7 * cols, 3.5 * rows))
    omega0 = ds["omega0"].values
    d_all, c_all = list(ds["delta"].values), list(ds["chi"].values)
    tau_start = float(_spec(ds)["run"].get("tau_start", 1e-2))
    for idx, (model, name, d, c, k, conf) in enumerate(reps):
        tau, omega = series_of(ds, model, d_all.index(d), c_all.index(c), k)
        w0 = float(np.linalg.norm(omega0[k]))
        # omega sqrt(tau) has a limit for every braking type; a residual rotation does not brake
        scale = np.full_like(tau, 1.0 / w0) if name == "R" else np.sqrt(tau + 1.0 / w0**2)
        x = omega * scale[:, None]
        ax = fig.add_subplot(rows, cols, idx + 1, projection="3d")
        lt = np.log10(np.maximum(tau, tau_start))
        # points, not a line: log-spaced samples alias the precession, and chords between
        # them would draw a motion that never happened
        ax.scatter(x[:, 0], x[:, 1], x[:, 2], c=lt, cmap="viridis", s=2.5, linewidths=0, depthshade=False)
        lim = float(np.nanmax(np.abs(x))) * 1.05 or 1.0
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_zlim(-lim, lim)
        ax.scatter(*x[-1], color="crimson", s=10)
        ax.set_xlabel("\u03c9\u2081\u221a\u03c4", fontsize=7, labelpad=-8)
        ax.set_ylabel("\u03c9\u2082\u221a\u03c4", fontsize=7, labelpad=-8)
        ax.set_zlabel("\u03c9\u2083\u221a\u03c4", fontsize=7, labelpad=-8)
        ax.tick_params(labelsize=6, pad=-3)
        ax.locator_params(nbins=4)
        unit = "  (\u03c9/|\u03c9\u2080|)" if name == "R" else ""
        ax.set_title(f"{model} \"{name}\"  \u03b4={d:+.2f} \u03c7={math.degrees(c):.1f}\u00b0{unit}\n"
                     f"confidence {conf:.2f}", fontsize=8)
    fig.suptitle("hodographs of \u03c9 \u221a(\u03c4 + 1/|\u03c9\u2080|\u00b2) at log-spaced samples, colour = "
                 "log\u2081\u2080 \u03c4 (dark: start, yellow: end; red: last sample)", fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    _save_small(fig, path, dpi=80)

