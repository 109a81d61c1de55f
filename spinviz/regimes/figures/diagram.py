"""The delta-chi diagram of an atlas (the paper's figures 2, 3.D and 5), as a PNG: one panel
per model; each cell is split into bars whose widths are the shares of the types among its
members (computed, not yet computed, failed and "other" included) -- as tau -> oo where the
store holds the limit (the hand-over engine), else at tau_end -- with the paper's
boundaries (4.15), (4.17), (4.19), (4.20), (4.43) drawn over it (black), spinviz's derived
lines (blue: alpha = -1, red: beta = -3/4; see ``physics.asymptotics``) and the two DAST
families of figure 5 (grey: family 1 solid, family 2 dash-dotted).  Each line says what it is
for the limit types (``asymptotics.boundaries``' kind): sharp (thick), a coexistence band
(a translucent band) or no boundary of a limit type (thin).
"""

from __future__ import annotations

import textwrap

import numpy as np

from ...physics import asymptotics as FM
from ...physics import presets as P
from ...plotting import pyplot
from .cells import compose_levels, limit_diagram, spec_of
from .style import COLORS, DELTA_AXIS, LINE_STYLE, ORDER, WORDS


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
    limit = limit_diagram(ds)
    for ax, model in zip(axes[0], models):
        seen |= _cells(ax, compose_levels(levels, model))
        _lines(ax, model)
        n = ds.sizes["member"]
        ax.set_xlim(-1, 1)
        ax.set_ylim(0, 90)
        ax.set_xlabel(DELTA_AXIS)
        ax.set_ylabel("\u03c7 = angle of the dipole from the symmetry axis (deg)")
        what = "type as \u03c4 \u2192 \u221e" if limit else "type at \u03c4_end"
        ax.set_title(f"{model} model: {what} of each of {n} starts per cell", fontsize=11)
    _legend(fig, seen, ncol=2 if one else 3, limit=limit)
    s = spec_of(ds)
    w0 = s["members"]["omega"]
    starts = f"|\u03c9\u2080|\u00a0=\u00a0{w0}" if w0 else "explicit starts"     # one unbreakable phrase
    grid = f"{ds.sizes['delta']} \u00d7 {ds.sizes['chi']} cells"
    if len(levels) > 1:
        fine = levels[-1]
        grid += f", refined {len(levels) - 1}\u00d7 near the boundaries to {fine.sizes['delta']} \u00d7 {fine.sizes['chi']}"
    how = "; full integration until the averaged flow holds, then the averaged flow" if limit else ""
    head = title or f"{ds.attrs.get('title', 'atlas')}   ({grid}; \u03c4_end = {s['run']['tau_end']:.0e}, {starts}{how})"
    fig.suptitle("\n".join(textwrap.wrap(head, 95 if one else 150)), y=0.985, fontsize=11)
    fig.tight_layout(rect=(0, 0.2 if one else 0.13, 1, 0.95))
    save_small(fig, path, dpi=110)


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


def _lines(ax, model: str) -> None:
    """The analytic boundaries, each labelled with its equation and drawn as what it is for the
    limit types (sharp: thick; a coexistence band: a translucent band under the line; no
    boundary of a limit type: thin), and the DAST families."""
    for line in FM.boundaries(model):
        key = next(k for k in sorted(LINE_STYLE, key=len, reverse=True) if line["name"].startswith(k))
        color, ls, at = LINE_STYLE[key]
        d, c = line["delta"], np.degrees(line["chi"])
        kind = line.get("kind", "sharp")
        if kind == "band":
            ax.plot(d, c, color=color, lw=9.0, alpha=0.25, solid_capstyle="butt", zorder=4)
        ax.plot(d, c, color=color, ls=ls, lw={"sharp": 2.2, "band": 1.4, "none": 1.0}[kind],
                alpha=0.65 if kind == "none" else 1.0, zorder=4)
        ok = np.isfinite(c) & (c > 2) & (c < 88)
        if np.ptp(d) == 0.0:  # a vertical line (delta = 0): its label half way up
            ax.annotate(line["label"], (d[0], 47.0), fontsize=7.5, color=color, ha="center", va="bottom", **_BOX)
        elif ok.any():
            k = int(np.argmin(np.where(ok, np.abs(d - at), np.inf)))
            ax.annotate(line["label"], (d[k], c[k]), fontsize=7.5, color=color, ha="center", va="bottom", **_BOX)
    for fam in P.dast_families():
        ax.plot(fam["delta"], np.degrees(fam["chi"]), color="0.25", ls=fam["style"], lw=1.2, alpha=0.9)
        ax.text(-0.98, np.degrees(fam["chi"][0]) + 0.8, fam["short"], fontsize=7, color="0.2", **_BOX)


# Labels above the cells' bars, hatching and coexistence dots (zorder 5), on a white box.
_BOX = {"zorder": 6, "bbox": {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85}}


def _legend(fig, seen: set, ncol: int = 3, limit: bool = False) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=COLORS[k], edgecolor="0.5", label=WORDS[k]) for k in ORDER if k in seen and k in WORDS]
    extra = []
    if "approaching" in seen:
        extra.append(Patch(facecolor="0.75", edgecolor="white", hatch="////",
                           label=("hatched: not yet settled, integrated in full to \u03c4_end" if limit else
                                  "hatched: still approaching that type at \u03c4_end (a slow hand-over)")))
    if "coexisting" in seen:
        extra.append(Line2D([], [], marker="o", ls="", color="black", markersize=4,
                            label="dot: two types coexist among the cell's starts (each \u2265 10 %)"))
    if limit:
        extra += [Line2D([], [], color="0.2", lw=2.2, label="thick line: sharp, one type for every start on each side"),
                  Line2D([], [], color="#a3001b", lw=9.0, alpha=0.25,
                         label="band: 4 and 5 coexist among the starts near \u03b2 = \u2212\u00be"),
                  Line2D([], [], color="0.2", lw=1.0, alpha=0.65, label="thin line: bounds no type as \u03c4 \u2192 \u221e")]
    if "other" in seen:
        extra.append(Patch(facecolor=COLORS["other"], edgecolor="0.5", label="other: no type fits (yet)"))
    if "failed" in seen:
        extra.append(Patch(facecolor=COLORS["failed"], label="failed run (see its reason in the store)"))
    extra += [Line2D([], [], color="k", lw=1.6, label="black: the paper's domain boundaries"),
              Line2D([], [], color="#0b3d91", lw=1.6, label="blue, red: lines spinviz derived (labelled)"),
              Line2D([], [], color="0.25", lw=1.2, label="grey: the DAST crystal families of figure 5")]
    fig.legend(handles=handles + extra, loc="lower center", ncol=ncol, fontsize=8, frameon=False, bbox_to_anchor=(0.5, 0.0))


def save_small(fig, path: str, dpi: int) -> None:
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
