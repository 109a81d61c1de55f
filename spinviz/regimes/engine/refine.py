"""Adaptive refinement of the atlas where the types change: a quadtree on the
(delta, chi) grid.

Level 0 is the spec's grid of ``n_delta x n_chi`` equal cells over [delta_min, delta_max] x
[chi_min, chi_max].  Level k is the same rectangle cut into ``2^k n_delta x 2^k n_chi`` cells;
a cell of level k + 1 is computed only where its parent at level k is *flagged*:

* its members disagree -- the most common type (an "approaching X" run counting for X)
  holds fewer than ``agree`` of them -- or
* a neighbour (edge-adjacent, at the same level, its type read from the finest level that
  computed it) has another most common type.

So after ``levels`` passes every boundary between two types runs through cells of the finest
size, (delta_max - delta_min) / (2^levels n_delta) by (chi_max - chi_min) / (2^levels n_chi):
the stated width of the boundary.  Everything here is plain NumPy on label codes; the atlas
(``api``) runs the cells and the store keeps each level as its own grid.
"""

from __future__ import annotations

import numpy as np

from . import classify as C

AGREE = 0.9                # a cell's members "agree" when its most common type holds at least this share
NONE = -128                # "no type" in the majority field (a cell not computed at any level)


def type_of(codes: np.ndarray, candidates: np.ndarray | None = None) -> np.ndarray:
    """The type a run counts for in the diagram: its label, or for an "approaching" run the
    class it approaches (``candidates``: the store's candidate codes)."""
    codes = np.asarray(codes)
    if candidates is None:
        return codes
    return np.where(codes == C.CODE["approaching"], np.asarray(candidates), codes)


def majority(types: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per cell the most common type and its share; ``types`` shape (..., members) int."""
    t = np.asarray(types)
    flat = t.reshape(-1, t.shape[-1])
    code = np.empty(flat.shape[0], dtype=np.int16)
    share = np.empty(flat.shape[0])
    for i, row in enumerate(flat):
        vals, counts = np.unique(row, return_counts=True)
        k = int(np.argmax(counts))
        code[i], share[i] = vals[k], counts[k] / len(row)
    return code.reshape(t.shape[:-1]), share.reshape(t.shape[:-1])


def upsample(field: np.ndarray) -> np.ndarray:
    """A level-k field on the level-(k + 1) grid: each cell repeated over its four children."""
    return np.repeat(np.repeat(field, 2, axis=0), 2, axis=1)


def effective(majorities: list[np.ndarray], computed: list[np.ndarray]) -> np.ndarray:
    """The most common type of every cell of the finest level, each read from the finest
    level that computed it (``majorities[k]``, ``computed[k]``: level k's fields, shapes
    (2^k n_delta, 2^k n_chi))."""
    out = np.where(computed[0], majorities[0], NONE).astype(np.int16)
    for maj, comp in zip(majorities[1:], computed[1:]):
        out = np.where(comp, maj, upsample(out))
    return out


def flags(maj: np.ndarray, share: np.ndarray, computed: np.ndarray, neighbours: np.ndarray,
          agree: float = AGREE) -> np.ndarray:
    """Cells of one level to refine (shape (n_delta_k, n_chi_k), bool): computed cells whose
    members disagree or whose edge neighbours (``neighbours``: the effective type field at this
    level) have another type."""
    f = computed & (share < agree)
    eff = np.where(computed, maj, neighbours)
    for axis in (0, 1):
        for step in (1, -1):
            other = np.roll(eff, step, axis=axis)
            valid = np.ones_like(f)
            idx = [slice(None), slice(None)]
            idx[axis] = 0 if step == 1 else -1                 # no wrap-around at the grid's edges
            valid[tuple(idx)] = False
            f |= computed & valid & (other != eff) & (other != NONE)
    return f


def children(flagged: np.ndarray) -> np.ndarray:
    """The level-(k + 1) cells to compute: the four children of every flagged level-k cell
    (bool, shape doubled)."""
    return upsample(flagged.astype(bool))


def width(lo: float, hi: float, cells: int, levels: int) -> float:
    """The finest cell size after ``levels`` refinements: the width a boundary is resolved to."""
    return (hi - lo) / (cells * 2**levels)
