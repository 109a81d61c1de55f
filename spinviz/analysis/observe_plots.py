"""The pictures of ``spinviz observe``: what each model's detector sees over time, when the
models part across resolutions (``plot``), and the detector's spectrogram, signal strength and
waveforms (``plot_detector``).  matplotlib, drawing an ``observe.Observation``."""

from __future__ import annotations

import math

import numpy as np

from .. import units as U
from ..plotting import model_color, model_line, pyplot, save, time_unit
from . import parting as PT
from .observe import MIN_LINE, OBSERVABLES, Observation, horizon_text


def _style(model: str):
    return model_line(model, label=model)


def _scale_marks(ax, obs: Observation, scale: float, t, axis: str = "x") -> None:
    """Dotted lines at T and Theta (one label when they coincide), across the time axis."""
    marks = {}
    for k, v in obs.scales.items():
        if k in ("T", "Theta") and t[0] <= v / scale <= t[-1]:
            marks.setdefault(round(math.log10(v), 3), []).append({"T": "T", "Theta": "Θ"}[k])
    for lv, names in marks.items():
        x = 10.0**lv / scale
        if axis == "x":
            ax.axvline(x, color="0.7", lw=0.8, ls=":")
            ax.annotate(" = ".join(names), (x, 0.02), xycoords=("data", "axes fraction"), xytext=(2, 2),
                        textcoords="offset points", fontsize=8, color="0.4")
        else:
            ax.axhline(x, color="0.7", lw=0.8, ls=":")
            ax.annotate(" = ".join(names), (0.98, x), xycoords=("axes fraction", "data"), xytext=(0, 2),
                        textcoords="offset points", fontsize=8, color="0.4", ha="right")


def _observable_panel(ax, obs: Observation, key: str, series, t, scale: float) -> None:
    """One observable of both models (``series``, one array per detection, at times ``t`` in
    the plot's unit), with the time this receiver tells them apart in it."""
    for d, y in zip(obs.detections, series):
        ax.plot(t, y, **_style(d.model))
    tp = obs.parting[key].setup_time
    if tp is not None and t[0] <= tp / scale:
        ax.axvline(tp / scale, color="tab:red", lw=1.0, ls="--")
        ax.annotate(f"apart for this receiver\nat {U.format_time(tp, obs.units)}", (tp / scale, 0.96),
                    xycoords=("data", "axes fraction"), xytext=(4, 0), textcoords="offset points", fontsize=8,
                    color="tab:red", va="top")
    elif tp is not None:
        ax.annotate(f"apart for this receiver at {U.format_time(tp, obs.units)}\n(before the first plotted instant)",
                    (0.02, 0.22), xycoords="axes fraction", fontsize=8, color="tab:red", va="bottom")
    elif obs.receiver is not None:
        ax.annotate("never apart for this receiver within the run", (0.98, 0.96), xycoords="axes fraction",
                    fontsize=8, color="0.35", va="top", ha="right")


def _parting_panel(ax, obs: Observation, key: str, scale: float, tl: str) -> None:
    """Parting time against resolution (log-log), with this receiver's 5 sigma over time and the
    point where they meet."""
    c = obs.parting[key]
    conv = (lambda r: np.degrees(r)) if key == "polarization" else (lambda r: r)   # noqa: E731
    ax.set_xscale("log")
    ax.set_yscale("log")
    if c.resolutions.size == 0:
        ax.annotate("the models never differ in this observable" + (" beyond the runs' accuracy" if c.floor > 0
                                                                    else ""), (0.6, 0.3), xycoords="axes fraction",
                    ha="center", fontsize=9, color="0.35")
    else:
        ok = np.isfinite(c.times)
        ax.plot(conv(c.resolutions[ok]), c.times[ok] / scale, color="black", lw=2.0,
                label="the models part (same known start)")
    if c.sigma is not None:
        pos = (c.t > 0) & np.isfinite(c.sigma)
        if np.any(pos):
            ax.plot(conv(PT.DECISION_SIGMA * c.sigma[pos]), c.t[pos] / scale, color="tab:blue", lw=1.3, ls="--",
                    label=f"this receiver: 5σ of one {obs.receiver.integration_s:g} s integration")
        if c.setup_time is not None:
            x, y = conv(c.setup_resolution), c.setup_time / scale
            ax.plot([x], [y], "o", color="tab:red", ms=7, zorder=5)
            ax.annotate(f"  {U.format_time(c.setup_time, obs.units)}", (x, y), fontsize=8, color="tab:red",
                        va="center")
    first = [float(np.nanmin(x.times)) for x in obs.parting.values() if np.any(np.isfinite(x.times))]
    t_lo = 0.5 * max(obs.receiver.integration_s / 100.0 if obs.receiver is not None else obs.horizon * 1e-8,
                     min(first, default=0.0)) / scale
    ax.set_ylim(t_lo, 2.0 * obs.horizon / scale)
    _few_log_ticks(ax)
    ax.set_xlabel(PT.LABELS[key] + ", log scale")
    ax.set_ylabel(tl + ", log scale")
    ax.set_title(f"{key}: when do they part, across resolutions?")
    ax.grid(True, which="major", color="0.9", lw=0.6)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8, loc="upper left")


