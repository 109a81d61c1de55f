"""``spinviz observe SCENE [--los X,Y,Z] [--distance-cm R] ...``: what a detector records from both
models of a scene, and when the two part; the plots ``PREFIX_observe.png`` and
``PREFIX_detector.png``."""

from __future__ import annotations

import json

from ..errors import SimulationError, UsageError
from .shared import EXIT_OK, cannot_write, need_matplotlib, out, p, positive, prefix_of, real, vector

MAX_SAMPLES = 100_000


def add_detector_options(parser, hidden: tuple = ()) -> None:
    """The detector's options, shared with ``listen``; their values are checked by the scene's
    ``[observe]`` schema (``detector_overrides``), so an option and the key it overrides take
    the same values."""
    import argparse

    parser.add_argument("--los", dest="line_of_sight", metavar="X,Y,Z", type=vector,
                        help="line of sight X,Y,Z in the world frame (default: the scene's [observe], else across L(0))")
    parser.add_argument("--distance-cm", type=real,
                        help=argparse.SUPPRESS if "distance_cm" in hidden else "where the field is given (default 1 cm)")


def detector_overrides(args, keys=("line_of_sight", "distance_cm")) -> dict:
    """The detector options given, checked by the ``[observe]`` table's own schema."""
    from ..inputs.scene import ObserveTable

    given = {k: getattr(args, k) for k in keys if getattr(args, k, None) is not None}
    ObserveTable(**given)                               # SpecError: named by its option
    return given


def add_parser(sub) -> None:
    """Add ``spinviz observe`` (what a detector records, and when the models part) and its options to ``sub``."""
    o = sub.add_parser("observe", help="what a detector records from both models of a scene, and when the two part "
                                       "(power, frequency, polarization); plots")
    o.add_argument("scene")
    o.add_argument("--out", help="prefix of the PNG plots (default renders/<scene>): <prefix>_observe.png, "
                                 "<prefix>_detector.png")
    add_detector_options(o)
    o.add_argument("--power-factor", type=real, help="power resolution, a ratio (default 2)")
    o.add_argument("--frequency-resolution", type=real, help="relative frequency resolution (default 0.01)")
    o.add_argument("--polarization-deg", type=real, help="polarization-angle resolution, degrees (default 5)")
    o.add_argument("--samples", type=positive, default=800, help="evenly spaced plus as many log-spaced instants")
    o.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args) -> int:
    """Carry out ``spinviz observe`` with the parsed ``args``; return its exit status."""
    from ..analysis import observe as OB
    from ..atomic import Outputs
    from ..inputs.scene_spec import load_scene

    detector_overrides(args, ("line_of_sight", "distance_cm", "power_factor", "frequency_resolution",
                              "polarization_deg"))
    sc = load_scene(args.scene)
    need_matplotlib("observe's plots")
    if args.samples > MAX_SAMPLES:
        raise UsageError(f"--samples: at most {MAX_SAMPLES}, got {args.samples}")
    prefix = prefix_of(args)
    paths = [f"{prefix}_observe.png", f"{prefix}_detector.png"]
    group = Outputs(paths, [args.scene])
    res = OB.scene_resolution(sc, args.power_factor, args.frequency_resolution, args.polarization_deg)
    try:
        obs, _ = OB.run_scene(sc, args.samples, args.line_of_sight, args.distance_cm, res)
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    except ValueError as e:
        raise UsageError(f"{args.scene}: {e}") from None
    try:
        with group as tmps:
            OB.plot(obs, tmps[0])
            OB.plot_detector(obs, tmps[1])
    except OSError as e:
        raise cannot_write(prefix, e) from None
    if args.json:
        print(json.dumps({**obs.record(), "plots": list(paths)}, indent=2, default=float))
    else:
        out(OB.format_table(obs))
        out(f"\nplots: {p(paths[0])}, {p(paths[1])}")
    return EXIT_OK
