"""``spinviz atlas run SPEC``, ``spinviz atlas verify STORE``, ``spinviz atlas bench SPEC`` and
``spinviz atlas evidence KIND`` and ``spinviz atlas boxes``: the regime atlas's jobs, one
sub-command each with exactly its own options (``boxes``: the atlas of an asymmetric crystal's
boxes, ``regimes.asymmetric``).  ``spinviz atlas SPEC`` (a spec where the job's name would be) is
``spinviz atlas run SPEC``.

Exit statuses of its own: 75 when the cluster failed and runs were not computed (sysexits'
EX_TEMPFAIL: the same command resumes) or when another command holds the store's lock (the
same command works once that one has finished), 1 when tasks failed as a whole, 128 + the
signal after a stop; for ``verify``, 0 (the whole atlas its spec implies, every chunk
matching its checksums) or 1 (damaged, incomplete, a level missing or foreign), 2 (not an
atlas store).
"""

from __future__ import annotations

import json
import os
import sys

from ..errors import UsageError, printable
from ..interrupt import check
from .shared import Parser, positive, progress, real, reals

JOBS = ("run", "verify", "bench", "evidence", "boxes")
# what each evidence option is, for the sub-command of a kind that takes it
_EVIDENCE_OPTIONS = {
    "workers": ("--workers", positive, None, "worker processes (default: one per core)"),
    "tau_end": ("--tau-end", real, None, "the horizon tau"),
    "horizons": ("--horizons", reals, "LIST", "the horizons tau, increasing, comma-separated"),
    "out": ("--out", str, "STORE", "keep the rows in this atlas store"),
}


def shorthand(argv: list[str]) -> list[str]:
    """``atlas SPEC ...`` is ``atlas run SPEC ...``; the job names and --help pass as they are."""
    if argv and argv[0] not in JOBS and not argv[0].startswith("-"):
        return ["run", *argv]
    if argv and argv[0] in ("--verify", "--evidence", "--bench"):
        raise UsageError(f"{argv[0]}: a job of its own: spinviz atlas {argv[0][2:]} ...")
    return argv


def add_parser(sub) -> None:
    """Add ``spinviz atlas`` and its four jobs (run, verify, bench, evidence KIND) to ``sub``."""
    a = sub.add_parser(
        "atlas", help="regime atlas: which asymptotic type each (delta, chi) ends in, from ensembles of runs on Dask",
        description="The regime atlas: run (integrate and classify every cell of a spec into a resumable Zarr "
                    "store), verify (check a store against its spec and checksums), bench (measure it), evidence "
                    "KIND (the checks it rests on).  'spinviz atlas SPEC' is 'spinviz atlas run SPEC'.")
    jobs = a.add_subparsers(dest="job", metavar="JOB", parser_class=Parser)
    jobs.required = True
    r = jobs.add_parser("run", help="integrate and classify every cell and member of a spec into a Zarr store, "
                                    "resumably (the embedded cluster or --scheduler)")
    r.add_argument("spec", help="the atlas spec (TOML)")
    r.add_argument("--out", help="the Zarr store (a directory; default <spec stem>.zarr); an existing store of the "
                                 "same spec is completed, one of another spec refused")
    r.add_argument("--scheduler", metavar="ADDRESS", help="run on an existing Dask cluster (tcp://HOST:8786) instead "
                                                          "of the embedded LocalCluster")
    r.add_argument("--workers", type=positive, help="worker processes of the embedded LocalCluster (default: one per core)")
    r.add_argument("--plot", metavar="PATH", help="also draw the delta-chi diagram (PNG, every refinement level), "
                   "PATH_hodographs.png and the interactive page PATH.html")
    r.add_argument("--runs-per-task", type=positive, default=None, help="runs per Dask task (default 32)")
    r.add_argument("--retry-failed", action="store_true", help="also recompute the runs the store records as failed")
    r.add_argument("--json", action="store_true", help="print the summary as JSON")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    v = jobs.add_parser("verify", help="check every level a store's spec implies: present, whole (every chunk "
                                       "against its checksum) and of this spec")
    v.add_argument("store", help="the atlas store (a directory)")
    v.add_argument("--json", action="store_true", help="print the report as JSON")
    b = jobs.add_parser("bench", help="measure runs per second on 1 and 2 workers, the scheduling overhead and the "
                                      "memory per worker on a spec (temporary stores), and project a 64 x 64 x 32 atlas")
    b.add_argument("spec", help="the atlas spec (TOML)")
    how = b.add_mutually_exclusive_group()
    how.add_argument("--peer", metavar="SCRIPT",
                     help="on a one-cell spec: the whole command against the standalone heyoka script SCRIPT "
                          "(benchmarks/peer_heyoka_atlas.py) as a whole process, 256 starts to tau 1e10, 1e12, 1e14 and "
                          "the spec's starts to 1e10, with the end states compared")
    how.add_argument("--write-path", action="store_true",
                     help="only the store's write path at the spec's size (chunk writes, checksums, verification; no "
                          "runs)")
    b.add_argument("--workers", type=positive, help="the second measurement's workers (default 2)")
    b.add_argument("--json", action="store_true", help="print the rows as JSON")
    b.add_argument("--quiet", action="store_true", help="no progress bar")
    _add_evidence(jobs)
    x = jobs.add_parser(
        "boxes", help="where a DAST box a x b x c's spin ends as tau -> oo, over the plane of edge ratios (b/a, c/a)",
        description="For every box of the grid: the averaged flow's shape (a flow on one line between the two extreme "
                    "axes), its attractors, and the share of evenly spread spin directions ending about each edge; "
                    "written as netCDF, drawn as a PNG with the families a = b and b = c of the paper's figure 5.")
    x.add_argument("--grid", type=positive, default=25, help="boxes per ratio (default 25: 625 boxes per model)")
    x.add_argument("--lo", type=real, default=0.5, help="smallest b/a and c/a (default 0.5)")
    x.add_argument("--hi", type=real, default=2.0, help="largest b/a and c/a (default 2)")
    x.add_argument("--starts", type=positive, default=600, help="spin directions per box (default 600)")
    x.add_argument("--models", default="reduced,truncated", help="reduced, truncated or both (default both)")
    x.add_argument("--out", default="boxes.nc", help="the netCDF file (default boxes.nc)")
    x.add_argument("--plot", metavar="PATH", help="also draw the atlas (PNG)")
    x.add_argument("--quiet", action="store_true", help="no progress bar")


