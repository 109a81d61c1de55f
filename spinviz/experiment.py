"""What an experiment would see: the front doors ``compare``, ``observe``, ``decide`` and
``listen`` (public as ``spinviz.compare`` ...), and ``test_measurements``.

Each takes a scene (a ``Scene`` or the path of its TOML), checks its request once -- the
arguments by the schema (``inputs.experiment``, ``inputs.decide``, ``inputs.options``), the
receiver's options by ``ReceiverSpec.with_options``, the scene by ``Scene.require`` (the
models, the body's symmetry and units the command needs) -- and only then simulates.  A bad
argument is a ``SpecError`` naming it, a scene that lacks what the command needs a
``SceneError`` naming its file and key.  The command line calls these very functions.

Receiver keywords (``distance_cm=``, ``integration_s=``, any key of
``inputs.receiver.DETECTOR_KEYS``) override the scene's ``[observe]`` keys of the same name;
environment keywords (``pressure_mbar=``, ``field_v_per_m=``, any key of ``ENVIRONMENT_KEYS``)
its ``[environment]``'s.
"""

from __future__ import annotations

import contextlib
import os

from .errors import SpecError

__all__ = ["compare", "observe", "decide", "requirements", "listen", "test_measurements", "receiver_of"]

DASK_TRIALS = 2000            # from this many trials (or with a scheduler) decide runs on Dask
# the [environment] keys observe and decide take as keywords (the command line's options)
ENVIRONMENT_KEYS = ("pressure_mbar", "gas", "gas_temperature_k", "accommodation", "body_temperature_k",
                    "field_v_per_m")


def _split(options: dict) -> tuple[dict, dict]:
    """(receiver keywords, environment keywords) of a front door's keywords."""
    env = {k: options.pop(k) for k in list(options) if k in ENVIRONMENT_KEYS}
    return options, env


def _with_environment(sc, env: dict):
    """The scene with the environment keywords given (``Scene.with_environment``)."""
    return sc.with_environment(**env) if any(v is not None for v in env.values()) else sc


def _scene(source):
    """A ``Scene`` from a scene or the path of one."""
    if isinstance(source, (str, os.PathLike)):
        from .inputs.scene_spec import load_scene

        return load_scene(source)
    from .inputs.scene_spec import Scene

    if not isinstance(source, Scene):
        from .errors import SpecTypeError

        raise SpecTypeError("scene", f"must be a Scene or the path of a scene file, got {type(source).__name__}")
    return source


def receiver_of(scene, **options):
    """The scene's receiver (``[observe]``) with the receiver ``options`` given (None: the
    scene's) in place of its keys: ``inputs.receiver.ReceiverSpec``."""
    return _scene(scene).observe.receiver.with_options(**options)


def _plots(sc, paths):
    """The outputs group of ``paths`` (checked now, before any work; written together at the end)."""
    from .atomic import Outputs

    return Outputs(paths, [sc.path] if sc.path else [])


def compare(scene, *, samples: int = 800, plots: str | None = None):
    """Run both models of a two-model scene at the same instants and compare them
    (``analysis.compare.Comparison``: misorientation, dipole angle, first times above 1° and
    10°, final states; ``.table()`` for people, ``.record()`` for JSON).

    samples : evenly spaced plus as many log-spaced instants.  plots : a path prefix: writes
    ``PREFIX_compare.png`` (how far apart, |Omega|, angle(d, L)) and ``PREFIX_hodograph.png``
    (like the paper's figures 3 and 4), together, atomically."""
    from .analysis import compare as CMP
    from .driver import simulate_request
    from .inputs.experiment import CompareRequest

    samples = CompareRequest(samples=samples).samples
    sc = _scene(scene).require("compare")
    group = _plots(sc, [f"{plots}_compare.png", f"{plots}_hodograph.png"]) if plots is not None else None
    times = CMP.compare_times(sc.t_end, samples)
    try:
        trajs = [simulate_request(sc.request(m, t_eval=times)) for m in sc.models]
    except SpecError as e:                              # the output times are this argument's
        raise SpecError("samples", e.reason) if e.key == "t_eval" else e from None
    c = CMP.compare(trajs)
    c.title = sc.title
    if group is not None:
        with group as (tmp_compare, tmp_hodograph):
            CMP.plot(c, tmp_compare, sc.title)
            CMP.plot_hodograph(c, tmp_hodograph, sc.title)
    return c


