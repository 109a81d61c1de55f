"""``spinviz observe``: when does a detector tell the two models apart?

For a two-model scene, both runs are watched by the same detector (``detector.detect``: the same
line of sight and distance) and compared, instant by instant, on three observables at a stated
resolution each:

* the power toward the detector: the models part when one receives ``power_factor`` (2) times
  the other's;
* the dominant frequency: when they differ by ``frequency_resolution`` (1 %) of the truncated
  model's;
* the polarization angle: when the angles of the linear polarization differ by
  ``polarization_deg`` (5 deg), counted only where both are at least 10 % linearly polarized
  (the angle of a circular signal means nothing).

The first such time (linear interpolation between output instants, log-spaced from 1e-6 of
the horizon on) is reported in human units and in the scene's T and Theta, beside the figures
the paper prints for them.  Numbers from NumPy; matplotlib only to draw the PNGs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..plotting import pyplot, save
from .compare import compare_times, first_crossing, model_color, time_unit
from .detector import Detection

MIN_LINEAR = 0.1          # below this linear fraction a polarization angle is not compared
OBSERVABLES = ("power", "frequency", "polarization")


@dataclass(frozen=True)
class Resolution:
    """How finely the detector resolves each observable."""

    power_factor: float = 2.0
    frequency: float = 0.01
    polarization_deg: float = 5.0

    def label(self, key: str) -> str:
        """The resolution of observable ``key`` ("power", "frequency" or "polarization") in words."""
        return {"power": f"factor {self.power_factor:g} in power toward the detector",
                "frequency": f"{100 * self.frequency:g} % in dominant frequency",
                "polarization": f"{self.polarization_deg:g}° in polarization angle"}[key]


def differences(a: Detection, b: Detection) -> dict[str, np.ndarray]:
    """Per instant: the power ratio (>= 1), the relative frequency difference |f_a/f_b - 1| and
    the polarization-angle difference in degrees (NaN where either is < 10 % linear)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        hi, lo = np.maximum(a.power_sr, b.power_sr), np.minimum(a.power_sr, b.power_sr)
        ratio = np.where(lo > 0, hi / np.where(lo > 0, lo, 1.0), np.where(hi > 0, np.inf, 1.0))
        fdiff = np.abs(a.f_dom / b.f_dom - 1.0)
    d = np.degrees(a.pol_angle - b.pol_angle)
    d = np.abs((d + 90.0) % 180.0 - 90.0)
    d = np.where((a.linear >= MIN_LINEAR) & (b.linear >= MIN_LINEAR), d, np.nan)
    return {"power": ratio, "frequency": fdiff, "polarization": d}


def parting_times(a: Detection, b: Detection, res: Resolution) -> dict[str, float | None]:
    """The first time each observable differs by its resolution, or None within the run."""
    diff = differences(a, b)
    thresholds = {"power": res.power_factor, "frequency": res.frequency, "polarization": res.polarization_deg}
    out = {}
    for key in OBSERVABLES:
        x = np.nan_to_num(diff[key], nan=0.0, posinf=1e300)
        out[key] = first_crossing(a.t, x, thresholds[key])
    return out


@dataclass
class Observation:
    """Both models' detections, the resolution and the parting times, with the scene's scales."""

    title: str
    units: str
    detections: list
    resolution: Resolution
    parting: dict
    scales: dict = field(default_factory=dict)       # "T", "Theta" in the body's time unit
    printed: dict = field(default_factory=dict)      # the paper's figures for them, seconds
    horizon: float = 0.0

    def record(self) -> dict:
        """The observation as a JSON-ready dict (``spinviz observe --json``): scales, parting
        times, and per model the scalar observables at the first and last samples."""
        a, b = self.detections
        return {
            "title": self.title, "units": self.units, "horizon": self.horizon,
            "line_of_sight": a.line_of_sight.tolist(), "distance_cm": a.distance_cm,
            "resolution": vars(self.resolution), "parting": self.parting, "scales": self.scales,
            "printed": self.printed, "phase_resolved": bool(a.phase_resolved and b.phase_resolved),
            "start": {d.model: d.record(0) for d in self.detections},
            "end": {d.model: d.record(-1) for d in self.detections},
        }


def observe_times(t_end: float, n: int = 800) -> np.ndarray:
    """Output instants: n evenly spaced and n log-spaced from 1e-6 t_end (``compare_times``)."""
    return compare_times(t_end, n)


