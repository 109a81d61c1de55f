"""What the trap must achieve: the largest pressure, static field, tau0 prior, gain slope and
clock instability at which 95 % of ``decide``'s trials still decide at 5 sigma within the
scene's horizon, each with the others at their stated values.

For each of them (``KEYS``), the same Monte Carlo as ``decide`` (the same seed, so the same
starts and noise at every value probed: the answer moves with the value, not with the draw)
is run at values rising by decades from ``GRIDS``' low end until one fails -- fewer than 95 %
of the trials of either truth decided by the horizon -- and the last decade is bisected
(``REFINE`` halvings of its logarithm: the answer to a factor 10^(1/16) ~ 1.15 for the pressure,
10^(1/8) for the others, whose decades are stepped two at a time).  For the pressure every
probe keeps the trials' decision times: the decision time against the pressure, and the
vacuum's beside it.  The others need only whether each trial decides by the horizon (one fit
of each model on all its records, ``Nuisances.horizon_only``).

The answers assume what the scene and the options state for everything else, and rest on the
Monte Carlo: with N trials the 95 % share has a binomial spread of ~sqrt(0.05 x 0.95 / N)
(0.022 at N = 100), so a value near the threshold can pass or fail on the trials drawn; the
probes' shares are kept (``Requirement.probes``) to show how sharp the edge is.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..inputs.options import DECIDE_S_PER_TRIAL
from . import decide as DC
from . import nuisance as NU

KEYS = ("pressure_mbar", "field_v_per_m", "tau0_prior", "gain_slope", "clock_stability")
GRIDS = {"pressure_mbar": (1e-18, 1e-4, 1), "field_v_per_m": (1e-4, 1e6, 2), "tau0_prior": (1e-8, 1.0, 2),
         "gain_slope": (1e-4, 10.0, 2), "clock_stability": (1e-16, 1e-6, 2)}     # low, high, decades a step
LABELS = {"pressure_mbar": ("max_pressure_mbar", "pressure", "mbar"),
          "field_v_per_m": ("max_field_v_per_m", "static field", "V/m"),
          "tau0_prior": ("max_tau0_prior", "tau0 known to (relative)", ""),
          "gain_slope": ("max_gain_slope_db_per_octave", "antenna gain slope", "dB/octave"),
          "clock_stability": ("max_clock_stability", "clock stability (fractional)", "")}
REFINE = 4
# measured costs of one trial (both truths), one core, the DAST cube (inputs.options): the
# vacuum's full decision, a full decision in gas (the dearest pressure's), and the horizon's fits
# alone with a nuisance
S_PER_TRIAL = {"vacuum": DECIDE_S_PER_TRIAL["known"], "full": DECIDE_S_PER_TRIAL["gas"], "horizon": 0.4}


@dataclass
class Requirement:
    """The answer for one key: ``value`` the largest value probed at which 95 % of the trials of
    each truth decide within the horizon (None: not even the lowest), ``at_least`` when the
    highest probed passed too; ``probes`` [(value, share decided (the worse truth), {truth:
    t95 s, None where never} or None where only the horizon was asked)]."""

    key: str
    value: float | None
    at_least: bool
    probes: list = field(default_factory=list)
    note: str = ""

    def record(self) -> dict:
        """JSON-ready."""
        return {"value": self.value, "at_least": self.at_least, "note": self.note or None,
                "probes": [{"value": v, "decided_share": s, "t95_s": t} for v, s, t in self.probes]}


@dataclass
class Requirements:
    """All the answers, the stated values they assume, and the vacuum's decision times."""

    title: str
    stated: dict
    trials: int
    seed: int
    horizon: float
    vacuum_t95: dict
    results: dict
    models: tuple
    gas: str = "N2"
    receiver: object = None          # inputs.receiver.ReceiverSpec the trials were watched by

    def table(self) -> str:
        """The answer for people (``format_requirements``)."""
        return format_requirements(self, self.receiver)

    def record(self) -> dict:
        """JSON: ``max_pressure_mbar`` and the others beside it, then the details."""
        out = {LABELS[k][0]: r.value for k, r in self.results.items()}
        out.update({"gas": self.gas, "stated": self.stated, "trials": self.trials, "seed": self.seed, "horizon_s": self.horizon,
                    "share": DC.SHARE, "decision_z": DC.DECISION_Z,
                    "vacuum_t95_s": {m: _num(v) for m, v in self.vacuum_t95.items()},
                    "requirements": {LABELS[k][0]: r.record() for k, r in self.results.items()}})
        return out


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


def work_seconds(trials: int, workers: int) -> float:
    """An upper estimate of the work (s of wall time on ``workers`` cores): every decade of
    every key probed, and the refinements."""
    lo, hi, step = GRIDS["pressure_mbar"]
    pressure = (math.log10(hi / lo) / step + 1 + REFINE) * S_PER_TRIAL["full"]
    others = sum((math.log10(h / l_) / s + 1 + REFINE) * S_PER_TRIAL["horizon"]
                 for k, (l_, h, s) in GRIDS.items() if k != "pressure_mbar")
    return trials * (S_PER_TRIAL["vacuum"] + pressure + others) / max(1, workers)


