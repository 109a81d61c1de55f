"""``spinviz bench [--quick] [--process] [--problems A,B] [--repeats N] [--json PATH] [--plot PATH]``:
the work-precision benchmark, in-process or as whole processes beside the standalone peers."""

from __future__ import annotations

import dataclasses

from .shared import EXIT_OK, names, positive, progress


def add_parser(sub) -> None:
    """Add ``spinviz bench`` (the work-precision benchmark) and its options to ``sub``."""
    b = sub.add_parser("bench", help="work-precision benchmark: error against run time, per method and horizon")
    b.add_argument("--quick", action="store_true", help="two problems, 1e2 and 1e4 turns, fewer settings (~2 min)")
    b.add_argument("--json", metavar="PATH", help="also write rows and summary as JSON")
    b.add_argument("--plot", metavar="PATH", help="also draw error against time, log-log, one line per method (PNG)")
    b.add_argument("--process", action="store_true",
                   help="time whole processes (spinviz simulate, and the standalone heyoka and scipy scripts of "
                        "benchmarks/) instead of in-process runs, at ~400 turns (~5 min; --quick ~1 min)")
    b.add_argument("--problems", type=names, help="only these problems, e.g. 6.10,askew (default: the plan's; "
                                                "with --process also asym)")
    b.add_argument("--repeats", type=positive, help="runs per point, the minimum time kept (default 3)")


def run(args) -> int:
    """Carry out ``spinviz bench`` with the parsed ``args``; return its exit status."""
    from ..atomic import check_outputs, write_json
    from ..validation import bench

    check_outputs([x for x in (args.json, args.plot) if x])      # before the minutes of work, not after

    if args.process:
        from ..validation import process_bench as PB

        pts = PB.run(args.problems or PB.PROBLEMS, repeats=args.repeats or 3, quick=args.quick, progress=progress)
        print(PB.format_table(pts))
        if args.json:
            write_json(args.json, {"points": [pt.record() for pt in pts], "headline": PB.headline(pts)})
        if args.plot:
            PB.plot(pts, args.plot)
        return EXIT_OK
    plan = bench.quick_plan() if args.quick else bench.Plan()
    plan = dataclasses.replace(plan, **{k: v for k, v in (("problems", args.problems), ("repeats", args.repeats))
                                        if v is not None})
    rows = bench.run(plan, progress=progress)
    summ = bench.summary(rows)
    print(bench.format_table(rows, summ, plan.notes))
    if args.json:
        write_json(args.json, {"rows": [r.record() for r in rows], "summary": summ, "notes": plan.notes})
    if args.plot:
        bench.plot(rows, args.plot)
    return EXIT_OK

