"""The tables of an atlas spec (``spinviz atlas SPEC``) and the arguments of ``spinviz.atlas``.

``spinviz.regimes.spec.parse_spec`` validates each table with the class below (errors name
the file, table and key) and builds the ``AtlasSpec``; ``AtlasArguments`` checks the Python
call (and so the command line's options, which are its arguments).

Adding a key is one change: one annotated field in its table below (type, range with its
reason, default).  Then:

* a key of ``[run]`` or ``[classify]`` reaches ``regimes.runs.Settings`` under the field name
  in ``SETTINGS_NAMES`` (or its own name), so ``Settings`` needs a field of that name;
* the key enters the spec's identity (``AtlasSpec.canonical``, the store's ``spec_sha256``)
  automatically -- mark it ``Added()`` so that it enters only when it differs from its
  default: stores made before the key existed keep their identity;
* a rule joining several keys goes in the table's ``_together`` validator (``SpecError``
  naming the key to blame);
* code that rebuilds ``Settings`` from a store (``regimes.plot``) should use
  ``regimes.spec.settings_from_canonical``, which reads the tables through this schema.
"""

from __future__ import annotations

import math
import os
from typing import Annotated, Any, Literal

from pydantic import Field, PlainValidator, model_validator
from pydantic_core import PydanticCustomError

from ..atomic import check_parent_writable, special_kind
from ..errors import SpecError, UsageError, brief
from ..physics import models as M
from .base import Flag, Int, Path, Positive, Real, Text, between, check_vector, refused, registered, request, shown, wrong_type
from .toml import Table

MAX_RUNS = 100_000_000
MAX_CELLS = 4096                 # per axis
MAX_MEMBERS = 100_000
OMEGA_RANGE = (1e-7, 10.0)       # |omega(0)|: above, tau0 |Omega| >> 1 is outside the model; below, T = 1/|omega0|^2
#                                  exceeds what the brute-force cap tau_end <= 1e16 can reach 100 times over
ENGINES = ("handover", "taylor")
# The horizon each engine can reach.  "taylor" integrates every run to tau_end: its cost grows
# as sqrt(tau_end) (the steps of a spiral), and past ~1e16 a spiral's phase (~1e8 turns) and
# float64's time steps leave nothing to resolve.  "handover" carries the spirals by the
# averaged flow (its cost does not grow with tau_end); what it integrates in full to tau_end
# are the regimes where the averaging cannot last (type 5, the 4|5 band beyond beta = -3/4,
# the domain "?", TF), whose steps and global error grow as tau^(1/4): 1.1e6 steps and 5e-7
# of omega_perp^2 tau (against rtol/100) a run at 1e20, measured (docs/atlas.md, "Horizons");
# the cap is where that was measured to hold.
TAU_END_MAX = {"handover": 1e20, "taylor": 1e16}
TAU_START_RANGE = (1e-12, 1e3, "the first sample after 0, tau")
MIN_BRAKING_TIMES = 100.0        # tau_end >= this many T = 1/|omega0|^2 for the slowest start: section 4's laws are asymptotic
MAX_STEPS = 10**12               # a run of 1e12 Taylor steps would take days


class Added:
    """Marks a key added after format 2: it enters the spec's identity only when it differs
    from its default (so older stores keep theirs)."""


def _models(v):
    if isinstance(v, str) or not isinstance(v, list | tuple) or not v:
        raise wrong_type(f"must be a non-empty list of {', '.join(M.for_atlas())}, got {brief(v)}")
    out = []
    for m in v:
        if m not in M.for_atlas():
            raise ValueError(f"unknown model {brief(m)}; valid: {', '.join(M.for_atlas())}")
        if m in out:
            raise ValueError(f"{m!r} named twice")
        out.append(m)
    return tuple(out)


def _axis(v):
    """A grid axis: a list of values, or a table {min, max, cells} (checked as ``AxisRange``)."""
    if isinstance(v, dict):
        return v
    if isinstance(v, list | tuple):
        if not v:
            raise ValueError("is empty: give at least one value, or {min, max, cells}")
        vals = []
        for x in v:
            if isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(float(x)):
                raise wrong_type(f"must be a list of finite numbers, got {brief(v)}")
            vals.append(float(x))
        if len(vals) > MAX_CELLS:
            raise ValueError(f"at most {MAX_CELLS} values, got {len(vals)}")
        if len(set(vals)) != len(vals):
            raise ValueError("a value is listed twice")
        if any(b <= a for a, b in zip(vals, vals[1:])):
            raise ValueError("values must increase")
        return tuple(vals)
    raise wrong_type(f"must be a list of values or a table {{min, max, cells}}, got {brief(v)}")


