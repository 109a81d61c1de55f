"""The arguments of a ``Trajectory``'s methods: ``sample(times)`` and ``radiation(line_of_sight)``.

Kept apart from ``inputs.simulation`` (which knows the integrators' limits): a trajectory is
read by the renderer, which must load no integrator.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import PlainValidator, model_validator

from ..errors import SpecError, brief
from .base import Direction, Real, request, shown, shown_bound, wrong_type

MAX_TIMES = 1_000_000           # instants one call may ask for (memory: 11 numbers an instant)


# --- the arguments of a Trajectory's methods ----------------------------------------------------
def _sample_times(v):
    """Instants to sample at: a number or a 1-D list or array of finite numbers (any order)."""
    if isinstance(v, str | bytes | bool) or v is None:
        raise wrong_type(f"must be a time or a list of times, got {brief(v)}")
    if hasattr(v, "__len__") and len(v) > MAX_TIMES:
        raise ValueError(f"must hold at most {MAX_TIMES} instants (memory), got {len(v)}")
    try:
        a = np.atleast_1d(np.array(v, dtype=float))
    except (TypeError, ValueError):
        raise wrong_type(f"must be a time or a list of times, got {brief(v)}") from None
    if a.ndim != 1 or a.size < 1:
        raise ValueError(f"must be a time or a 1-D list of at least one, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"must be finite, got {brief(v)}")
    return a


@request(eq=False)
class SampleRequest:
    """``Trajectory.sample(times)``: finite instants within the run, [start, end] (the stored
    first and last instants; a relative 1e-12 of the span beyond an end is the end itself)."""

    times: Annotated[np.ndarray, PlainValidator(_sample_times)]
    start: Real
    end: Real

    @model_validator(mode="after")
    def _inside(self):
        slack = 1e-12 * abs(self.end - self.start)
        outside = self.times[(self.times < self.start - slack) | (self.times > self.end + slack)]
        if outside.size:
            span = f"[{shown_bound(self.start)}, {shown_bound(self.end)}]"
            raise SpecError("times", f"must lie in {span} (the run's stored span: sampling interpolates, it never "
                                     f"integrates), got {shown(outside[0], self.start, self.end)}")
        return self


@request
class RadiationRequest:
    """``Trajectory.radiation(line_of_sight)``: a world-frame direction (``base.Direction``) or None."""

    line_of_sight: Direction | None = None