def _few_log_ticks(ax) -> None:
    """At most ~8 labelled decades on a log axis (a parting curve spans 20): fast to lay out,
    legible; an axis under two decades gets 1, 2, 5 in each."""
    from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullLocator

    for axis, lim in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        narrow = lim[0] > 0 and lim[1] / lim[0] < 100.0
        axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0) if narrow else (1.0,), numticks=8 if not narrow else 12))
        axis.set_major_formatter(LogFormatterSciNotation(labelOnlyBase=not narrow))
        axis.set_minor_locator(NullLocator())


def plot(obs: Observation, path: str) -> None:
    """Two rows against log time and resolution: power toward the detector, dominant frequency
    and polarization angle of both models (their video colours), each with the time this
    receiver tells them apart; below each, the parting time against the resolution, with the
    receiver's 5 sigma over time and the point where they meet (PNG, atomic)."""
    plt = pyplot()
    a = obs.detections[0]
    scale, tl = time_unit(obs.horizon, obs.units)
    pos = a.t > 0
    t = a.t[pos] / scale
    cgs = obs.units == "cgs"
    fig, axes = plt.subplots(2, 3, figsize=(18, 9.4))
    fs = 1e9 if cgs else 1.0
    f_all = np.concatenate([d.f_dom[pos] for d in obs.detections])
    f_log = float(np.max(f_all)) > 5.0 * max(float(np.min(f_all)), 1e-300)
    panels = (("power", lambda d: d.power_sr * (U.ERG_PER_S_IN_W if cgs else 1.0),
               "power toward the detector (W/sr)" if cgs else f"dP/dΩ ({a.power_sr_unit})", "log",
               "power per steradian toward the antenna"),
              ("frequency", lambda d: d.f_dom / fs, "dominant frequency (GHz)" if cgs else f"dominant frequency "
               f"({a.freq_unit})", "log" if f_log else "linear", "strongest spectral line"),
              ("polarization", lambda d: np.degrees(d.pol_angle), "polarization angle from u1 (°)", "linear",
               "linear polarization"))
    for ax, (key, fn, ylabel, yscale, title) in zip(axes[0], panels):
        _observable_panel(ax, obs, key, [fn(d)[pos] for d in obs.detections], t, scale)
        ax.set_yscale(yscale)
        ax.set_title(title)
        ax.set_ylabel(ylabel)
        ax.set_xscale("log")
        ax.set_xlabel(tl + ", log scale")
        ax.grid(True, which="major", color="0.9", lw=0.6)
        ax.legend(fontsize=8, loc="lower left")
        _scale_marks(ax, obs, scale, t)
    axes[0, 2].set_ylim(-95, 95)
    axes[0, 2].set_yticks([-90, -45, 0, 45, 90])
    for ax, key in zip(axes[1], OBSERVABLES):
        _parting_panel(ax, obs, key, scale, tl)
        _scale_marks(ax, obs, scale, t, axis="y")
    n = ", ".join(f"{x:.2g}" for x in a.line_of_sight)
    rx = f"\nreceiver: {obs.receiver.describe()}" if obs.receiver is not None else ""
    note = " — line frequencies and powers from the slow variables (spin phase not resolved)" if a.notes else ""
    fig.suptitle(f"{obs.title}\nwhat a detector along n = ({n}) sees, {horizon_text(obs)}{note}{rx}", fontsize=11)
    fig.tight_layout()
    save(fig, path)


