"""The counts and horizons of the commands that run studies -- ``check --sweep``, ``bench``,
``bench --process``, ``atlas evidence KIND`` -- as request classes of the one schema.

Each field is named as the library function's argument, which is also the command-line
option's ``dest`` (``--tau-end`` is ``tau_end``), so a value is refused with the same reason
from Python (``SpecError("tau_end", ...)``) and from the command line (``--tau-end: ...``),
before any work.  Numbers are finite and in range, the range and its reason in the message.

Work.  A count can ask for years of computing (``--runs 1000000000``).  Each request
estimates the time its work takes on this machine from measured costs (below) and refuses it
above ``max_days()`` -- 30 days unless the environment variable ``SPINVIZ_MAX_DAYS`` says
otherwise, which is how someone who means it (on a machine or cluster that can take it)
raises the cap; the message says so.  The atlas's own feasibility check
(``regimes.engine.cost.check_feasible``) reads the same cap.

A new long command joins in with one call, before any work: ``check_units(key, units,
seconds_each, what, workers)`` for work made of alike pieces (trials, runs, starts), each
measured on one core of this machine (the constant beside the others here, with where it was
measured), or ``check_work(key, seconds, what)`` for any other estimate; ``key`` is the
argument that sets the amount, so the refusal names it (``--trials: ...``).
"""

from __future__ import annotations

import math
import os
from typing import Annotated, Any, Literal

from pydantic import Field, PlainValidator, model_validator

from ..errors import SpecError, brief
from .base import Flag, Int, Path, Real, Text, between, request, shown, wrong_type

MAX_DAYS_ENV = "SPINVIZ_MAX_DAYS"
MAX_DAYS = 30.0                  # default cap on the estimated work of one command, days


def max_days() -> float:
    """The cap on one command's estimated work, in days: ``SPINVIZ_MAX_DAYS`` or 30."""
    raw = os.environ.get(MAX_DAYS_ENV)
    if raw is None or raw.strip() == "":
        return MAX_DAYS
    try:
        value = float(raw)
    except ValueError:
        raise SpecError(MAX_DAYS_ENV, f"must be a number of days, got {brief(raw)}") from None
    if not (math.isfinite(value) and value > 0):
        raise SpecError(MAX_DAYS_ENV, f"must be a positive finite number of days, got {brief(raw)}")
    return value


def check_work(key: str, seconds: float, what: str) -> None:
    """Refuse (``SpecError(key, ...)``) work estimated at more than ``max_days()``."""
    cap = max_days()
    if not seconds <= cap * 86400.0:
        raise SpecError(key, f"{what} would take ~{_duration(seconds)} here, more than the cap of {cap:g} days; "
                             f"someone who means it (on a machine or cluster that can take it) raises the cap with "
                             f"{MAX_DAYS_ENV}=DAYS")


def check_units(key: str, units: float, seconds_each: float, what: str, workers: int = 1) -> float:
    """``check_work`` for ``units`` alike pieces of work, each measured at ``seconds_each`` on
    one core, shared by ``workers`` processes; returns the estimate, s."""
    workers = max(1, int(workers))
    seconds = float(units) * float(seconds_each) / workers
    check_work(key, seconds, f"{what} (~{seconds_each:.2g} s each on one core, {workers} worker"
                             f"{'s' if workers != 1 else ''})")
    return seconds


