"""``spinviz stress [--json]``: stiff and extreme cases, pass or fail, with the method the driver picked."""

from __future__ import annotations

import json

from .shared import EXIT_FAIL, EXIT_OK, progress


def add_parser(sub) -> None:
    """Add ``spinviz stress`` (the stiff and extreme cases) and its options to ``sub``."""
    st = sub.add_parser("stress", help="stiff and extreme cases: pass/fail, error, time, and the method the driver picked")
    st.add_argument("--json", action="store_true", help="print a JSON list of records instead of a table")


def run(args) -> int:
    """Carry out ``spinviz stress`` with the parsed ``args``; return its exit status."""
    from ..validation import stress

    results = stress.run_all(progress=lambda r: progress(f"{r.case}: {'pass' if r.passed else 'FAIL'}"))
    if args.json:
        print(json.dumps([r.record() for r in results], indent=2, default=float))
    else:
        print(stress.format_table(results))
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL
