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

import numpy as np

from ..atomic import Outputs, check_outputs
from ..errors import UsageError
from ..plotting import pyplot
from . import formulas as FM

COLORS = {"1": "#1f5fa8", "2": "#8fc1e3", "3": "#3a9a3a", "4": "#f08c1e", "5": "#d62728", "3.9": "#8c564b",
          "R": "#7f7f7f", "T2": "#8fc1e3", "Tcone": "#3a9a3a", "T4": "#f08c1e", "TF": "#8c564b", "T1": "#1f5fa8",
          "T5": "#d62728", "other": "#e4e4e4", "1|2": "#e4e4e4", "4|5": "#e4e4e4", "approaching": "#b0b0b0",
          "failed": "#111111", "missing": "#ffffff"}
ORDER = ("1", "2", "3", "4", "5", "3.9", "R", "T2", "Tcone", "T4", "TF", "approaching", "other", "failed", "missing")


def hodograph_path(path: str) -> str:
    stem, ext = os.path.splitext(path)
    return f"{stem}_hodographs{ext}"


def check_plot_paths(path: str, out: str, spec=None) -> list[str]:
    """The two picture paths of ``--plot PATH``, checked before any work."""
    if os.path.splitext(path)[1].lower() != ".png":
        raise UsageError(f"--plot: {path}: the pictures are PNG; give a path ending in .png")
    paths = [path, hodograph_path(path)]
    for p in paths:
        if os.path.abspath(p).startswith(os.path.abspath(out) + os.sep) or os.path.abspath(p) == os.path.abspath(out):
            raise UsageError(f"--plot: {p}: inside the store {out}")
    inputs = [spec.path] if spec is not None and os.path.exists(spec.path) else []
    check_outputs(paths, inputs)
    return paths


def draw(store_path: str, paths: list[str]) -> list[str]:
    """Both pictures of the store, landed together (atomically)."""
    from .store import open_atlas

    ds = open_atlas(store_path)
    with Outputs(paths) as tmps:
        diagram(ds, tmps[0])
        hodographs(ds, tmps[1])
    return list(paths)


def shares(ds, model: str) -> dict:
    """label -> array (delta, chi) of the share of the members with that label."""
    lab = ds["label"].sel(model=model).values                # (delta, chi, member) strings
    n = lab.shape[-1]
    out = {}
    for name in ORDER:
        if name == "other":
            s = np.isin(lab, ["other", "1|2", "4|5"]).sum(axis=-1) / n
        else:
            s = (lab == name).sum(axis=-1) / n
        if np.any(s > 0):
            out[name] = s
    return out


