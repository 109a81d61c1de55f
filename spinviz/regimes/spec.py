"""The atlas spec: a TOML file, validated like a scene (one line naming file, key, reason).

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
    tau_end = 1e10                        # horizon, tau = t/tau0
    tau_start = 1e-2                      # first sample after 0
    samples_per_decade = 20
    rtol = 1e-8                           # Taylor tolerance on omega sqrt(1 + tau/T) / |omega0| (T = 1/|omega0|^2)
    max_steps = 20000000                  # step budget of one run

    [classify]
    window_decades = 2.0                  # decades at the end of a run the classifier analyses

Every member uses the same omega(0) at every cell and in both models, so that cells and
models are compared on the same starts (paired), and the store records them.

Defaults and why: the asymptotic laws of section 4 need tau |omega0|^2 >> 1 (T = 1/|omega0|^2
is the braking time); with |omega0| = 0.1 the default horizon 1e10 is 1e8 T.  The slowest
regimes need it: near (delta, chi) = (0.3, 0.72) type 3's amplitudes still drift ~9 % a
decade after 10 decades, and a type-4 phase with beta just below -3/4 is captured into type
5 only at tau ~ 1e16.  Spirals cost ~ sqrt(tau_end) steps (~0.005-0.4 s a run at 1e10, up
to ~3 s in the worst cells), so 1e10 is where the labels of the prototype's studies stopped
changing while a 12 x 12 x 8 atlas still runs in minutes on two cores.  rtol 1e-8: Taylor's
method on the scaled omega sqrt(1 + tau/T) / |omega0|, so the tolerance holds relative to the
braking law to the end of the run (docs/atlas.md: labels and amplitudes against rtol).
20 samples a decade and a 2-decade window: 41 samples, the labels are the same at 10-50.

Every table is declared in the schema, ``spinviz.inputs.atlas`` (how to add a key is said
there); this module builds the ``AtlasSpec`` from the validated tables and says, before any
work, whether the atlas can finish on this machine (``check_feasible``: memory, run count,
time).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError, SpecError, SpecTypeError
from ..inputs import atlas as IA
from ..inputs.base import fields_of
from ..inputs.render import usable_cores
from ..inputs.toml import document, read_toml, table
from ..physics.bodies import MIN_INERTIA_RATIO
from .runs import Settings

MODELS = IA.MODELS
FORMAT = 2                       # the store's version (identity): 2 = Taylor's method (heyoka), no atol
MAX_RUNS = IA.MAX_RUNS
MAX_CELLS = IA.MAX_CELLS         # per axis
MAX_MEMBERS = IA.MAX_MEMBERS
OMEGA_MAX = IA.OMEGA_RANGE[1]    # |omega(0)| beyond which the start is hopelessly stiff (tau0 Omega >> 1)


@dataclass(frozen=True)
class AtlasSpec:
    """A validated atlas spec (also when made by hand: every field is checked).

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
        models = tuple(self.models) if isinstance(self.models, list | tuple) else None
        if not models or any(m not in MODELS for m in models) or len(set(models)) != len(models):
            raise SpecError("models", f"must be one or two of {', '.join(MODELS)}, each once, got {self.models!r}")
        object.__setattr__(self, "models", models)
        for name, lo, hi in (("deltas", -1.0, 1.0 - MIN_INERTIA_RATIO), ("chis", 0.0, 0.5 * math.pi)):
            a = _array(name, getattr(self, name), 1)
            if not (a.size and np.all((a >= lo) & (a <= hi)) and np.all(np.diff(a) > 0)):
                raise SpecError(name, f"must be increasing values in [{lo:g}, {hi:g}] (at most {MAX_CELLS}), got {a!r}")
            if a.size > MAX_CELLS:
                raise SpecError(name, f"at most {MAX_CELLS} values, got {a.size}")
            object.__setattr__(self, name, a)
        w = _array("omega0", self.omega0, 2)
        norms = np.linalg.norm(w, axis=1) if w.ndim == 2 and w.shape[1] == 3 else None
        lo, hi = IA.OMEGA_RANGE
        if norms is None or not 1 <= len(w) <= MAX_MEMBERS or not np.all((norms >= lo) & (norms <= hi)):
            raise SpecError("omega0", f"must be 1..{MAX_MEMBERS} starts [w1, w2, w3] with |omega0| in [{lo:g}, {hi:g}], "
                                      f"got shape {w.shape}")
        object.__setattr__(self, "omega0", w)
        if not isinstance(self.settings, Settings):
            raise SpecTypeError("settings", f"must be a regimes.runs.Settings, got {type(self.settings).__name__}")
        if self.refine_levels and self.axes is None:
            raise SpecError("refine", "levels > 0 needs both grid axes as {min, max, cells} (a quadtree of equal cells)")

    @property
    def members(self) -> int:
        return int(self.omega0.shape[0])

    @property
    def runs(self) -> int:
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
        return json.dumps(self.canonical(), sort_keys=True, separators=(",", ":"))

    def identity(self) -> str:
        """sha256 of the canonical JSON (with the classifier's version): equal identities,
        equal numbers."""
        from .classify import VERSION

        return hashlib.sha256(f"classifier {VERSION}\n{self.canonical_json()}".encode()).hexdigest()


