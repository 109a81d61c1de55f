"""``spinviz atlas SPEC.toml [--out PATH] [--scheduler ADDRESS] [--workers N] [--plot PATH]``,
``spinviz atlas --verify STORE``, ``spinviz atlas SPEC --bench [--write-path]`` and
``spinviz atlas --evidence KIND``.

Exit statuses of its own: 75 when the cluster failed and runs were not computed (sysexits'
EX_TEMPFAIL: the same command resumes) or when another command holds the store's lock (the
same command works once that one has finished), 1 when tasks failed as a whole, 128 + the
signal after a stop; for ``--verify``, 0 (the whole atlas its spec implies, every chunk
matching its checksums) or 1 (damaged, incomplete, a level missing or foreign), 2 (not an
atlas store).
"""

from __future__ import annotations

import json
import os
import sys

from ..errors import UsageError, printable
from ..interrupt import check
from .shared import positive, progress, real, reals

EVIDENCE = ("validate", "crosscheck", "physical", "convergence", "tolerance", "handover", "basins", "flows")


def add_parser(sub) -> None:
    """Add ``spinviz atlas`` (the regime atlas, its --verify, --bench and --evidence) and its options to ``sub``."""
    a = sub.add_parser(
        "atlas", help="regime atlas: which asymptotic type each (delta, chi) ends in, from ensembles of runs on Dask",
        description="Integrate the Euler equation (no orientation) for every cell and member of an atlas spec, "
                    "classify each run into the paper's asymptotic types, and write an xarray Dataset to a Zarr "
                    "store, resumably.")
    a.add_argument("spec", nargs="?", help="the atlas spec (TOML)")
    a.add_argument("--out", help="the Zarr store (a directory; default <spec stem>.zarr); an existing store of the "
                                 "same spec is completed, one of another spec refused")
    a.add_argument("--scheduler", metavar="ADDRESS", help="run on an existing Dask cluster (tcp://HOST:8786) instead "
                                                          "of the embedded LocalCluster")
    a.add_argument("--workers", type=positive, help="worker processes of the embedded LocalCluster (default: one per core)")
    a.add_argument("--plot", metavar="PATH", help="also draw the delta-chi diagram (PNG, every refinement level), "
                   "PATH_hodographs.png and the interactive page PATH.html")
    a.add_argument("--runs-per-task", type=positive, default=None, help="runs per Dask task (default 32)")
    a.add_argument("--retry-failed", action="store_true", help="also recompute the runs the store records as failed")
    a.add_argument("--json", action="store_true", help="print the summary as JSON")
    a.add_argument("--quiet", action="store_true", help="no progress bar")
    a.add_argument("--verify", metavar="STORE", help="instead: check every chunk of an atlas store against its "
                                                     "checksums and say, per variable, whether it is intact "
                                                     "(exit status 0) or damaged (1)")
    a.add_argument("--bench", action="store_true",
                   help="instead: measure runs per second on 1 and 2 workers, the scheduling overhead and the memory "
                        "per worker on this spec (temporary stores), and project a 64 x 64 x 32 atlas")
    a.add_argument("--peer", metavar="SCRIPT",
                   help="with --bench, on a one-cell spec: the whole command against the standalone heyoka script "
                        "SCRIPT (benchmarks/peer_heyoka_atlas.py) as a whole process, 256 starts to tau 1e10, 1e12, "
                        "1e14 and the spec's starts to 1e10, with the end states compared")
    a.add_argument("--write-path", action="store_true",
                   help="with --bench: only the store's write path at the spec's size (chunk writes, checksums, "
                        "verification; no runs)")
    ev = a.add_argument_group("evidence (instead of an atlas; no spec: the points are built in)")
    ev.add_argument("--evidence", metavar="KIND", choices=EVIDENCE,
                    help="validate (every domain against the paper's formulas), crosscheck (the disputed points with "
                         "SciPy), physical (against physical-unit simulate runs), convergence (horizon x 100, x 1e4 "
                         "and 4x members; --out STORE keeps the rows in that atlas), tolerance (labels against rtol), handover "
                         "(the hand-over engine against brute force at 1e12 and 1e14; --out STORE keeps the rows), basins (the "
                         "4|5 band: shares ending in 4 and 5 against beta), flows (the averaged flows against full "
                         "integration: error, bound, order in mu)")
    ev.add_argument("--members", type=positive, help="starts per point (default: validate 32, crosscheck 3, physical 4, "
                                                     "convergence 32, tolerance 8, handover 16, basins 32)")
    ev.add_argument("--tau-end", type=real, help="physical: the horizon (default 1e10); basins: (default 1e16)")
    ev.add_argument("--horizons", metavar="LIST", type=reals, help="convergence: the horizons (default "
                                                                   "1e10,1e12,1e14,1e16,1e20); handover: (default 1e12,1e14)")