Axis = Annotated[Any, PlainValidator(_axis)]


@request
class AxisRange:
    """``{min, max, cells}``: the centres of ``cells`` equal cells of (min, max)."""

    min: Real
    max: Real
    cells: Annotated[Int, Field(ge=1, le=MAX_CELLS)]

    @model_validator(mode="after")
    def _order(self):
        if not self.min < self.max:
            raise SpecError("max", f"must exceed min ({shown(self.min, self.max)}), got {shown(self.max, self.min)}")
        return self


@request
class GridTable:
    """``[grid]``: delta in (-1, 1); chi (rad) or chi_deg in [0, 90]: a list or {min, max, cells}."""

    delta: Axis
    chi: Axis | None = None
    chi_deg: Axis | None = None

    @model_validator(mode="after")
    def _chi(self):
        if self.chi is not None and self.chi_deg is not None:
            raise SpecError("chi", "give chi (rad) or chi_deg, not both")
        if self.chi is None and self.chi_deg is None:
            raise SpecError("chi", "missing value (or give chi_deg)")
        return self


def _start_list(v):
    if isinstance(v, str) or not isinstance(v, list | tuple) or not v:
        raise wrong_type(f"must be a non-empty list of [w1, w2, w3], got {brief(v)}")
    if len(v) > MAX_MEMBERS:
        raise ValueError(f"at most {MAX_MEMBERS} starts, got {len(v)}")
    rows = []
    for row in v:
        try:
            r = check_vector(row, 3)
        except PydanticCustomError:
            raise wrong_type(f"each start must be [w1, w2, w3] (numbers), got {brief(row)}") from None
        except ValueError:
            raise ValueError(f"each start must be finite, got {brief(row)}") from None
        n = math.hypot(*r)
        if not OMEGA_RANGE[0] <= n <= OMEGA_RANGE[1]:
            raise ValueError(f"|omega(0)| must lie in [{OMEGA_RANGE[0]:g}, {OMEGA_RANGE[1]:g}], got "
                             f"{shown(n, *OMEGA_RANGE)} for {brief(row)}")
        rows.append(r)
    return tuple(rows)


@request
class MembersTable:
    """``[members]``: ``count`` starts from ``seed`` with |omega(0)| = ``omega`` (directions
    uniform on the sphere), or an explicit ``list`` of body-frame omega(0) (dimensionless)."""

    count: Annotated[Int, Field(ge=1, le=MAX_MEMBERS)] | None = None
    seed: Annotated[Int, Field(ge=0, lt=2**63)] | None = None
    omega: Annotated[Real, between(*OMEGA_RANGE, "tau0 |Omega| << 1 above; below, T = 1/|omega0|^2 is beyond any "
                                                 "horizon")] | None = None
    list: Annotated[tuple, PlainValidator(_start_list)] | None = None

    @model_validator(mode="after")
    def _form(self):
        if self.list is not None:
            for other in ("count", "seed", "omega"):
                if getattr(self, other) is not None:
                    raise SpecError(other, "give list (explicit starts) or count, seed and omega, not both")
            return self
        for k in ("count", "seed"):
            if getattr(self, k) is None:
                raise SpecError(k, "missing value")
        return self


@request
class RunTable:
    """``[run]``: how each run is integrated (tau = t/tau0, dimensionless)."""

    # not Added: the default gives other numbers than the brute force of the stores made before
    # the key (their classifier version differs too, so they are refused either way)
    engine: Literal[ENGINES] = "handover"
    tau_end: Annotated[Positive, Field(le=max(TAU_END_MAX.values()))] = 1e10
    tau_start: Annotated[Real, between(*TAU_START_RANGE)] = 1e-2
    samples_per_decade: Annotated[Int, Field(ge=6, le=1000)] = 20
    rtol: Annotated[Real, between(1e-14, 1e-3, "Taylor's method in float64")] = 1e-8
    max_steps: Annotated[Int, Field(ge=1000, le=MAX_STEPS)] = 20_000_000
    atol: refused("is not used since the atlas integrates with Taylor's method: its one tolerance, rtol, holds on "
                  "omega sqrt(1 + tau/T) / |omega0| (docs/atlas.md); remove the key") = None

    @model_validator(mode="after")
    def _together(self):
        cap = TAU_END_MAX[self.engine]
        if self.tau_end > cap:
            raise SpecError("tau_end", f"must be at most {cap:g} with engine = {self.engine!r}, got {shown(self.tau_end, cap)}"
                            + ("; engine = \"handover\" reaches 1e20" if self.engine == "taylor" else ""))
        return self


