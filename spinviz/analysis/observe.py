"""``spinviz observe``: what a stated receiver records from both models of a scene, and when it
tells them apart.

Both runs are watched by the same detector (``detector.detect``: one line of sight) and the
same receiver (``receiver.budget``, CGS bodies: distance, band, integration time, noise,
antenna), which gives, per output instant and line, the received power, the SNR of one
integration, the coherent interval of the drifting line and the resolutions it reaches in
frequency, power and polarization angle (Cramer-Rao bounds), the field at the antenna with all
its terms and the zone the antenna is in.  From them:

* when the models part (``parting``): for each observable the first time they differ by a
  given resolution, across resolutions, from the same known start -- and the time this
  receiver sees it (the difference reaching 5 standard errors of one integration);
* the start-free test (``pftest``): each model's own line, as this receiver would measure it
  (one integration at each output instant with its noise, a fixed seed), fitted to the P-f
  laws; for a top without them, why not.

Times are reported in human units and in the scene's T and Theta, beside the figures the paper
prints.  Numbers from NumPy (and SciPy for the fits); matplotlib only to draw the PNGs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..plotting import pyplot, save
from . import parting as PT
from .compare import compare_times, model_color, time_unit
from .detector import Detection

OBSERVABLES = PT.OBSERVABLES
SEED = 1                  # the synthetic P-f series' noise: fixed, so a report is reproducible


@dataclass
class Observation:
    """Both models' detections, the receiver and its budgets (CGS), the parting curves and the
    P-f tests, with the scene's scales."""

    title: str
    units: str
    detections: list
    parting: dict
    scales: dict = field(default_factory=dict)       # "T", "Theta" in the body's time unit
    printed: dict = field(default_factory=dict)      # the paper's figures for them, seconds
    horizon: float = 0.0
    receiver: object = None                          # inputs.receiver.ReceiverSpec, CGS only
    budgets: list | None = None
    pf: dict = field(default_factory=dict)           # model -> pftest.PfTest (or None)
    pf_series: dict = field(default_factory=dict)    # model -> pftest.Series (or None)
    pf_law: str | None = None
    pf_reason: str = ""
    notes: list = field(default_factory=list)

    def record(self) -> dict:
        """The observation as a JSON-ready dict (``spinviz observe --json``): the receiver, per
        model its observables and budget at the first and last samples, the parting curves, the
        P-f tests, the scales."""
        a, b = self.detections
        out = {
            "title": self.title, "units": self.units, "horizon": self.horizon,
            "line_of_sight": a.line_of_sight.tolist(), "distance_cm": a.distance_cm,
            "parting": {k: c.record() for k, c in self.parting.items()}, "scales": self.scales,
            "printed": self.printed, "phase_resolved": bool(a.phase_resolved and b.phase_resolved),
            "start": {d.model: d.record(0) for d in self.detections},
            "end": {d.model: d.record(-1) for d in self.detections}, "notes": self.notes,
        }
        if self.receiver is not None:
            out["receiver"] = self.receiver.record()
            out["budget"] = {bg.model: {"start": bg.record(_first(bg)), "end": bg.record(-1),
                                        "series": _thinned(bg)} for bg in self.budgets}
        out["pf_test"] = {"law": self.pf_law, "reason": self.pf_reason or None,
                          "fits": {m: (r.record() if r is not None else None) for m, r in self.pf.items()}}
        return out


def _first(bg) -> int:
    """The first instant after t = 0 (the budget's drift rates are one-sided at t = 0)."""
    return int(np.argmax(bg.t > 0))


def _thinned(bg, n: int = 60) -> dict:
    """The strongest line's SNR and resolutions at ~n log-spaced instants (JSON)."""
    i = np.unique(np.searchsorted(bg.t, np.geomspace(max(bg.t[bg.t > 0][0], 1e-300), bg.t[-1], n)))
    i = i[i < bg.t.size]
    rows = np.arange(bg.t.size)

    def clean(x):
        return [float(v) if math.isfinite(v) else None for v in x]

    return {"t": clean(bg.t[i]), "snr_integration": clean(bg.rho[rows, bg.dominant][i]),
            "sigma_f_relative": clean((bg.sigma_f / bg.freq[rows, bg.dominant])[i]),
            "sigma_power_relative": clean(bg.sigma_lnp[i]), "sigma_polarization_rad": clean(bg.sigma_pol[i]),
            "zone": [str(z) for z in bg.zone[i]]}


def observe_times(t_end: float, n: int = 800) -> np.ndarray:
    """Output instants: n evenly spaced and n log-spaced from 1e-6 t_end (``compare_times``)."""
    return compare_times(t_end, n)


def observe(trajs, title: str, line_of_sight=None, receiver=None, omega0=None, rtol: float = 1e-10,
            receive: bool = True) -> Observation:
    """Detect both runs (same times), put them through ``receiver`` (an
    ``inputs.receiver.ReceiverSpec``; CGS bodies, unless ``receive`` is False) and find when they
    part; ``omega0`` (the scene's start) gives T, Theta and, for a top with d along its axis or a
    sphere, the closed forms the parting curves use."""
    from ..inputs.receiver import ReceiverSpec
    from ..physics import longitudinal as LG
    from .detector import default_line_of_sight, detect

    if len(trajs) != 2:
        raise ValueError("observe needs a scene with two models (models = [\"reduced\", \"truncated\"])")
    receiver = ReceiverSpec() if receiver is None else receiver
    n = default_line_of_sight(trajs[0]) if line_of_sight is None else line_of_sight
    dets = [detect(tr, n, receiver.distance_cm) for tr in trajs]
    body = trajs[0].body
    scales, printed = _scales(body, omega0)
    law = LG.has_line_law(body.delta, body.chi, body.is_symmetric)
    start = (LG.start_state(omega0, body.dipole_direction, body.epsilon)
             if law and omega0 is not None and {t.model for t in trajs} == set(LG.MODELS) else None)
    by_model = {d.model: d for d in dets}
    a, b = (by_model["reduced"], by_model["truncated"]) if start is not None else dets
    obs = Observation(title=title, units=body.units, detections=dets,
                      parting=PT.curves(a, b, start, body.tau0, rtol), scales=scales, printed=printed,
                      horizon=float(trajs[0].t[-1]))
    if body.units == "cgs" and receive:
        _receive(obs, receiver, body, start)
    elif body.units != "cgs":
        obs.notes.append("a dimensionless body: no receiver (it needs distances, powers and noise in physical units)")
    return obs


def _scales(body, omega0) -> tuple[dict, dict]:
    """T, Theta and 1/(tau0 Omega0^2) of the start, and the paper's printed T and Theta."""
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
    return scales, printed


def _receive(obs: Observation, receiver, body, start) -> None:
    """The receiver's budgets, its parting times and the P-f tests, into ``obs``."""
    from . import pftest as PF
    from .receiver import budget

    obs.receiver = receiver
    obs.budgets = [budget(d, receiver) for d in obs.detections]
    by = {bg.model: bg for bg in obs.budgets}
    rows = {m: np.arange(bg.t.size) for m, bg in by.items()}
    sig = {"frequency": [bg.sigma_f / bg.freq[rows[m], bg.dominant] for m, bg in by.items()],
           "power": [bg.sigma_lnp for bg in by.values()], "polarization": [bg.sigma_pol for bg in by.values()]}
    t = obs.budgets[0].t
    for key, c in obs.parting.items():
        worse = np.fmax(*sig[key]) if len(sig[key]) == 2 else sig[key][0]
        worse = np.where(np.isnan(sig[key][0]) | np.isnan(sig[key][1]), np.nan, worse)
        PT.setup_parting(c, t, worse, receiver.integration_s)
    obs.pf_law, obs.pf_reason = PF.line_law(body)
    if obs.pf_law is None:
        return
    rng = np.random.default_rng(SEED)
    f_inf = math.sqrt(start[1]) / (2.0 * math.pi) if start is not None else None
    for bg in obs.budgets:
        series = PF.synthetic(bg, rng)
        obs.pf_series[bg.model] = series
        obs.pf[bg.model] = PF.fit(series, f_inf_expected=f_inf) if series is not None else None
        if series is None:
            obs.notes.append(f"{bg.model}: fewer than four instants with the line detected in the radiation zone: "
                             f"no P-f series")


