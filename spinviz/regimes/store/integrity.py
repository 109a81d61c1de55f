"""Checksums of the atlas store: what a resumed atlas reads is what was written, or it is recomputed.

Zarr checks nothing: a deleted chunk file reads as the fill value (a run "not computed", or a
``regime`` of 0 beside a ``done`` of 1), a truncated one fails deep inside the decompressor
naming no file, and a flipped bit may decode to a wrong number.  So the store carries its
own record, beside the Zarr data, in ``STORE/.checksums/`` (a dot-name: Zarr and xarray never
look at it):

* ``skeleton.json`` -- the sha256 of every file the store was created with (metadata,
  coordinates, ``omega0``, ``paper``), written inside the temporary directory before the
  store is renamed into place: a store without it was not made by this code;
* ``chunks/M.D.C.K.json`` -- one record per storage chunk (``M.D.C.K``: its Zarr chunk
  index, model, delta, chi block, member block): the sha256 of the chunk file of every
  per-run variable (``null``: no file, the chunk holds only the fill value, which Zarr does
  not store) and the number of runs done in it.

Order of a chunk's write (``store.Writer``): the record is deleted, the variables' files
are written, ``done``'s last, and then the new record (temporary file, then rename).  A
process killed in between leaves a chunk without a record: it counts as unverified and its
runs are recomputed, like a damaged chunk.  One record per chunk (not one manifest for the
store) keeps each write O(1) however large the atlas.

``verify(path)`` checks everything against the record without decoding a byte (``--verify``
prints it); ``atlas()`` runs it before resuming, recomputes the runs of every chunk found
damaged or unrecorded, after removing its files, and says which in one line.  Damaged
metadata cannot be recomputed from the runs: such a store is refused.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
from dataclasses import dataclass, field

from ...atomic import loads_json, open_regular, read_regular, write_text

DIR = ".checksums"
SKELETON = "skeleton.json"
CHUNKS = "chunks"
PARTIAL = ".partial"                  # what an interrupted atomic write leaves (Zarr's and spinviz's temporaries)
TRAILING = {"evidence": 1, "omega_final": 1, "series": 2}   # per-run variables' further (unchunked) dimensions


def sha256_file(path: str) -> str | None:
    """sha256 (hex) of a file's bytes, or None if there is no such file; ``NotRegularFile``
    at once for a directory, FIFO, device or socket in its place (never read, never waited on)."""
    h = hashlib.sha256()
    try:
        with open_regular(path) as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except FileNotFoundError:
        return None
    return h.hexdigest()


def _hash_or_why(path: str) -> tuple[str | None, str | None]:
    """(sha256 or None when absent, None) -- or (None, why) when the path is not a regular file
    or cannot be read."""
    try:
        return sha256_file(path), None
    except OSError as e:
        return None, e.strerror or str(e)


MAX_RECORD_BYTES = 64_000_000     # the skeleton's record of a large atlas is ~1 MB; a chunk's, ~1 kB


def read_json(path: str):
    """A record of the store, parsed (``open_regular``: a FIFO planted in its place is refused
    at once, ``NotRegularFile``); a record larger than ``MAX_RECORD_BYTES`` or nested deeper
    than ``atomic.MAX_JSON_DEPTH`` is refused as damaged (``ValueError``)."""
    raw = read_regular(path, MAX_RECORD_BYTES)
    if len(raw) > MAX_RECORD_BYTES:
        raise ValueError(f"{path}: larger than {MAX_RECORD_BYTES} bytes: not a record of this store")
    return loads_json(raw.decode("utf-8"))


def key_name(key) -> str:
    """``M.D.C.K`` of a chunk index (model, delta, chi block, member block)."""
    return ".".join(str(int(i)) for i in key)


def chunk_files(variables, key) -> dict:
    """variable -> the chunk file of storage chunk ``key`` (relative to the store)."""
    base = key_name(key)
    return {v: f"{v}/{base}" + ".0" * TRAILING.get(v, 0) for v in variables}


def record_path(path: str, key) -> str:
    """Where the checksum record of chunk ``key`` lives."""
    return os.path.join(path, DIR, CHUNKS, key_name(key) + ".json")


def forget(path: str, key) -> None:
    """Remove the record of chunk ``key`` (before its files are rewritten)."""
    try:
        os.unlink(record_path(path, key))
    except FileNotFoundError:
        pass


def record(path: str, variables, key, runs_done: int) -> None:
    """Record the sha256 of chunk ``key``'s files as they are on disk now (after the write)."""
    files = {rel: sha256_file(os.path.join(path, rel)) for rel in chunk_files(variables, key).values()}
    os.makedirs(os.path.join(path, DIR, CHUNKS), exist_ok=True)
    write_text(record_path(path, key), json.dumps({"chunk": [int(i) for i in key], "runs_done": int(runs_done),
                                                   "sha256": files}, sort_keys=True))


