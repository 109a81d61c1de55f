"""``spinviz boxes [--grid N] [--lo R] [--hi R] [--starts N] [--models M] [--out PATH.nc] [--plot PATH.png]``:
the atlas of one crystal's boxes -- where each box's spin ends as tau -> oo."""

from __future__ import annotations

from .shared import positive, real


def add_parser(sub) -> None:
    """Add ``spinviz boxes`` (the boxes atlas of the DAST crystal) and its options to ``sub``."""
    b = sub.add_parser(
        "boxes", help="where a DAST box a x b x c's spin ends as tau -> oo, over the plane of edge ratios (b/a, c/a)",
        description="For every box of the grid: the averaged flow's shape (a flow on one line between the two extreme "
                    "axes), its attractors, and the share of evenly spread spin directions ending about each edge; "
                    "written as netCDF, drawn as a PNG with the families a = b and b = c of the paper's figure 5.")
    b.add_argument("--grid", type=positive, default=25, help="boxes per ratio (default 25: 625 boxes per model)")
    b.add_argument("--lo", type=real, default=0.5, help="smallest b/a and c/a (default 0.5)")
    b.add_argument("--hi", type=real, default=2.0, help="largest b/a and c/a (default 2)")
    b.add_argument("--starts", type=positive, default=600, help="spin directions per box (default 600)")
    b.add_argument("--models", default="reduced,truncated", help="reduced, truncated or both (default both)")
    b.add_argument("--out", default="boxes.nc", help="the netCDF file (default boxes.nc)")
    b.add_argument("--plot", metavar="PATH", help="also draw the atlas (PNG)")
    b.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args) -> int:
    """Carry out ``spinviz boxes`` with the parsed ``args``; return its exit status."""
    from ..inputs.boxes import BoxesRequest
    from ..progress import Progress
    from ..regimes.asymmetric.atlas import run as boxes
    from .shared import out

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
    out(f"{req.out}: {ds.attrs['cells']} boxes x models in {ds.attrs['seconds']:.1f} s "
        f"({ds.attrs['cpu_seconds']:.1f} s CPU)" + (f"; {req.plot}" if req.plot else ""))
    return 0