def _when(t: float | None, obs: Observation) -> str:
    if t is None:
        return f"not within the run ({U.format_time(obs.horizon, obs.units)})"
    out = U.format_time(t, obs.units)
    extra = [f"{t / v:.3g} {k}" for k, v in obs.scales.items() if k in ("T", "Theta")]
    return out + (f"  ({', '.join(extra)})" if extra else "")


def _res_text(key: str, r: float) -> str:
    return f"{math.degrees(r):.3g}°" if key == "polarization" else f"{r:.3g}"


def format_table(obs: Observation) -> str:
    """The answer for people: the detector and receiver, what they see at the start and the end,
    when the models part across resolutions and for this receiver, and the P-f tests."""
    a, b = obs.detections
    cgs = obs.units == "cgs"
    n = ", ".join(f"{x:.3g}" for x in a.line_of_sight)
    lines = [obs.title, "", f"detector along n = ({n}) (world frame)"]
    if obs.receiver is not None:
        lines.append(f"receiver: {obs.receiver.describe()}")
    for note in a.notes + obs.notes:
        lines.append(f"note: {note}")
    lines.append(f"{_horizon_text(obs)} (the scene's [observe] horizon, else its own)")
    lines.append("")
    head = f"{'':<40} {a.model:>22} {b.model:>22}"
    budgets = {bg.model: bg for bg in obs.budgets} if obs.budgets else {}
    for label, i in (("at the start", 0), (f"at the end, t = {U.format_time(obs.horizon, obs.units)}", -1)):
        lines += [label, head]
        cells = [_cells(d, i, cgs) for d in obs.detections]
        if budgets:
            for c, d in zip(cells, obs.detections):
                c.update(_budget_cells(budgets[d.model], _first(budgets[d.model]) if i == 0 else -1))
        for name in cells[0]:
            lines.append(f"  {name:<38} {cells[0][name]:>22} {cells[1][name]:>22}")
        lines.append("")
    lines += _parting_lines(obs)
    lines += _pf_lines(obs)
    for k, v in obs.scales.items():
        printed = obs.printed.get(k)
        text = f"  {k:<18} = {U.format_time(v, obs.units)}"
        if printed:
            text += f"   (the paper, {printed['where']}: {'~' if printed['approx'] else ''}{U.human_time(printed['value_s'])})"
        lines.append(text)
    return "\n".join(lines)


def _parting_lines(obs: Observation) -> list[str]:
    out = ["when do the models part? (the same, known start; first time the difference reaches the resolution)"]
    for key in OBSERVABLES:
        c = obs.parting[key]
        cells = [f"{_res_text(key, r)}: {_short_when(c.at(r), obs)}" for r in PT.TABLE[key]]
        out.append(f"  {key:<13} " + "; ".join(cells))
        if obs.receiver is not None:
            if c.setup_time is not None:
                out.append(f"  {'':<13} this receiver (5σ in one {obs.receiver.integration_s:g} s integration, "
                           f"{_res_text(key, c.setup_resolution)}): {_when(c.setup_time, obs)}")
            else:
                out.append(f"  {'':<13} this receiver: not within the run")
    out.append(f"  (power and frequency from {obs.parting['frequency'].source})")
    out.append("")
    return out


def _short_when(t, obs) -> str:
    return "never" if t is None else U.format_time(t, obs.units)


def _pf_lines(obs: Observation) -> list[str]:
    if obs.receiver is None:
        return []
    out = ["the start-free test: each model's line as this receiver measures it, fitted to the P-f laws"]
    if obs.pf_law is None:
        return out + [f"  none: {obs.pf_reason}", ""]
    out.append(f"  line: {obs.pf_law}")
    for m, r in obs.pf.items():
        if r is None:
            out.append(f"  {m}: no series (the line is not detected in the radiation zone at four instants)")
            continue
        out.append(f"  {m}'s run:")
        out += [f"    {line}" for line in r.summary()]
    out.append("")
    return out