def _duration(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "forever"
    days = seconds / 86400.0
    if days >= 1:
        return f"{days / 365.25:.3g} years" if days > 730 else f"{days:.3g} days"
    return f"{seconds / 3600:.3g} h" if seconds >= 3600 else f"{seconds / 60:.3g} min" if seconds >= 60 else f"{seconds:.3g} s"


def _count(limit: int, why: str):
    """A whole number in [1, ``limit``] (beyond the limit the estimate of its work is absurd anyway)."""
    return Annotated[Int, between(1, limit, why)]


def count_of(seeds) -> int:
    """How many seeds (a range's length without listing it, however long)."""
    if isinstance(seeds, range):
        return max(0, -(-(seeds.stop - seeds.start) // seeds.step)) if seeds.step > 0 else max(
            0, -(-(seeds.start - seeds.stop) // -seeds.step))
    return len(seeds)


# --- check --sweep --------------------------------------------------------------------------
SWEEP_S_PER_RUN = 0.2            # one secular-against-taylor comparison (docs/integrators.md: 18 seeds x 40 runs in 142 s)
MAX_SEED = 2**63 - 1             # numpy's default_rng takes any non-negative integer; this one fits an int64


def _seeds(v):
    """A non-empty ``range`` or sequence of seeds (non-negative whole numbers), kept as given
    (a range stays a range: its length is known without listing it)."""
    if isinstance(v, range):
        if count_of(v) == 0:
            raise ValueError(f"no seeds in {v.start}-{v.stop - 1}")
        ends = (min(v.start, v.start + (count_of(v) - 1) * v.step), max(v.start, v.start + (count_of(v) - 1) * v.step))
    elif isinstance(v, list | tuple):
        if not v:
            raise ValueError("no seeds given")
        if any(isinstance(s, bool) or not isinstance(s, int) for s in v):
            raise wrong_type(f"must be whole numbers, got {brief(v)}")
        ends = (min(v), max(v))
        v = tuple(v)
    else:
        raise wrong_type(f"must be a range or a list of whole numbers, got {brief(v)}")
    if ends[0] < 0 or ends[1] > MAX_SEED:
        raise ValueError(f"every seed must lie in [0, {MAX_SEED}] (NumPy's generator), got {ends[0]}..{ends[1]}")
    return v


Seeds = Annotated[Any, PlainValidator(_seeds)]


@request
class SweepRequest:
    """``check --sweep``'s arguments (``validation.secular_sweep.run``): the seeds and the runs of each."""

    seeds: Seeds = range(1, 4)
    runs: _count(10**9, "runs per seed") = 40

    @model_validator(mode="after")
    def _work(self):
        n = count_of(self.seeds)
        blame = "seeds" if n / 3 > self.runs / 40 else "runs"           # the one further from its default
        check_work(blame, float(n) * self.runs * SWEEP_S_PER_RUN,
                   f"{n} seed(s) x {self.runs} runs (~{SWEEP_S_PER_RUN:g} s a run)")
        return self


# --- bench, bench --process -----------------------------------------------------------------
# One repeat runs every point of the plan once more (the minimum of the repeats is kept): from
# the durations the docs and the commands' help give for 3 repeats, with their warm-up and
# reference runs counted as one more repeat.
BENCH_S_PER_REPEAT = {"quick": 40.0, "full": 600.0}
PROCESS_S_PER_REPEAT = {"quick": 15.0, "full": 75.0}


def _names(v):
    if isinstance(v, str) or not isinstance(v, list | tuple) or not v or not all(isinstance(x, str) for x in v):
        raise wrong_type(f"must be a non-empty list of names, got {brief(v)}")
    return tuple(v)


@request
class BenchRequest:
    """``spinviz bench``'s arguments (``validation.bench.run``, ``validation.process_bench.run``)."""

    repeats: _count(10**9, "timings per point, the minimum kept") = 3
    quick: Flag = False
    process: Flag = False
    turns: Annotated[Real, between(10.0, 1e5, "turns of each problem with --process; the references resolve every "
                                               "turn")] = 400.0
    problems: Annotated[Any, PlainValidator(_names)] | None = None
    known: Annotated[Any, PlainValidator(_names)] | None = None          # the problems there are (for the message)

    @model_validator(mode="after")
    def _check(self):
        if self.problems is not None and self.known is not None:
            unknown = [n for n in self.problems if n not in self.known]
            if unknown:
                raise SpecError("problems", f"unknown {', '.join(map(brief, unknown))}; valid: {', '.join(self.known)}")
        per = (PROCESS_S_PER_REPEAT if self.process else BENCH_S_PER_REPEAT)["quick" if self.quick else "full"]
        per *= max(1.0, self.turns / 400.0) if self.process else 1.0
        check_work("repeats", self.repeats * per, f"{self.repeats} repeats of every point (~{per:g} s a repeat)")
        return self


# --- atlas evidence KIND ------------------------------------------------------------------
TAU_MIN = 1e5                    # below: the classifier's two 2-decade windows and 100 braking times of |omega0| = 0.04
TAU_MAX = 1e20                   # the hand-over engine's horizons: where it was measured to hold (a kind may ask less)
MAX_HORIZONS = 8


def _horizons(v):
    if isinstance(v, str) or not isinstance(v, list | tuple):
        raise wrong_type(f"must be a list of horizons tau, got {brief(v)}")
    out = []
    for x in v:
        if isinstance(x, bool) or not isinstance(x, int | float):
            raise wrong_type(f"must be numbers, got {brief(v)}")
        x = float(x)
        if not math.isfinite(x):
            raise ValueError(f"must be finite, got {brief(v)}")
        out.append(x)
    if not 2 <= len(out) <= MAX_HORIZONS:
        raise ValueError(f"give 2 to {MAX_HORIZONS} horizons, got {len(out)}")
    if any(not b > a for a, b in zip(out, out[1:])):
        raise ValueError(f"must increase, got {brief(v)}")
    return tuple(out)


@request
class EvidenceRequest:
    """The arguments of an evidence kind (``validation.atlas.evidence``): the starts per point,
    the horizon (``tau_end``) or horizons, the worker processes and the store to keep rows in.
    ``tau_max`` (and ``tau_why``): the kind's own largest horizon, given by its registry entry;
    a horizon outside [``TAU_MIN``, ``tau_max``] is refused with the kind's reason."""

    members: _count(10**9, "starts per point") | None = None
    workers: Annotated[Int, Field(ge=1)] | None = None
    tau_end: Real | None = None
    horizons: Annotated[Any, PlainValidator(_horizons)] | None = None
    out: Path = None
    tau_max: Real = TAU_MAX
    tau_why: Text = "where the hand-over engine was measured to hold"

    @model_validator(mode="after")
    def _check(self):
        if self.workers is not None:
            from ..executors.processes import usable_cores

            cores = usable_cores()
            if self.workers > cores:
                raise SpecError("workers", f"must be at most {cores}, the cores this process may use, got {self.workers}")
        why = f"the classifier's windows and 100 braking times below, {self.tau_why} above"
        if self.tau_end is not None and not TAU_MIN <= self.tau_end <= self.tau_max:
            raise SpecError("tau_end", f"must lie in [{TAU_MIN:g}, {self.tau_max:g}] ({why}), got "
                                       f"{shown(self.tau_end, TAU_MIN, self.tau_max)}")
        for x in self.horizons or ():
            if not TAU_MIN <= x <= self.tau_max:
                raise SpecError("horizons", f"each must lie in [{TAU_MIN:g}, {self.tau_max:g}] ({why}), got "
                                            f"{shown(x, TAU_MIN, self.tau_max)}")
        return self


# --- decide ------------------------------------------------------------------------------------
# One trial (a start, both models as the truth, the decision time of each by bisection over the
# records), CPU time on one core of this 2-core machine, 2026 (load ~4-7): 0.40-0.46 s with tau0
# known, 1.14-1.36 s fitted, at 47-89 records (the default receiver over 0.01-30 x the cube's
# horizon), where every trial is decided; undecided trials cost a tenth of that.  The fits grow
# with the records a trial holds, so the estimate scales by records / DECIDE_RECORDS beyond them.
# With what must be known (analysis.nuisance; 2026-11-28, the same machine, load ~5): 2.8 s with
# tau0, gain and clock priors; in a residual gas 1.6 s (1e-10 mbar: the walk alone), 4.0 s (1e-14
# and 1e-12 mbar) and 11.0 s at 1e-13 mbar, where up to 64 collisions are located and fitted: the
# dearest, taken for every pressure.
DECIDE_S_PER_TRIAL = {"known": 0.5, "fitted": 1.4, "nuisances": 3.0, "gas": 12.0}
DECIDE_RECORDS = 71


# --- listen ------------------------------------------------------------------------------------
SOUND_SECONDS = (0.5, 600.0, "seconds of sound")
LISTEN_SAMPLES = 100_000         # instants of each model's run (the detector's memory per instant)


def _extension(ext: str, what: str, required: bool = False):
    """A path (str or os.PathLike) ending in ``ext``, kept as str (None allowed unless ``required``)."""

    def check(v):
        if v is None and required:
            raise wrong_type(f"must be a path ending in {ext}, got None")
        if v is None:
            return None
        if not isinstance(v, str | os.PathLike):
            raise wrong_type(f"must be a path (str or os.PathLike), got {type(v).__name__} {brief(v)}")
        v = os.fspath(v)
        if os.path.splitext(v)[1].lower() != ext:
            raise ValueError(f"{brief(v)}: {what}; give a path ending in {ext}")
        return v

    return Annotated[Any, PlainValidator(check)]


@request
class ListenRequest:
    """``spinviz listen``'s sound (``experiment.listen``): where it goes (``out``, a WAV, and its
    spectrogram ``png``, default beside it), how long, at which pitch, how sound time and pitch
    follow the run's, how much dynamic range, from how many instants."""

    out: _extension(".wav", "the sound is written as WAV", required=True)
    png: _extension(".png", "the spectrogram is a PNG") = None

    duration: Annotated[Real, between(*SOUND_SECONDS)] = 20.0
    f0: Annotated[Real, between(20.0, 5000.0, "Hz: audible, well under the Nyquist frequency")] = 440.0
    time_map: Literal["log", "linear"] = "log"
    pitch: Literal["auto", "linear"] = "auto"
    dynamic_range_db: Annotated[Real, between(1.0, 120.0, "dB of sound")] = 60.0
    samples: Annotated[Int, between(2, LISTEN_SAMPLES, "instants of each model's run")] = 800

    @property
    def png_path(self) -> str:
        """The spectrogram's path: ``png``, or the WAV's with .png."""
        return self.png if self.png is not None else os.path.splitext(self.out)[0] + ".png"