def record_skeleton(path: str) -> None:
    """Record the sha256 of every file of a freshly created (still empty) store."""
    files = {}
    for rel in _walk(path):
        files[rel] = sha256_file(os.path.join(path, rel))
    os.makedirs(os.path.join(path, DIR, CHUNKS), exist_ok=True)
    write_text(os.path.join(path, DIR, SKELETON), json.dumps({"sha256": files}, sort_keys=True, indent=0))


def rewrite_metadata(path: str, files, write) -> None:
    """Let spinviz itself rewrite metadata ``files`` (relative paths) of a finished store --
    an attribute added -- and record their new sha256: the record is checked first, so a
    file damaged before is never blessed (``ValueError``, nothing written); ``write()`` does
    the rewriting."""
    damaged = verify_skeleton(path)
    if damaged is None or damaged:
        raise ValueError(f"{path}: its metadata do not match their checksums; nothing recorded")
    rec_path = os.path.join(path, DIR, SKELETON)
    recorded = read_json(rec_path)["sha256"]
    write()
    for rel in files:
        recorded[rel] = sha256_file(os.path.join(path, rel))
    write_text(rec_path, json.dumps({"sha256": recorded}, sort_keys=True, indent=0))


LEVEL = re.compile(r"level[1-9][0-9]*")        # a refinement level's own store, inside the atlas's


def _walk(path: str):
    """Relative paths of the store's files, sorted: the record itself, the refinement levels
    (stores of their own) and the temporary directories of an interrupted level creation
    excluded."""
    out = []
    for root, dirs, files in os.walk(path):
        rel_root = os.path.relpath(root, path)
        if rel_root == DIR or rel_root.startswith(DIR + os.sep):
            dirs[:] = []
            continue
        if rel_root == ".":
            dirs[:] = [d for d in dirs if not LEVEL.fullmatch(d) and not creation_leftover(d)]   # stores of their own
        for f in files:
            out.append(os.path.normpath(os.path.join(rel_root, f)).replace(os.sep, "/"))
    return sorted(out)


def creation_leftover(name: str) -> bool:
    """Whether ``name`` is the temporary directory a store's creation works in
    (``.NAME.XXXXXXXX.partial``, ``dataset.create``): what a kill during the creation leaves."""
    return name.startswith(".") and name.endswith(PARTIAL) and name.count(".") >= 3


@dataclass
class Damage:
    """One file that does not match the record: ``what`` is "missing", "checksum mismatch",
    "not recorded" (a file where the record says there is none) or "no record"."""

    file: str
    what: str

    def __str__(self) -> str:
        return f"{self.file} ({self.what})"


@dataclass
class Report:
    """What ``verify`` found.

    skeleton : problems with the metadata and the fixed arrays (None: no record at all).
    damaged : chunk key -> problems (checksum mismatch, missing file, record unreadable).
    unrecorded : chunk keys that hold runs marked done but no record (a write cut short by a
        kill, or a record deleted): their runs cannot be trusted.
    ok : chunk keys verified.  runs_done : runs the verified chunks hold.
    leftovers : temporary files of interrupted writes (harmless; removed on resume).
    per_variable : variable -> (chunks verified, chunk files damaged).
    """

    path: str
    variables: tuple
    skeleton: list | None = None
    damaged: dict = field(default_factory=dict)
    unrecorded: list = field(default_factory=list)
    ok: list = field(default_factory=list)
    runs_done: int = 0
    leftovers: list = field(default_factory=list)
    per_variable: dict = field(default_factory=dict)

    @property
    def skeleton_ok(self) -> bool:
        """True when the skeleton has checksums and all of them match."""
        return self.skeleton is not None and not self.skeleton

    @property
    def bad_keys(self) -> list:
        """Chunks whose runs must be recomputed, in store order."""
        return sorted(set(self.damaged) | set(self.unrecorded))

    @property
    def clean(self) -> bool:
        """True when the skeleton and every chunk match their records (leftover temporary files aside)."""
        return self.skeleton_ok and not self.damaged and not self.unrecorded

    def problems(self) -> list:
        """Every chunk problem, one ``Damage`` per file."""
        out = []
        for key in self.bad_keys:
            out.extend(self.damaged.get(key) or [Damage(f"{DIR}/{CHUNKS}/{key_name(key)}.json", "no record")])
        return out


