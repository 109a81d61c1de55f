"""What an atlas costs, from the engines' measured speeds, and the refusal, before any work,
of one that cannot finish here: more memory in this process than half the machine's, or
more than ``options.max_days()`` of work on the embedded cluster's workers.  The cost of a run depends
on the engine and, for the hand-over engine, on whether its cell hands over to the averaged
flow (``physics.averaged.averaging_holds``)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from ...errors import SceneError
from ...executors.processes import usable_cores
from ...inputs import atlas as IA
from ...inputs.atlas_spec import AtlasSpec, Settings
from ...inputs.options import MAX_DAYS_ENV, max_days
from ...physics.averaged import averaging_holds

# What this process holds for an atlas, measured with tracemalloc around runs.plan and the
# store's predictions (64 x 64 cells x 32 members: 955 B a cell at the peak, 650 B a task),
# with a margin; and what a run costs, one core, rtol 1e-8, classification included
# (docs/atlas.md, "Benchmark" and "Horizons").
BYTES_PER_CELL = 1200            # the paper's predictions at each (delta, chi), as Python lists, then float64
BYTES_PER_TASK = 1000            # a batch (its chi tuple, omega0 view, region), its key and counters
BYTES_PER_RUN = 16               # done mask, label codes and their copies
CPU_S_PER_RUN = 0.010            # engine "taylor": a run to tau_end = 1e10, growing as sqrt(tau_end) (a spiral's steps)
CPU_S_HANDED = 0.002             # engine "handover", a cell where the averaged flow holds: the same at any tau_end
CPU_S_FULL = (0.002, 0.021)      # engine "handover", a cell integrated in full (5, 4|5, "?"): a + b (tau_end/1e16)^(1/4)
SAMPLED_AXIS = 64               # cells per axis of the subgrid a large grid's CPU time is estimated on
MEMORY_SHARE = 0.5               # of physical memory, for this process (the workers need the rest)


def full_run_s(tau_end: float) -> float:
    """The CPU seconds of a hand-over engine run kept in full to ``tau_end`` (``CPU_S_FULL``)."""
    a, b = CPU_S_FULL
    return a + b * (tau_end / 1e16) ** 0.25


def run_cost_s(settings: Settings, model: str, delta: float, chi: float) -> float:
    """The estimated CPU seconds of one run of ``model`` at (delta, chi): "taylor" as
    sqrt(tau_end); "handover" by whether the cell's runs hand over to the averaged flow
    (``physics.averaged.averaging_holds``: then the full stage to the hand-over, ~tau = 1e6 ..
    1e10, whatever tau_end) or stay in full (the libration's steps grow as tau^(1/4): measured
    2.8, 21, 179 ms a run at 1e10, 1e16, 1e20; docs/atlas.md, "Horizons")."""
    te = max(settings.tau_end, 1.0)
    if settings.engine == "taylor":
        return CPU_S_PER_RUN * math.sqrt(te / 1e10)
    handed = CPU_S_HANDED * min(1.0, math.sqrt(te / 1e8))
    full = full_run_s(te)
    return handed if averaging_holds(model, float(delta), float(chi))[0] else full


def work_s(batches) -> float:
    """The estimated CPU seconds of ``batches`` (``runs.Batch``: ``run_cost_s`` of each of their runs)."""
    return sum(len(b.omega0) * run_cost_s(b.settings, b.model, d, c) for b in batches for d in b.deltas for c in b.chis)


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
    """The estimate ``check_feasible`` judges: memory of this process, CPU time (``run_cost_s``
    of every cell and model; of a ``SAMPLED_AXIS`` x ``SAMPLED_AXIS`` subgrid, scaled, for a
    larger grid: each cell's cost decides whether averaging holds there, a few microseconds),
    and wall time on ``workers``."""
    cells = len(spec.deltas) * len(spec.chis)
    tm = min(spec.members, 256, max(1, runs_per_task))
    tc = max(1, runs_per_task // tm)
    tasks = len(spec.models) * len(spec.deltas) * math.ceil(len(spec.chis) / tc) * math.ceil(spec.members / tm)
    nbytes = BYTES_PER_CELL * cells + BYTES_PER_TASK * tasks + BYTES_PER_RUN * spec.runs
    if spec.settings.engine == "taylor":                 # the same cost at every cell: one stands for all
        sample, weight = [(spec.models[0], 0.5, 0.5)], spec.runs
    else:
        ds, cs = spec.deltas, spec.chis
        ds, cs = ds[::max(1, len(ds) // SAMPLED_AXIS)], cs[::max(1, len(cs) // SAMPLED_AXIS)]
        sample, weight = [(m, d, c) for m in spec.models for d in ds for c in cs], spec.members * cells / (len(ds) * len(cs))
    cpu = weight * sum(run_cost_s(spec.settings, m, d, c) for m, d, c in sample)
    return Cost(spec.runs, tasks, nbytes, cpu, None if not workers else cpu / workers, workers)


def check_feasible(spec: AtlasSpec, arguments: IA.AtlasArguments) -> Cost:
    """Refuse, before any work, an atlas that cannot finish here: more memory in this process
    than half the machine's, or (on the embedded cluster) more than ``options.max_days()`` of work on
    its workers.  ``SceneError`` names the spec and the key to change; returns the estimate."""
    workers = None if arguments.scheduler is not None else (arguments.workers or usable_cores())
    c = cost(spec, arguments.runs_per_task, workers)
    mem = physical_memory()
    if mem and c.bytes > MEMORY_SHARE * mem:
        raise SceneError(spec.path, "[grid]", f"{c.runs} runs in {c.tasks} tasks would need ~{c.bytes / 1e9:.3g} GB in this "
                                              f"process (~{BYTES_PER_CELL} B a cell, {BYTES_PER_TASK} B a task); this "
                                              f"machine has {mem / 1e9:.3g} GB (limit {MEMORY_SHARE:g} of it): use fewer "
                                              f"cells or members, or more runs per task")
    days = max_days()
    if c.wall_s is not None and c.wall_s > days * 86400.0:
        raise SceneError(spec.path, "[grid]", f"{c.runs} runs to tau_end = {spec.settings.tau_end:g} would take "
                                              f"~{c.wall_s / 86400.0:.3g} days on {workers} workers (engine "
                                              f"{spec.settings.engine!r}: ~{c.cpu_s / max(1, c.runs):.3g} s a run); at most "
                                              f"{days:g} days: use fewer cells or members, a shorter [run].tau_end, "
                                              f"or a cluster (scheduler); someone who means it raises the cap with "
                                              f"{MAX_DAYS_ENV}=DAYS")
    return c
