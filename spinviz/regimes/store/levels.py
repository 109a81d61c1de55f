"""The refinement levels an atlas store holds, and which of them its spec implies.

Level 0 is the store itself; level k (k = 1 .. ``[refine] levels``) is a store of its own
inside it, ``STORE/levelK``, over the grid cut 2^k times finer (``level_spec``), holding only
the children of the level-(k - 1) cells that ``refine.flags`` marks (``wanted``).  So which
levels exist is not a matter of what is found on disk: it follows from the spec and from the
labels of the levels below.  Level k is *implied* when k <= ``[refine] levels`` and the
levels below flag at least one cell; every implied level must be present, whole and of this
spec -- its ``spec_sha256`` the identity of ``level_spec(spec, k)`` -- and nothing else named
``levelK`` may be there.  ``--verify`` (``verify.report``) and the resume (``api``) both judge
a store this way.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace

import numpy as np

from ...errors import SceneError
from ..engine import refine as RF
from . import dataset as DS
from . import integrity as IN

LEVEL_DIR = re.compile(r"level([1-9][0-9]*)")


def level_spec(spec, k: int):
    """The spec of refinement level ``k``: every axis cut 2^k times finer, the rest unchanged."""
    if k == 0:
        return spec
    (d0, d1, nd), (c0, c1, nc) = spec.axes["delta"], spec.axes["chi"]
    return replace(spec, title=f"{spec.title or os.path.basename(spec.path)}: refinement level {k}",
                   deltas=RF.centres(d0, d1, nd, k), chis=RF.centres(c0, c1, nc, k), refine_levels=0,
                   axes={"delta": (d0, d1, nd * 2**k), "chi": (c0, c1, nc * 2**k)})


def level_identity(spec, k: int) -> str:
    """The ``spec_sha256`` level ``k`` of an atlas of ``spec`` must carry."""
    return DS.identity(level_spec(spec, k))


def level_types(path: str, model_index: int):
    """(types (delta, chi, member) int, computed (delta, chi) bool) of one model of a level's
    store: an approaching run counts for the type it approaches (``refine.type_of``)."""
    import zarr

    g = zarr.open_group(path, mode="r", zarr_format=2)
    codes = np.asarray(g["label_inf" if "label_inf" in g else "regime"][model_index])   # the type as tau -> oo
    types = RF.type_of(codes, np.asarray(g["candidate"][model_index]))
    return types, (np.asarray(g["done"][model_index]) == 1).all(axis=-1)


def wanted(spec, paths: list, k: int) -> np.ndarray:
    """The cells (model, delta, chi) of level ``k`` to compute: the children of the
    level-(k - 1) cells ``refine.flags`` marks, from the types the levels below computed
    (``paths[j]``: level j's store, j < k; a cell counts as computed when all its members are)."""
    sub = level_spec(spec, k)
    out = np.zeros((len(spec.models), len(sub.deltas), len(sub.chis)), dtype=bool)
    for mi in range(len(spec.models)):
        maj, share, comp = [], None, []
        for path in paths[:k]:
            types, done = level_types(path, mi)
            m, share = RF.majority(types)
            maj.append(m)
            comp.append(done)
        eff = RF.effective(maj, comp)
        out[mi] = RF.children(RF.flags(maj[-1], share, comp[-1], eff, spec.refine_agree))
    return out


def found(out: str) -> list[int]:
    """The levels k >= 1 with an entry ``levelK`` in the store (whatever it holds), in order."""
    try:
        names = os.listdir(out)
    except OSError:
        return []
    return sorted(int(m.group(1)) for m in map(LEVEL_DIR.fullmatch, names) if m)


@dataclass
class State:
    """What a level's directory holds, judged against the identity it must carry.

    kind : "absent" (nothing there), "damaged" (not a whole store: no .zgroup, no checksums,
        metadata that do not match them, or not a directory), "foreign" (a whole store of
        another atlas: ``sha256`` is what it carries), or "ok" (this atlas's level; its chunks
        are checked apart).  why : one phrase for "damaged".
    """

    kind: str
    why: str = ""
    sha256: str = ""


def state(path: str, identity: str) -> State:
    """The ``State`` of the level store at ``path`` for an atlas whose level must carry ``identity``."""
    if not os.path.lexists(path):
        return State("absent")
    if not os.path.isdir(path) or os.path.islink(path):
        return State("damaged", "not a directory")
    if not os.path.exists(os.path.join(path, ".zgroup")):
        return State("damaged", "no .zgroup: not a whole Zarr store")
    skeleton = IN.verify_skeleton(path)
    if skeleton is None:
        return State("damaged", f"no checksums ({IN.DIR}/{IN.SKELETON} missing)")
    if skeleton:
        return State("damaged", f"its metadata do not match their checksums ({IN.summary(skeleton, 3)})")
    carried = recorded_identity(path)
    if carried != identity:
        return State("foreign", sha256=carried or "")
    return State("ok")


def recorded_identity(path: str) -> str | None:
    """The ``spec_sha256`` a store's attributes carry (read from ``.zattrs``; None if absent)."""
    try:
        value = IN.read_json(os.path.join(path, ".zattrs")).get("spec_sha256")
    except (OSError, ValueError, AttributeError):
        return None
    return value if isinstance(value, str) else None


def recorded_spec(path: str):
    """The ``AtlasSpec`` the store at ``path`` records (``inputs.atlas_spec.spec_from_record``),
    checked against its own ``spec_sha256``: ``SceneError`` naming ``.zattrs`` when the record
    is unreadable or does not match its hash."""
    from ...inputs.atlas_spec import spec_from_record

    where = os.path.join(path, ".zattrs")
    try:
        attrs = IN.read_json(where)
        if not isinstance(attrs, dict):
            raise ValueError
    except (OSError, ValueError):
        raise SceneError(where, "(file)", "unreadable: not the attributes of an atlas store") from None
    spec = replace(spec_from_record(attrs, where), path=path)
    if DS.identity(spec) != attrs.get("spec_sha256"):
        raise SceneError(where, "spec_sha256", "does not match the recorded spec (the attributes were changed)")
    return spec


def done_within(path: str, cells: np.ndarray | None) -> tuple[int, int]:
    """(runs done, runs wanted) of a level store: all its runs, or the members of ``cells``."""
    done = DS.done_mask(path)
    if cells is None:
        return int(done.sum()), int(done.size)
    return int((done & cells[..., None]).sum()), int(cells.sum()) * done.shape[-1]


def creation_leftovers(out: str) -> list[str]:
    """The temporary directories an interrupted creation of the store at ``out`` left beside it
    (``.NAME.XXXXXXXX.partial``, ``dataset.create``): paths."""
    parent = os.path.dirname(os.path.abspath(out)) or "."
    name = os.path.basename(os.path.normpath(out))
    try:
        entries = os.listdir(parent)
    except OSError:
        return []
    return sorted(os.path.join(parent, n) for n in entries
                  if n.startswith(f".{name}.") and IN.creation_leftover(n) and n.count(".") == name.count(".") + 3
                  and os.path.isdir(os.path.join(parent, n)))