def verify(path: str, variables) -> Report:
    """Check every file of the store at ``path`` against its record (reads and hashes every
    chunk file, decodes nothing); ``variables`` are the per-run ones, ``done`` among them.
    The chunks are checked only when the skeleton is sound (their layout is read from it)."""
    variables = tuple(variables)
    rep = Report(path, variables)
    rep.per_variable = {v: [0, 0] for v in variables}
    rep.leftovers = [rel for rel in _walk(path) if PARTIAL in os.path.basename(rel)]
    with _suppress_os():
        rep.leftovers += [f"{DIR}/{CHUNKS}/{n}" for n in sorted(os.listdir(os.path.join(path, DIR, CHUNKS)))
                          if PARTIAL in n]
    with _suppress_os():
        rep.leftovers += sorted(n for n in os.listdir(path) if creation_leftover(n) and os.path.isdir(os.path.join(path, n)))
    rep.skeleton = verify_skeleton(path)
    if not rep.skeleton_ok:
        return rep
    shape, chunks = layout(path)
    present = _present_chunk_files(path, variables)
    for key in _keys(shape, chunks):
        files = chunk_files(variables, key)
        try:
            rec = read_json(record_path(path, key))
            recorded = rec["sha256"]
            runs = int(rec["runs_done"])
            if not isinstance(recorded, dict):
                raise ValueError("sha256 is not a table")
        except FileNotFoundError:
            if files["done"] in present:              # runs marked done, nothing vouches for them
                rep.unrecorded.append(key)
            continue
        except (OSError, ValueError, KeyError, TypeError):
            rep.damaged[key] = [Damage(f"{DIR}/{CHUNKS}/{key_name(key)}.json", "record unreadable")]
            continue
        problems = []
        for v, rel in files.items():
            want = recorded.get(rel, "absent from the record")
            have, why = _hash_or_why(os.path.join(path, rel)) if rel in present else (None, None)
            if have == want and why is None:
                rep.per_variable[v][0] += 1
                continue
            rep.per_variable[v][1] += 1
            what = (why if why is not None else "missing" if have is None else "not recorded" if want is None else
                    "checksum mismatch" if isinstance(want, str) and len(want) == 64 else "record unreadable")
            problems.append(Damage(rel, what))
        if problems:
            rep.damaged[key] = problems
        else:
            rep.ok.append(key)
            rep.runs_done += runs
    return rep


def layout(path: str) -> tuple:
    """(shape, chunks) of the per-run variables, from ``done``'s Zarr metadata."""
    meta = read_json(os.path.join(path, "done", ".zarray"))
    return tuple(meta["shape"]), tuple(meta["chunks"])


def verify_skeleton(path: str) -> list | None:
    """The skeleton's files that do not match their checksums ([] when all do; None without a record)."""
    try:
        recorded = read_json(os.path.join(path, DIR, SKELETON))["sha256"]
        if not isinstance(recorded, dict):
            raise ValueError
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, TypeError):
        return [Damage(f"{DIR}/{SKELETON}", "record unreadable")]
    out = []
    for rel, want in sorted(recorded.items()):
        have, why = _hash_or_why(os.path.join(path, rel))
        if why is not None:
            out.append(Damage(rel, why))
        elif have != want:
            out.append(Damage(rel, "missing" if have is None else "checksum mismatch"))
    return out


def _suppress_os():
    import contextlib

    return contextlib.suppress(OSError)


def _present_chunk_files(path: str, variables) -> set:
    out = set()
    for v in variables:
        try:
            names = os.listdir(os.path.join(path, v))
        except OSError:
            continue
        out.update(f"{v}/{n}" for n in names if not n.startswith("."))
    return out


def _keys(shape: tuple, chunks: tuple):
    import itertools

    counts = [-(-n // c) for n, c in zip(shape, chunks)]
    return itertools.product(*(range(n) for n in counts))


def chunk_region(key, shape: tuple, chunks: tuple) -> tuple:
    """The slices of storage chunk ``key`` (clipped at the array's edge)."""
    return tuple(slice(k * c, min((k + 1) * c, n)) for k, c, n in zip(key, chunks, shape))


def discard(path: str, variables, keys, leftovers=()) -> None:
    """Remove the files and records of chunks ``keys`` (their runs become "not computed")
    and the leftover temporary files."""
    for key in keys:
        forget(path, key)
        for rel in chunk_files(variables, key).values():
            remove(os.path.join(path, rel))
    for rel in leftovers:
        remove(os.path.join(path, rel))            # a temporary file, or an interrupted level creation's directory


def remove(target: str) -> None:
    """Remove a file, a FIFO or socket planted in its place, or a directory (not followed if a link)."""
    if os.path.isdir(target) and not os.path.islink(target):
        shutil.rmtree(target, ignore_errors=True)
        return
    try:
        os.unlink(target)
    except FileNotFoundError:
        pass


def summary(problems, limit: int = 6) -> str:
    """``a (what), b (what), ... and N more``: the files named in one line."""
    names = [str(p) for p in problems[:limit]]
    more = len(problems) - limit
    return ", ".join(names) + (f" and {more} more" if more > 0 else "")
