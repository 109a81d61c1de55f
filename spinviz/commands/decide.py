"""``spinviz decide SCENE [--trials N] [--seed S] [--spin-range LO,HI] [--tau0 known|fitted] ...``:
how long to watch -- a Monte Carlo over noise and unknown starts of the time a likelihood-ratio
test needs to tell the two models apart at 5 sigma in 95 % of trials, with its plot
``PREFIX_decide.png``; or, with ``--measurements FILE``, the start-free P-f test of measured data."""

from __future__ import annotations

import json

from .shared import (
    EXIT_OK,
    add_detector_options,
    cannot_write,
    numbers,
    out,
    p,
    positive,
    prefix_of,
    progress,
    receiver_options,
    whole,
)


def add_parser(sub) -> None:
    """Add ``spinviz decide`` (how long to watch, or the P-f test of measurements) and its options to ``sub``."""
    d = sub.add_parser("decide", help="how long to watch: a Monte Carlo over noise and unknown starts of the time a "
                                      "likelihood-ratio test needs to tell the models apart at 5 sigma in 95 %% of "
                                      "trials; or the start-free P-f test of a file of measurements")
    d.add_argument("scene")
    d.add_argument("--measurements", help="a CSV or JSON file of line frequency and power (docs: Designing an "
                                          "experiment): fit the P-f laws to it instead")
    d.add_argument("--trials", type=whole, help="Monte Carlo trials (default 200)")
    d.add_argument("--seed", type=whole, help="seed of the trials' random streams (default 1)")
    d.add_argument("--spin-range", type=numbers("LO,HI"), help="LO,HI: |Omega0| log-uniform over LO..HI x the scene's (default "
                                                    "0.5,2)")
    d.add_argument("--tau0", choices=("known", "fitted"), help="the body's tau0 known (default), or fitted with the start")
    add_detector_options(d, line_of_sight=False)
    d.add_argument("--workers", type=positive, help="worker processes (default: one per core)")
    d.add_argument("--scheduler", help="run the trials on a Dask cluster at this address (tcp://HOST:8786)")
    d.add_argument("--out", help="prefix of the plot (default renders/<scene>): <prefix>_decide.png")
    d.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args) -> int:
    """Carry out ``spinviz decide`` with the parsed ``args``; return its exit status."""
    from .. import experiment

    if args.measurements is not None:
        return _measurements(args, args.scene)
    given = {k: getattr(args, k) for k in ("trials", "seed", "spin_range", "tau0", "workers", "scheduler")
             if getattr(args, k) is not None}
    plot = f"{prefix_of(args)}_decide.png"
    try:
        outcome = experiment.decide(args.scene, plot=plot, say=progress, **given, **receiver_options(args))
    except OSError as e:
        raise cannot_write(plot, e) from None
    if args.json:
        print(json.dumps({**outcome.record(), "receiver": outcome.receiver.record(), "plots": [plot]}, indent=2))
    else:
        out(outcome.table())
        out(f"\nplot: {p(plot)}")
    return EXIT_OK


def _measurements(args, scene) -> int:
    """``decide --measurements FILE``: the start-free P-f test of measured data."""
    from .. import experiment
    from ..inputs.scene_spec import load_scene

    sc = load_scene(scene)
    law, test = experiment.test_measurements(sc, args.measurements)
    if law is None:
        if args.json:
            print(json.dumps({"measurements": args.measurements, "law": None, "reason": test}, indent=2))
        else:
            out(f"{p(args.measurements)}: no test: {test}")
        return EXIT_OK
    if args.json:
        print(json.dumps({"measurements": args.measurements, "law": law, **test.record()}, indent=2, default=float))
    else:
        out("\n".join([f"{p(args.measurements)} ({sc.title}): line: {law}"] + [f"  {x}" for x in test.summary()]))
    return EXIT_OK
