"""The picture of ``spinviz decide --requirements``: the decision time against the pressure (each
model the truth, the vacuum's answer marked, the largest pressure that still decides), and for
each requirement the share of trials decided against its value.  matplotlib, drawing an
``analysis.requirements.Requirements``; the PNG is written atomically."""

from __future__ import annotations

import math
import textwrap

import numpy as np

from .. import units as U
from ..plotting import model_color, model_line, pyplot, save, time_unit
from .decide import DECISION_Z, SHARE
from .requirements import LABELS


def _pressure_panel(ax, req) -> None:
    r = req.results["pressure_mbar"]
    full = [(v, t) for v, _, t in r.probes if t is not None]
    scale, tl = time_unit(req.horizon, "cgs")
    top = req.horizon / scale
    for m in req.models:
        pts = [(v, t[m]) for v, t in full if m in t]
        if not pts:
            continue
        v = np.array([p for p, _ in pts])
        t = np.array([np.nan if x is None else x / scale for _, x in pts])
        ax.plot(v, np.where(np.isfinite(t), t, np.nan), marker="o", ms=4, **model_line(m, label=f"truth: {m}"))
        never = ~np.isfinite(t)
        if np.any(never):
            ax.plot(v[never], np.full(int(never.sum()), top), "v", ms=7, color=model_color(m),
                    label=f"truth: {m}, fewer than {100 * SHARE:g} % decided (drawn at the horizon)")
        t_vac = req.vacuum_t95.get(m, math.inf)
        if math.isfinite(t_vac):
            ax.axhline(t_vac / scale, color=model_color(m), lw=0.9, ls=":")
            ax.annotate(f"vacuum, everything known: {U.human_time(t_vac)} ({m})", (0.01, t_vac / scale),
                        xycoords=("axes fraction", "data"), xytext=(0, 3 if m == req.models[0] else -10),
                        textcoords="offset points", fontsize=8, color=model_color(m))
    ax.axhline(top, color="0.5", lw=0.8, ls="--")
    ax.annotate(f"horizon {U.human_time(req.horizon)}", (0.99, top), xycoords=("axes fraction", "data"), ha="right",
                va="bottom", fontsize=8, color="0.35")
    if r.value is not None:
        ax.axvline(r.value, color="tab:red", lw=1.1, ls="--")
        ax.annotate(f"{'≥ ' if r.at_least else ''}max_pressure_mbar = {r.value:.3g}", (r.value, 0.5),
                    xycoords=("data", "axes fraction"), xytext=(-4, 0), textcoords="offset points", ha="right",
                    rotation=90, fontsize=8, color="tab:red", va="center")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"pressure of {req.gas} at the scene's temperature, mbar, log scale")
    ax.set_ylabel(tl.replace("time t", f"time by which {100 * SHARE:g} % decide") + ", log scale")
    ax.set_title(f"how long to watch against the trap's pressure (Z ≥ {DECISION_Z:g})")
    ax.grid(True, which="major", color="0.9", lw=0.6)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper left")


def _share_panel(ax, req, key: str) -> None:
    r = req.results[key]
    name, what, unit = LABELS[key]
    if not r.probes:
        ax.annotate("not probed:\n" + textwrap.fill(r.note or "", 34), (0.5, 0.5), xycoords="axes fraction", ha="center", va="center",
                    fontsize=8, color="0.3")
        ax.set_axis_off()
        ax.set_title(what, fontsize=9)
        return
    v = np.array([p[0] for p in r.probes])
    s = np.array([p[1] for p in r.probes])
    ax.plot(v, 100 * s, "o-", ms=4, color="0.2", lw=1.0)
    ax.axhline(100 * SHARE, color="tab:red", lw=0.8, ls="--")
    stated = req.stated.get(key, 0.0)
    if stated and stated > 0:
        ax.axvline(stated, color="0.5", lw=0.8, ls=":")
        ax.annotate("stated", (stated, 0.05), xycoords=("data", "axes fraction"), fontsize=7, color="0.4",
                    rotation=90, xytext=(2, 0), textcoords="offset points")
    if r.value is not None:
        ax.axvline(r.value, color="tab:red", lw=1.0)
    text = "none" if r.value is None else f"{'≥' if r.at_least else '≤'} {r.value:.3g} {unit}".strip()
    ax.set_title(f"{what}: {text}", fontsize=9)
    ax.set_xscale("log")
    ax.set_ylim(-3, 103)
    ax.set_xlabel(f"{what} ({unit})" if unit else what, fontsize=8)
    ax.set_ylabel("% of trials decided (worse truth)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="major", color="0.9", lw=0.6)


def plot_requirements(req, path: str) -> None:
    """Top: the decision time against the pressure, with the vacuum's answer and the largest
    pressure that still decides; beside and below it, the share of trials decided against each
    requirement's value, the 95 % line and the answer (PNG, atomic)."""
    plt = pyplot()
    if not any(r.probes for r in req.results.values()):
        fig, ax = plt.subplots(figsize=(9, 3.6))
        note = next((r.note for r in req.results.values() if r.note), "nothing probed")
        ax.text(0.5, 0.55, textwrap.fill(f"No requirement can be met: {note}.", 64), ha="center", va="center",
                fontsize=11, transform=ax.transAxes)
        ax.text(0.5, 0.15, f"horizon {U.human_time(req.horizon)}; {req.trials} trials (seed {req.seed}); "
                f"decided: {100 * SHARE:g} % of the trials of each truth at Z ≥ {DECISION_Z:g}", ha="center",
                va="center", fontsize=9, color="0.35", transform=ax.transAxes)
        ax.set_axis_off()
        fig.suptitle(f"{req.title}\nwhat the trap must achieve", fontsize=11)
        fig.tight_layout()
        save(fig, path)
        return
    fig = plt.figure(figsize=(17, 10))
    grid = fig.add_gridspec(2, 4, height_ratios=(1.25, 1.0))
    _pressure_panel(fig.add_subplot(grid[0, :3]), req)
    _share_panel(fig.add_subplot(grid[0, 3]), req, "pressure_mbar")
    for j, key in enumerate(("field_v_per_m", "tau0_prior", "gain_slope", "clock_stability")):
        _share_panel(fig.add_subplot(grid[1, j]), req, key)
    stated = ", ".join(f"{k} {v:g}" for k, v in req.stated.items())
    fig.suptitle(f"{req.title}\nwhat the trap must achieve: {req.trials} trials (seed {req.seed}) at every value, "
                 f"the others as stated ({stated})", fontsize=11)
    fig.tight_layout()
    save(fig, path)
