"""``atlas(spec, out)``: the regime atlas from Python (the command line calls the same).

    import spinviz
    res = spinviz.atlas("scenes/atlas_quick.toml", out="atlas_quick.zarr", plot="atlas_quick.png")
    ds = res.dataset          # xarray, straight from the Zarr store (xarray.open_zarr works too)

Order of work, chosen so that nothing half-made is ever left behind: the spec is validated,
the output is checked (an existing store must be of this very spec, its checksums are
verified, and the runs of any damaged chunk are recomputed, said in one line), the cluster is
reached (an unreachable scheduler stops everything here), and only then is the store created
-- in one atomic step -- and filled batch by batch.  Running it again computes only what the
store lacks, with the same numbers.  Runs the cluster failed to compute (the scheduler gone,
no worker left, a task killing its workers) are never written: ``AtlasIncomplete`` says how
many and why, and the same call completes the store.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import SpecTypeError, UsageError, printable
from ..inputs.atlas import AtlasArguments
from ..inputs.atlas_spec import AtlasSpec, load_spec, store_path
from ..interrupt import check, deferred
from .engine import runs as RN
from .engine.cost import check_feasible, run_cost_s
from .faults import AtlasIncomplete, ForeignLevel, StoreDamaged
from .store import dataset as DS
from .store import integrity as IN
from .store import levels as LV
from .store.lock import StoreLock

RUNS_PER_TASK = 32          # a task of ~32 runs lasts ~0.2-10 s: scheduling (~ms) stays below 1 %
SMALL_WORK_S = 15.0         # estimated CPU seconds below which no cluster is started (docs/atlas.md, "Where it runs")


def work_s(spec: AtlasSpec, batch) -> float:
    """The estimated CPU seconds of a batch (``engine.cost.run_cost_s`` per cell)."""

    n = len(batch.omega0)
    return sum(n * run_cost_s(spec.settings, batch.model, d, c) for d in batch.deltas for c in batch.chis)


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


def plan(spec: AtlasSpec, chunks: tuple, done: np.ndarray, runs_per_task: int = RUNS_PER_TASK):
    """Batches covering exactly the runs not yet done, each inside one storage chunk, in store
    order (a block that is partly done is cut into the missing stretches of members).

    Returns (batches, the storage chunk of each -- its Zarr chunk index (model, delta, chi
    block, member block) --, expected batches per chunk)."""
    _, _, cc, cm = chunks
    tm = min(cm, max(1, runs_per_task))
    tc = max(1, min(cc, runs_per_task // tm))
    batches, keys, expected = [], [], {}
    nd, nc, nm = len(spec.deltas), len(spec.chis), spec.members
    for mi, model in enumerate(spec.models):
        for di in range(nd):
            for c0 in range(0, nc, cc):
                for a in range(c0, min(c0 + cc, nc), tc):
                    b = min(a + tc, c0 + cc, nc)
                    for m0 in range(0, nm, cm):
                        key = (mi, di, c0 // cc, m0 // cm)
                        for ma in range(m0, min(m0 + cm, nm), tm):
                            mb = min(ma + tm, m0 + cm, nm)
                            block = done[mi, di, a:b, ma:mb]
                            if block.all():
                                continue
                            if not block.any():
                                parts = [(a, b, ma, mb)]
                            else:                    # partly done: only the missing runs, cell by cell
                                parts = [(a + j, a + j + 1, ma + s0, ma + s1) for j in range(b - a)
                                         for s0, s1 in _runs_of(~block[j])]
                            for pa, pb, pma, pmb in parts:
                                batches.append(RN.Batch(model, (float(spec.deltas[di]),),
                                                        tuple(float(x) for x in spec.chis[pa:pb]),
                                                        np.asarray(spec.omega0[pma:pmb]), spec.settings,
                                                        (mi, (di, di + 1), (pa, pb), (pma, pmb)), spec.series))
                                keys.append(key)
                                expected[key] = expected.get(key, 0) + 1
    return batches, keys, expected


def _runs_of(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) of each stretch of True in a 1-D mask."""
    out, start = [], None
    for i, m in enumerate(mask):
        if m and start is None:
            start = i
        elif not m and start is not None:
            out.append((start, i))
            start = None
    if start is not None:
        out.append((start, len(mask)))
    return out


