"""Regime atlas: which asymptotic type of section 4 a top ends in, over the (delta, chi) plane.

Ensembles of Euler-only runs (compiled kernel) classified one by one, computed on Dask and
written to a resumable Zarr store (issue 12).  Modules, in the order data flows:

* ``formulas`` -- the paper's asymptotic solutions and domains, spinviz's derived lines,
  the DAST families of figure 5;
* ``spec`` -- the TOML spec, validated like a scene;
* ``runs`` -- one run (decade by decade) and a batch of runs, each classified;
* ``classify`` -- the classifier: label, confidence, evidence;
* ``store`` -- the xarray / Zarr store: creation, identity, chunk writes, reading;
* ``integrity`` -- the store's checksums: a record per chunk, verified before a resume;
* ``cluster`` -- LocalCluster or an existing scheduler, worker warm-up, progress, and
  what a lost task or a lost cluster means (never a written result);
* ``faults`` -- how the atlas fails, in one line each (``AtlasIncomplete``, ``StoreDamaged``,
  ``OptionError``);
* ``api`` -- ``atlas(spec, out, ...)``; ``plot`` -- the diagram and the hodographs;
* ``command`` -- the ``atlas`` subcommand; ``bench`` -- its benchmark; ``crosscheck`` --
  the paper discrepancies re-checked with an independent integrator (scipy).

Importing this package is light (numba, dask and matplotlib load on first use).
"""

from __future__ import annotations

import importlib

_API = {
    "atlas": ("api", "atlas"),
    "AtlasResult": ("api", "AtlasResult"),
    "load_spec": ("spec", "load_spec"),
    "parse_spec": ("spec", "parse_spec"),
    "AtlasSpec": ("spec", "AtlasSpec"),
    "open_atlas": ("store", "open_atlas"),
    "verify": ("store", "verify"),
    "AtlasIncomplete": ("faults", "AtlasIncomplete"),
    "StoreDamaged": ("faults", "StoreDamaged"),
}

__all__ = sorted(_API)


def __getattr__(name: str):
    if name in _API:
        mod, attr = _API[name]
        value = getattr(importlib.import_module(f".{mod}", __name__), attr)
        return value
    raise AttributeError(f"module 'spinviz.regimes' has no attribute {name!r}")
