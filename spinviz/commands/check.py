"""``spinviz check [--json] [--quick]``: the validation suite against the paper's closed forms;
``spinviz check --sweep [--seeds A-B] [--runs N]``: are ``secular``'s stated errors bounds?"""

from __future__ import annotations

import argparse
import json

from ..errors import UsageError
from .shared import EXIT_FAIL, EXIT_OK, out, positive, progress


def _seed_list(text: str):
    """Seeds ``A-B`` (a range, never listed out: its size is the schema's to judge) or ``A,B,C``."""
    try:
        if "-" in text.lstrip("-"):
            lo, hi = (int(x) for x in text.split("-"))
            return range(lo, hi + 1)
        return tuple(int(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seeds A-B or A,B,C, got {text!r}") from None


def add_parser(sub) -> None:
    """Add ``spinviz check`` (the validation suite (or --sweep)) and its options to ``sub``."""
    c = sub.add_parser("check", help="validate the integrators against the paper's closed forms, and secular against "
                                     "full integration at real scales (~2.5 min)")
    c.add_argument("--json", action="store_true", help="print a JSON list of records instead of a table")
    c.add_argument("--quick", action="store_true", help="secular comparisons at tau0 |Omega0| = 1e-4, 1e-5 only (~16 s)")
    c.add_argument("--sweep", action="store_true",
                   help="instead: secular against taylor on random symmetric tops, are its stated errors bounds? "
                        "(~8 s per seed of 40 runs)")
    c.add_argument("--seeds", type=_seed_list, help="with --sweep: the seeds, e.g. 1-9 or 1,4,7 (default 1-3)")
    c.add_argument("--runs", type=positive, help="with --sweep: runs per seed (default 40)")


def run(args) -> int:
    """Carry out ``spinviz check`` with the parsed ``args``; return its exit status."""
    from ..validation import checks

    if args.sweep:
        return _sweep(args)
    for given, option in ((args.seeds, "--seeds"), (args.runs, "--runs")):
        if given is not None:
            raise UsageError(f"{option}: only with --sweep")
    results = checks.run_all(quick=args.quick)
    if args.json:
        print(json.dumps([r.record() for r in results], indent=2, default=float))
    else:
        out(checks.format_table(results))
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


def _sweep(args) -> int:
    import time

    from ..validation import secular_sweep as SW

    if args.quick:
        raise UsageError("--quick: not with --sweep (give fewer --seeds or --runs)")
    start = time.perf_counter()
    rows = SW.run(range(1, 4) if args.seeds is None else args.seeds, 40 if args.runs is None else args.runs,
                  progress=lambda r: progress(SW.row_line(r)))
    if args.json:
        print(json.dumps(rows, indent=2, default=float))
    else:
        out(SW.format_table(rows, time.perf_counter() - start))
    return EXIT_OK if SW.passed(rows) else EXIT_FAIL
