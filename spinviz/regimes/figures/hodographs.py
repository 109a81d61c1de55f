"""The hodographs of an atlas (the paper's figure 3), as a PNG: one small panel per type found,
a run of that type from the cell deepest inside the type's domain (``representatives``) -- its
series read from the store, or integrated again where the store kept none (the runs are
deterministic) -- as omega scaled
by sqrt(tau + 1/|omega0|^2): the unit sphere at the start, omega sqrt(tau) at the end, where
the asymptotic types are fixed points (1), circles (3, 4), spirals onto an axis (2) or arcs (5).

A run the hand-over engine carried by the averaged flow has, after its hand-over (a black
ring), samples rebuilt from the averaged amplitudes with the averaged phase
phi_bar = phi_h - delta int omega3_bar dtau: the amplitudes are physical (to the stated bound),
the phase is not resolved -- drawn so (the circles and spirals keep their radii, the points
on them are not where the spin was) and said under the panel.  (Drawing the amplitudes alone
would lose the picture's point, the shape of the motion, for every run; the averaged phase
keeps it, and the ring says where it stops being the integration's.)
"""

from __future__ import annotations

import math

import numpy as np

from ...inputs.atlas_spec import settings_from_canonical
from ...plotting import pyplot
from ..engine.runs import integrate
from .cells import spec_of
from .diagram import save_small
from .style import ORDER

MARGIN_CELLS = 2.0          # a representative's cell: at least this many grid steps from any cell of another type


def depth(pure: np.ndarray) -> np.ndarray:
    """How deep each cell lies inside a region: ``pure`` (n_delta, n_chi) bool -> the distance,
    in grid steps (Euclidean on the cell indices), from each cell of the region to the nearest
    cell outside it -- the grid's surroundings count as outside, so its edges (delta = +-1,
    chi = 0, 90 deg: other regimes) are boundaries too; 0 outside the region."""
    ni, nj = pure.shape
    oi, oj = np.nonzero(~pure)
    ring_i = np.concatenate([np.arange(-1, ni + 1), np.arange(-1, ni + 1), np.full(nj, -1), np.full(nj, ni)])
    ring_j = np.concatenate([np.full(ni + 2, -1), np.full(ni + 2, nj), np.arange(nj), np.arange(nj)])
    oi, oj = np.concatenate([oi, ring_i]).astype(float), np.concatenate([oj, ring_j]).astype(float)
    ii, jj = np.meshgrid(np.arange(ni, dtype=float), np.arange(nj, dtype=float), indexing="ij")
    d2 = np.min((ii[..., None] - oi) ** 2 + (jj[..., None] - oj) ** 2, axis=-1)
    return np.where(pure, np.sqrt(d2), 0.0)


def representatives(ds) -> list[tuple]:
    """(model, type, delta, chi, member index, confidence, depth) for each type the diagram
    shows (``cells.cell_types``: the types as tau -> oo where the store has them), per model: a
    run that ends in that type *and* shows it at tau_end (its label there), from the cell that
    lies deepest inside the type's domain -- every start of the cell of that type, and the cell
    ``depth`` grid steps from the nearest cell holding anything else or the grid's edge (at least
    ``MARGIN_CELLS`` wherever the domain is that wide) -- so a panel shows the type as it is
    inside its domain, not a slow run by a boundary.  Ties go to the more confident run; among
    a cell's runs, those whose series the store keeps (``[output].series``: drawn without
    integrating again) first, then the most confident.  A type that no whole cell holds is
    shown from the cell where it has its largest share; one no run shows at tau_end, by its
    most confident run."""
    from .cells import cell_types

    out = []
    d_all, c_all = ds["delta"].values, ds["chi"].values
    kept = ds.sizes["start"] if "series" in ds else 0
    for model in [str(m) for m in ds["model"].values]:
        types, _ = cell_types(ds, model)
        shows = ds["label"].sel(model=model).values
        conf = np.nan_to_num(ds["confidence"].sel(model=model).values.astype(float), nan=-1.0)
        for name in ORDER:
            if name in ("other", "failed", "missing", "approaching"):
                continue
            ends = types == name
            if not ends.any():
                continue
            share = ends.mean(axis=-1)
            deep = depth(share == 1.0)
            good = ends & (shows == name)
            pick = good if good.any() else ends
            score = np.where(pick, conf, -2.0) + np.where(np.arange(pick.shape[-1]) < kept, 3.0, 0.0)
            best = np.max(np.where(pick, score, -np.inf), axis=-1)           # per cell: its best run's score
            cell = np.where(pick.any(axis=-1))
            i, j = max(zip(*cell), key=lambda ij: (deep[ij], share[ij], best[ij]))
            k = int(np.argmax(np.where(pick[i, j], score[i, j], -np.inf)))
            out.append((model, name, float(d_all[i]), float(c_all[j]), k, float(conf[i, j, k]), float(deep[i, j])))
    return out


