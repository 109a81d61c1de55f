"""The pictures of an experiment's design: what the receiver makes of the lines
(``plot_receiver``, ``spinviz observe``'s third PNG) and how long to watch (``plot_decide``,
``spinviz decide``).  matplotlib only when drawn; PNGs written atomically."""

from __future__ import annotations

import math

import numpy as np

from .. import units as U
from ..physics import models as M
from ..plotting import model_color, model_line, pyplot, save, time_unit


def _style(model: str, **kw):
    return model_line(model, **kw)


def _time_axis(ax, tl: str) -> None:
    ax.set_xscale("log")
    ax.set_xlabel(tl + ", log scale")
    ax.grid(True, which="major", color="0.9", lw=0.6)


def _nothing(ax, obs, what: str) -> bool:
    """Say so on ``ax`` when no budget has a radiation-zone value of ``what`` (the antenna in
    the near zone throughout, or the line never detected); True when it did."""
    has = any(np.any(np.isfinite(getattr(bg, what)) & (getattr(bg, what) > 0)) for bg in obs.budgets)
    if not has:
        near = not any(np.any(bg.radiation_zone) for bg in obs.budgets)
        ax.annotate("the antenna is inside a wavelength throughout (R < λ):\nno radiation-zone SNR" if near else
                    "the line is not detected at any instant", (0.5, 0.5), xycoords="axes fraction", ha="center",
                    va="center", fontsize=9, color="0.3")
        ax.set_axis_off()
    return not has


def _snr_panel(ax, obs, pos, scale) -> None:
    """SNR of one integration of every line above 1e-6 of the strongest in power (both models),
    and the coherent interval's detection threshold scaled to one integration."""
    ax.set_title("signal-to-noise ratio of each line (below the dotted line: not detected)")
    if _nothing(ax, obs, "rho"):
        return
    for j, bg in enumerate(obs.budgets):
        t = bg.t[pos] / scale
        top = np.max(bg.power_sr[pos], axis=1, keepdims=True)
        strong = bg.power_sr[pos] >= 1e-6 * top           # the rest is the line spectrum's round-off
        for k in range(bg.rho.shape[1]):
            y = np.where(strong[:, k], bg.rho[pos, k], np.nan)
            if np.any(np.nan_to_num(y, nan=0.0) > 0):
                dom = k == np.bincount(bg.dominant[pos]).argmax()
                ax.plot(t, np.where(y > 0, y, np.nan), **_style(bg.model, lw=1.8 if dom else 0.7,
                                                                label=f"{bg.model}: strongest line" if dom else None))
        rows = np.arange(bg.t.size)[pos]
        need = bg.threshold[rows, bg.dominant[pos]] * obs.receiver.integration_s / bg.t_coh[rows, bg.dominant[pos]]
        ax.plot(t, need, color=model_color(bg.model), lw=0.8, ls=":",
                label=f"{bg.model}: detection threshold (per coherent interval, scaled)")
        inside = ~bg.radiation_zone[rows, bg.dominant[pos]]
        if np.any(inside) and not np.all(inside):
            i = int(np.argmax(inside))
            ax.axvline(t[i], color=model_color(bg.model), lw=0.8, ls="-.")
            ax.annotate(f"{bg.model}: λ > R from here,\nno radiation-zone SNR", (t[i], 0.5 - 0.12 * j),
                        xycoords=("data", "axes fraction"), xytext=(-4, 0), textcoords="offset points", ha="right",
                        fontsize=7, color=model_color(bg.model))
    ax.set_yscale("log")
    ax.set_ylabel(f"SNR of one {obs.receiver.integration_s:g} s integration")
    ax.legend(fontsize=7, loc="best")


def _resolution_panel(ax, obs, pos, scale) -> None:
    """The strongest line's resolutions of one integration over time, both models."""
    ax.set_title("resolutions (Cramér–Rao bounds); gaps: not detected or near zone")
    if _nothing(ax, obs, "sigma_lnp"):
        return
    colors = {"frequency": "tab:blue", "power": "tab:orange", "polarization": "tab:green"}
    for bg in obs.budgets:
        t = bg.t[pos] / scale
        rows = np.arange(bg.t.size)[pos]
        f = bg.freq[rows, bg.dominant[pos]]
        series = {"frequency": bg.sigma_f[pos] / f, "power": bg.sigma_lnp[pos], "polarization": bg.sigma_pol[pos]}
        for key, y in series.items():
            y = np.where(np.isfinite(y), y, np.nan)
            ax.plot(t, y, color=colors[key], ls=model_line(bg.model)["ls"], lw=1.4,
                    label=f"{key} ({'σ_f/f' if key == 'frequency' else 'σ_P/P' if key == 'power' else 'σ_ψ, rad'}), "
                          f"{bg.model}")
    ax.set_yscale("log")
    ax.set_ylabel("1σ of one integration")
    ax.legend(fontsize=7, loc="upper left", ncol=2)