def observe(trajs, title: str, res: Resolution = Resolution(), line_of_sight=None, distance_cm: float = 1.0,
            omega0=None) -> Observation:
    """Detect both runs (same times) and find when they part; ``omega0`` (the scene's start)
    gives T and Theta."""
    from .detector import default_line_of_sight, detect

    if len(trajs) != 2:
        raise ValueError("observe needs a scene with two models (models = [\"reduced\", \"truncated\"])")
    n = default_line_of_sight(trajs[0]) if line_of_sight is None else line_of_sight
    dets = [detect(tr, n, distance_cm) for tr in trajs]
    body = trajs[0].body
    scales, printed = {}, {}
    if omega0 is not None:
        w = np.asarray(omega0, dtype=float)
        wp, w3 = math.hypot(w[0], w[1]), abs(float(w[2]))
        if wp > 0:
            scales["T"] = body.braking_time_T(wp)
        if w3 > 0:
            scales["Theta"] = body.residual_time_Theta(w3)
        scales["1/(tau0 Omega0^2)"] = 1.0 / (body.tau0 * float(w @ w))
    for p in body.printed:
        if p.key in ("T", "Theta"):
            printed[p.key] = {"value_s": p.value, "where": p.where, "approx": p.approx}
    return Observation(title=title, units=body.units, detections=dets, resolution=res,
                       parting=parting_times(dets[0], dets[1], res), scales=scales, printed=printed,
                       horizon=float(trajs[0].t[-1]))


def _when(t: float | None, obs: Observation) -> str:
    if t is None:
        return f"not within the run ({U.format_time(obs.horizon, obs.units)})"
    out = U.format_time(t, obs.units)
    extra = [f"{t / v:.3g} {k}" for k, v in obs.scales.items() if k in ("T", "Theta")]
    return out + (f"  ({', '.join(extra)})" if extra else "")


def format_table(obs: Observation) -> str:
    """The answer for people: the detector, what it sees at the start and the end, and when the
    models part."""
    a, b = obs.detections
    cgs = obs.units == "cgs"
    n = ", ".join(f"{x:.3g}" for x in a.line_of_sight)
    lines = [obs.title, "", f"detector along n = ({n}) (world frame)" + (f", field at {a.distance_cm:g} cm" if cgs else "")]
    for note in a.notes:
        lines.append(f"note: {note}")
    lines.append(f"{_horizon_text(obs)} (the scene's [observe] horizon, else its own)")
    lines.append("")
    head = f"{'':<34} {a.model:>22} {b.model:>22}"
    for label, i in (("at the start", 0), (f"at the end, t = {U.format_time(obs.horizon, obs.units)}", -1)):
        lines += [label, head]
        cells = [_cells(d, i, cgs) for d in obs.detections]
        for name in cells[0]:
            lines.append(f"  {name:<32} {cells[0][name]:>22} {cells[1][name]:>22}")
        lines.append("")
    lines.append("when do the models part?")
    for key in OBSERVABLES:
        lines.append(f"  {obs.resolution.label(key):<44} {_when(obs.parting[key], obs)}")
    lines.append("")
    for k, v in obs.scales.items():
        printed = obs.printed.get(k)
        text = f"  {k:<18} = {U.format_time(v, obs.units)}"
        if printed:
            text += f"   (the paper, {printed['where']}: {'~' if printed['approx'] else ''}{U.human_time(printed['value_s'])})"
        lines.append(text)
    return "\n".join(lines)


def _cells(d: Detection, i: int, cgs: bool) -> dict[str, str]:
    """One column of ``format_table``: the detection's observables at sample i, as text."""
    freq = (lambda f: U.format_frequency(f)) if cgs else (lambda f: f"{f:.4g} {d.freq_unit}")
    pol = round(math.degrees(d.pol_angle[i]), 1) + 0.0                      # never "-0.0"
    out = {"radiated power": _num(d.power[i], d.power_unit, cgs, "power"),
           "power toward the detector": _num(d.power_sr[i], d.power_sr_unit, cgs, "sr"),
           "RMS field": _num(d.field_rms[i], d.field_unit, cgs, "field"),
           "dominant frequency": freq(d.f_dom[i]), "rotation |L|/(2 pi I1)": freq(d.f_rot[i]),
           "polarization angle (from u1)": f"{pol:.1f}° ({100 * d.linear[i]:.0f} % lin.)"}
    if cgs:
        out["photons per second per sr"] = f"{d.photons_sr[i]:.3g}"
    return out