def series_of(ds, model: str, i: int, j: int, k: int):
    """(tau, omega (N, 3)) of member ``k`` of cell (i, j): read from the store when it kept
    that series, else computed again by the store's engine (the runs are deterministic)."""
    if "series" in ds and k < ds.sizes["start"]:
        w = ds["series"].sel(model=model).isel(delta=i, chi=j, start=k).values.astype(float)
        if np.isfinite(w).any():
            return ds["tau"].values, w
    st = settings_from_canonical(spec_of(ds))
    d, c, w0 = float(ds["delta"].values[i]), float(ds["chi"].values[j]), ds["omega0"].values[k]
    if st.engine == "handover":
        from ..engine.handover_engine import cell_records

        return st.times(), cell_records(model, d, c, [w0], st, series=True)[0].series
    r = integrate(model, d, c, w0, st)
    return r.tau, r.omega


def handed_over_at(ds, model: str, i: int, j: int, k: int) -> float:
    """tau at which member ``k`` of cell (i, j) went over to the averaged flow (NaN: in full)."""
    if "tau_handover" not in ds:
        return float("nan")
    return float(ds["tau_handover"].sel(model=model).isel(delta=i, chi=j, member=k).values)


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
    tau_start = float(spec_of(ds)["run"].get("tau_start", 1e-2))
    for idx, (model, name, d, c, k, conf, deep) in enumerate(reps):
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
        t_h = handed_over_at(ds, model, d_all.index(d), c_all.index(c), k)
        handed = np.isfinite(t_h)
        if handed:
            h = int(np.argmin(np.abs(np.log(np.maximum(tau, 1e-300) / t_h))))
            ax.scatter(*x[h], s=40, facecolors="none", edgecolors="black", linewidths=1.0)
        ax.set_xlabel("\u03c9\u2081\u221a\u03c4", fontsize=7, labelpad=-8)
        ax.set_ylabel("\u03c9\u2082\u221a\u03c4", fontsize=7, labelpad=-8)
        ax.set_zlabel("\u03c9\u2083\u221a\u03c4", fontsize=7, labelpad=-8)
        ax.tick_params(labelsize=6, pad=-3)
        ax.locator_params(nbins=4)
        unit = "  (\u03c9/|\u03c9\u2080|)" if name == "R" else ""
        after = f"\naveraged flow from \u03c4 = {t_h:.0e} (ring)" if handed else ""
        inside = f", {deep:.1f} cells inside" if deep > 0 else ""
        ax.set_title(f"{model} \"{name}\"  \u03b4={d:+.2f} \u03c7={math.degrees(c):.1f}\u00b0{unit}\n"
                     f"confidence {conf:.2f}{inside}{after}", fontsize=8)
    note = ("\nafter a hand-over (black ring) the samples are the averaged flow's: the amplitudes are the run's "
            "(to its stated bound), the phase is the averaged one, not resolved"
            if "tau_handover" in ds and np.isfinite(ds["tau_handover"].values).any() else "")
    fig.suptitle("hodographs of \u03c9 \u221a(\u03c4 + 1/|\u03c9\u2080|\u00b2) at log-spaced samples, colour = "
                 "log\u2081\u2080 \u03c4 (dark: start, yellow: end; red: last sample)" + note, fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    save_small(fig, path, dpi=80)

