"""The arguments of ``spinviz decide`` (and ``spinviz.analysis.decide.run``): the Monte Carlo's
size and seed, the start distribution's spin range, whether the body's tau0 is known, and the
priors of what must be known (``analysis.nuisance``): tau0's relative width, the antenna's gain
slope, the reference clock's stability, the pressure's relative width; and whether to answer
the requirements (``analysis.requirements``) instead of the decision time."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from ..errors import SpecError
from .atlas import check_cluster
from .base import Flag, Int, Real, Text, between, request, shown, vector

MAX_TRIALS = 100_000


@request
class DecideArguments:
    """trials : Monte Carlo trials (each: a start, both models as the truth); seed : of the
    trials' random streams; spin_range : (lo, hi), |Omega0| log-uniform over lo..hi times the
    scene's |Omega0|; tau0 : "known" (the scene's body) or "fitted" (a free parameter of both
    models, as when the crystal's size and dipole are uncertain); workers : processes on this
    machine (at most its cores), or of the embedded Dask cluster; scheduler : an existing Dask
    cluster's address instead; tau0_prior, gain_slope, clock_stability, pressure_prior : the
    nuisances' priors (``analysis.nuisance``); requirements : the largest pressure, field and
    nuisance widths at which 95 % of the trials decide within the horizon
    (``analysis.requirements``)."""

    trials: Annotated[Int, between(8, MAX_TRIALS, "enough for a 95 % quantile, and a bound on run time")] = 200
    seed: Annotated[Int, between(0, 2**63 - 1)] = 1
    spin_range: vector(2) = (0.5, 2.0)
    tau0: Literal["known", "fitted"] = "known"
    workers: Annotated[Int, Field(ge=1)] | None = None
    scheduler: Text | None = None
    tau0_prior: Annotated[Real, between(0.0, 10.0, "the relative 1-sigma width of tau0's prior; 0: known")] = 0.0
    gain_slope: Annotated[Real, between(0.0, 20.0, "dB per octave, 1 sigma of the antenna's uncalibrated slope")] = 0.0
    clock_stability: Annotated[Real, between(0.0, 1e-3, "the reference clock's fractional frequency stability")] = 0.0
    pressure_prior: Annotated[Real, between(0.0, 10.0, "the relative 1-sigma width of the pressure's prior")] = 1.0
    requirements: Flag = False

    @model_validator(mode="after")
    def _range(self):
        lo, hi = self.spin_range
        if not (1e-3 <= lo <= hi <= 1e3):
            raise SpecError("spin_range", f"must be LO,HI with 1e-3 <= LO <= HI <= 1e3 (factors of the scene's "
                                          f"|Omega0|), got {shown(lo, 1e-3, hi)},{shown(hi, lo, 1e3)}")
        if self.tau0 == "fitted" and self.tau0_prior > 0.0:
            raise SpecError("tau0_prior", "give tau0 fitted (no prior) or a prior's width, not both")
        check_cluster(self.workers, self.scheduler)
        return self