def plot_detector(obs: Observation, path: str, epochs: int = 4) -> None:
    """Both models side by side: the spectrogram of the detected field over the run (log time,
    frequency, dP/dOmega of each line in dB on one scale for both, the rotation and precession
    frequencies drawn and labelled), the RMS field over the run, and the field's waveform over
    three rotation periods at a few instants (PNG, atomic)."""
    plt = pyplot()
    a = obs.detections[0]
    scale, tl = time_unit(obs.horizon, obs.units)
    cgs = obs.units == "cgs"
    fscale, fl = (1e9, "frequency (GHz)") if cgs else (1.0, f"frequency ({a.freq_unit})")
    pos = a.t > 0
    t = a.t[pos]
    x = np.log10(t / scale)
    # each instant's reference: the stronger model's strongest line then (the strength itself is the
    # middle panel's): lines stay visible over a run whose power falls by 1e10, and the weaker model shows dimmer
    ref = np.maximum.reduce([np.max(d.line_power_sr, axis=1) for d in obs.detections])
    ref = np.where(ref > 0, ref, 1.0)
    shown = [(d.line_power_sr > MIN_LINE * ref[:, None]) & (d.freq > 0) for d in obs.detections]
    fmax = max(float(np.max(np.where(m, d.freq, 0.0))) for m, d in zip(shown, obs.detections)) or 1.0
    fmin = min(float(np.min(np.where(m, d.freq, np.inf))) for m, d in zip(shown, obs.detections)) / 1.3
    log_f = math.isfinite(fmin) and fmax > 10.0 * fmin        # lines over a decade or more: log frequency
    fmax *= 1.6 if log_f else 1.15                             # room for the labels above the top line
    nf, floor = 320, -60.0
    edges = np.geomspace(fmin, fmax, nf) if log_f else np.linspace(0.0, fmax, nf)
    fig = plt.figure(figsize=(15, 12.5))
    grid = fig.add_gridspec(3, 2, height_ratios=(1.3, 0.8, 1.0))
    picks = np.unique(np.geomspace(max(t[0], obs.horizon * 1e-4), obs.horizon, epochs))
    for col, d in enumerate(obs.detections):
        ax = fig.add_subplot(grid[0, col])
        img = _spectrogram_image(d, pos, edges, ref, floor)
        mesh = ax.pcolormesh(x, edges / fscale, img, vmin=floor, vmax=0.0, cmap="magma", shading="nearest",
                             rasterized=True)
        if log_f:
            ax.set_yscale("log")
            ax.yaxis.set_major_formatter(lambda v, _: f"{v:g}")
            ax.yaxis.set_minor_formatter(lambda v, _: "")
        _frequency_guides(ax, d, x, pos, fscale)
        ax.set_ylim(edges[0] / fscale, fmax / fscale)
        _log_ticks(ax, x)
        ax.set_xlabel(tl + ", log scale")
        ax.set_ylabel(fl)
        ax.set_title(f"{d.model}: spectrogram toward the detector", color=model_color(d.model))
        cb = fig.colorbar(mesh, ax=ax, pad=0.01)
        cb.set_label("dP/dΩ per line, dB re the stronger model at that instant")
        for tp in picks:
            ax.axvline(math.log10(tp / scale), color="0.6", lw=0.6, ls=":")
        _waveforms(fig.add_subplot(grid[2, col]), obs, d, picks)
    _field_strength(fig.add_subplot(grid[1, :]), obs, pos, scale, tl)
    dist = f", antenna at {a.distance_cm:g} cm" if cgs else ""
    n = ", ".join(f"{v:.2g}" for v in a.line_of_sight)
    fig.suptitle(f"{obs.title}\ndetector along n = ({n}){dist}, {horizon_text(obs)}: the spectral lines of the free "
                 f"precession at each instant" + ("\nfrom the slow variables; waveform phases reconstructed (the spin "
                                                  "phase is not resolved)" if a.notes else ""), fontsize=11)
    fig.tight_layout()
    save(fig, path)


def _spectrogram_image(d, pos, edges, ref, floor: float) -> np.ndarray:
    """(frequency bin, instant) image of one detection's lines, dB re ``ref`` (per instant),
    ``floor`` where no line falls; each line drawn three bins tall."""
    nf = edges.size
    img = np.full((nf, int(np.count_nonzero(pos))), floor)
    fb = np.clip(np.searchsorted(edges, d.freq[pos]), 0, nf - 1)
    db = 10.0 * np.log10(np.maximum(d.line_power_sr[pos], 1e-300) / ref[pos, None])
    cols = np.arange(img.shape[1])
    for k in range(d.freq.shape[1]):
        for dr in (-1, 0, 1):                       # three bins: a line stays visible at any size
            r = np.clip(fb[:, k] + dr, 0, nf - 1)
            img[r, cols] = np.maximum(img[r, cols], db[:, k])
    return img


