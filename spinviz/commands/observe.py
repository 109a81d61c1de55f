"""``spinviz observe SCENE [--los X,Y,Z] [--distance-cm R] [--integration-s T] ...``: what a stated
receiver records from both models of a scene -- SNR, resolutions, the field at the antenna,
when the models part across resolutions, the start-free P-f test -- and the plots
``PREFIX_observe.png``, ``PREFIX_detector.png`` and, for a physical body, ``PREFIX_receiver.png``."""

from __future__ import annotations

import argparse
import json

from ..errors import SimulationError
from .shared import (
    EXIT_OK,
    add_detector_options,
    add_environment_options,
    cannot_write,
    environment_options,
    need_matplotlib,
    out,
    p,
    positive,
    prefix_of,
    receiver_options,
)


def _refused_option(text: str):
    """The type of a fixed resolution observe does not take: always an error, with the reason."""
    from ..inputs.receiver import RESOLUTION_COMPUTED

    raise argparse.ArgumentTypeError(RESOLUTION_COMPUTED)


def add_parser(sub) -> None:
    """Add ``spinviz observe`` (what a detector records, and when the models part) and its options to ``sub``."""
    o = sub.add_parser("observe", help="what a stated receiver records from both models of a scene: SNR, resolutions, "
                                       "the field at the antenna, when the models part across resolutions, the P-f "
                                       "test; plots")
    o.add_argument("scene")
    o.add_argument("--out", help="prefix of the PNG plots (default renders/<scene>): <prefix>_observe.png, "
                                 "<prefix>_detector.png and, for a physical body, <prefix>_receiver.png")
    add_detector_options(o)
    add_environment_options(o)
    for gone in ("--power-factor", "--frequency-resolution", "--polarization-deg"):
        # fixed thresholds: the resolutions are the receiver's; say so instead of "unrecognized"
        o.add_argument(gone, type=_refused_option, help=argparse.SUPPRESS)
    o.add_argument("--samples", type=positive, default=800, help="evenly spaced plus as many log-spaced instants")
    o.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args) -> int:
    """Carry out ``spinviz observe`` with the parsed ``args``; return its exit status."""
    from .. import experiment

    need_matplotlib("observe's plots")
    prefix = prefix_of(args)
    try:
        obs = experiment.observe(args.scene, samples=args.samples, line_of_sight=args.line_of_sight, plots=prefix,
                                 **receiver_options(args), **environment_options(args))
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    except OSError as e:
        raise cannot_write(prefix, e) from None
    paths = [f"{prefix}_{n}.png" for n in ("observe", "detector", "receiver")][:3 if obs.units == "cgs" else 2]
    if args.json:
        print(json.dumps({**obs.record(), "plots": paths}, indent=2, default=float))
    else:
        out(obs.table())
        out(f"\nplots: {', '.join(p(x) for x in paths)}")
    return EXIT_OK