def atlas(spec, out: str | None = None, *, scheduler: str | None = None, workers: int | None = None,
          plot: str | None = None, progress: bool = True, runs_per_task: int = RUNS_PER_TASK,
          processes: bool = True, flush_s: float = 30.0, retry_failed: bool = False, on_result=None,
          notify=None) -> AtlasResult:
    """Compute (or complete) the regime atlas of ``spec`` into the Zarr store ``out``.

    spec : a path to an atlas spec (TOML) or an ``AtlasSpec``.
    out : the store (a directory, default ``<spec stem>.zarr``); an existing store of the same
        spec is verified against its checksums and completed, one of another spec refused.
    scheduler : address of an existing Dask cluster (``tcp://HOST:8786``); default: a
        LocalCluster with ``workers`` single-threaded processes (default and at most one per
        core) that starts and stops here.
    plot : also draw the delta-chi diagram there (PNG, every refinement level over the
        coarser), the hodographs beside it (``<stem>_hodographs.png``) and the interactive
        page (``<stem>.html``: hover a cell for its shares, click it for its hodograph).
    progress : the progress bar on stderr.
    runs_per_task : runs per Dask task (the store's chunking is fixed when it is created).
    processes : LocalCluster workers as processes (default) or threads of this process.
    flush_s : results waiting longer than this for the rest of their chunk are written anyway.
    retry_failed : also recompute the runs recorded as failed (runs that failed physically:
        a runaway, a singular start, an exception inside the run).
    on_result : called with (batches done so far, the batch's result) after each result
        (tests interrupt with it, or kill the worker that ran the batch).
    notify : called with each notice about the store (one line: damaged chunks recomputed,
        leftovers removed); default: printed on stderr.

    Raises ``AtlasIncomplete`` when runs could not be computed (the cluster failed, or tasks
    failed as a whole): nothing of them is written, the store holds every finished run, and
    the same call computes what is missing.  ``StoreDamaged`` for a store whose metadata do
    not match their checksums.
    """

    # the one schema (spinviz.inputs.atlas): arguments named as here, then the spec, then
    # whether it can finish on this machine -- all before any work
    args = AtlasArguments(out=out, scheduler=scheduler, workers=workers, plot=plot, progress=progress,
                          runs_per_task=runs_per_task, processes=processes, flush_s=flush_s, retry_failed=retry_failed,
                          on_result=on_result)
    spec = spec if isinstance(spec, AtlasSpec) else load_spec(spec)
    out = store_path(spec, args.out)
    check_feasible(spec, args)
    if notify is not None and not callable(notify):
        raise SpecTypeError("notify", f"must be callable (line) or None, got {type(notify).__name__}")
    say = notify if notify is not None else _say
    plots = []
    if plot is not None:
        from .figures.draw import check_plot_paths

        plots = check_plot_paths(plot, out, spec)
    # one writer at a time (an advisory lock beside the store), taken before anything reads or
    # writes it; a second atlas command on this store is refused here, at once
    with StoreLock(out, exclusive=True, what="this atlas command"):
        res = _compute(spec, out, scheduler, workers, processes, runs_per_task, flush_s, retry_failed, on_result,
                       progress, say)
        if plot is not None:
            from .figures.draw import draw

            res.plots = draw(out, plots)
    return res


