"""The atlas spec: a TOML file read through the schema into an ``AtlasSpec`` (errors: one line
naming file, key, reason), and whether that atlas can finish here.

A spec says which model(s), which (delta, chi) cells, which initial conditions at each cell,
how far and how finely to integrate, and how to classify::

    title = "reduced model, 12 x 12 cells, 8 members"
    models = ["reduced"]                  # or model = "reduced"; ["reduced", "truncated"] for both

    [grid]
    delta = { min = -1.0, max = 1.0, cells = 12 }   # centres of 12 equal cells of (min, max)
    chi_deg = { min = 0.0, max = 90.0, cells = 12 } # or chi (rad); or a list of values

    [members]
    count = 8                             # initial conditions per cell
    seed = 1                              # directions of omega(0) uniform on the sphere, from this seed
    omega = 0.1                           # |omega(0)| (dimensionless, 1/tau0)
    # or: list = [[0.0, 0.1, 0.0], ...]   explicit omega(0) vectors, body frame

    [run]
    engine = "handover"                   # or "taylor": every run integrated to tau_end (brute force)
    tau_end = 1e10                        # horizon, tau = t/tau0 (at most 1e20; 1e16 with "taylor")
    tau_start = 1e-2                      # first sample after 0
    samples_per_decade = 20
    rtol = 1e-8                           # Taylor tolerance on omega sqrt(1 + tau/T) / |omega0| (T = 1/|omega0|^2)
    max_steps = 20000000                  # step budget of one run

    [classify]
    window_decades = 2.0                  # decades at the end of a run the classifier analyses

Every member uses the same omega(0) at every cell and in both models, so that cells and
models are compared on the same starts (paired), and the store records them.

Defaults and why: the asymptotic laws of section 4 need tau |omega0|^2 >> 1 (T = 1/|omega0|^2
is the braking time); with |omega0| = 0.1 the default horizon 1e10 is 1e8 T.  The hand-over
engine labels a spiral by the attractor of the averaged flow it is in, whatever tau_end, and
its cost does not grow with tau_end; the regimes it integrates in full (the libration "5",
TF) settle by 1e10 .. 1e16 and cost ~tau_end^(1/4) (the shipped atlases use 1e16).  With
engine = "taylor" spirals cost ~ sqrt(tau_end) steps (~0.005-0.4 s a run at 1e10).  rtol 1e-8: Taylor's
method on the scaled omega sqrt(1 + tau/T) / |omega0|, so the tolerance holds relative to the
braking law to the end of the run (docs/atlas.md: labels and amplitudes against rtol).
20 samples a decade and a 2-decade window: 41 samples, the labels are the same at 10-50.

Every table is declared in ``spinviz.inputs.atlas`` (how to add a key is said there); this
module builds the ``AtlasSpec`` from the validated tables -- every rule joining keys (the
axes, the inertia limit, the horizon, the run cap) is checked here, once, and the spec is
trusted after.  Where its store goes is the arguments' (``atlas.store_path``).  Whether the atlas can finish on
this machine (memory, time) is the engine's to say, from its measured costs
(``regimes.engine.cost.check_feasible``), before any work.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass

import numpy as np

from ..atomic import loads_json
from ..errors import SceneError, SpecTypeError
from ..physics.bodies import MIN_INERTIA_RATIO
from . import atlas as IA
from .base import fields_of, shown
from .toml import document, read_document, table

FORMAT = 2                       # the store's version (identity): 2 = Taylor's method (heyoka), no atol


@dataclass(frozen=True)
class Settings:
    """How every run of an atlas is integrated and classified (part of the spec's identity).

    tau_end : horizon, tau = t/tau0.  tau_start : first sample after 0.  per_decade : samples
    a decade.  rtol : Taylor tolerance on the scaled omega sqrt(1 + tau/T) / |omega0|.
    max_steps : step budget of one run (of its SIMD batch).  window : decades the classifier analyses.
    engine : "handover" (full integration until the averaged flow holds, then the averaged
    flow: ``regimes.engine.handover_engine``) or "taylor" (every run integrated to tau_end).
    """

    tau_end: float = 1e10
    tau_start: float = 1e-2
    per_decade: int = 20
    rtol: float = 1e-8
    max_steps: int = 20_000_000
    window: float = 2.0
    engine: str = "handover"

    def times(self) -> np.ndarray:
        """Output times [0, tau_start, ..., tau_end], ``per_decade`` log-spaced a decade."""
        return log_times(self.tau_start, self.tau_end, self.per_decade)


def log_times(tau_start: float, tau_end: float, per_decade: int) -> np.ndarray:
    """[0, tau_start, ..., tau_end] with ``per_decade`` samples a decade (shape (N,))."""
    n = int(round(per_decade * math.log10(tau_end / tau_start))) + 1
    return np.concatenate([[0.0], np.logspace(math.log10(tau_start), math.log10(tau_end), n)])


@dataclass(frozen=True)
class AtlasSpec:
    """A validated atlas spec, made by ``parse_spec`` or ``load_spec`` (which check every rule
    once) and trusted after: ``dataclasses.replace`` of one is the caller's responsibility.

    deltas : shape (n_delta,), (3.6), each in (-1, 1).  chis : shape (n_chi,), rad, in [0, pi/2].
    omega0 : shape (members, 3), body-frame starts (dimensionless), the same at every cell.
    settings : how each run is integrated and classified.
    axes : {"delta": (min, max, cells), "chi": (min, max, cells) in rad} when both axes were
        given as {min, max, cells} (the grid refinement needs), else None.
    refine_levels, refine_agree : ``[refine]``; series : ``[output].series``.
    """

    path: str
    title: str
    description: str
    models: tuple
    deltas: np.ndarray
    chis: np.ndarray
    omega0: np.ndarray
    settings: Settings
    seed: int | None = None
    omega_magnitude: float | None = None
    axes: dict | None = None
    refine_levels: int = 0
    refine_agree: float = 0.9
    series: int = 1

    def __post_init__(self):
        for name in ("deltas", "chis", "omega0"):            # read-only views: a spec is shared, never changed
            a = np.array(getattr(self, name), dtype=float)
            a.flags.writeable = False
            object.__setattr__(self, name, a)
        object.__setattr__(self, "models", tuple(self.models))

    @property
    def members(self) -> int:
        """Starts per cell."""
        return int(self.omega0.shape[0])

    @property
    def runs(self) -> int:
        """Runs of the whole grid: models x deltas x chis x members."""
        return len(self.models) * len(self.deltas) * len(self.chis) * self.members

    def canonical(self) -> dict:
        """Everything that decides the numbers, as plain JSON types (title and description
        excluded: renaming a study does not change it)."""
        return {
            "format": FORMAT,
            "models": list(self.models),
            "delta": [float(x) for x in self.deltas],
            "chi": [float(x) for x in self.chis],
            "members": {"count": self.members, "seed": self.seed, "omega": self.omega_magnitude,
                        "omega0": [[float(x) for x in row] for row in self.omega0]},
            "run": _identity_values(IA.RunTable, self.settings),
            "classify": _identity_values(IA.ClassifyTable, self.settings),
            **({"refine": {"levels": self.refine_levels, "agree": self.refine_agree}} if self.refine_levels else {}),
            **({"output": {"series": self.series}} if self.series != 1 else {}),
        }

    def canonical_json(self) -> str:
        """``canonical()`` as compact JSON with sorted keys (what the store records)."""
        return json.dumps(self.canonical(), sort_keys=True, separators=(",", ":"))


def _kept(cls) -> dict:
    """The keys of table ``cls`` that reach ``Settings`` (refused keys do not)."""
    return {k: f for k, f in fields_of(cls).items() if k != "atol"}


def _identity_values(cls, settings: Settings) -> dict:
    out = {}
    for key, f in _kept(cls).items():
        value = getattr(settings, IA.SETTINGS_NAMES.get(key, key))
        if any(isinstance(m, IA.Added) for m in f.metadata) and value == f.default:
            continue
        out[key] = value
    return out


def settings_from(run, classify) -> Settings:
    """``Settings`` from the validated ``[run]`` and ``[classify]`` tables."""
    kw = {}
    for t in (run, classify):
        for key in _kept(type(t)):
            kw[IA.SETTINGS_NAMES.get(key, key)] = getattr(t, key)
    return Settings(**kw)


def settings_from_canonical(canonical: dict) -> Settings:
    """``Settings`` from a store's canonical spec (``json.loads(ds.attrs["spec"])``): its
    ``run`` and ``classify`` tables through the schema, so a key added later is read, and a
    store made before it gets the key's default."""
    run = IA.RunTable(**canonical.get("run", {}))
    classify = IA.ClassifyTable(**canonical.get("classify", {}))
    return settings_from(run, classify)


def spec_from_record(attrs: dict, where: str) -> AtlasSpec:
    """The ``AtlasSpec`` an atlas store records (its attributes ``spec``, ``grid_axes``,
    ``title``), read back through the same schema as a spec file, so that ``--verify`` judges
    a store by what its own spec implies.  ``where`` names the record in errors
    (``SceneError(where, key, reason)``); the caller compares the result's identity with the
    recorded ``spec_sha256``."""
    import dataclasses

    try:
        canonical = loads_json(attrs["spec"])
        if not isinstance(canonical, dict):
            raise ValueError
    except (KeyError, TypeError, ValueError):
        raise SceneError(where, "spec", "missing or not a JSON table") from None
    members = canonical.get("members") if isinstance(canonical.get("members"), dict) else {}
    doc = {"models": canonical.get("models"), "grid": {"delta": canonical.get("delta"), "chi": canonical.get("chi")},
           "members": {"list": members.get("omega0")}, "run": canonical.get("run", {}),
           "classify": canonical.get("classify", {}), "output": canonical.get("output", {}),
           "title": attrs.get("title", "") if isinstance(attrs.get("title", ""), str) else ""}
    spec = parse_spec(doc, where)
    refine = table(IA.RefineTable, canonical.get("refine", {}), "refine", where)
    seed, omega = members.get("seed"), members.get("omega")
    if seed is not None or omega is not None:
        table(IA.MembersTable, {"count": spec.members, "seed": seed, "omega": omega}, "members", where)
    axes = None
    if "grid_axes" in attrs:
        try:
            raw = loads_json(attrs["grid_axes"])
            axes = {k: (float(raw[k][0]), float(raw[k][1]), int(raw[k][2])) for k in ("delta", "chi")}
        except (KeyError, TypeError, ValueError, IndexError):
            raise SceneError(where, "grid_axes", "not {delta: [min, max, cells], chi: [...]}") from None
        for k, values in (("delta", spec.deltas), ("chi", spec.chis)):
            lo, hi, n = axes[k]
            r = table(IA.AxisRange, {"min": lo, "max": hi, "cells": n}, f"grid_axes.{k}", where)
            centres = _centres(r)
            if centres.shape != values.shape or not np.allclose(centres, values, rtol=0.0, atol=1e-12 * (r.max - r.min)):
                raise SceneError(where, f"grid_axes.{k}", "does not give the recorded grid")
    if refine.levels and axes is None:
        raise SceneError(where, "refine", "refinement levels are recorded but not the grid's ranges (grid_axes)")
    return dataclasses.replace(spec, seed=seed, omega_magnitude=omega, axes=axes, refine_levels=refine.levels,
                               refine_agree=refine.agree)


def load_spec(path) -> AtlasSpec:
    """Read and validate an atlas spec; ``SceneError`` (file, key, reason) on any problem."""
    if not isinstance(path, str | os.PathLike):
        raise SpecTypeError("spec", f"must be the path of an atlas spec (TOML) or an AtlasSpec, got {type(path).__name__}")
    path = os.fspath(path)
    return _build(path, *read_document(path, IA.AtlasFile, _TABLES, _EMPTY, "atlas spec", _NESTED))


# every table of a spec, validated in one place (inputs.toml.document) before anything is computed
_TABLES = {"grid": IA.GridTable, "members": IA.MembersTable, "run": IA.RunTable, "classify": IA.ClassifyTable,
           "refine": IA.RefineTable, "output": IA.OutputTable}
_EMPTY = ("run", "classify", "refine", "output")
_NESTED = {"grid.delta": IA.AxisRange, "grid.chi": IA.AxisRange, "grid.chi_deg": IA.AxisRange}


def parse_spec(data: dict, path: str = "<atlas spec>") -> AtlasSpec:
    """Validate a parsed TOML document (see the module docstring for every key)."""
    path = os.fspath(path)
    return _build(path, *document(IA.AtlasFile, data, path, _TABLES, _EMPTY, _NESTED))


def _build(path: str, top, tables: dict) -> AtlasSpec:
    """The ``AtlasSpec`` of a validated document: the axes resolved, the starts drawn, the
    rules across tables (inertia limit, refinement needs ranges, horizon, run cap) checked."""
    grid, members, run, classify, refine, output = (tables[k] for k in _TABLES)
    deltas = _axis(path, "delta", tables["grid.delta"] or grid.delta, (-1.0, 1.0), open_ends=True, unit="")
    if grid.chi_deg is not None:
        chis_deg = _axis(path, "chi_deg", tables["grid.chi_deg"] or grid.chi_deg, (0.0, 90.0), open_ends=False,
                         unit=" deg")
        chis = np.radians(chis_deg)
        chis[chis_deg == 90.0] = 0.5 * math.pi             # exactly pi/2: the transverse case (5.5)
    else:
        chis = _axis(path, "chi", tables["grid.chi"] or grid.chi, (0.0, 0.5 * math.pi), open_ends=False, unit=" rad")
    for d in deltas:
        if 1.0 - d < MIN_INERTIA_RATIO:
            raise SceneError(path, "[grid].delta", f"delta = {d:g}: 1 - delta = I3/I1 is below {MIN_INERTIA_RATIO:g}, "
                                                   f"too thin to integrate")
    if members.list is not None:
        omega0, seed, mag = np.array(members.list), None, None
    else:
        mag = members.omega if members.omega is not None else 0.1
        omega0, seed = directions(members.count, members.seed) * mag, int(members.seed)
    axes = _ranges(grid)
    if refine.levels and axes is None:
        raise SceneError(path, "[refine].levels", "needs [grid].delta and [grid].chi (or chi_deg) as {min, max, cells}")
    settings = settings_from(run, classify)
    _check_horizon(path, settings, omega0)
    models = top.model_names
    n_runs = len(models) * len(deltas) * len(chis) * len(omega0)
    if n_runs > IA.MAX_RUNS:
        raise SceneError(path, "[grid]", f"{n_runs} runs exceed the limit of {IA.MAX_RUNS}")
    return AtlasSpec(path=path, title=top.title, description=top.description, models=models, deltas=deltas, chis=chis,
                     omega0=omega0, settings=settings, seed=seed, omega_magnitude=mag, axes=axes,
                     refine_levels=refine.levels, refine_agree=refine.agree,
                     series=min(output.series, len(omega0)))


def _ranges(grid) -> dict | None:
    """{axis: (min, max, cells)} (chi in rad) when both axes are {min, max, cells}, else None."""
    chi = grid.chi_deg if grid.chi_deg is not None else grid.chi
    if not (isinstance(grid.delta, dict) and isinstance(chi, dict)):
        return None
    scale = math.pi / 180.0 if grid.chi_deg is not None else 1.0
    return {"delta": (float(grid.delta["min"]), float(grid.delta["max"]), int(grid.delta["cells"])),
            "chi": (float(chi["min"]) * scale, float(chi["max"]) * scale, int(chi["cells"]))}


def _axis(path, k: str, v, bounds: tuple, open_ends: bool, unit: str) -> np.ndarray:
    """A grid axis: a list of values, or an ``AxisRange`` (validated by ``document``: the
    centres of ``cells`` equal cells, so never an end of the range)."""
    lo, hi = bounds
    ends = f"({lo:g}, {hi:g})" if open_ends else f"[{lo:g}, {hi:g}]"
    if isinstance(v, IA.AxisRange):
        if v.min < lo or v.max > hi:
            raise SceneError(path, f"[grid.{k}].{'min' if v.min < lo else 'max'}",
                             f"the range must lie within {ends}{unit}, got [{shown(v.min, lo)}, {shown(v.max, hi)}]")
        return _centres(v)
    for x in v:
        if not (lo < x < hi if open_ends else lo <= x <= hi):
            raise SceneError(path, f"[grid].{k}", f"{x:g} is outside {ends}{unit}")
    return np.array(v, dtype=float)


def _centres(r) -> np.ndarray:
    """The centres of ``r.cells`` equal cells of (``r.min``, ``r.max``) (an ``AxisRange``)."""
    out = r.min + (np.arange(r.cells) + 0.5) * (r.max - r.min) / r.cells
    out[np.abs(out) < 1e-12 * (r.max - r.min)] = 0.0     # an odd count centred on 0 hits it exactly (delta = 0: (5.2))
    return out


def _check_horizon(path, s: Settings, omega0) -> None:
    """The horizon must hold the classifier's windows and reach the asymptotic regime of the
    slowest start (section 4's laws hold for tau |omega0|^2 >> 1)."""
    decades = math.log10(s.tau_end / s.tau_start)
    if decades < 2.0 * s.window:
        raise SceneError(path, "[run].tau_end", f"tau_end/tau_start spans {decades:.2g} decades; the classifier needs at "
                                                f"least 2 x window_decades = {2 * s.window:g} (one window, and one before "
                                                f"it to see the label hold)")
    if s.per_decade * s.window < 12:
        raise SceneError(path, "[run].samples_per_decade", f"{s.per_decade} a decade gives {s.per_decade * s.window:g} "
                                                           f"samples in the {s.window:g}-decade window; the classifier needs 12")
    slowest = float(np.min(np.linalg.norm(omega0, axis=1)))
    braking = s.tau_end * slowest**2
    if braking < IA.MIN_BRAKING_TIMES:
        raise SceneError(path, "[run].tau_end", f"tau_end = {s.tau_end:g} is {braking:.3g} braking times T = 1/|omega0|^2 "
                                                f"of the slowest start (|omega0| = {slowest:g}); the asymptotic laws need at "
                                                f"least {IA.MIN_BRAKING_TIMES:g}")


def directions(count: int, seed: int) -> np.ndarray:
    """``count`` unit vectors uniform on the sphere (normalized Gaussians), from ``seed``; shape (count, 3)."""
    v = np.random.default_rng(seed).normal(size=(count, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)