def _cells(d: Detection, i: int, cgs: bool) -> dict[str, str]:
    """One column of ``format_table``: the detection's observables at sample i, as text."""
    freq = (lambda f: U.format_frequency(f)) if cgs else (lambda f: f"{f:.4g} {d.freq_unit}")
    pol = round(math.degrees(d.pol_angle[i]), 1) + 0.0                      # never "-0.0"
    out = {"radiated power": _num(d.power[i], d.power_unit, cgs, "power"),
           "power toward the detector": _num(d.power_sr[i], d.power_sr_unit, cgs, "sr"),
           "dominant frequency": freq(d.f_dom[i]), "rotation |L|/(2 pi I1)": freq(d.f_rot[i]),
           "polarization angle (from u1)": f"{pol:.1f}° ({100 * d.linear[i]:.0f} % lin.)"}
    if cgs:
        out["photons per second per sr"] = f"{d.photons_sr[i]:.3g}"
    else:
        out["RMS field"] = _num(d.field_rms[i], d.field_unit, cgs, "field")
    return out


def _budget_cells(bg, i: int) -> dict[str, str]:
    """The receiver's view of the strongest line at sample i, as text."""
    r = bg.record(i)

    def g(x, fmt="{:.3g}", none="-"):
        return none if x is None else fmt.format(x)

    lam = r["wavelength_cm"]
    return {"wavelength, zone at the antenna": f"{g(lam)} cm, {r['zone']}",
            "field at the antenna, all terms (1/R)": f"{r['field_full_rms_v_per_m'] * 1e6:.3g} "
                                                     f"({r['field_radiation_term_rms_v_per_m'] * 1e6:.3g}) µV/m",
            "received power": g(r["received_w"], "{:.3g} W", "(near zone)"),
            "SNR of one integration": g(r["snr_integration"], "{:.3g}", "(near zone)"),
            "coherent interval (SNR, threshold)": f"{g(r['coherent_interval_s'], '{:.3g} s')} "
                                                  f"({g(r['snr_coherent'])}, {g(r['threshold'])})",
            "resolution: frequency (relative)": g(r["sigma_f_relative"], "{:.2g}", "not detected"),
            "resolution: power (relative)": g(r["sigma_power_relative"], "{:.2g}", "not detected"),
            "resolution: polarization angle": g(r["sigma_polarization_deg"], "{:.2g}°", "not detected")}


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


def _horizon_text(obs: Observation) -> str:
    return f"watched for {U.format_time(obs.horizon, obs.units)}"


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
               "power toward the detector (W/sr)" if cgs else f"dP/dΩ ({a.power_sr_unit})", "log", "power received"),
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
    fig.suptitle(f"{obs.title}\nwhat a detector along n = ({n}) sees, {_horizon_text(obs)}{note}{rx}", fontsize=11)
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


MIN_LINE = 1e-6


def run_scene(sc, samples: int = 800, line_of_sight=None, distance_cm=None, receive: bool = True,
              integration_s=None):
    """Simulate both models of scene ``sc`` over its ``[observe]`` horizon (or its own) at
    ``observe_times`` and observe them with its receiver (its distance and integration time
    overridden by ``distance_cm``, ``integration_s``; none with ``receive`` False):
    (Observation, trajectories)."""
    from dataclasses import replace

    from ..driver import simulate_request

    if len(sc.models) != 2:
        raise ValueError("[simulation].models: observe needs two models, e.g. models = [\"reduced\", \"truncated\"]")
    if not sc.body.is_symmetric:
        raise ValueError("[body]: the detector needs a symmetric top (I1 = I2); this body is asymmetric")
    horizon = sc.observe.t_end or sc.t_end
    times = observe_times(horizon, samples)
    trajs = [simulate_request(sc.request(m, t_eval=times)) for m in sc.models]
    los = line_of_sight if line_of_sight is not None else sc.observe.line_of_sight
    receiver = sc.observe.receiver
    if distance_cm is not None:
        receiver = replace(receiver, distance_cm=float(distance_cm))
    if integration_s is not None:
        receiver = replace(receiver, integration_s=float(integration_s))
    obs = observe(trajs, sc.title, los, receiver, omega0=sc.omega0, rtol=sc.rtol, receive=receive)
    return obs, trajs
