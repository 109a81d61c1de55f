"""Regime atlas: which asymptotic type of section 4 a top ends in, over the (delta, chi) plane.

Ensembles of Euler-only runs (heyoka's batch mode) classified one by one, computed on Dask and
written to a resumable Zarr store.  The spec is an input like any other (``inputs.atlas``:
its tables; ``inputs.atlas_spec``: the ``AtlasSpec``, built once); the evidence the atlas
rests on is with the project's other checks (``validation.atlas``).  Rooms, in the order
data flows:

* ``engine`` -- ``runs`` (a batch of runs through the one driver, each classified where it
  ran), ``classify`` (label, confidence, evidence), ``refine`` (which cells to cut in four);
* ``cluster`` -- LocalCluster or an existing scheduler, worker warm-up, progress, and what a
  lost task or a lost cluster means (never a written result);
* ``store`` -- ``dataset`` (the xarray / Zarr store), ``integrity`` (its checksums),
  ``verify`` (``--verify``'s report);
* ``figures`` -- the diagram and the hodographs (PNG) and the interactive page (HTML);
* ``api`` -- ``atlas(spec, out, ...)``: levels, resume, execution; ``bench`` -- its
  benchmark; ``faults`` -- how the atlas fails, one line each.

Public here: ``atlas``, ``open_atlas``, ``verify``, the failures, and the pictures of a store's
levels (``diagram``, ``hodographs``, ``shares``; ``TYPE_CODES``: each type's name -> the code
the store keeps).  Importing this package is light (numba, dask and matplotlib load on first use).
"""

from __future__ import annotations

import importlib

_API = {
    "atlas": ("api", "atlas"),
    "AtlasResult": ("api", "AtlasResult"),
    "open_atlas": ("store.dataset", "open_atlas"),
    "verify": ("store.dataset", "verify"),
    "AtlasIncomplete": ("faults", "AtlasIncomplete"),
    "StoreDamaged": ("faults", "StoreDamaged"),
    # the pictures of a store's levels, as ``atlas(..., plot=...)`` draws them, for a notebook
    "diagram": ("figures.diagram", "diagram"),
    "hodographs": ("figures.hodographs", "hodographs"),
    "shares": ("figures.cells", "shares"),
    "TYPE_CODES": ("engine.classify", "CODE"),
}

__all__ = sorted(_API)


def __getattr__(name: str):
    if name in _API:
        mod, attr = _API[name]
        value = getattr(importlib.import_module(f".{mod}", __name__), attr)
        return value
    raise AttributeError(f"module 'spinviz.regimes' has no attribute {name!r}")