def _frequency_guides(ax, d, x, pos, fscale: float) -> None:
    """The rotation |L|/2 pi I1 and body precession |delta Omega3|/2 pi frequencies over the
    spectrogram (``x``: log10 time), labelled."""
    at = lambda frac: int(np.argmin(np.abs(x - (x[0] + frac * (x[-1] - x[0])))))   # noqa: E731
    j = at(0.03)
    ax.plot(x, d.f_rot[pos] / fscale * 1.04, color="white", lw=0.8, ls=(0, (2, 3)), alpha=0.8)
    ax.annotate("rotation |L|/2πI₁ (dashed, just above its line)", (x[j], d.f_rot[pos][j] / fscale * 1.04),
                xytext=(0, 5), textcoords="offset points", color="white", fontsize=8)
    if np.any(d.f_prec[pos] > 0):
        ax.plot(x, d.f_prec[pos] / fscale, color="cyan", lw=0.8, ls=(0, (1, 2)), alpha=0.8)
        j = at(0.45)
        ax.annotate("body precession |δΩ₃|/2π (dotted)", (x[j], d.f_prec[pos][j] / fscale), xytext=(0, -11),
                    textcoords="offset points", color="cyan", fontsize=8)
    else:
        ax.annotate("no body precession (δΩ₃ = 0): one line", (0.02, 0.03), xycoords="axes fraction",
                    color="0.85", fontsize=8)


def _waveforms(ax, obs: Observation, d, picks) -> None:
    """The field's two polarizations over three rotation periods at the instants ``picks``
    (later lower, each row normalized), with its peak and period."""
    from .detector import waveform

    cgs = obs.units == "cgs"
    for j, tp in enumerate(picks[::-1]):
        i = int(np.argmin(np.abs(d.t - tp)))
        tw, E = waveform(d, i)
        amp = float(np.max(np.abs(E))) or 1.0
        span = float(tw[-1]) or 1.0
        ax.plot(tw / span * 3.0, E[:, 0] / amp * 0.42 + j, color=model_color(d.model), lw=1.2)
        ax.plot(tw / span * 3.0, E[:, 1] / amp * 0.42 + j, color=model_color(d.model), lw=0.8, ls="--", alpha=0.6)
        unit = "µV/m" if cgs else d.field_unit
        peak = amp * (1e6 if cgs else 1.0)
        per = (f"{1e9 / d.f_rot[i]:.3g} ns" if cgs else f"{1.0 / d.f_rot[i]:.3g} τ₀") if d.f_rot[i] > 0 else "-"
        ax.annotate(f"t = {U.format_time(d.t[i], obs.units)}: peak {peak:.3g} {unit}, period {per}",
                    (3.05, j), xycoords="data", fontsize=8, va="center")
    ax.set_xlim(0, 5.5)
    ax.set_ylim(-0.6, len(picks) - 0.4)
    ax.set_yticks([])
    ax.set_xlabel("time within the snapshot (rotation periods at that instant)")
    ax.set_title("field at the dotted instants (later lower, rows normalized; solid u1, dashed u2)", fontsize=9)
    for side in ("left", "right", "top"):
        ax.spines[side].set_visible(False)


def _field_strength(ax, obs: Observation, pos, scale: float, tl: str) -> None:
    """Both models' RMS field at the detector over the run, log-log."""
    a = obs.detections[0]
    cgs = obs.units == "cgs"
    t = a.t[pos] / scale
    for d in obs.detections:
        ax.plot(t, d.field_rms[pos] * (1e6 if cgs else 1.0), **_style(d.model))
    for bg in obs.budgets or ():
        ax.plot(t, bg.field_full_rms[pos] * 1e6, color=model_color(bg.model), lw=0.9, ls=":",
                label=f"{bg.model}: all terms (1/R, 1/R², 1/R³)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(tl + ", log scale")
    ax.set_ylabel(f"RMS field at {a.distance_cm:g} cm (µV/m)" if cgs else f"RMS field ({a.field_unit})")
    ax.set_title("the detected signal's strength over the run (radiation term; dotted: the whole field at the antenna)")
    ax.grid(True, which="major", color="0.9", lw=0.6)
    ax.legend(fontsize=8, loc="lower left")
    _scale_marks(ax, obs, scale, t)


def _log_ticks(ax, x) -> None:
    """Decade ticks on an axis holding log10 values."""
    lo, hi = math.floor(x[0]), math.ceil(x[-1])
    step = max(1, (hi - lo) // 8)
    ticks = list(range(lo, hi + 1, step))
    ax.set_xticks(ticks, [f"$10^{{{v}}}$" for v in ticks])
    ax.set_xlim(x[0], x[-1])