def observe(scene, *, samples: int = 800, line_of_sight=None, plots: str | None = None, **receiver):
    """What the scene's receiver records from both models (``analysis.observe.Observation``:
    SNR, resolutions, the field at the antenna, when the models part, the P-f test;
    ``.table()`` for people, ``.record()`` for JSON).

    line_of_sight : world-frame direction to the detector (default the scene's [observe], else
    across L(0)); ``receiver``: receiver keys (``distance_cm=`` ...) in place of the scene's.
    plots : a path prefix: writes ``PREFIX_observe.png``, ``PREFIX_detector.png`` and, for a
    physical body, ``PREFIX_receiver.png``, together, atomically."""
    from .analysis import observe as OB
    from .inputs.experiment import ObserveRequest

    req = ObserveRequest(samples=samples, line_of_sight=line_of_sight)
    receiver, env = _split(receiver)
    sc = _scene(scene)
    rx = receiver_of(sc, **receiver)
    sc = _with_environment(sc, env)
    try:
        sc.require("observe")
    except SpecError as e:
        raise _environment_error(e, sc, env) from None
    names = ["observe", "detector"] + (["receiver"] if sc.units == "cgs" else [])
    group = _plots(sc, [f"{plots}_{n}.png" for n in names]) if plots is not None else None
    try:
        obs, _ = OB.run_scene(sc, req.samples, req.line_of_sight, rx)
    except SpecError as e:
        raise _environment_error(e, sc, env) from None
    if group is not None:
        from .analysis import experiment_plots as EP
        from .analysis import observe_plots as OP

        with group as tmps:
            OP.plot(obs, tmps[0])
            OP.plot_detector(obs, tmps[1])
            if len(tmps) > 2:
                EP.plot_receiver(obs, tmps[2])
    return obs


def _environment_error(e: SpecError, sc, env: dict) -> SpecError:
    """A run's refusal in a trap, blamed on the environment key that made it (the option given,
    or the scene's): a horizon the gas makes unaffordable is the pressure's."""
    if not sc.environment.active:
        return e
    key = e.key.split(".", 1)[1] if e.key.startswith("environment.") else None
    if key is None and e.key in ("t_eval", "t_end", "samples") and "gas" in e.reason:
        key = "pressure_mbar"
    if key is None:
        return e
    if env.get(key) is not None:
        return SpecError(key, e.reason)
    from .errors import SceneError

    return SceneError(sc.path, f"[environment].{key}", e.reason)


def listen(scene, out: str, *, png: str | None = None, duration: float = 20.0, f0: float = 440.0,
           time_map: str = "log", pitch: str = "auto", dynamic_range_db: float = 60.0, samples: int = 800,
           line_of_sight=None, **receiver):
    """The detector's signal of both models as a stereo WAV (left one model, right the other)
    at ``out`` and its spectrogram at ``png`` (default beside it), written together, atomically;
    returns the ``analysis.sonify.Mapping`` (how sound time and pitch follow the run's)."""
    from .analysis import sonify
    from .atomic import Outputs
    from .inputs.options import ListenRequest

    req = ListenRequest(duration=duration, f0=f0, time_map=time_map, pitch=pitch, dynamic_range_db=dynamic_range_db,
                        samples=samples, out=out, png=png)
    sc = _scene(scene)
    rx = receiver_of(sc, **receiver)
    sc.require("listen")
    group = Outputs([req.out, req.png_path], [sc.path])
    with group as (tmp_wav, tmp_png):
        return sonify.listen_scene(sc, tmp_wav, tmp_png, req, line_of_sight, rx)


