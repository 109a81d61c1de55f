"""``spinviz compare SCENE [--out PREFIX] [--json]``: reduced against truncated for a two-model
scene -- misorientation and dipole angle between the predictions, crossing times, final
states -- and the plots ``PREFIX_compare.png``, ``PREFIX_hodograph.png``."""

from __future__ import annotations

import json

from .shared import EXIT_OK, cannot_write, need_matplotlib, out, p, positive, prefix_of


def add_parser(sub) -> None:
    """Add ``spinviz compare`` (the comparison of a two-model scene) and its options to ``sub``."""
    c = sub.add_parser("compare", help="reduced vs truncated for a two-model scene: angles, crossing times, final states, "
                                       "plots")
    c.add_argument("scene")
    c.add_argument("--out", help="prefix of the PNG plots (default renders/<scene>): "
                                 "<prefix>_compare.png, <prefix>_hodograph.png")
    c.add_argument("--samples", type=positive, default=800, help="evenly spaced plus as many log-spaced output times")
    c.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args) -> int:
    """Carry out ``spinviz compare`` with the parsed ``args``; return its exit status."""
    from .. import experiment

    need_matplotlib("compare's plots")
    prefix = prefix_of(args)
    try:
        c = experiment.compare(args.scene, samples=args.samples, plots=prefix)
    except OSError as e:
        raise cannot_write(prefix, e) from None
    paths = [f"{prefix}_compare.png", f"{prefix}_hodograph.png"]
    if args.json:
        print(json.dumps({**c.record(), "plots": paths}, indent=2, default=float))
    else:
        out(c.table())
        out(f"\nplots: {p(paths[0])}, {p(paths[1])}")
    return EXIT_OK