def run(args) -> int:
    """Carry out ``spinviz atlas`` with the parsed ``args``; return its exit status."""
    from ..regimes.api import RUNS_PER_TASK, atlas
    from ..regimes.faults import AtlasIncomplete

    if args.verify is not None:
        if args.spec is not None or args.out or args.scheduler or args.plot or args.bench:
            raise UsageError("--verify: checks a store on its own; give no spec and no other option")
        return verify(args.verify, as_json=args.json)
    evidence_only = (args.members, args.tau_end, args.horizons)
    if args.evidence is not None:
        from ..validation.atlas import evidence

        if args.spec is not None or args.scheduler or args.plot or args.bench or args.retry_failed:
            raise UsageError("--evidence: runs its own points; give no spec, --scheduler, --plot, --bench or "
                             "--retry-failed")
        return evidence.run(args.evidence, args.members, workers=args.workers, tau_end=args.tau_end,
                            horizons=args.horizons, out=args.out, as_json=args.json)
    if any(v is not None for v in evidence_only):
        raise UsageError("--members, --tau-end and --horizons go with --evidence")
    if args.write_path and not args.bench:
        raise UsageError("--write-path goes with --bench")
    if args.peer is not None and not args.bench:
        raise UsageError("--peer goes with --bench")
    if args.spec is None:
        raise UsageError("atlas: the spec is missing (spinviz atlas SPEC.toml, spinviz atlas --verify STORE, or "
                         "spinviz atlas --evidence KIND)")
    from ..inputs.atlas_spec import load_spec

    spec = load_spec(args.spec)                       # SceneError: file, key, reason
    if args.bench:
        return _bench(spec, args)
    try:
        res = atlas(spec, args.out, scheduler=args.scheduler, workers=args.workers, plot=args.plot,
                    progress=not args.quiet, runs_per_task=args.runs_per_task or RUNS_PER_TASK,
                    retry_failed=args.retry_failed)
        check()                                       # a signal that reached a library that swallowed it
    except AtlasIncomplete as e:
        print(f"spinviz: {printable(e.cli_message())}", file=sys.stderr)
        return e.exit_status
    if args.json:
        st = res.stats
        print(json.dumps({"path": res.path, "total": res.total, "computed": res.computed, "reused": res.reused,
                          "failed": res.failed, "repaired": res.repaired, "seconds": res.seconds,
                          "cluster": res.cluster, "plots": res.plots,
                          "levels": res.levels, "runs_per_s": (st.runs / st.wall_s) if st and st.wall_s else None,
                          "overhead_share": st.overhead_share if st else None,
                          "breakdown": st.breakdown() if st else None}, indent=2, default=float))
    else:
        print(printable(res.summary(), 2000))
        for path in res.plots:
            print(printable(path, 2000))
    return 0


def stopped(args, signal_name) -> str:
    """The one line of an atlas command stopped by a signal (wherever it landed): the finished
    chunks are on disk and the same command completes the store -- that is the point."""
    from ..inputs.atlas_spec import default_out

    if args.verify is not None or args.evidence is not None or args.bench or args.spec is None:
        return f"interrupted by {signal_name}; nothing was written"
    out = args.out or default_out(args.spec)
    if not os.path.isdir(out):
        return f"atlas stopped by {signal_name} before its store was made; nothing was written"
    return (f"atlas stopped by {signal_name}; every finished chunk is in {printable(out, 200)} and the same command "
            f"computes only what is missing")


def _bench(spec, args) -> int:
    from ..regimes import bench

    if args.out or args.scheduler or args.plot:
        raise UsageError("--bench: measures on temporary stores and the embedded cluster; drop --out, --scheduler "
                         "and --plot")
    unused = [o for o, v in (("--runs-per-task", args.runs_per_task), ("--retry-failed", args.retry_failed),
                             ("--workers", args.workers if args.write_path else None)) if v]
    if unused:                                        # never ignored in silence
        raise UsageError(f"{unused[0]}: not used by --bench{' --write-path' if args.write_path else ''}")
    if args.peer is not None:
        import os

        if not os.path.isfile(args.peer):
            raise UsageError(f"--peer: {printable(args.peer, 200)}: no such file")
        rows = bench.against_peer(spec, args.peer, progress=None if args.quiet else
                                  progress)
        print(bench.format_peer(rows) if not args.json else json.dumps(rows, indent=2, default=float))
        return 0
    if args.write_path:
        rows = bench.store_cost(spec)
        print(bench.format_store_cost(rows) if not args.json else json.dumps(rows, indent=2, default=float))
        return 0
    rows = bench.run(spec, workers=args.workers, progress=not args.quiet)
    print(bench.format_table(rows) if not args.json else json.dumps(rows, indent=2, default=float))
    return 0


def verify(path: str, as_json: bool = False) -> int:
    """``--verify STORE``: one line per variable (chunks intact, or the damaged ones named),
    the metadata and the spec, and a verdict, for the store and each refinement level its spec
    implies; 0 if every level the spec implies is present, whole (every file matches its
    checksum, every run computed) and of this spec, 1 if not (what is missing, damaged or
    foreign named)."""
    from ..regimes.store.verify import report

    r = report(path)
    if as_json:
        first = r["reports"][0]
        print(json.dumps({"path": path, "ok": r["ok"], "lines": first["lines"], "runs_verified": r["runs_verified"],
                          "damaged_chunks": r["damaged_chunks"], "problems": r["problems"], "levels": r["reports"][1:]},
                         indent=2))
    else:
        many = len(r["reports"]) > 1
        for level in r["reports"]:
            prefix = f"level {level['level']}: " if many else ""
            for line in level["lines"]:
                print(printable(prefix + line, 2000))
        print(printable(r["verdict"], 2000))
    return 0 if r["ok"] else 1