def _array(name: str, v, ndim: int) -> np.ndarray:
    try:
        a = np.array(v, dtype=float)
    except (TypeError, ValueError):
        raise SpecTypeError(name, f"must be an array of numbers, got {type(v).__name__}") from None
    if a.ndim != ndim or not np.all(np.isfinite(a)):
        raise SpecError(name, f"must be a finite {ndim}-D array, got shape {a.shape}")
    a.flags.writeable = False
    return a


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


def load_spec(path) -> AtlasSpec:
    """Read and validate an atlas spec; ``SceneError`` (file, key, reason) on any problem."""
    if not isinstance(path, str | os.PathLike):
        raise SpecTypeError("spec", f"must be the path of an atlas spec (TOML) or an AtlasSpec, got {type(path).__name__}")
    path = os.fspath(path)
    return parse_spec(read_toml(path, kind="atlas spec"), path)


# every table of a spec, validated in one place (inputs.toml.document) before anything is computed
_TABLES = {"grid": IA.GridTable, "members": IA.MembersTable, "run": IA.RunTable, "classify": IA.ClassifyTable,
           "refine": IA.RefineTable, "output": IA.OutputTable}


def parse_spec(data: dict, path: str = "<atlas spec>") -> AtlasSpec:
    """Validate a parsed TOML document (see the module docstring for every key)."""
    path = os.fspath(path)
    top, tables = document(IA.AtlasFile, data, path, _TABLES, ("run", "classify", "refine", "output"))
    grid, members, run, classify, refine, output = (tables[k] for k in _TABLES)
    deltas = _axis(path, "delta", grid.delta, (-1.0, 1.0), open_ends=True, unit="")
    if grid.chi_deg is not None:
        chis_deg = _axis(path, "chi_deg", grid.chi_deg, (0.0, 90.0), open_ends=False, unit=" deg")
        chis = np.radians(chis_deg)
        chis[chis_deg == 90.0] = 0.5 * math.pi             # exactly pi/2: the transverse case (5.5)
    else:
        chis = _axis(path, "chi", grid.chi, (0.0, 0.5 * math.pi), open_ends=False, unit=" rad")
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
    if n_runs > MAX_RUNS:
        raise SceneError(path, "[grid]", f"{n_runs} runs exceed the limit of {MAX_RUNS}")
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
    """A grid axis: a list of values, or ``{min, max, cells}`` (the centres of ``cells``
    equal cells, so never an end of the range)."""
    lo, hi = bounds
    ends = f"({lo:g}, {hi:g})" if open_ends else f"[{lo:g}, {hi:g}]"
    if isinstance(v, dict):
        r = table(IA.AxisRange, v, f"grid.{k}", path)
        if r.min < lo or r.max > hi:
            raise SceneError(path, f"[grid.{k}].{'min' if r.min < lo else 'max'}",
                             f"the range must lie within {ends}{unit}, got [{r.min:g}, {r.max:g}]")
        out = r.min + (np.arange(r.cells) + 0.5) * (r.max - r.min) / r.cells
        out[np.abs(out) < 1e-12 * (r.max - r.min)] = 0.0     # an odd count centred on 0 hits it exactly (delta = 0: (5.2))
        return out
    for x in v:
        if not (lo < x < hi if open_ends else lo <= x <= hi):
            raise SceneError(path, f"[grid].{k}", f"{x:g} is outside {ends}{unit}")
    return np.array(v, dtype=float)


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


