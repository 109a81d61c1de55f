"""The quadtree's levels of an atlas (``engine.refine``'s rule) as stores: level 0 is the spec
and its store; level k the grid cut 2^k times finer, kept in ``out/levelK``, computing only
the children of the cells the levels below flagged."""

from __future__ import annotations

import os
from dataclasses import dataclass, replace

import numpy as np

from ...inputs.atlas_spec import AtlasSpec
from ..engine import refine as RF
from . import dataset as ST


@dataclass
class Level:
    """One level of the quadtree (``refine``): its spec (level 0: the spec itself; level k: the
    grid cut 2^k times finer), its store (level 0: ``out``; level k: ``out/levelK``, an atlas
    store of its own), and the cells to compute (model, delta, chi) -- None: all."""

    spec: AtlasSpec
    out: str
    wanted: np.ndarray | None

    @property
    def runs(self) -> int:
        """Runs this level holds: all of its spec's, or its wanted cells' members."""
        return self.spec.runs if self.wanted is None else int(self.wanted.sum()) * self.spec.members


def level_spec(spec: AtlasSpec, k: int) -> AtlasSpec:
    """The spec of refinement level ``k``: every axis cut 2^k times finer, the rest unchanged."""
    (d0, d1, nd), (c0, c1, nc) = spec.axes["delta"], spec.axes["chi"]
    return replace(spec, title=f"{spec.title or os.path.basename(spec.path)}: refinement level {k}",
                   deltas=RF.centres(d0, d1, nd, k), chis=RF.centres(c0, c1, nc, k), refine_levels=0,
                   axes={"delta": (d0, d1, nd * 2**k), "chi": (c0, c1, nc * 2**k)})


def refined_level(spec: AtlasSpec, out: str, levels: list, k: int) -> Level:
    """Level ``k``: the children of the level-(k - 1) cells that ``refine.flags`` marks, from
    the types the levels below computed (a cell counts as computed when all its members are)."""
    sub = level_spec(spec, k)
    wanted = np.zeros((len(spec.models), len(sub.deltas), len(sub.chis)), dtype=bool)
    for mi in range(len(spec.models)):
        maj, share, comp = [], None, []
        for lv in levels:
            types, done = level_types(lv.out, mi)
            m, share = RF.majority(types)
            maj.append(m)
            comp.append(done)
        eff = RF.effective(maj, comp)
        wanted[mi] = RF.children(RF.flags(maj[-1], share, comp[-1], eff, spec.refine_agree))
    return Level(sub, ST.level_path(out, k), wanted)


def level_types(path: str, model_index: int):
    """(types (delta, chi, member) int, computed (delta, chi) bool) of one model of a level's
    store: an approaching run counts for the type it approaches (``refine.type_of``)."""
    import zarr

    g = zarr.open_group(path, mode="r", zarr_format=2)
    codes = np.asarray(g["label_inf" if "label_inf" in g else "regime"][model_index])   # the type as tau -> oo
    types = RF.type_of(codes, np.asarray(g["candidate"][model_index]))
    return types, (np.asarray(g["done"][model_index]) == 1).all(axis=-1)
