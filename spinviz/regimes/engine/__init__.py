"""The atlas's engine: ``runs`` (batches of Euler-only runs through the one driver, each
classified where it ran: brute force), ``handover`` (full integration until the averaged flow
holds, then the averaged flow; ``limit``: what a run records of its limit), ``classify``
(label, confidence, evidence), ``refine`` (which cells of a level are cut in four for the
next) and ``cost`` (what an atlas costs, and the refusal of one that cannot finish).

The hand-over engine is imported here so that it is registered with ``runs`` (its
``ENGINES``) wherever a batch is run."""

from . import handover_engine  # noqa: F401  (registers the hand-over engine with runs)
