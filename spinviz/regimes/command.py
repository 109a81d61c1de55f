"""``spinviz atlas SPEC.toml [--out PATH] [--scheduler ADDRESS] [--workers N] [--plot PATH]``.

``add_parser(subparsers)`` adds the subcommand to spinviz's parser; ``run(args) -> int`` does
the work and raises spinviz's errors (``SceneError`` for the spec, ``UsageError`` for the
options, the store and the scheduler), which the command line maps to exit status 2.
``python -m spinviz.regimes`` runs the same command on its own.
"""

from __future__ import annotations

import argparse
import json
import sys

from ..errors import UsageError, printable
from ..interrupt import Interrupted


def add_parser(subparsers) -> argparse.ArgumentParser:
    a = subparsers.add_parser(
        "atlas", help="regime atlas: which asymptotic type each (delta, chi) ends in, from ensembles of runs on Dask",
        description="Integrate the Euler equation (no orientation) for every cell and member of an atlas spec, "
                    "classify each run into the paper's asymptotic types, and write an xarray Dataset to a Zarr "
                    "store, resumably.")
    a.add_argument("spec", help="the atlas spec (TOML)")
    a.add_argument("--out", help="the Zarr store (a directory; default <spec stem>.zarr); an existing store of the "
                                 "same spec is completed, one of another spec refused")
    a.add_argument("--scheduler", metavar="ADDRESS", help="run on an existing Dask cluster (tcp://HOST:8786) instead "
                                                          "of the embedded LocalCluster")
    a.add_argument("--workers", type=_count, help="worker processes of the embedded LocalCluster (default: one per core)")
    a.add_argument("--plot", metavar="PATH", help="also draw the delta-chi diagram (PNG) and PATH_hodographs.png")
    a.add_argument("--runs-per-task", type=_count, default=None, help="runs per Dask task (default 32)")
    a.add_argument("--retry-failed", action="store_true", help="also recompute the runs the store records as failed")
    a.add_argument("--json", action="store_true", help="print the summary as JSON")
    a.add_argument("--quiet", action="store_true", help="no progress bar")
    a.add_argument("--bench", action="store_true",
                   help="instead: measure runs per second on 1 and 2 workers, the scheduling overhead and the memory "
                        "per worker on this spec (temporary stores), and project a 64 x 64 x 32 atlas")
    return a


def _count(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {v}")
    return v


def run(args) -> int:
    from .api import RUNS_PER_TASK, atlas, default_out
    from .spec import load_spec

    spec = load_spec(args.spec)                       # SceneError: file, key, reason
    if args.bench:
        from . import bench

        if args.out or args.scheduler or args.plot:
            raise UsageError("--bench: measures on temporary stores and the embedded cluster; drop --out, --scheduler "
                             "and --plot")
        rows = bench.run(spec, workers=args.workers, progress=not args.quiet)
        print(bench.format_table(rows) if not args.json else json.dumps(rows, indent=2, default=float))
        return 0
    try:
        res = atlas(spec, args.out, scheduler=args.scheduler, workers=args.workers, plot=args.plot,
                    progress=not args.quiet, runs_per_task=args.runs_per_task or RUNS_PER_TASK,
                    retry_failed=args.retry_failed)
    except Interrupted as e:
        # said here, not by the command line's generic "nothing was written": the finished
        # chunks are on disk, and that is the point
        out = args.out or default_out(spec)
        print(f"spinviz: atlas stopped by {e}; every finished chunk is in {printable(out, 200)} and the same command "
              f"computes only what is missing", file=sys.stderr)
        return e.exit_status
    if args.json:
        st = res.stats
        print(json.dumps({"path": res.path, "total": res.total, "computed": res.computed, "reused": res.reused,
                          "failed": res.failed, "seconds": res.seconds, "cluster": res.cluster, "plots": res.plots,
                          "runs_per_s": (st.runs / st.wall_s) if st and st.wall_s else None,
                          "overhead_share": st.overhead_share if st else None}, indent=2, default=float))
    else:
        print(printable(res.summary(), 2000))
        for p in res.plots:
            print(printable(p, 2000))
    return 0