def _field_panel(ax, obs, pos, scale) -> None:
    """The field at the antenna: all three terms and the radiation term alone, with R/lambda."""
    for bg in obs.budgets:
        t = bg.t[pos] / scale
        ax.plot(t, bg.field_full_rms[pos] * 1e6, **_style(bg.model, label=f"{bg.model}: all terms"))
        ax.plot(t, bg.field_radiation_rms[pos] * 1e6, color=model_color(bg.model), lw=0.9, ls=":",
                label=f"{bg.model}: radiation term (1/R) alone")
    ax.set_yscale("log")
    ax.set_ylabel(f"RMS field at {obs.receiver.distance_cm:g} cm (µV/m)")
    ax.set_title("the field where the antenna stands")
    ax.legend(fontsize=7, loc="lower left")
    tw = ax.twinx()
    for bg in obs.budgets:
        rows = np.arange(bg.t.size)[pos]
        lam = U.wavelength_cm(bg.freq[rows, bg.dominant[pos]])
        tw.plot(bg.t[pos] / scale, obs.receiver.distance_cm / lam, color=model_color(bg.model), lw=0.8, ls="-.")
    tw.axhline(1.0, color="tab:red", lw=0.8, ls="--")
    tw.annotate("R/λ = 1 on the right axis: radiation zone above", (0.99, 1.0), xycoords=("axes fraction", "data"),
                ha="right", va="bottom", fontsize=7, color="tab:red")
    tw.set_yscale("log")
    tw.tick_params(axis="y", labelsize=8, colors="0.35")
    tw.set_ylabel("R/λ (dash-dot and the red line: right axis)", fontsize=8, color="0.35")


