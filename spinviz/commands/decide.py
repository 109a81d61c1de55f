"""``spinviz decide SCENE [--trials N] [--seed S] [--spin-range LO,HI] [--tau0 known|fitted] ...``:
how long to watch -- a Monte Carlo over noise and unknown starts of the time a likelihood-ratio
test needs to tell the two models apart at 5 sigma in 95 % of trials, with its plot
``PREFIX_decide.png``; or, with ``--measurements FILE``, the start-free P-f test of measured data."""

from __future__ import annotations

import dataclasses
import json

from ..errors import UsageError
from .shared import EXIT_OK, add_detector_options, cannot_write, numbers, out, p, positive, prefix_of, progress, whole

DASK_TRIALS = 2000            # from this many trials (or with --scheduler) the Monte Carlo runs on Dask
KEYS = ("distance_cm", "integration_s")


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
    add_detector_options(d, KEYS)
    d.add_argument("--workers", type=positive, help="worker processes (default: one per core)")
    d.add_argument("--scheduler", help="run the trials on a Dask cluster at this address (tcp://HOST:8786)")
    d.add_argument("--out", help="prefix of the plot (default renders/<scene>): <prefix>_decide.png")
    d.add_argument("--json", action="store_true", help="print the results as JSON")


def run(args) -> int:
    """Carry out ``spinviz decide`` with the parsed ``args``; return its exit status."""
    from ..analysis import decide as DC
    from ..atomic import Outputs
    from ..inputs.decide import DecideArguments
    from ..inputs.scene_spec import load_scene

    spec = DecideArguments(**{k: getattr(args, k) for k in ("trials", "seed", "spin_range", "tau0", "workers",
                                                            "scheduler") if getattr(args, k) is not None})
    sc = load_scene(args.scene)
    receiver = sc.observe.receiver
    given = {k: getattr(args, k) for k in KEYS if getattr(args, k) is not None}
    if given:
        receiver = dataclasses.replace(receiver, **given)       # SpecError: named by its option
    if args.measurements is not None:
        return _measurements(args, sc)
    try:
        setup = DC.setup_from_scene(sc, receiver, sc.observe.t_end or sc.t_end, spec.spin_range, spec.tau0)
    except ValueError as e:
        raise UsageError(f"{args.scene}: {e}") from None
    prefix = prefix_of(args)
    plot = f"{prefix}_decide.png"
    group = Outputs([plot], [args.scene])
    outcome = _trials(DC, setup, spec, args)
    try:
        with group as tmps:
            from ..analysis.experiment_plots import plot_decide

            plot_decide(outcome, sc.title, tmps[0])
    except OSError as e:
        raise cannot_write(prefix, e) from None
    if args.json:
        print(json.dumps({**outcome.record(), "receiver": receiver.record(), "plots": [plot]}, indent=2))
    else:
        out(DC.format_outcome(outcome, sc.title, receiver))
        out(f"\nplot: {p(plot)}")
    return EXIT_OK


def _trials(DC, setup, spec, args):
    """The Monte Carlo where it belongs: a Dask cluster when large or asked for (the atlas's
    ``Cluster``), worker processes otherwise."""
    from ..inputs.render import usable_cores

    if args.scheduler is not None or spec.trials >= DASK_TRIALS:
        from ..regimes.cluster import Cluster, check_workers, polled

        check_workers(args.workers, args.scheduler)
        with Cluster(args.scheduler, args.workers) as cl:
            progress(f"decide: {spec.trials} trials on {cl.describe}")

            def mapper(fn, items):
                return polled(cl.client.gather, cl.client.map(fn, items, pure=False))

            return DC.run(setup, spec.trials, spec.seed, mapper)
    workers = min(args.workers or usable_cores(), max(1, spec.trials // 8))
    if workers == 1:
        return DC.run(setup, spec.trials, spec.seed)
    with DC.ProcessMapper(workers) as mapper:
        return DC.run(setup, spec.trials, spec.seed, mapper)


def _measurements(args, sc) -> int:
    """``decide --measurements FILE``: the start-free P-f test of measured data."""
    from ..analysis import pftest as PF
    from ..inputs.measurements import read_measurements

    law, reason = PF.line_law(sc.body)
    data, unit = read_measurements(args.measurements)
    if law is None:
        if args.json:
            print(json.dumps({"measurements": args.measurements, "law": None, "reason": reason}, indent=2))
        else:
            out(f"{p(args.measurements)}: no test: {reason}")
        return EXIT_OK
    test = PF.fit(PF.from_measurements(data, unit, args.measurements))
    if args.json:
        print(json.dumps({"measurements": args.measurements, "law": law, **test.record()}, indent=2, default=float))
    else:
        out("\n".join([f"{p(args.measurements)} ({sc.title}): line: {law}"] + [f"  {x}" for x in test.summary()]))
    return EXIT_OK
