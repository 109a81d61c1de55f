"""``spinviz report [--quick] [--out docs/accuracy.md] [--out-dir renders]``: regenerate the
accuracy report (benchmark plot and tables, stress table)."""

from __future__ import annotations

from .shared import EXIT_FAIL, EXIT_OK, out, p, progress


def add_parser(sub) -> None:
    """Add ``spinviz report`` (the regeneration of the accuracy report) and its options to ``sub``."""
    rp = sub.add_parser("report", help="regenerate docs/accuracy.md: bench plot and tables, stress table")
    rp.add_argument("--quick", action="store_true", help="the quick benchmark plan")
    rp.add_argument("--out", default="docs/accuracy.md", help="the Markdown file to write")
    rp.add_argument("--out-dir", default="renders", help="where the plot and JSON go")


def run(args) -> int:
    """Carry out ``spinviz report`` with the parsed ``args``; return its exit status."""
    from ..validation import report

    results, plot_path = report.generate(args.out, args.out_dir, args.quick, progress=progress)
    out(f"{p(args.out)}: regenerated; {p(plot_path)}")
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL
