"""The atlas's levels, computed or completed in order under the store's lock (``api.atlas``
holds it): each level opened by the store (``levels.open_level``: judged, repaired and
resumed), its missing runs cut into batches (``runs.plan``), the cluster reached -- or, for
small work, this process -- and only then the level's store created and filled batch by
batch.  Runs the cluster failed to compute are never written: ``AtlasIncomplete`` says how
many and why, and the same call completes the store.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from dataclasses import dataclass, field

from ..errors import UsageError, printable
from ..interrupt import check, deferred
from ..progress import Progress
from .engine import runs as RN
from .engine.cost import work_s
from .faults import AtlasIncomplete
from .inprocess import InProcess
from .inprocess import execute as execute_here
from .store import dataset as DS
from .store import integrity as IN
from .store import levels as LV

SMALL_WORK_S = 15.0         # estimated CPU seconds below which no cluster is started (docs/atlas.md, "Where it runs")


@dataclass
class AtlasResult:
    """What ``atlas`` did.

    path : the store.  computed : runs computed now.  reused : runs already in the store.
    failed : runs recorded as failed now.  seconds : wall time.  cluster : where it ran.
    plots : pictures written.  stats : the execution's measurements (``cluster.Stats``) or None.
    repaired : runs of damaged or unverified chunks found on resume, recomputed now.
    notices : what was said about the store on the way (one line each).
    levels : refinement levels computed beyond the spec's grid (``[refine]``).
    """

    path: str
    total: int
    computed: int
    reused: int
    failed: int
    seconds: float
    cluster: str
    plots: list = field(default_factory=list)
    stats: object = None
    repaired: int = 0
    notices: list = field(default_factory=list)
    levels: int = 0

    @property
    def dataset(self):
        """The atlas (``store.open_atlas``: labels decoded, evidence unpacked)."""
        return DS.open_atlas(self.path)

    def summary(self) -> str:
        """One line for people: runs reused, computed and failed, time, where, and where the time went."""
        if self.computed == 0:
            return f"{self.path}: all {self.total} runs already there, nothing to compute"
        s = (f"{self.path}: {self.total} runs ({self.reused} already there, {self.computed} computed now"
             f"{f', {self.failed} failed' if self.failed else ''}"
             f"{f', over {self.levels + 1} refinement levels' if self.levels else ''}) in {self.seconds:.1f} s on {self.cluster}")
        if self.stats is not None and self.stats.runs:
            st = self.stats
            b = {k: 100 * v for k, v in st.breakdown().items() if k != "write_s"}
            s += (f"; {st.runs / st.wall_s:.1f} runs/s, {st.tasks} tasks; of the workers' time "
                  f"{b['integrate_share']:.0f} % integrating, {b['classify_share']:.0f} % classifying, "
                  f"{b['overhead_share']:.0f} % overhead; writing the store {st.write_s:.1f} s "
                  f"({b['write_share_of_wall']:.1f} % of the wall time)")
        return s


def compute(spec, out: str, *, scheduler=None, workers=None, processes: bool = True,
            runs_per_task: int = RN.RUNS_PER_TASK, flush_s: float = 30.0, retry_failed: bool = False, on_result=None,
            progress: bool = True, say=None) -> AtlasResult:
    """Every level of the atlas of ``spec`` in the store ``out``, computed or completed in order
    (the arguments as ``api.atlas``'s); the caller holds the store's lock."""
    say = say or _say
    t0 = time.perf_counter()
    notices = _clear_creation_leftovers(out, say)
    levels: list[LV.Level] = []
    totals = dict.fromkeys(("todo", "reused", "repaired", "failed", "runs"), 0)    # runs, summed over the levels
    stats = None
    where = "nothing to compute"
    # stop signals are recorded, and acted on where this code looks (check()), never raised
    # inside Dask or Zarr, whose callbacks could swallow them
    with deferred(), contextlib.ExitStack() as stack:
        cluster = _LazyCluster(stack, scheduler, workers, processes)
        for k in range(spec.refine_levels + 1):
            lv = LV.open_level(spec, out, levels, k, retry_failed=retry_failed, say=say)
            if lv is None:
                break
            levels.append(lv)
            notices += lv.notices
            check()
            path = DS.level_path(out, k)
            skip = lv.skip
            batches, keys, expected = RN.plan(lv.spec, lv.chunks, skip, runs_per_task)
            for key, n in (("runs", lv.runs), ("reused", lv.reused), ("repaired", lv.repaired),
                           ("todo", sum(b.runs for b in batches))):
                totals[key] += n
            if not batches:
                if not lv.exists and lv.wanted is None:     # an empty plan and no store: cannot happen
                    raise UsageError(f"{spec.path}: the spec holds no runs")
                continue
            cl = cluster.get(small=work_s(batches) < SMALL_WORK_S)
            if not lv.exists:
                DS.create(lv.spec, path, lv.chunks, lv.identity)
            writer = DS.Writer(path, expected, flush_s=flush_s)
            label = os.path.basename(path) if k == 0 else f"{os.path.basename(os.path.dirname(path))}/{os.path.basename(path)}"
            bar = Progress(sum(b.runs for b in batches), f"atlas {printable(label, 80)}", enabled=progress)
            s = None
            try:                                 # each result written into the level's store as it arrives
                if isinstance(cl, InProcess):
                    s = execute_here(cl, batches, keys, writer, bar, on_result=on_result)
                else:
                    from .cluster import execute

                    s = execute(cl, batches, keys, writer, bar, on_result=on_result)
            finally:
                writer.close()
                bar.finish()
                if s is not None:
                    s.write_s, s.checksum_s, s.chunk_writes = writer.write_s, writer.checksum_s, writer.chunk_writes
            totals["failed"] += int(((DS.regime_codes(path) == -1) & ~skip).sum())
            stats = s if stats is None else stats.merged(s)
            where = cluster.describe
            if s.incomplete is not None:
                if s.incomplete.cluster_lost:
                    cluster.close_fast()
                done, runs = LV.done_within(path, lv.wanted)
                raise AtlasIncomplete(path, s.incomplete.cause, runs - done, runs, done, s.incomplete.cluster_lost)
        notices += _not_implied(out, len(levels), say)
    seconds = time.perf_counter() - t0
    return AtlasResult(out, totals["runs"], totals["todo"], totals["reused"], totals["failed"], seconds, where, [], stats,
                       totals["repaired"], notices, levels=len(levels) - 1)


def _not_implied(out: str, implied: int, say) -> list:
    """The levels in the store beyond the ``implied`` ones (the labels below flag no cell for
    them): left as they are, each said in one line with the command that removes it."""
    lines = []
    for k in LV.found(out):
        if k >= implied:
            lines.append(f"{DS.level_path(out, k)}: not a level this atlas implies (the labels of level {implied - 1} "
                         f"flag no cell for it); left as it is: rm -r {DS.level_path(out, k)} removes it")
            say(lines[-1])
    return lines


def _clear_creation_leftovers(out: str, say) -> list:
    """The temporary directories a killed creation of this store left beside it
    (``.NAME.XXXXXXXX.partial``): removed (the lock says no creation is under way), in one line."""
    left = LV.creation_leftovers(out)
    if not left:
        return []
    with deferred():
        for path in left:
            IN.remove(path)
    names = ", ".join(printable(os.path.basename(p), 80) for p in left[:3]) + (" ..." if len(left) > 3 else "")
    line = (f"{out}: removed {len(left)} temporary director{'ies' if len(left) != 1 else 'y'} an interrupted creation "
            f"left beside it ({names})")
    say(line)
    return [line]


class _LazyCluster:
    """The Dask cluster, started on the first level that has work (and then kept for the others)."""

    def __init__(self, stack, scheduler, workers, processes):
        self.stack, self.args, self.cl, self.where = stack, (scheduler, workers, processes), None, "nothing to compute"

    def get(self, small: bool = False):
        """The cluster; with ``small`` (little work, no scheduler or worker count asked for) this
        process instead, in threads (``inprocess.InProcess``), unless a cluster is already up."""
        scheduler, workers, _ = self.args
        if small and self.cl is None and scheduler is None and workers is None:
            from ..executors.processes import usable_cores

            here = InProcess(usable_cores())
            if self.where == "nothing to compute":
                self.where = here.describe
            return here
        if self.cl is None:
            from .cluster import atlas_cluster

            scheduler, workers, processes = self.args
            self.cl = self.stack.enter_context(atlas_cluster(scheduler, workers, processes=processes))
            self.where = self.cl.describe          # asked now: a cluster lost later cannot answer
        return self.cl

    @property
    def describe(self) -> str:
        return self.where

    def close_fast(self) -> None:
        if self.cl is not None:
            self.cl.close(fast=True)           # no point waiting for a cluster that is gone


def _say(line: str) -> None:
    print(f"spinviz: {printable(line)}", file=sys.stderr, flush=True)