def _num(x, unit, cgs, kind) -> str:
    x = float(x)
    if cgs and kind in ("power", "sr"):
        w = x * U.ERG_PER_S_IN_W
        return f"{w:.3g} W" + ("/sr" if kind == "sr" else "")
    if cgs and kind == "field":
        return f"{x * 1e6:.3g} µV/m"
    return f"{x:.3g} {unit}"


# --- pictures -------------------------------------------------------------------------------
STYLES = {"reduced": ("-", 2.4), "truncated": ("--", 1.7)}     # both visible where they coincide


def _style(model: str):
    ls, lw = STYLES.get(model, ("-", 1.7))
    return {"color": model_color(model), "ls": ls, "lw": lw, "label": model}


def _scale_marks(ax, obs: Observation, scale: float, t) -> None:
    """Dotted verticals at T and Theta (one label when they coincide)."""
    marks = {}
    for k, v in obs.scales.items():
        if k in ("T", "Theta") and t[0] <= v / scale <= t[-1]:
            marks.setdefault(round(math.log10(v), 3), []).append({"T": "T", "Theta": "Θ"}[k])
    for lv, names in marks.items():
        x = 10.0**lv / scale
        ax.axvline(x, color="0.7", lw=0.8, ls=":")
        ax.annotate(" = ".join(names), (x, 0.02), xycoords=("data", "axes fraction"), xytext=(2, 2),
                    textcoords="offset points", fontsize=8, color="0.4")


def _horizon_text(obs: Observation) -> str:
    return f"watched for {U.format_time(obs.horizon, obs.units)}"


def _observable_panel(ax, obs: Observation, key: str, series, t, scale: float) -> None:
    """One observable of both models (``series``, one array per detection, at times ``t`` in
    the plot's unit), with the time the models part in it, or that they never do."""
    for d, y in zip(obs.detections, series):
        ax.plot(t, y, **_style(d.model))
    tp = obs.parting[key]
    word = obs.resolution.label(key).split(" in ")[0]
    if tp is not None and tp > 0:
        ax.axvline(tp / scale, color="tab:red", lw=1.0, ls="--")
        ax.annotate(f"{word} apart\nat {U.format_time(tp, obs.units)}", (tp / scale, 0.96),
                    xycoords=("data", "axes fraction"), xytext=(4, 0), textcoords="offset points", fontsize=8,
                    color="tab:red", va="top")
    elif tp is None:
        ax.annotate(f"never {word} apart within the run", (0.98, 0.96), xycoords="axes fraction", fontsize=8,
                    color="0.35", va="top", ha="right")


def _difference_panel(ax, obs: Observation, t, pos) -> None:
    """Each observable's difference between the models in units of its resolution: the models
    part where a curve crosses 1."""
    diff = differences(*obs.detections)
    res = obs.resolution
    with np.errstate(divide="ignore", invalid="ignore"):
        norm = {"power": np.log(diff["power"]) / math.log(res.power_factor), "frequency": diff["frequency"] / res.frequency,
                "polarization": diff["polarization"] / res.polarization_deg}
    for key, col in zip(OBSERVABLES, ("tab:orange", "tab:blue", "tab:green")):
        y = np.clip(np.nan_to_num(norm[key][pos], nan=np.nan, posinf=1e6), 1e-8, 1e6)
        flat = not np.any(y > 1e-6)                        # below the axis: say so in the legend
        ax.plot(t, y, color=col, lw=1.6, label=res.label(key) + (" (below 1e-6 throughout)" if flat else ""))
    ax.axhline(1.0, color="tab:red", lw=1.0, ls="--")
    ax.annotate("resolved: the models part", (0.01, 1.0), xycoords=("axes fraction", "data"), xytext=(2, 3),
                textcoords="offset points", fontsize=8, color="tab:red")
    ax.set_yscale("log")
    ax.set_ylim(1e-6, 1e4)
    ax.set_ylabel("difference / resolution")
    ax.set_title("reduced vs truncated, in units of the resolution")


