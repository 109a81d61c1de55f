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
prints.  Numbers from NumPy (and SciPy for the fits); the pictures are ``observe_plots``'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from . import parting as PT
from .compare import compare_times
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
    environment: dict | None = None                  # the trap's numbers at the start (environment_report)

    def table(self) -> str:
        """The observation for people (``format_table``): the receiver, the observables, when the
        models part, the P-f test."""
        return format_table(self)

    def record(self) -> dict:
        """The observation as a JSON-ready dict (``spinviz observe --json``): the receiver, per
        model its observables at the start and the end and its budget at the first output instant
        after the start ("first", its time in it) and the end, the parting curves, the P-f tests,
        the scales, and the trap's numbers where there is one."""
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
            out["budget"] = {bg.model: {"first": bg.record(_first(bg)), "end": bg.record(-1),
                                        "series": _thinned(bg)} for bg in self.budgets}
        out["pf_test"] = {"law": self.pf_law, "reason": self.pf_reason or None,
                          "fits": {m: (r.record() if r is not None else None) for m, r in self.pf.items()}}
        if self.environment is not None:
            out["environment"] = self.environment
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
    from ..physics import models as M
    from .detector import default_line_of_sight, detect

    if len(trajs) != 2:
        raise ValueError(f"observe takes two trajectories (one model each), got {len(trajs)}")
    receiver = ReceiverSpec() if receiver is None else receiver
    n = default_line_of_sight(trajs[0]) if line_of_sight is None else line_of_sight
    dets = [detect(tr, n, receiver.distance_cm) for tr in trajs]
    body = trajs[0].body
    scales, printed = _scales(body, omega0)
    law = LG.has_line_law(body.delta, body.chi, body.is_symmetric)
    start = (LG.start_state(omega0, body.dipole_direction, body.epsilon)
             if law and omega0 is not None and all(M.get(t.model).line is not None for t in trajs) else None)
    a, b = dets
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


def horizon_text(obs: Observation) -> str:
    """How long the detector watches, for titles and tables."""
    return f"watched for {U.format_time(obs.horizon, obs.units)}"


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
    lines.append(f"{horizon_text(obs)} (the scene's [observe] horizon, else its own)")
    lines.append("")
    head = f"{'':<40} {a.model:>22} {b.model:>22}"
    budgets = {bg.model: bg for bg in obs.budgets} if obs.budgets else {}
    for label, i in (("at the start", 0), (f"at the end, t = {U.format_time(obs.horizon, obs.units)}", -1)):
        lines += [label, head]
        cells = [_cells(d, i, cgs) for d in obs.detections]
        for name in cells[0]:
            lines.append(f"  {name:<38} {cells[0][name]:>22} {cells[1][name]:>22}")
        if budgets:
            if i == 0:
                # the receiver's drift rates need an instant after t = 0: its columns are named by that instant
                first = _first(budgets[obs.detections[0].model])
                lines.append(f"  the receiver at t = {U.format_time(float(budgets[obs.detections[0].model].t[first]), obs.units)}"
                             f" (the first output instant):")
            bc = [_budget_cells(budgets[d.model], _first(budgets[d.model]) if i == 0 else -1) for d in obs.detections]
            for name in bc[0]:
                lines.append(f"  {name:<38} {bc[0][name]:>22} {bc[1][name]:>22}")
        lines.append("")
    if obs.environment is not None:
        from .environment_report import lines as env_lines

        lines += env_lines(obs.environment)
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
            "coherent interval (SNR, threshold; exact)": f"{g(r['coherent_interval_s'], '{:.3g} s')} "
                                                         f"({g(r['snr_coherent'])}, {g(r['threshold'])}; "
                                                         f"{g(r['threshold_exact'])})",
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


MIN_LINE = 1e-6


def run_scene(sc, samples: int = 800, line_of_sight=None, receiver=None, receive: bool = True,
              command: str = "observe"):
    """Simulate both models of scene ``sc`` over its ``[observe]`` horizon (or its own) at
    ``observe_times`` and observe them with ``receiver`` (an ``inputs.receiver.ReceiverSpec``;
    default the scene's; nothing received with ``receive`` False): (Observation, trajectories).
    The scene must have what ``command`` needs (``Scene.require``)."""
    from ..driver import simulate_request

    sc.require(command)
    horizon = sc.observe.t_end or sc.t_end
    times = observe_times(horizon, samples)
    trajs = [simulate_request(sc.request(m, t_eval=times)) for m in sc.models]
    los = line_of_sight if line_of_sight is not None else sc.observe.line_of_sight
    receiver = sc.observe.receiver if receiver is None else receiver
    obs = observe(trajs, sc.title, los, receiver, omega0=sc.omega0, rtol=sc.rtol, receive=receive)
    if sc.environment.active and sc.units == "cgs":
        from .environment_report import report

        obs.environment = report(sc, obs)
    return obs, trajs