def _add_evidence(jobs) -> None:
    """``atlas evidence KIND``: one sub-command per registered kind, with the options it takes."""
    from ..validation.atlas.evidence import KINDS

    e = jobs.add_parser("evidence", help="the checks the atlas rests on: " + ", ".join(KINDS))
    kinds = e.add_subparsers(dest="kind", metavar="KIND", parser_class=Parser)
    kinds.required = True
    for k in KINDS.values():
        p = kinds.add_parser(k.name, help=k.summary, description=k.summary)
        p.add_argument("--members", type=positive, help=f"starts per point (default {k.members})")
        for key in k.options:
            flag, kind, metavar, text = _EVIDENCE_OPTIONS[key]
            default = {"tau_end": k.tau_end, "horizons": k.horizons}.get(key)
            text = f"{text} (default {', '.join(f'{x:g}' for x in default)})" if isinstance(default, tuple) else (
                f"{text} (default {default:g})" if default is not None else text)
            p.add_argument(flag, dest=key, type=kind, metavar=metavar, help=text)
        p.add_argument("--json", action="store_true", help="print the rows as JSON")


def run(args) -> int:
    """Carry out ``spinviz atlas JOB`` with the parsed ``args``; return its exit status."""
    if args.job == "verify":
        return verify(args.store, as_json=args.json)
    if args.job == "boxes":
        return _boxes(args)
    if args.job == "evidence":
        from ..validation.atlas import evidence

        given = {k: getattr(args, k, None) for k in _EVIDENCE_OPTIONS}
        return evidence.run(args.kind, args.members, as_json=args.json, **given)
    from ..inputs.atlas_spec import load_spec

    spec = load_spec(args.spec)                       # SceneError: file, key, reason
    if args.job == "bench":
        return _bench(spec, args)
    return _run(spec, args)


def _boxes(args) -> int:
    """``atlas boxes``: the boxes atlas of the DAST crystal (``regimes.asymmetric.atlas``)."""
    from ..inputs.boxes import BoxesRequest
    from ..progress import Progress
    from ..regimes.asymmetric.atlas import run as boxes

    req = BoxesRequest(grid=args.grid, lo=args.lo, hi=args.hi, starts=args.starts, models=args.models, out=args.out,
                       plot=args.plot)
    bar = Progress(req.grid * req.grid * len(req.models), "boxes", unit="boxes", enabled=not args.quiet)
    done = [0]

    def step():
        done[0] += 1
        bar.update(done[0])

    try:
        ds = boxes(req, progress=step)
    finally:
        bar.finish()
    print(printable(f"{req.out}: {ds.attrs['cells']} boxes x models in {ds.attrs['seconds']:.1f} s "
                    f"({ds.attrs['cpu_seconds']:.1f} s CPU)" + (f"; {req.plot}" if req.plot else ""), 2000))
    return 0


def _run(spec, args) -> int:
    from ..regimes.api import RUNS_PER_TASK, atlas
    from ..regimes.faults import AtlasIncomplete

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
    from ..inputs.atlas import default_out

    if args.job != "run":
        return f"interrupted by {signal_name}; nothing was written"
    out = args.out or default_out(args.spec)
    if not os.path.isdir(out):
        return f"atlas stopped by {signal_name} before its store was made; nothing was written"
    return (f"atlas stopped by {signal_name}; every finished chunk is in {printable(out, 200)} and the same command "
            f"computes only what is missing")


def _bench(spec, args) -> int:
    from ..regimes import bench

    if args.peer is not None:
        if not os.path.isfile(args.peer):
            raise UsageError(f"--peer: {printable(args.peer, 200)}: no such file")
        rows = bench.against_peer(spec, args.peer, progress=None if args.quiet else
                                  progress)
        print(bench.format_peer(rows) if not args.json else json.dumps(rows, indent=2, default=float))
        return 0
    if args.write_path:
        if args.workers is not None:
            raise UsageError("--workers: not used by bench --write-path")
        rows = bench.store_cost(spec)
        print(bench.format_store_cost(rows) if not args.json else json.dumps(rows, indent=2, default=float))
        return 0
    rows = bench.run(spec, workers=args.workers, progress=not args.quiet)
    print(bench.format_table(rows) if not args.json else json.dumps(rows, indent=2, default=float))
    return 0


def verify(path: str, as_json: bool = False) -> int:
    """``verify STORE``: one line per variable (chunks intact, or the damaged ones named),
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