def plot(obs: Observation, path: str) -> None:
    """Four panels against log time: power toward the detector, dominant frequency, polarization
    angle (both models in their video colours), and each difference in units of its resolution
    (the models part where a curve crosses 1); parting times marked (PNG, atomic)."""
    plt = pyplot()
    a = obs.detections[0]
    scale, tl = time_unit(obs.horizon, obs.units)
    pos = a.t > 0
    t = a.t[pos] / scale
    cgs = obs.units == "cgs"
    fig, axes = plt.subplots(2, 2, figsize=(14, 8.6))
    fs = 1e9 if cgs else 1.0
    f_all = np.concatenate([d.f_dom[pos] for d in obs.detections])
    f_log = float(np.max(f_all)) > 5.0 * max(float(np.min(f_all)), 1e-300)
    panels = (("power", lambda d: d.power_sr * (U.ERG_PER_S_IN_W if cgs else 1.0),
               "power toward the detector (W/sr)" if cgs else f"dP/dΩ ({a.power_sr_unit})", "log", "power received"),
              ("frequency", lambda d: d.f_dom / fs, "dominant frequency (GHz)" if cgs else f"dominant frequency "
               f"({a.freq_unit})", "log" if f_log else "linear", "strongest spectral line"),
              ("polarization", lambda d: np.degrees(d.pol_angle), "polarization angle from u1 (°)", "linear",
               "linear polarization"))
    for ax, (key, fn, ylabel, yscale, title) in zip(axes.flat, panels):
        _observable_panel(ax, obs, key, [fn(d)[pos] for d in obs.detections], t, scale)
        ax.set_yscale(yscale)
        ax.set_title(title)
        ax.set_ylabel(ylabel)
    axes[1, 0].set_ylim(-95, 95)
    axes[1, 0].set_yticks([-90, -45, 0, 45, 90])
    _difference_panel(axes[1, 1], obs, t, pos)
    for ax in axes.flat:
        ax.set_xscale("log")
        ax.set_xlabel(tl + ", log scale")
        ax.grid(True, which="major", color="0.9", lw=0.6)
        ax.legend(fontsize=8, loc="lower left")
        _scale_marks(ax, obs, scale, t)
    n = ", ".join(f"{x:.2g}" for x in a.line_of_sight)
    note = " — line frequencies and powers from the slow variables (spin phase not resolved)" if a.notes else ""
    fig.suptitle(f"{obs.title}\nwhat a detector along n = ({n}) sees, {_horizon_text(obs)}{note}", fontsize=11)
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
    dist = f", field at {a.distance_cm:g} cm" if cgs else ""
    n = ", ".join(f"{v:.2g}" for v in a.line_of_sight)
    fig.suptitle(f"{obs.title}\ndetector along n = ({n}){dist}, {_horizon_text(obs)}: the spectral lines of the free "
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
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(tl + ", log scale")
    ax.set_ylabel(f"RMS field at {a.distance_cm:g} cm (µV/m)" if cgs else f"RMS field ({a.field_unit})")
    ax.set_title("the detected signal's strength over the run (its time series, averaged over each turn)")
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


MIN_LINE = 1e-6


def scene_resolution(sc, power_factor=None, frequency=None, polarization_deg=None) -> Resolution:
    """The scene's ``[observe]`` resolutions, each overridden when given."""
    o = sc.observe
    return Resolution(power_factor=o.power_factor if power_factor is None else float(power_factor),
                      frequency=o.frequency_resolution if frequency is None else float(frequency),
                      polarization_deg=o.polarization_deg if polarization_deg is None else float(polarization_deg))


def run_scene(sc, samples: int = 800, line_of_sight=None, distance_cm=None, resolution: Resolution | None = None):
    """Simulate both models of scene ``sc`` over its ``[observe]`` horizon (or its own) at
    ``observe_times`` and observe them: (Observation, trajectories)."""
    from ..driver import simulate_request

    if len(sc.models) != 2:
        raise ValueError("[simulation].models: observe needs two models, e.g. models = [\"reduced\", \"truncated\"]")
    if not sc.body.is_symmetric:
        raise ValueError("[body]: the detector needs a symmetric top (I1 = I2); this body is asymmetric")
    horizon = sc.observe.t_end or sc.t_end
    times = observe_times(horizon, samples)
    trajs = [simulate_request(sc.request(m, t_eval=times)) for m in sc.models]
    los = line_of_sight if line_of_sight is not None else sc.observe.line_of_sight
    dist = sc.observe.distance_cm if distance_cm is None else float(distance_cm)
    obs = observe(trajs, sc.title, resolution or scene_resolution(sc), los, dist, omega0=sc.omega0)
    return obs, trajs