def _edges(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Cell edges around the centres ``v`` (midpoints; the outer ones reflected, clipped to [lo, hi])."""
    if len(v) == 1:
        w = 0.1 * (hi - lo)
        return np.array([max(lo, v[0] - w / 2), min(hi, v[0] + w / 2)])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[max(lo, 2 * v[0] - mid[0])], mid, [min(hi, 2 * v[-1] - mid[-1])]])


def diagram(ds, path: str, title: str | None = None):
    """The delta-chi diagram, one panel per model (see the module docstring)."""
    plt = pyplot()
    from matplotlib.patches import Patch, Rectangle

    models = [str(m) for m in ds["model"].values]
    deltas = ds["delta"].values
    chis = np.degrees(ds["chi"].values)
    de, ce = _edges(deltas, -1.0, 1.0), _edges(chis, 0.0, 90.0)
    fig, axes = plt.subplots(1, len(models), figsize=(6.4 * len(models), 6.6), squeeze=False)
    seen = set()
    for ax, model in zip(axes[0], models):
        sh = shares(ds, model)
        for i in range(len(deltas)):
            for j in range(len(chis)):
                x0, w = de[i], de[i + 1] - de[i]
                y0, h = ce[j], ce[j + 1] - ce[j]
                x = x0
                for name, s in sh.items():
                    if s[i, j] > 0:
                        ax.add_patch(Rectangle((x, y0), w * s[i, j], h, facecolor=COLORS[name], edgecolor="none"))
                        x += w * s[i, j]
                        seen.add(name)
                ax.add_patch(Rectangle((x0, y0), w, h, facecolor="none", edgecolor="white", lw=0.6))
        for line in FM.boundaries(model):
            paper = line["source"] == "paper"
            color = "k" if paper else ("#1030c0" if ("alpha" in line["name"] or "delta = 0" in line["name"]) else "#c01010")
            ls = {"(4.15)": "-", "(4.17)": "--", "(4.20)": ":", "(4.43)": "-."}.get(line["name"][:6], "-")
            ax.plot(line["delta"], np.degrees(line["chi"]), color=color, ls=ls if paper else "-", lw=1.4 if paper else 1.8,
                    label=("paper " if paper else "spinviz ") + line["name"])
        for fam in FM.dast_families():
            ax.plot(fam["delta"], np.degrees(fam["chi"]), color="0.35", ls=fam["style"], lw=2.2, alpha=0.8, label=fam["name"])
        ax.set_xlim(-1, 1)
        ax.set_ylim(0, 90)
        ax.set_xlabel("\u03b4 = 1 \u2212 I\u2083/I\u2081")
        ax.set_ylabel("\u03c7 (deg)")
        n = ds.sizes["member"]
        ax.set_title(f"{model} model: share of each type among {n} member{'s' if n != 1 else ''} per cell", fontsize=10)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=2, fontsize=7, frameon=False)
    handles = [Patch(facecolor=COLORS[k], edgecolor="0.6", label=k) for k in ORDER if k in seen]
    fig.legend(handles=handles, loc="upper center", ncol=len(handles), fontsize=8, frameon=False,
               bbox_to_anchor=(0.5, 1.0))
    s = _spec(ds)
    w0 = s["members"]["omega"]
    starts = f"|\u03c9\u2080| = {w0}" if w0 else "explicit starts"
    fig.suptitle(title or f"{ds.attrs.get('title', 'atlas')}: \u03c4_end = {s['run']['tau_end']:.0e}, {starts}",
                 y=0.955, fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    _save_small(fig, path, dpi=90)


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
    type's cells), and there the member labelled so with the highest confidence."""
    out = []
    d_all, c_all = ds["delta"].values, ds["chi"].values
    for model in [str(m) for m in ds["model"].values]:
        lab = ds["label"].sel(model=model).values
        conf = ds["confidence"].sel(model=model).values
        for name in ORDER:
            if name in ("other", "failed", "missing"):
                continue
            m = lab == name
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


def hodographs(ds, path: str):
    """One panel per type found (per model), the most confident run of that type."""
    from .runs import Settings, integrate

    plt = pyplot()
    reps = representatives(ds)
    s = _spec(ds)
    rs = s["run"]
    st = Settings(tau_end=rs["tau_end"], tau_start=rs["tau_start"], per_decade=max(60, rs["samples_per_decade"]),
                  rtol=rs["rtol"], max_steps=rs["max_steps"], window=s["classify"]["window_decades"])
    n = max(1, len(reps))
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig = plt.figure(figsize=(3.7 * cols, 3.5 * rows))
    omega0 = ds["omega0"].values
    for idx, (model, name, d, c, k, conf) in enumerate(reps):
        r = integrate(model, d, c, omega0[k], st)
        w0 = float(np.linalg.norm(omega0[k]))
        # omega sqrt(tau) has a limit for every braking type; a residual rotation does not brake
        scale = np.full_like(r.tau, 1.0 / w0) if name == "R" else np.sqrt(r.tau + 1.0 / w0**2)
        x = r.omega * scale[:, None]
        ax = fig.add_subplot(rows, cols, idx + 1, projection="3d")
        lt = np.log10(np.maximum(r.tau, st.tau_start))
        # points, not a line: log-spaced samples alias the precession, and chords between
        # them would draw a motion that never happened
        ax.scatter(x[:, 0], x[:, 1], x[:, 2], c=lt, cmap="viridis", s=2.5, linewidths=0, depthshade=False)
        lim = float(np.max(np.abs(x))) * 1.05 or 1.0
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