def _compute(spec, out, scheduler, workers, processes, runs_per_task, flush_s, retry_failed, on_result, progress,
             say) -> AtlasResult:
    """The atlas's levels, computed or completed in order under the store's lock."""
    t0 = time.perf_counter()
    notices: list = []
    _clear_creation_leftovers(out, say, notices)
    if os.path.exists(out):
        LV.check_store(spec, out)
    levels: list[LV.Level] = []
    totals = {"todo": 0, "reused": 0, "repaired": 0, "failed": 0, "runs": 0}
    stats = None
    where = "nothing to compute"
    # stop signals are recorded, and acted on where this code looks (check()), never raised
    # inside Dask or Zarr, whose callbacks could swallow them
    with deferred(), contextlib.ExitStack() as stack:
        cluster = _LazyCluster(stack, scheduler, workers, processes)
        for k in range(spec.refine_levels + 1):
            lv = LV.level(spec, out, levels, k)
            if lv is None:
                break
            _prepare_level(lv, say, notices)
            levels.append(lv)
            s = _run_level(lv, cluster, runs_per_task, flush_s, retry_failed, on_result, progress, say, notices, totals)
            stats = s if stats is None else stats.merged(s)
            if s is not None:
                where = cluster.describe
                if s.incomplete is not None:
                    if s.incomplete.cluster_lost:
                        cluster.close_fast()
                    inc = s.incomplete
                    done = DS.done_mask(lv.out)
                    done = int((done if lv.wanted is None else done & lv.wanted[..., None]).sum())
                    raise AtlasIncomplete(lv.out, inc.cause, lv.runs - done, lv.runs, done, inc.cluster_lost)
        for k in LV.found(out):
            if k >= len(levels):
                line = (f"{DS.level_path(out, k)}: not a level this atlas implies (the labels of level {len(levels) - 1} "
                        f"flag no cell for it); left as it is: rm -r {DS.level_path(out, k)} removes it")
                notices.append(line)
                say(line)
    seconds = time.perf_counter() - t0
    return AtlasResult(out, totals["runs"], totals["todo"], totals["reused"], totals["failed"], seconds, where, [], stats,
                       totals["repaired"], notices, levels=len(levels) - 1)


def _prepare_level(lv: LV.Level, say, notices: list) -> None:
    """A refinement level's store before its runs (``lv.state``, judged by ``levels.level``): a
    damaged one (no .zgroup, no checksums, metadata that do not match them) is removed -- a
    level is recomputable from the spec and the levels below -- and said in one line; a foreign
    one was refused before any work (``levels.check_store``)."""
    st = lv.state
    if st is None:
        return
    if st.kind == "foreign":                         # appeared since the check: another hand in the store
        raise ForeignLevel(f"{lv.out}: holds a refinement level of another atlas; remove it (rm -r {lv.out}) and "
                           f"run the same command again")
    if st.kind == "damaged":
        with deferred():
            IN.remove(lv.out)
        line = f"{lv.out}: {st.why}; the level is computed again"
        notices.append(line)
        say(line)


def _clear_creation_leftovers(out: str, say, notices: list) -> None:
    """The temporary directories a killed creation of this store left beside it
    (``.NAME.XXXXXXXX.partial``): removed (the lock says no creation is under way), in one line."""
    left = LV.creation_leftovers(out)
    if not left:
        return
    with deferred():
        for path in left:
            IN.remove(path)
    names = ", ".join(printable(os.path.basename(p), 80) for p in left[:3]) + (" ..." if len(left) > 3 else "")
    line = (f"{out}: removed {len(left)} temporary director{'ies' if len(left) != 1 else 'y'} an interrupted creation "
            f"left beside it ({names})")
    notices.append(line)
    say(line)


class _LazyCluster:
    """The Dask cluster, started on the first level that has work (and then kept for the others)."""

    def __init__(self, stack, scheduler, workers, processes):
        self.stack, self.args, self.cl, self.where = stack, (scheduler, workers, processes), None, "nothing to compute"

    def get(self, small: bool = False):
        """The cluster; with ``small`` (little work, no scheduler or worker count asked for) this
        process instead, in threads (``cluster.InProcess``), unless a cluster is already up."""
        scheduler, workers, _ = self.args
        if small and self.cl is None and scheduler is None and workers is None:
            from ..executors.processes import usable_cores
            from .inprocess import InProcess

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


