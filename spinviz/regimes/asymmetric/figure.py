"""The boxes atlas as a picture: one panel per model over (b/a, c/a), each box coloured by the
crystal edge most starts end spinning about (its share as the colour's depth), with the two
families of the paper's figure 5 (a = b, b = c), the cube and a marked box drawn in."""

from __future__ import annotations

import numpy as np

COLORS = {0: "#d95f02", 1: "#7570b3", 2: "#1b9e77", 3: "#e7298a", 4: "#666666"}
NAMES = {0: "about a", 1: "about b", 2: "about c", 3: "on a fixed polhode", 4: "onto the separatrix"}


def figure(ds, path: str, title: str, mark=None) -> None:
    """Draw ``ds`` (``atlas.atlas``) to the PNG ``path``; ``mark``: (b/a, c/a, label) of a box to point at."""
    from ...plotting import pyplot, save

    plt = pyplot()
    models = list(ds["model"].values)
    fig, axes = plt.subplots(1, len(models), figsize=(5.2 * len(models) + 1.2, 5.0), squeeze=False)
    bx, cy = ds["b_over_a"].values, ds["c_over_a"].values
    d = np.asarray(ds.attrs["dipole_crystal"], dtype=float)
    ang = np.degrees(np.arccos(np.clip(np.abs(d), 0.0, 1.0)))
    for ax, model in zip(axes[0], models):
        sel = ds.sel(model=model)
        dom = sel["dominant"].values
        stack = np.concatenate([sel["axis_share"].values, sel["polhode_share"].values[..., None],
                                sel["separatrix_share"].values[..., None]], axis=-1)
        share = np.max(np.nan_to_num(stack, nan=0.0), axis=-1)       # the cube's cell has none
        rgb = np.ones(dom.shape + (3,))
        for code, col in COLORS.items():
            c = np.array([int(col[i:i + 2], 16) / 255.0 for i in (1, 3, 5)])
            w = (0.35 + 0.65 * np.nan_to_num(share))[..., None]
            rgb = np.where((dom == code)[..., None], 1.0 - w * (1.0 - c), rgb)
        xe, ye = _edges(bx), _edges(cy)
        ax.pcolormesh(xe, ye, rgb, shading="flat")                   # an RGB per box
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(xe[0], xe[-1])
        ax.set_ylim(ye[0], ye[-1])
        ax.plot([1.0, 1.0], [ye[0], ye[-1]], color="k", lw=1.6, label="family 1: a = b (symmetric about c)")
        lo, hi = max(xe[0], ye[0]), min(xe[-1], ye[-1])
        ax.plot([lo, hi], [lo, hi], color="k", lw=1.6, ls="-.", label="family 2: b = c (symmetric about a)")
        ax.plot([xe[0], xe[-1]], [1.0, 1.0], color="k", lw=1.0, ls=":", label="a = c (symmetric about b, d ⊥ b)")
        ax.plot([1.0], [1.0], marker="s", ms=9, mfc="white", mec="k", ls="", label="the cube (no polhode)")
        if mark is not None:
            ax.plot([mark[0]], [mark[1]], marker="*", ms=14, mfc="yellow", mec="k", ls="", label=mark[2])
        ax.set_xlabel("b / a")
        ax.set_ylabel("c / a")
        ax.set_title(f"{model}: where the spin ends (τ → ∞)")
        ax.grid(True, which="both", alpha=0.25)
    handles = [plt.Rectangle((0, 0), 1, 1, color=COLORS[k]) for k in (0, 1, 2, 3)]
    labels = [f"{NAMES[0]} (d {ang[0]:.0f}° or {180 - ang[0]:.0f}° from L)",
              f"{NAMES[1]} (d {ang[1]:.0f}° from L)", f"{NAMES[2]} (d {ang[2]:.0f}° or {180 - ang[2]:.0f}° from L)",
              NAMES[3]]
    lines, line_labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles + lines, labels + line_labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle(title + "  —  colour depth: share of evenly spread spin directions", fontsize=10)
    fig.tight_layout(rect=(0, 0.12, 1, 0.95))
    save(fig, path)


def _edges(v) -> np.ndarray:
    """Cell edges of log-spaced centres v (midpoints in log, half a cell beyond the ends)."""
    lv = np.log(np.asarray(v, dtype=float))
    mid = 0.5 * (lv[1:] + lv[:-1])
    return np.exp(np.concatenate([[lv[0] - (mid[0] - lv[0])], mid, [lv[-1] + (lv[-1] - mid[-1])]]))
