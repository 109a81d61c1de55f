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

import json
import os
import re
from dataclasses import dataclass, field, replace

import numpy as np

from ...atomic import loads_json
from ...errors import SceneError, UsageError
from ...interrupt import deferred
from ..engine import classify as C
from ..engine import refine as RF
from ..faults import ForeignLevel, StoreDamaged
from . import dataset as DS
from . import integrity as IN

LEVEL_DIR = re.compile(r"level([1-9][0-9]*)")
MAX_CHUNK_RUNS = 4096
MAX_CHUNK_MEMBERS = 256


def centres(lo: float, hi: float, cells: int, level: int) -> np.ndarray:
    """Cell centres of level ``level`` over [lo, hi] (``cells`` at level 0)."""
    n = cells * 2**level
    return lo + (np.arange(n) + 0.5) * (hi - lo) / n


def level_spec(spec, k: int):
    """The spec of refinement level ``k``: every axis cut 2^k times finer, the rest unchanged."""
    if k == 0:
        return spec
    (d0, d1, nd), (c0, c1, nc) = spec.axes["delta"], spec.axes["chi"]
    return replace(spec, title=f"{spec.title or os.path.basename(spec.path)}: refinement level {k}",
                   deltas=centres(d0, d1, nd, k), chis=centres(c0, c1, nc, k), refine_levels=0,
                   axes={"delta": (d0, d1, nd * 2**k), "chi": (c0, c1, nc * 2**k)})


def identity(spec) -> str:
    """sha256 of the spec's canonical JSON with the classifier's version: equal identities,
    equal numbers (the title and description do not enter)."""
    import hashlib

    return hashlib.sha256(f"classifier {C.VERSION}\n{spec.canonical_json()}".encode()).hexdigest()


def level_identity(spec, k: int) -> str:
    """The ``spec_sha256`` level ``k`` of an atlas of ``spec`` must carry."""
    return identity(level_spec(spec, k))


def check_identity(spec, path: str) -> None:
    """Refuse (``UsageError``, one line) a store that is not an atlas of this very spec."""
    import zarr

    try:
        attrs = dict(zarr.open_group(path, mode="r", zarr_format=2).attrs)
    except Exception as e:                             # not a Zarr group at all
        raise UsageError(f"{path}: exists and is not an atlas store ({type(e).__name__}); choose another store path") from None
    if "spec_sha256" not in attrs:
        raise UsageError(f"{path}: exists and is not an atlas store (no spec_sha256); choose another store path")
    want = identity(spec)
    if attrs["spec_sha256"] != want:
        what = "the same spec from another classifier version" if _same_spec(attrs, spec) else "another spec"
        raise UsageError(f"{path}: holds an atlas of {what} (sha256 {attrs['spec_sha256'][:12]}, this spec "
                         f"{want[:12]}); refusing to mix them: choose another store path or delete it")


def _same_spec(attrs: dict, spec) -> bool:
    try:
        return loads_json(attrs.get("spec", "")) == json.loads(spec.canonical_json())
    except (TypeError, ValueError):
        return False