@request
class ClassifyTable:
    """``[classify]``: the classifier's window."""

    window_decades: Annotated[Real, between(0.5, 6.0, "the classifier's window")] = 2.0


@request
class RefineTable:
    """``[refine]``: adaptive refinement where the types change (``regimes.refine``): each of
    ``levels`` passes computes the four children of every cell whose members disagree (the
    most common type below ``agree``) or whose neighbours' type differs.  Needs both grid axes
    as {min, max, cells}."""

    levels: Annotated[Int, Field(ge=0, le=6)] = 0
    agree: Annotated[Real, between(0.5, 1.0, "a share of the members")] = 0.9


@request
class OutputTable:
    """``[output]``: what the store keeps beyond each run's label and evidence: the full
    omega(tau) series of the first ``series`` members of every cell (the hodographs and the
    web page read them; 0 keeps none)."""

    series: Annotated[Int, Field(ge=0, le=16)] = 1


@request
class AtlasFile:
    """The top level of an atlas spec."""

    grid: Table
    members: Table
    title: Text = ""
    description: Text = ""
    model: registered(M.for_atlas) | None = None
    models: Annotated[tuple, PlainValidator(_models)] | None = None
    run: Table | None = None
    classify: Table | None = None
    refine: Table | None = None
    output: Table | None = None

    @model_validator(mode="after")
    def _one_model_key(self):
        if self.model is not None and self.models is not None:
            raise SpecError("models", "give only one of model, models")
        return self

    @property
    def model_names(self) -> tuple[str, ...]:
        """The spec's models in order: ``models``, the one ``model``, or ("reduced",)."""
        return self.models or ((self.model,) if self.model else ("reduced",))


SETTINGS_NAMES = {"samples_per_decade": "per_decade", "window_decades": "window"}    # TOML key -> Settings field


# --- spinviz.atlas(...) ----------------------------------------------------------------------
def _callback(v):
    if v is not None and not callable(v):
        raise wrong_type(f"must be callable (n, result) or None, got {type(v).__name__}")
    return v


@request
class AtlasArguments:
    """The arguments of ``spinviz.atlas`` besides the spec (the command line's options)."""

    out: Path = None
    scheduler: Text | None = None
    workers: Annotated[Int, Field(ge=1)] | None = None
    plot: Path = None
    progress: Flag = True
    runs_per_task: Annotated[Int, Field(ge=1, le=1_000_000)] = 32
    processes: Flag = True
    flush_s: Annotated[Positive, Field(le=86400.0)] = 30.0
    retry_failed: Flag = False
    on_result: Annotated[Any, PlainValidator(_callback)] = None

    @model_validator(mode="after")
    def _cluster(self):
        check_cluster(self.workers, self.scheduler)
        return self


def check_cluster(workers: int | None, scheduler: str | None) -> None:
    """Workers of an embedded cluster: at most the cores this process may use, and none asked of
    an existing cluster (``SpecError`` naming ``workers``)."""
    if scheduler is not None and workers is not None:
        raise SpecError("workers", "applies to the embedded cluster only; an existing cluster (scheduler) has the "
                                   "workers it was started with")
    from ..executors.processes import usable_cores

    cores = usable_cores()
    if workers is not None and workers > cores:
        raise SpecError("workers", f"must be at most {cores}, the cores this process may use (more workers than "
                                   f"cores only share them), got {workers}")


def default_out(spec) -> str:
    """``<spec stem>.zarr`` in the current directory (``spec``: an ``AtlasSpec`` or its path)."""
    path = spec if isinstance(spec, str | os.PathLike) else spec.path
    stem = os.path.splitext(os.path.basename(os.fspath(path)))[0] or "atlas"
    return f"{stem}.zarr"


def store_path(spec, out: str | None) -> str:
    """The store of ``spec``: ``out``, or ``default_out``; a directory to be created or an
    existing atlas store (checked later), not a file or a special file, not the spec itself,
    in a writable directory (``UsageError`` naming it)."""
    path = out if out is not None else default_out(spec)
    if os.path.exists(path) and not os.path.isdir(path):
        kind = special_kind(os.stat(path).st_mode) or "a file"
        raise UsageError(f"{path}: exists and is {kind}; an atlas store is a directory (e.g. atlas.zarr)")
    if spec.path and os.path.exists(path) and os.path.exists(spec.path) and os.path.samefile(path, spec.path):
        raise UsageError(f"{path}: is the spec itself")
    check_parent_writable(path)
    return path