def _pf_panel(ax, obs) -> None:
    """Each model's synthetic series in the P-f plane with the two laws fitted to it."""
    if obs.pf_law is None:
        ax.annotate("no P–f law for this top:\n" + "\n".join(_wrap(obs.pf_reason, 60)), (0.5, 0.5),
                    xycoords="axes fraction", ha="center", va="center", fontsize=9, color="0.3")
        ax.set_axis_off()
        return
    if not any(s is not None for s in obs.pf_series.values()):
        ax.annotate("no P–f series: the line is not detected in the radiation zone", (0.5, 0.5),
                    xycoords="axes fraction", ha="center", va="center", fontsize=9, color="0.3")
        ax.set_axis_off()
        return
    for m, s in obs.pf_series.items():
        r = obs.pf.get(m)
        if s is None or r is None:
            continue
        ax.errorbar(s.f_hz / 1e9, s.power, yerr=s.sigma_power, fmt="o", ms=2.0, color=model_color(m), alpha=0.45,
                    elinewidth=0.6, label=f"{m}'s run, {len(s)} integrations: verdict {r.verdict} (Z = {r.z:.3g})")
        f = np.linspace(s.f_hz.min(), s.f_hz.max(), 300)
        for law in ("truncated", "reduced"):
            fit = getattr(r, law)
            y = np.exp(fit.params["a"]) * M.get(law).line.law(f, fit.params["f_inf_hz"])
            ax.plot(f / 1e9, y, **model_line(law, lw=1.0))
    for law in ("truncated", "reduced"):
        formula = M.get(law).line.formula.replace("P ∝", "P = A")
        ax.plot([], [], **model_line(law, lw=1.0), label=f"fitted {formula} ({law} law)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_major_formatter(lambda v, _: f"{v:g}")
    ax.xaxis.set_minor_formatter(lambda v, _: f"{v:g}" if round(v, 6) in (2, 3, 4, 5, 6, 7, 8) else "")
    ax.set_xlabel("line frequency (GHz), log scale")
    ax.set_ylabel("power toward the antenna (W/sr)")
    ax.set_title("the start-free test: power against frequency")
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(True, which="both", color="0.92", lw=0.5)


def _wrap(text: str, width: int) -> list[str]:
    out, line = [], ""
    for w in text.split():
        if len(line) + len(w) + 1 > width:
            out.append(line)
            line = w
        else:
            line = f"{line} {w}".strip()
    return out + [line]


def _environment_box(fig, rep: dict) -> None:
    """The trap's numbers at the start (``environment_report``), boxed under the panels."""
    from .environment_report import lines

    text = "\n".join(line.strip() if i == 0 else "    " + line.strip() for i, line in enumerate(lines(rep))
                     if line.strip())
    fig.text(0.01, 0.01, text, ha="left", va="bottom", fontsize=8, color="0.1", family="monospace",
             bbox={"boxstyle": "round", "fc": "lightyellow", "ec": "0.6"})


def plot_receiver(obs, path: str) -> None:
    """Four panels of ``spinviz observe`` for a CGS scene: the SNR of each line over time, the
    resolutions the receiver reaches, the field at the antenna (all terms and the radiation term,
    with R/lambda), and the P-f test on each model's synthetic series (PNG, atomic)."""
    plt = pyplot()
    a = obs.budgets[0]
    scale, tl = time_unit(obs.horizon, obs.units)
    pos = a.t > 0
    fig, axes = plt.subplots(2, 2, figsize=(15, 10))
    for ax, fn in zip(axes.flat[:3], (_snr_panel, _resolution_panel, _field_panel)):
        fn(ax, obs, pos, scale)
        _time_axis(ax, tl)
    _pf_panel(axes[1, 1], obs)
    fig.suptitle(f"{obs.title}\nthe receiver: {obs.receiver.describe()}", fontsize=11)
    fig.tight_layout(w_pad=2.5)
    if obs.environment is not None:
        fig.set_size_inches(15, 12)
        fig.tight_layout(w_pad=2.5, rect=(0.0, 0.1, 1.0, 1.0))
        _environment_box(fig, obs.environment)
    save(fig, path)


def plot_decide(out, title: str, path: str) -> None:
    """Two panels of ``spinviz decide``: the share of trials decided at 5 sigma against the
    observation time (each model the truth; the 95 % line and the answer with its Monte Carlo
    interval), and each trial's decision time against its start's f_inf / f0 = eps |Omega_par| /
    omega_L0 (the slow trials are the starts spun nearly across the dipole) (PNG, atomic)."""
    plt = pyplot()
    from .decide import DECISION_Z, SHARE

    s = out.setup
    finite = np.concatenate([out.times(m)[np.isfinite(out.times(m))] for m in out.setup.models])
    lo = max(float(finite.min()) / 2 if finite.size else s.integration_s, s.integration_s / 2)
    T = np.geomspace(lo, s.horizon, 400)
    scale, tl = time_unit(max(float(finite.max()) if finite.size else s.horizon, lo * 10), "cgs")
    fig, axes = plt.subplots(1, 2, figsize=(15, 5.8))
    ax = axes[0]
    for j, m in enumerate(out.setup.models):
        never = 100.0 * float(np.mean(~np.isfinite(out.times(m))))
        ax.plot(T / scale, out.fraction(m, T), **_style(m, label=f"truth: {m} ({never:.3g} % never decided)"))
        t95 = out.t95[m]
        if math.isfinite(t95):
            lo95, hi95 = (min(x, s.horizon) for x in out.interval[m])      # an interval may reach "never"
            ax.axvspan(lo95 / scale, hi95 / scale, color=model_color(m), alpha=0.15)
            ax.annotate(f"{m}: {U.human_time(t95)} (band: Monte Carlo 68 %)", (hi95 / scale, SHARE),
                        xytext=(6, -14 - 12 * j), textcoords="offset points", fontsize=8, color=model_color(m))
    ax.axhline(SHARE, color="tab:red", lw=0.9, ls="--")
    ax.set_ylim(0, 1.02)
    ax.set_ylabel(f"share of trials decided (Z ≥ {DECISION_Z:g})")
    ax.set_title(f"{out.trials} trials: when does the likelihood ratio reach {DECISION_Z:g}σ?")
    _time_axis(ax, tl.replace("time t", "observation time"))
    ax.legend(fontsize=8, loc="center right")
    ax = axes[1]
    for m in out.setup.models:
        share = np.array([r["b0"] / (r["u0"] + r["b0"]) for r in out.rows])
        t = out.times(m)
        never = ~np.isfinite(t)
        ax.plot(np.sqrt(share[~never]), t[~never] / scale, "o", ms=3, color=model_color(m), alpha=0.6,
                label=f"truth: {m}")
        if np.any(never):
            ax.plot(np.sqrt(share[never]), np.full(int(never.sum()), s.horizon / scale), "x", ms=5,
                    color=model_color(m), label=f"truth: {m}, not within the horizon (drawn at it)")
    ax.axhline(s.horizon / scale, color="0.6", lw=0.8, ls=":")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("start's f∞/f0 = ε|Ω∥|/ω_L0 (0: spun across the dipole), log scale")
    ax.set_ylabel(tl.replace("time t", "decision time") + ", log scale")
    ax.set_title("each trial's decision time against its start")
    ax.grid(True, which="major", color="0.9", lw=0.6)
    ax.legend(fontsize=8, loc="upper center")
    nu = s.nuisance
    exact = s.tau0_mode == "known" and (nu is None or nu.tau0_width == 0.0)
    tau = ("τ0 known exactly: the truncated curve rests on it (with τ0 fitted no truncated trial decides)" if exact
           else "τ0 fitted with the start" if s.tau0_mode == "fitted" else "τ0 as below")
    trap = ""
    if nu is not None:
        from .nuisance import describe

        trap = "\n" + describe(nu).split(" -- ")[0]
    fig.suptitle(f"{title}\nhow long to watch: {tau}; |Ω0| log-uniform over "
                 f"{s.spin_range[0]:g}–{s.spin_range[1]:g} × the scene's, directions isotropic{trap}", fontsize=11)
    fig.tight_layout()
    save(fig, path)