# --- can it finish? ------------------------------------------------------------------------------
# What this process holds for an atlas, measured with tracemalloc around api.plan and the
# store's predictions (64 x 64 cells x 32 members: 955 B a cell at the peak, 650 B a task),
# with a margin; and what a run costs (docs/atlas.md, "Benchmark": 10.4 runs/s per worker on
# the shipped atlas, tau_end = 1e10, both models).
BYTES_PER_CELL = 1200            # the paper's predictions at each (delta, chi), as Python lists, then float64
BYTES_PER_TASK = 1000            # a batch (its chi tuple, omega0 view, region), its key and counters
BYTES_PER_RUN = 16               # done mask, label codes and their copies
CPU_S_PER_RUN = 0.096            # a run to tau_end = 1e10 at rtol 1e-8, one core
MAX_DAYS = 30.0                  # an embedded atlas expected to take longer is refused: it would not finish here
MEMORY_SHARE = 0.5               # of physical memory, for this process (the workers need the rest)


@dataclass(frozen=True)
class Cost:
    """What an atlas needs: ``bytes`` in this process, ``cpu_s`` of integration, ``wall_s`` on ``workers``."""

    runs: int
    tasks: int
    bytes: float
    cpu_s: float
    wall_s: float | None
    workers: int | None


def physical_memory() -> float:
    """Bytes of physical memory (0 if unknown)."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 0.0


def cost(spec: AtlasSpec, runs_per_task: int = 32, workers: int | None = None) -> Cost:
    """The estimate ``check_feasible`` judges: memory of this process, CPU time (a run's cost
    grows as sqrt(tau_end), the steps of a spiral), and wall time on ``workers``."""
    cells = len(spec.deltas) * len(spec.chis)
    tm = min(spec.members, 256, max(1, runs_per_task))
    tc = max(1, runs_per_task // tm)
    tasks = len(spec.models) * len(spec.deltas) * math.ceil(len(spec.chis) / tc) * math.ceil(spec.members / tm)
    nbytes = BYTES_PER_CELL * cells + BYTES_PER_TASK * tasks + BYTES_PER_RUN * spec.runs
    cpu = spec.runs * CPU_S_PER_RUN * math.sqrt(max(spec.settings.tau_end, 1.0) / 1e10)
    return Cost(spec.runs, tasks, nbytes, cpu, None if not workers else cpu / workers, workers)


def check_feasible(spec: AtlasSpec, arguments: IA.AtlasArguments) -> Cost:
    """Refuse, before any work, an atlas that cannot finish here: more memory in this process
    than half the machine's, or (on the embedded cluster) more than ``MAX_DAYS`` of work on
    its workers.  ``SceneError`` names the spec and the key to change; returns the estimate."""
    workers = None if arguments.scheduler is not None else (arguments.workers or usable_cores())
    c = cost(spec, arguments.runs_per_task, workers)
    mem = physical_memory()
    if mem and c.bytes > MEMORY_SHARE * mem:
        raise SceneError(spec.path, "[grid]", f"{c.runs} runs in {c.tasks} tasks would need ~{c.bytes / 1e9:.3g} GB in this "
                                              f"process (~{BYTES_PER_CELL} B a cell, {BYTES_PER_TASK} B a task); this "
                                              f"machine has {mem / 1e9:.3g} GB (limit {MEMORY_SHARE:g} of it): use fewer "
                                              f"cells or members, or more runs per task")
    if c.wall_s is not None and c.wall_s > MAX_DAYS * 86400.0:
        raise SceneError(spec.path, "[grid]", f"{c.runs} runs to tau_end = {spec.settings.tau_end:g} would take "
                                              f"~{c.wall_s / 86400.0:.3g} days on {workers} workers (~{CPU_S_PER_RUN:g} s a "
                                              f"run at tau_end 1e10, growing as sqrt(tau_end)); at most {MAX_DAYS:g} days: "
                                              f"use fewer cells or members, a shorter [run].tau_end, or a cluster (scheduler)")
    return c
