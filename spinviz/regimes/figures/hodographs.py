"""The hodographs of an atlas (the paper's figure 3), as a PNG: one small panel per type found,
the run with the highest confidence of that type -- its series read from the store, or
integrated again where the store kept none (the runs are deterministic) -- as omega scaled
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
        after = f"; averaged flow from \u03c4 = {t_h:.0e} (ring)" if handed else ""
        ax.set_title(f"{model} \"{name}\"  \u03b4={d:+.2f} \u03c7={math.degrees(c):.1f}\u00b0{unit}\n"
                     f"confidence {conf:.2f}{after}", fontsize=8)
    note = ("\nafter a hand-over (black ring) the samples are the averaged flow's: the amplitudes are the run's "
            "(to its stated bound), the phase is the averaged one, not resolved"
            if "tau_handover" in ds and np.isfinite(ds["tau_handover"].values).any() else "")
    fig.suptitle("hodographs of \u03c9 \u221a(\u03c4 + 1/|\u03c9\u2080|\u00b2) at log-spaced samples, colour = "
                 "log\u2081\u2080 \u03c4 (dark: start, yellow: end; red: last sample)" + note, fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    save_small(fig, path, dpi=80)

