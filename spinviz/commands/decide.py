"""``spinviz decide SCENE [--trials N] [--seed S] [--spin-range LO,HI] [--tau0 known|fitted] ...``:
how long to watch -- a Monte Carlo over noise and unknown starts of the time a likelihood-ratio
test needs to tell the two models apart at 5 sigma in 95 % of trials, with its plot
``PREFIX_decide.png``; with the trap's environment (``--pressure-mbar`` ...) and the priors of
what must be known (``--tau0-prior``, ``--gain-slope``, ``--clock-stability``); with
``--requirements``, what the trap must achieve (``PREFIX_requirements.png``); or, with
``--measurements FILE``, the start-free P-f test of measured data."""

from __future__ import annotations

import json

from .shared import (
    EXIT_OK,
    add_detector_options,
    add_environment_options,
    cannot_write,
    environment_options,
    numbers,
    out,
    p,
    positive,
    prefix_of,
    progress,
    real,
    receiver_options,
    whole,
)

NUISANCES = ("tau0_prior", "gain_slope", "clock_stability", "pressure_prior")


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
    add_environment_options(d)
    d.add_argument("--tau0-prior", dest="tau0_prior", type=real, metavar="REL",
                   help="tau0 known to this relative width (1 sigma, log-normal; default 0: exactly)")
    d.add_argument("--gain-slope", dest="gain_slope", type=real, metavar="DB",
                   help="the antenna's gain slope over the band uncalibrated to this, dB per octave (1 sigma; default 0)")
    d.add_argument("--clock-stability", dest="clock_stability", type=real, metavar="Y",
                   help="the reference clock's fractional frequency stability over seconds to 100 s (default 0)")
    d.add_argument("--pressure-prior", dest="pressure_prior", type=real, metavar="REL",
                   help="the pressure known to this relative width (1 sigma, log-normal; default 1)")
    d.add_argument("--requirements", action="store_true",
                   help="what the trap must achieve: the largest pressure, field, tau0 prior, gain slope and clock "
                        "instability at which 95 %% of the trials still decide (default 100 trials); "
                        "<prefix>_requirements.png")
    d.add_argument("--workers", type=positive, help="worker processes (default: one per core)")
    d.add_argument("--scheduler", help="run the trials on a Dask cluster at this address (tcp://HOST:8786)")
    d.add_argument("--out", help="prefix of the plot (default renders/<scene>): <prefix>_decide.png")
    d.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args) -> int:
    """Carry out ``spinviz decide`` with the parsed ``args``; return its exit status."""
    from .. import experiment

    if args.measurements is not None:
        return _measurements(args, args.scene)
    given = {k: getattr(args, k) for k in ("trials", "seed", "spin_range", "tau0", "workers", "scheduler") + NUISANCES
             if getattr(args, k) is not None}
    if args.requirements:
        return _requirements(args, given)
    plot = f"{prefix_of(args)}_decide.png"
    try:
        outcome = experiment.decide(args.scene, plot=plot, say=progress, **given, **receiver_options(args),
                                     **environment_options(args))
    except OSError as e:
        raise cannot_write(plot, e) from None
    if args.json:
        print(json.dumps({**outcome.record(), "receiver": outcome.receiver.record(), "plots": [plot]}, indent=2))
    else:
        out(outcome.table())
        out(f"\nplot: {p(plot)}")
    return EXIT_OK


def _requirements(args, given: dict) -> int:
    """``decide --requirements``: what the trap must achieve, and its plot."""
    from .. import experiment

    if given.pop("tau0", None) is not None:
        from ..errors import UsageError

        raise UsageError("--tau0: --requirements searches tau0's prior itself (give --tau0-prior for the others' runs)")
    plot = f"{prefix_of(args)}_requirements.png"
    try:
        req = experiment.requirements(args.scene, plot=plot, say=progress, **given, **receiver_options(args),
                                      **environment_options(args))
    except OSError as e:
        raise cannot_write(plot, e) from None
    if args.json:
        print(json.dumps({**req.record(), "receiver": req.receiver.record(), "plots": [plot]}, indent=2))
    else:
        out(req.table())
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