def _run_level(lv: LV.Level, cluster: _LazyCluster, runs_per_task, flush_s, retry_failed, on_result, progress, say,
               notices: list, totals: dict):
    """Compute what level ``lv`` lacks (its wanted cells): the store created or verified and
    resumed, the batches planned, executed and written.  Returns the execution's stats or None."""
    from ..progress import Progress

    spec, out = lv.spec, lv.out
    exists = os.path.exists(out)                     # a level's damaged or foreign store never gets here
    repaired = 0
    if exists:
        chunks, done, repaired, said = _resume(spec, out, say)
        notices += said
        if retry_failed:
            done &= DS.regime_codes(out) != -1
    else:
        chunks = DS.chunk_shape(spec)
        done = np.zeros((len(spec.models), len(spec.deltas), len(spec.chis), spec.members), dtype=bool)
    check()
    skip = done if lv.wanted is None else (done | ~lv.wanted[..., None])
    totals["runs"] += lv.runs
    totals["reused"] += int(done.sum() if lv.wanted is None else (done & lv.wanted[..., None]).sum())
    totals["repaired"] += repaired
    batches, keys, expected = plan(spec, chunks, skip, runs_per_task)
    todo = int(sum(b.runs for b in batches))
    totals["todo"] += todo
    if not batches:
        if not exists and lv.wanted is None:       # an empty plan and no store: cannot happen
            raise UsageError(f"{spec.path}: the spec holds no runs")
        return None
    cl = cluster.get(small=sum(work_s(spec, b) for b in batches) < SMALL_WORK_S)
    if not exists:
        DS.create(spec, out, chunks)
    writer = DS.Writer(out, expected, flush_s=flush_s)
    label = os.path.basename(out) if lv.wanted is None else f"{os.path.basename(os.path.dirname(out))}/" \
                                                             f"{os.path.basename(out)}"
    bar = Progress(todo, f"atlas {printable(label, 80)}", enabled=progress)
    stats = None
    try:
        from . import inprocess

        if isinstance(cl, inprocess.InProcess):
            stats = inprocess.execute(cl, batches, keys, writer, bar, on_result=on_result)
        else:
            from .cluster import execute

            stats = execute(cl, batches, keys, writer, bar, on_result=on_result)
    finally:
        writer.close()
        bar.finish()
        if stats is not None:
            stats.write_s, stats.checksum_s = writer.write_s, writer.checksum_s
            stats.chunk_writes = writer.chunk_writes
    totals["failed"] += int(((DS.regime_codes(out) == -1) & ~skip).sum())
    return stats


def _say(line: str) -> None:
    print(f"spinviz: {printable(line)}", file=sys.stderr, flush=True)


def _resume(spec: AtlasSpec, out: str, say) -> tuple:
    """An existing store: its skeleton verified, then its identity, then every chunk against
    its checksums; damaged or unverified chunks are emptied (their runs recomputed) and
    leftover temporary files removed, each said in one line.

    Returns (chunks, done mask, runs to recompute, notices)."""
    rep = DS.verify(out)
    if rep.skeleton is None:
        if not os.path.exists(os.path.join(out, ".zgroup")):
            raise UsageError(f"{out}: exists and is not an atlas store (no .zgroup); choose another store path")
        DS.check_identity(spec, out)                 # another Zarr store, or another spec: said as such
        raise StoreDamaged(f"{out}: carries no checksums (made by an earlier spinviz, or its {IN.DIR} was deleted), "
                           f"so its runs cannot be trusted; move it away and compute the atlas again")
    if rep.skeleton:
        raise StoreDamaged(f"{out}: its metadata are damaged ({IN.summary(rep.skeleton, 4)}); they cannot be "
                           f"recomputed from the runs: move it away and compute the atlas again")
    DS.check_identity(spec, out)
    notices = []
    shape, chunks = IN.layout(out)
    bad = rep.bad_keys
    repaired = 0
    if bad:
        with deferred():
            IN.discard(out, DS.run_variables(out), bad, rep.leftovers)
        n = sum(int(np.prod([r.stop - r.start for r in IN.chunk_region(k, shape, chunks)])) for k in bad)
        repaired = n
        what = "damaged" if rep.damaged else "unverified"
        if rep.damaged and rep.unrecorded:
            what = "damaged or unverified"
        notices.append(f"{out}: {len(bad)} {what} chunk{'s' if len(bad) != 1 else ''} ({IN.summary(rep.problems())}); "
                       f"{'their' if len(bad) != 1 else 'its'} {n} runs are recomputed")
    elif rep.leftovers:
        with deferred():
            IN.discard(out, DS.run_variables(out), [], rep.leftovers)
    if rep.leftovers and not bad:
        notices.append(f"{out}: removed {len(rep.leftovers)} temporary file{'s' if len(rep.leftovers) != 1 else ''} "
                       f"of an interrupted write ({IN.summary([IN.Damage(x, 'leftover') for x in rep.leftovers], 3)})")
    for line in notices:
        say(line)
    return tuple(chunks), DS.done_mask(out), repaired, notices