def decide(scene, *, trials: int = 200, seed: int = 1, spin_range=(0.5, 2.0), tau0: str = "known",
           workers: int | None = None, scheduler: str | None = None, plot: str | None = None, say=None,
           tau0_prior: float = 0.0, gain_slope: float = 0.0, clock_stability: float = 0.0,
           pressure_prior: float = 1.0, **options):
    """How long to watch: a Monte Carlo over noise and unknown starts of the time a
    likelihood-ratio test needs to tell the scene's two models apart at 5 sigma in 95 % of
    trials (``analysis.decide.Outcome``; ``.table()`` for people, ``.record()`` for JSON).

    What must be known (``analysis.nuisance``): ``tau0_prior`` (tau0's relative width; 0:
    known), ``gain_slope`` (the antenna's, dB per octave, 1 sigma), ``clock_stability`` (the
    reference's fractional stability), ``pressure_prior`` (the pressure's relative width), and
    the trap: the scene's ``[environment]`` with the environment keywords in place of its keys.
    All zero (and no gas or field): the perfect experiment, exactly as without them.

    Runs on worker processes of this machine (``workers``, default one per core), or on Dask
    from ``DASK_TRIALS`` trials or with ``scheduler`` (an existing cluster's address);
    ``say(text)``, if given, hears where it runs.  plot : a PNG path for the share of trials
    decided against observation time, written atomically."""
    from .analysis import decide as DC

    spec, sc, rx = _decide_request(scene, trials, seed, spin_range, tau0, workers, scheduler, tau0_prior, gain_slope,
                                   clock_stability, pressure_prior, False, options)
    setup = _decide_setup(sc, rx, spec)
    DC.check_work(setup, spec.trials, _workers(spec))          # SPINVIZ_MAX_DAYS, before any trial
    group = _plots(sc, [plot]) if plot is not None else None
    with contextlib.ExitStack() as stack:
        mapper = _mapper(stack, spec, say)
        outcome = DC.run(setup, spec.trials, spec.seed, mapper)
    outcome.title, outcome.receiver = sc.title, rx
    if group is not None:
        from .analysis.experiment_plots import plot_decide

        with group as (tmp,):
            plot_decide(outcome, sc.title, tmp)
    return outcome


def requirements(scene, *, trials: int = 100, seed: int = 1, spin_range=(0.5, 2.0), workers: int | None = None,
                 scheduler: str | None = None, plot: str | None = None, say=None, tau0_prior: float = 0.0,
                 gain_slope: float = 0.0, clock_stability: float = 0.0, pressure_prior: float = 1.0, **options):
    """What the trap must achieve (``analysis.requirements.Requirements``): the largest pressure,
    field, tau0 prior, gain slope and clock instability at which 95 % of ``decide``'s trials
    still decide within the horizon, each with the others at their stated values (the
    keywords, and the scene's ``[environment]``).  Its work is estimated first and refused
    above ``SPINVIZ_MAX_DAYS`` (``inputs.options.check_work``).  plot : a PNG path for the
    decision time against pressure, written atomically; ``.table()`` for people,
    ``.record()`` for JSON."""
    from .analysis import requirements as RQ
    from .inputs.options import check_work

    spec, sc, rx = _decide_request(scene, trials, seed, spin_range, "known", workers, scheduler, tau0_prior,
                                   gain_slope, clock_stability, pressure_prior, True, options)
    from .executors.processes import usable_cores

    seconds = RQ.work_seconds(spec.trials, spec.workers or usable_cores())
    check_work("trials", seconds, f"the requirements' Monte Carlo of {spec.trials} trials at every value probed")
    if say is not None:
        say(f"requirements: at most ~{seconds / 3600:.2g} h of work estimated")
    stated = {"pressure_mbar": sc.environment.pressure_mbar, "field_v_per_m": sc.environment.field_magnitude_v_per_m,
              "tau0_prior": spec.tau0_prior, "gain_slope": spec.gain_slope, "clock_stability": spec.clock_stability,
              "pressure_prior": spec.pressure_prior}
    group = _plots(sc, [plot]) if plot is not None else None
    with contextlib.ExitStack() as stack:
        mapper = _mapper(stack, spec, say)
        req = RQ.run(sc.require("decide"), rx, stated, spec.trials, spec.seed, spec.spin_range, mapper, say)
    if group is not None:
        from .analysis.requirement_plots import plot_requirements

        with group as (tmp,):
            plot_requirements(req, tmp)
    return req