def chunk_shape(spec) -> tuple:
    """A level's storage chunk: one model, one delta, a row of chi, the members (at most
    ``MAX_CHUNK_RUNS`` runs, ``MAX_CHUNK_MEMBERS`` members)."""
    cm = min(spec.members, MAX_CHUNK_MEMBERS)
    cc = max(1, min(len(spec.chis), MAX_CHUNK_RUNS // cm))
    return (1, 1, cc, cm)


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


@dataclass
class Level:
    """One level of the quadtree (``refine``), opened for a run (``open_level``).

    spec : level 0: the spec itself; level k: the grid cut 2^k times finer.  out : its store
    (level 0: ``out``; level k: ``out/levelK``, an atlas store of its own).  wanted : the cells
    (model, delta, chi) to compute -- None: all.  state : what its directory held (``State``;
    None for level 0, which ``check_store`` judged).  identity : the ``spec_sha256`` it carries.
    chunks : its storage chunk (``chunk_shape``, or the existing store's).  done : the runs on
    disk (model, delta, chi, member).  exists : whether its store exists.  repaired : runs of
    damaged or unverified chunks to recompute.  notices : what was said on opening it.
    """

    spec: object
    out: str
    wanted: np.ndarray | None
    state: State | None = None
    identity: str = ""
    chunks: tuple = ()
    done: np.ndarray | None = None
    exists: bool = False
    repaired: int = 0
    notices: list = field(default_factory=list)

    @property
    def runs(self) -> int:
        """Runs this level holds: all of its spec's, or its wanted cells' members."""
        return self.spec.runs if self.wanted is None else int(self.wanted.sum()) * self.spec.members

    @property
    def skip(self) -> np.ndarray:
        """The runs not to compute: those on disk, and those outside the wanted cells."""
        return self.done if self.wanted is None else (self.done | ~self.wanted[..., None])

    @property
    def reused(self) -> int:
        """Runs of this level already on disk."""
        return counted(self.done, self.wanted)[0]


def open_level(spec, out: str, below: list, k: int, *, retry_failed: bool = False, say=print) -> Level | None:
    """Level ``k`` of the atlas of ``spec`` in the store ``out``, ready to run, given the levels
    ``below`` it (computed); None when they flag no cell for it.

    Level 0 is the store itself: an existing one is judged whole first (``check_store``: of
    this very spec, every ``levelK`` in it a level of this spec).  Level k holds the children of
    the cells the levels below flag (``wanted``); a damaged level store is removed -- a level is
    recomputable from the spec and the levels below -- and said in one line, a foreign one
    refused.  An existing store is then resumed (``dataset.resume``: every chunk against its
    checksums); ``retry_failed`` also recomputes the runs recorded as failed."""
    sub = level_spec(spec, k)
    path = DS.level_path(out, k)
    sha = identity(sub)
    chunks = chunk_shape(sub)
    notices: list = []
    cells, st = None, None
    if k == 0:
        if os.path.exists(path):
            check_store(spec, path)
    else:
        st = state(path, sha)
        cells = wanted(spec, [x.out for x in below], k)
        if not cells.any():
            return None
        if st.kind == "foreign":                     # appeared since the check: another hand in the store
            raise ForeignLevel(f"{path}: holds a refinement level of another atlas; remove it (rm -r {path}) and "
                               f"run the same command again")
        if st.kind == "damaged":
            with deferred():
                IN.remove(path)
            notices.append(f"{path}: {st.why}; the level is computed again")
            say(notices[-1])
    exists = os.path.exists(path)
    if exists:
        chunks, done, repaired, said = DS.resume(path, say)
        notices += said
        if retry_failed:
            done &= DS.regime_codes(path) != -1
    else:
        done, repaired = np.zeros((len(sub.models), len(sub.deltas), len(sub.chis), sub.members), dtype=bool), 0
    return Level(sub, path, cells, st, sha, chunks, done, exists, repaired, notices)


def check_store(spec, out: str) -> None:
    """Before any work: an existing store must be an atlas of this very spec (its metadata
    whole: ``StoreDamaged`` otherwise), and every ``levelK`` inside it a level of this spec --
    one of another atlas, or beyond the spec's ``[refine] levels``, is refused with the one
    command that removes it (``ForeignLevel``), never mixed in and never deleted.  (A level
    that is damaged or missing is recomputed when its turn comes.)"""
    if not os.path.isdir(out):
        return                                       # store_path has said what it is
    skeleton = IN.verify_skeleton(out)
    if skeleton is None:
        if not os.path.exists(os.path.join(out, ".zgroup")):
            raise UsageError(f"{out}: exists and is not an atlas store (no .zgroup); choose another store path")
        check_identity(spec, out)                    # another Zarr store, or another spec: said as such
        raise StoreDamaged(f"{out}: carries no checksums (made by an earlier spinviz, or its {IN.DIR} was deleted), "
                           f"so its runs cannot be trusted; move it away and compute the atlas again")
    if skeleton:
        raise StoreDamaged(f"{out}: its metadata are damaged ({IN.summary(skeleton, 4)}); they cannot be "
                           f"recomputed from the runs: move it away and compute the atlas again")
    check_identity(spec, out)
    for k in found(out):
        path = DS.level_path(out, k)
        if k > spec.refine_levels:
            raise ForeignLevel(f"{path}: not a refinement level of this spec ([refine] levels = {spec.refine_levels}); "
                               f"refusing to mix it in: remove it (rm -r {path}) and run the same command again")
        want = level_identity(spec, k)
        st = state(path, want)
        if st.kind == "foreign":
            raise ForeignLevel(f"{path}: holds a refinement level of another atlas (sha256 {st.sha256[:12]}; this "
                               f"spec's level {k}: {want[:12]}); refusing to mix them: remove it (rm -r {path}) and "
                               f"the same command computes this spec's")


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
    is unreadable, was made by another classifier version, or does not match its hash."""
    from ...inputs.atlas_spec import spec_from_record

    where = os.path.join(path, ".zattrs")
    try:
        attrs = IN.read_json(where)
        if not isinstance(attrs, dict):
            raise ValueError
    except (OSError, ValueError):
        raise SceneError(where, "(file)", "unreadable: not the attributes of an atlas store") from None
    spec = replace(spec_from_record(attrs, where), path=path)
    version = attrs.get("classifier_version")
    if version != C.VERSION and identity(spec) != attrs.get("spec_sha256"):
        raise SceneError(where, "classifier_version", f"{version!r}: made by another classifier version (this "
                                                      f"spinviz's is {C.VERSION}), whose labels mean another thing")
    if identity(spec) != attrs.get("spec_sha256"):
        raise SceneError(where, "spec_sha256", "does not match the recorded spec (the attributes were changed)")
    return spec


def done_within(path: str, cells: np.ndarray | None) -> tuple[int, int]:
    """(runs done, runs wanted) of a level store: all its runs, or the members of ``cells``."""
    return counted(DS.done_mask(path), cells)


def counted(done: np.ndarray, cells: np.ndarray | None) -> tuple[int, int]:
    """(runs done, runs wanted) of a done mask (model, delta, chi, member): all its runs, or
    the members of ``cells`` (model, delta, chi)."""
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
