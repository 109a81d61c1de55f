"""The counts and horizons of the commands that run studies -- ``check --sweep``, ``bench``,
``bench --process``, ``atlas --evidence KIND`` -- as request classes of the one schema.

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
from .base import Flag, Int, Path, Real, between, request, shown, wrong_type

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
SWEEP_S_PER_RUN = 0.2            # one secular-against-taylor comparison (README: 18 seeds x 40 runs in 142 s)
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
# the durations the README and the commands' help give for 3 repeats, with their warm-up and
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


# --- atlas --evidence KIND ------------------------------------------------------------------
TAU_END_RANGE = (1e5, 1e16)      # below: the classifier's two 2-decade windows and 100 braking times of |omega0|
#                                  = 0.04 do not fit; above: float64 time steps (the limit of integration in full)
HANDOVER_TAU_MAX = 1e20          # the hand-over engine's horizons (convergence, basins): where it was measured to hold
MAX_HORIZONS = 8
# Measured costs at tau = 1e10 (docs/atlas.md), growing as sqrt(tau / 1e10) -- the steps of a spiral:
ATLAS_S_PER_RUN = 0.096          # a run of a single-cell atlas, cluster and classification included (one core)
PHYSICAL_S_PER_RUN = 0.094       # an atlas run and its physical-unit simulate run (32 in 3 s)
CROSSCHECK_S_PER_RUN = 25.0      # a SciPy DOP853 run of (4.2)-(4.4) at rtol 1e-10
CONVERGENCE_S_PER_RUN = 0.0102   # a run of the study, per unit of sqrt(tau / 1e10) (8 min 46 s at its defaults)
TOLERANCE_S_PER_RUN = 0.009      # a run of the 12 x 12 grid at one rtol (82 s for 9216)
# The hand-over engine, one core, rtol 1e-8 (docs/atlas.md, "Horizons"; regimes.engine.cost's model
# reads these): a handed-over run costs HANDED_S_PER_RUN at any tau, a run kept in full
# a + b (tau/1e16)^(1/4) s; brute force in the handover kind 0.7 s per start and unit of
# sqrt(tau/1e10) over its 19 points (1 222 s for 16 starts at 1e12 and 1e14, the machine shared)
HANDED_S_PER_RUN = 0.002
ENGINE_S_PER_RUN = (0.002, 0.021)
HANDOVER_S_PER_START = 0.7
EVIDENCE_MEMBERS = {"validate": 32, "crosscheck": 3, "physical": 4, "convergence": 32, "tolerance": 8, "handover": 16,
                    "basins": 32, "flows": 1}
ACCEPTS = {"validate": {"workers"}, "crosscheck": set(), "physical": {"tau_end"}, "convergence": {"horizons", "out"},
           "tolerance": set(), "handover": {"horizons", "out"}, "basins": {"tau_end"},
           "flows": set()}         # what each kind takes on the command line beyond --members


def check_accepts(kind: str, given: dict) -> None:
    """An option ``--evidence KIND`` does not use is refused (``SpecError`` naming it), not ignored."""
    for key, value in given.items():
        if value is not None and key not in ACCEPTS.get(kind, set()):
            raise SpecError(key, f"not used by --evidence {kind} (it takes "
                                 f"{', '.join(sorted(ACCEPTS[kind] | {'members'}))})")


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
        lo, hi = TAU_END_RANGE[0], HANDOVER_TAU_MAX
        if not lo <= x <= hi:
            raise ValueError(f"each must lie in [{lo:g}, {hi:g}] (the classifier's windows and 100 braking times below, "
                             f"where the hand-over engine was measured to hold above), got {shown(x, lo, hi)}")
        out.append(x)
    if not 2 <= len(out) <= MAX_HORIZONS:
        raise ValueError(f"give 2 to {MAX_HORIZONS} horizons, got {len(out)}")
    if any(not b > a for a, b in zip(out, out[1:])):
        raise ValueError(f"must increase, got {brief(v)}")
    return tuple(out)


@request
class EvidenceRequest:
    """``spinviz atlas --evidence KIND``'s arguments (``validation.atlas.evidence.run``): the
    kind, the starts per point, and what the kind takes beyond them."""

    kind: Literal["validate", "crosscheck", "physical", "convergence", "tolerance", "handover", "basins", "flows"]
    members: _count(10**9, "starts per point") | None = None
    workers: Annotated[Int, Field(ge=1)] | None = None
    tau_end: Annotated[Real, between(*TAU_END_RANGE, "the classifier's windows and 100 braking times below, float64 "
                                                    "time steps of integration in full above")] | None = None
    horizons: Annotated[Any, PlainValidator(_horizons)] | None = None
    out: Path = None

    @model_validator(mode="after")
    def _check(self):
        if self.workers is not None:
            from ..executors.processes import usable_cores

            cores = usable_cores()
            if self.workers > cores:
                raise SpecError("workers", f"must be at most {cores}, the cores this process may use, got {self.workers}")
        if self.kind == "handover" and self.horizons and max(self.horizons) > TAU_END_RANGE[1]:
            raise SpecError("horizons", f"each must be at most {TAU_END_RANGE[1]:g} for handover (brute force integrates "
                                        f"in full to each), got {shown(max(self.horizons), TAU_END_RANGE[1])}")
        n = self.n_members
        key = "members" if self.members is not None else {"physical": "tau_end", "convergence": "horizons",
                                                          "handover": "horizons", "basins": "tau_end"}.get(self.kind,
                                                                                                           "members")
        check_work(key, self.seconds(), f"--evidence {self.kind} with {n} member(s) per point")
        return self

    @property
    def n_members(self) -> int:
        """The starts per point: as given, or the kind's default."""
        return self.members if self.members is not None else EVIDENCE_MEMBERS[self.kind]

    def seconds(self) -> float:
        """The estimated work, s (see the constants: measured at tau = 1e10, growing as sqrt(tau))."""
        n = self.n_members
        grows = math.sqrt((self.tau_end or 1e10) / 1e10)
        if self.kind == "validate":
            from ..executors.processes import usable_cores

            return 11 * n * ATLAS_S_PER_RUN * grows / (self.workers or usable_cores())
        if self.kind == "crosscheck":
            return 6 * n * CROSSCHECK_S_PER_RUN * grows
        if self.kind == "physical":
            return 8 * n * PHYSICAL_S_PER_RUN * grows
        if self.kind == "tolerance":
            return 144 * n * 2 * 4 * TOLERANCE_S_PER_RUN * grows
        a, b = ENGINE_S_PER_RUN
        full = lambda tau: a + b * (tau / 1e16) ** 0.25          # noqa: E731 -- an upper bound: every run in full
        if self.kind == "basins":
            return 12 * n * full(self.tau_end or 1e16)
        if self.kind == "flows":
            return 60.0                                           # eight starts to 1e10 at tol 1e-15 (measured 25-50 s)
        if self.kind == "handover":
            horizons = self.horizons or (1e12, 1e14)
            return n * HANDOVER_S_PER_START * sum(math.sqrt(h / 1e10) for h in horizons)
        horizons = self.horizons or (1e10, 1e12, 1e14, 1e16, 1e20)
        return 15 * n * (sum(full(h) for h in horizons) + 4 * full(horizons[0]))


# --- decide ------------------------------------------------------------------------------------
# One trial (a start, both models as the truth, the decision time of each by bisection over the
# records), CPU time on one core of this 2-core machine, 2026 (load ~4-7): 0.40-0.46 s with tau0
# known, 1.14-1.36 s fitted, at 47-89 records (the default receiver over 0.01-30 x the cube's
# horizon), where every trial is decided; undecided trials cost a tenth of that.  The fits grow
# with the records a trial holds, so the estimate scales by records / DECIDE_RECORDS beyond them.
DECIDE_S_PER_TRIAL = {"known": 0.5, "fitted": 1.4}
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