class _Probe:
    """Runs the Monte Carlo at one value of one key, the others stated."""

    def __init__(self, sc, receiver, stated: dict, trials: int, seed: int, spin_range, mapper, say):
        self.sc, self.receiver, self.stated = sc, receiver, stated
        self.trials, self.seed, self.spin_range, self.mapper, self.say = trials, seed, spin_range, mapper, say
        self.horizon = sc.observe.t_end or sc.t_end

    def setup(self, values: dict, horizon_only: bool) -> DC.Setup:
        sc = self.sc.with_environment(pressure_mbar=values["pressure_mbar"],
                                      field_v_per_m=(0.0, 0.0, values["field_v_per_m"]))
        setup = DC.setup_from_scene(sc, self.receiver, self.horizon, self.spin_range, "known")
        nu = NU.from_scene(sc, tau0_width=values["tau0_prior"], gain_slope_db=values["gain_slope"],
                           clock=values["clock_stability"], pressure_width=values["pressure_prior"],
                           horizon_only=horizon_only)
        return dataclasses.replace(setup, nuisance=nu)

    def __call__(self, key: str, value: float, horizon_only: bool):
        values = {**self.stated, key: value}
        out = DC.run(self.setup(values, horizon_only), self.trials, self.seed, self.mapper)
        share = min(float(np.mean(np.isfinite(out.times(m)))) for m in out.setup.models)
        t95 = None if horizon_only else {m: _num(out.t95[m]) for m in out.setup.models}
        if self.say is not None:
            self.say(f"requirements: {LABELS[key][1]} {value:.3g} {LABELS[key][2]}: {100 * share:.1f} % decided")
        return share, t95


def search(probe: _Probe, key: str) -> Requirement:
    """The largest value of ``key`` at which the trials decide (module docstring)."""
    lo, hi, step = GRIDS[key]
    full = key == "pressure_mbar"
    start = lo
    values = [start * 10.0 ** (step * i) for i in range(int(math.floor(math.log10(hi / start) / step + 1e-9)) + 1)]
    if values[-1] < hi * (1.0 - 1e-9):
        values.append(hi)                        # the grid's top is always probed
    probes = []
    good = None
    for v in values:
        share, t95 = probe(key, v, not full)
        probes.append((v, share, t95))
        if share < DC.SHARE:
            break
        good = v
    else:
        return Requirement(key, good, True, probes, f"decides at the highest value probed ({hi:g})")
    if good is None:
        return Requirement(key, None, False, probes, f"does not decide even at {start:g}")
    a, b = math.log10(good), math.log10(probes[-1][0])
    for _ in range(REFINE):
        mid = 0.5 * (a + b)
        share, t95 = probe(key, 10.0**mid, True)
        probes.append((10.0**mid, share, t95))
        a, b = (mid, b) if share >= DC.SHARE else (a, mid)
    probes.sort(key=lambda p: p[0])
    return Requirement(key, 10.0**a, False, probes)


def run(sc, receiver, stated: dict, trials: int, seed: int = 1, spin_range=(0.5, 2.0), mapper=None,
        say=None) -> Requirements:
    """Every requirement of scene ``sc`` watched by ``receiver``, the others at ``stated``
    (pressure_mbar, field_v_per_m (its size), tau0_prior, gain_slope, clock_stability,
    pressure_prior); the Monte Carlo of ``trials`` trials by ``mapper``."""
    probe = _Probe(sc, receiver, stated, trials, seed, spin_range, mapper, say)
    base = probe.setup(stated, False)
    vac = DC.run(dataclasses.replace(base, nuisance=None), trials, seed, mapper)
    results = {}
    if min(float(np.mean(np.isfinite(vac.times(m)))) for m in vac.setup.models) < DC.SHARE:
        for key in KEYS:
            results[key] = Requirement(key, None, False, [], "not decided within the horizon even in a perfect vacuum "
                                                             "with everything known")
    else:
        for key in KEYS:
            results[key] = search(probe, key)
    return Requirements(title=sc.title, stated=dict(stated), trials=trials, seed=seed, horizon=probe.horizon,
                        vacuum_t95=dict(vac.t95), results=results, models=tuple(sc.models), gas=sc.environment.gas,
                        receiver=receiver)


def format_requirements(req: Requirements, receiver) -> str:
    """The answer for people: one line per requirement, with what it assumes."""
    lines = [req.title, "", f"receiver: {receiver.describe()}",
             f"stated: {', '.join(f'{k} = {v:g}' for k, v in req.stated.items())}",
             f"{req.trials} trials (seed {req.seed}); decided: {100 * DC.SHARE:g} % of the trials of each truth at "
             f"Z >= {DC.DECISION_Z:g} within {U.human_time(req.horizon)}",
             "vacuum, everything known: " + ", ".join(
                 f"{m} {U.human_time(t) if math.isfinite(t) else 'never'}" for m, t in req.vacuum_t95.items()), "",
             "what the trap must achieve (each with the others as stated):"]
    for key, r in req.results.items():
        name, what, unit = LABELS[key]
        if r.value is None:
            text = f"none: {r.note}"
        else:
            text = f"{'>= ' if r.at_least else '<= '}{r.value:.3g} {unit}".rstrip()
        lines.append(f"  {what:<32} {text}")
    return "\n".join(lines)
