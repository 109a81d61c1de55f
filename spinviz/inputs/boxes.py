"""The boxes atlas's arguments (``regimes.asymmetric.atlas.run``, ``spinviz boxes``), checked once
for the command line and Python alike: the grid of edge ratios, the starts per box, the models."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import PlainValidator, model_validator

from ..errors import SpecError, brief
from ..physics import models as M
from .base import Int, Path, Real, between, request, wrong_type
from .options import check_work

BOX_S_PER_CELL = 0.17            # measured 2026-11-27 on a 2-core machine, load ~2: one box and model at 600 starts


def _braking() -> tuple[str, ...]:
    """The models whose radiation torque the averaged flow carries: every registered one that brakes."""
    return tuple(n for n in M.names() if M.get(n).brakes)


def _models(v):
    if isinstance(v, str):
        v = tuple(x.strip() for x in v.split(","))
    names = _braking()
    if not isinstance(v, list | tuple) or not v or any(m not in names for m in v) or len(set(v)) != len(v):
        raise wrong_type(f"must be some of {', '.join(names)} (comma-separated), got {brief(v)}")
    return tuple(v)


@request
class BoxesRequest:
    """grid : boxes per edge ratio (the plane is grid x grid); lo, hi : the ratios b/a and c/a
    span [lo, hi], log-spaced; starts : spin directions per box; models : "reduced",
    "truncated" or both; out : the netCDF file; plot : the PNG (optional)."""

    grid: Annotated[Int, between(3, 401, "boxes per ratio")] = 25
    lo: Annotated[Real, between(0.05, 1.0, "the smallest edge ratio")] = 0.5
    hi: Annotated[Real, between(1.0, 20.0, "the largest edge ratio")] = 2.0
    starts: Annotated[Int, between(10, 100_000, "spin directions per box")] = 600
    models: Annotated[Any, PlainValidator(_models)] = ("reduced", "truncated")
    out: Path = "boxes.nc"
    plot: Path | None = None

    @model_validator(mode="after")
    def _check(self):
        if not self.lo < self.hi:
            raise SpecError("lo", f"{self.lo:g} must be below hi = {self.hi:g}")
        cells = self.grid * self.grid * len(self.models)
        check_work("grid", cells * BOX_S_PER_CELL * self.starts / 600.0,
                   f"{cells} boxes x models at {self.starts} starts (~{BOX_S_PER_CELL:g} s each at 600)")
        return self