def _decide_request(scene, trials, seed, spin_range, tau0, workers, scheduler, tau0_prior, gain_slope, clock_stability,
                    pressure_prior, requirements, options):
    """decide's and requirements' arguments checked once: (DecideArguments, scene in its
    environment, receiver)."""
    from .inputs.decide import DecideArguments

    spec = DecideArguments(trials=trials, seed=seed, spin_range=spin_range, tau0=tau0, workers=workers,
                           scheduler=scheduler, tau0_prior=tau0_prior, gain_slope=gain_slope,
                           clock_stability=clock_stability, pressure_prior=pressure_prior, requirements=requirements)
    receiver, env = _split(dict(options))
    sc = _scene(scene)
    rx = receiver_of(sc, **receiver)
    sc = _with_environment(sc, env)
    return spec, sc, rx


def _decide_setup(sc, rx, spec):
    """decide's ``Setup``, with its nuisances when there are any."""
    import dataclasses

    from .analysis import decide as DC
    from .analysis import nuisance as NU

    setup = DC.setup_from_scene(sc.require("decide"), rx, sc.observe.t_end or sc.t_end, spec.spin_range, spec.tau0)
    nu = NU.from_scene(sc, tau0_width=spec.tau0_prior, gain_slope_db=spec.gain_slope, clock=spec.clock_stability,
                       pressure_width=spec.pressure_prior)
    return dataclasses.replace(setup, nuisance=nu) if nu.active else setup


def _mapper(stack: contextlib.ExitStack, spec, say):
    """Where decide's trials run: a Dask cluster when large or asked for, worker processes
    otherwise (None: this process, for a handful of trials on one core)."""
    from .executors.processes import ProcessMapper

    if spec.scheduler is not None or spec.trials >= DASK_TRIALS:
        from .executors.cluster import Cluster, mapper

        cl = stack.enter_context(Cluster(spec.scheduler, spec.workers))
        if say is not None:
            say(f"decide: {spec.trials} trials on {cl.describe}")
        return mapper(cl)
    workers = _workers(spec)
    return None if workers == 1 else stack.enter_context(ProcessMapper(workers))


def _workers(spec) -> int:
    """The processes decide's trials run on: the given workers or one per core, no more than
    the batches of 8 trials; on Dask, the embedded cluster's (an existing cluster's size is not
    known before it is reached: its work is estimated as on this machine)."""
    from .executors.processes import usable_cores

    if spec.scheduler is not None or spec.trials >= DASK_TRIALS:
        return spec.workers or usable_cores()
    return min(spec.workers or usable_cores(), max(1, spec.trials // 8))


def test_measurements(scene, measurements):
    """The start-free P-f test of a file of measured line frequency and power (CSV or JSON;
    ``inputs.measurements``) against the scene's laws: (law, ``analysis.pftest.PfTest``), or
    (None, why there is no law for this body)."""
    from .analysis import pftest as PF
    from .inputs.measurements import read_measurements

    sc = _scene(scene)
    law, reason = PF.line_law(sc.body)
    data, unit = read_measurements(measurements)
    if law is None:
        return None, reason
    return law, PF.fit(PF.from_measurements(data, unit, os.fspath(measurements)))


test_measurements.__test__ = False          # a front door named "test_...", not a test for pytest
