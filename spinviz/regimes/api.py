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

from ..errors import SpecTypeError
from ..inputs.atlas import AtlasArguments, store_path
from ..inputs.atlas_spec import AtlasSpec, load_spec
from .compute import SMALL_WORK_S, AtlasResult, compute
from .engine.cost import check_feasible
from .engine.runs import RUNS_PER_TASK
from .store.lock import StoreLock

__all__ = ["RUNS_PER_TASK", "SMALL_WORK_S", "AtlasResult", "atlas"]


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
    plots = []
    if plot is not None:
        from .figures.draw import check_plot_paths

        plots = check_plot_paths(plot, out, spec)
    # one writer at a time (an advisory lock beside the store), taken before anything reads or
    # writes it; a second atlas command on this store is refused here, at once
    with StoreLock(out, exclusive=True, what="this atlas command"):
        res = compute(spec, out, scheduler=scheduler, workers=workers, processes=processes,
                      runs_per_task=runs_per_task, flush_s=flush_s, retry_failed=retry_failed, on_result=on_result,
                      progress=progress, say=notify)
        if plot is not None:
            from .figures.draw import draw

            res.plots = draw(out, plots)
    return res
