"""The arguments of the experiment's front doors (``spinviz.experiment``: ``compare``,
``observe``, ``listen``; ``decide``'s are ``inputs.decide``): how many output instants, where
the detector looks.  The receiver's keys are ``ReceiverSpec.with_options``'s."""

from __future__ import annotations

from typing import Annotated

from .base import Direction, Int, between, request

MAX_SAMPLES = 100_000          # per kind of output time: 2 x 1e5 instants x 7 floats x 2 models ~ 22 MB


@request
class CompareRequest:
    """samples : evenly spaced plus as many log-spaced output instants per model."""

    samples: Annotated[Int, between(2, MAX_SAMPLES, "each model is stored at 2 x samples instants")] = 800


@request
class ObserveRequest:
    """samples : evenly spaced plus as many log-spaced output instants per model;
    line_of_sight : world-frame direction to the detector (None: the scene's [observe], else
    across L(0))."""

    samples: Annotated[Int, between(2, MAX_SAMPLES, "each model is stored at 2 x samples instants")] = 800
    line_of_sight: Direction | None = None
