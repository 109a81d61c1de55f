"""``spinviz atlas verify STORE``: is the store the whole atlas its own spec implies?

A store is judged from its spec, not from what happens to be on disk.  The spec it records
(attributes ``spec``, ``grid_axes``; checked against its ``spec_sha256``) says which levels
exist: level 0, then each refinement level the labels below flag cells for (``levels``).
Every one of them must be

* present -- a missing level (``rm -r STORE/level1``, a lost ``.zgroup``) is named;
* whole -- every file matches its checksum record and every run the level wants is computed
  (an interrupted atlas is "incomplete", not "ok");
* of this spec -- its ``spec_sha256`` the identity of its level's spec (a level copied from an
  atlas of another seed is "foreign").

Anything else named ``levelK`` is named too.  ``report`` says ok exactly when all of that
holds; nothing is decoded but the ``done`` flags and the labels that decide the levels, and
only after their checksums matched.  It takes the store's shared lock: a store another
command is writing is not judged in the middle of a write (``lock``).
"""

from __future__ import annotations

import os

from ...errors import SceneError, UsageError, printable
from . import dataset as DS
from . import levels as LV
from .integrity import summary
from .lock import StoreLock


def report(path: str) -> dict:
    """The verdict on the store at ``path``: ``ok``, ``reports`` (per level: path, level, ok,
    lines, runs_verified, damaged_chunks, skeleton_ok), ``runs_verified``, ``damaged_chunks``,
    ``problems`` (one phrase each) and the closing ``verdict`` line.  ``UsageError`` when
    ``path`` is not an atlas store; ``StoreBusy`` when another command is writing it."""
    if not os.path.isdir(path) or not os.path.exists(os.path.join(path, ".zgroup")):
        left = LV.creation_leftovers(path)
        hint = (f"; {printable(left[0], 200)} is what an interrupted creation left (rm -r it, or run the atlas "
                f"command again)" if left else "")
        raise UsageError(f"--verify {printable(path, 200)}: not an atlas store (no such directory, or no .zgroup in "
                         f"it){hint}")
    with StoreLock(path, exclusive=False, what="--verify"):
        return _judge(path)


def _judge(path: str) -> dict:
    problems: list = []
    spec, first = _judge_top(path, problems)
    reports = [first]
    paths, judged, sound = [path], {0}, first["ok"]
    for k in range(1, (spec.refine_levels if spec is not None else 0) + 1):
        lpath = DS.level_path(path, k)
        if not sound:                                  # the labels that decide level k cannot be trusted
            if os.path.isdir(lpath):
                lines, lrep = level_lines(lpath)
                lines.append(f"not judged against the spec until level {k - 1} is whole")
                entry = _entry(lpath, k, lines, lrep, ok=False)
                _chunk_problems(entry, lrep, problems)
                reports.append(entry)
                judged.add(k)
            continue
        cells = LV.wanted(spec, paths, k)
        if not cells.any():
            break
        judged.add(k)
        entry = _judge_level(spec, lpath, k, cells, problems)
        reports.append(entry)
        sound = entry["ok"]
        paths.append(lpath)
    for k in LV.found(path):
        if k in judged:
            continue
        lpath = DS.level_path(path, k)
        if spec is None:                               # nothing says which levels belong: their files only
            lines, lrep = level_lines(lpath) if os.path.isdir(lpath) else (["not a directory"], None)
            lines.append("not judged against the spec: the store's own spec cannot be read")
            reports.append(_entry(lpath, k, lines, lrep, ok=False))
            continue
        why = (f"[refine] levels = {spec.refine_levels}" if k > spec.refine_levels else
               f"level {k - 1}'s labels flag no cell for it")
        reports.append(_entry(lpath, k, [f"NOT IMPLIED by the spec ({why}): rm -r {lpath} removes it"], None, ok=False))
        problems.append(("extra", f"level{k} is not part of this atlas (rm -r {lpath})"))
    return _verdict(path, reports, problems)


def _judge_top(path: str, problems: list):
    """(the recorded spec or None, level 0's entry): its files, its spec, its runs."""
    lines, rep = level_lines(path)
    spec = None
    if rep.skeleton_ok:
        try:
            spec = LV.recorded_spec(path)
        except SceneError as e:
            lines.insert(1, f"spec: DAMAGED ({e.key}: {e.reason})")
            problems.append(("metadata", "the recorded spec does not hold; compute the atlas again into a new store"))
        else:
            lines.insert(1, f"spec: ok (sha256 {LV.identity(spec)[:12]}, [refine] levels = {spec.refine_levels})")
    entry = _entry(path, 0, lines, rep, ok=rep.clean and spec is not None)
    _chunk_problems(entry, rep, problems)
    if spec is not None and rep.clean:
        _complete(entry, path, None, problems)
    return spec, entry


def _judge_level(spec, lpath: str, k: int, cells, problems: list) -> dict:
    """Level ``k``'s entry: present, whole and of this spec, or what it is instead."""
    want = LV.level_identity(spec, k)
    st = LV.state(lpath, want)
    if st.kind == "absent":
        problems.append(("missing", f"level{k} missing (the same atlas command computes it)"))
        return _entry(lpath, k, [f"MISSING: the labels of level {k - 1} call for {int(cells.sum())} of its cells "
                                 f"([refine] levels = {spec.refine_levels})"], None, ok=False)
    if st.kind == "damaged":
        problems.append(("damaged level", f"level{k} not a whole store (the same atlas command computes it again)"))
        return _entry(lpath, k, [f"DAMAGED: {st.why}"], None, ok=False)
    if st.kind == "foreign":
        problems.append(("foreign", f"level{k} is of another atlas (rm -r {lpath}, then the same atlas command)"))
        return _entry(lpath, k, [f"FOREIGN: holds a level of another atlas (sha256 {st.sha256[:12]}; this atlas's "
                                 f"level {k}: {want[:12]})"], None, ok=False)
    lines, lrep = level_lines(lpath)
    entry = _entry(lpath, k, lines, lrep)
    _chunk_problems(entry, lrep, problems)
    if lrep.clean:
        _complete(entry, lpath, cells, problems)
    return entry


def _entry(path: str, k: int, lines: list, rep, ok: bool | None = None) -> dict:
    return {"path": path, "level": k, "ok": rep.clean if ok is None else ok, "lines": lines,
            "runs_verified": rep.runs_done if rep is not None else 0,
            "damaged_chunks": len(rep.bad_keys) if rep is not None else 0,
            "skeleton_ok": rep.skeleton_ok if rep is not None else False}


def _chunk_problems(entry: dict, rep, problems: list) -> None:
    if not rep.skeleton_ok:
        problems.append(("metadata", "the metadata cannot be recomputed; compute the atlas again into a new store"))
    elif rep.bad_keys:
        problems.append(("damaged", len(rep.bad_keys)))


def _complete(entry: dict, path: str, cells, problems: list) -> None:
    """Every run the level wants is computed (``done``, read only after its checksums matched)."""
    done, want = LV.done_within(path, cells)
    if done < want:
        entry["ok"] = False
        entry["lines"].append(f"runs: INCOMPLETE ({want - done} of {want} not computed yet)")
        problems.append(("incomplete", want - done))
    else:
        entry["lines"].append(f"runs: all {want} computed")


ORDER = ("metadata", "foreign", "damaged", "damaged level", "missing", "incomplete", "extra")
WORD = {"metadata": "DAMAGED", "foreign": "FOREIGN LEVEL", "damaged": "DAMAGED", "damaged level": "DAMAGED LEVEL",
        "missing": "MISSING LEVEL", "incomplete": "INCOMPLETE", "extra": "NOT OK"}


def _verdict(path: str, reports: list, problems: list) -> dict:
    ok = not problems and all(r["ok"] for r in reports)
    runs = sum(r["runs_verified"] for r in reports)
    n_bad = sum(r["damaged_chunks"] for r in reports)
    if ok:
        levels = f" over {len(reports)} refinement levels" if len(reports) > 1 else ""
        verdict = f"{path}: ok: {runs} runs verified{levels}"
    else:
        kinds = sorted({k for k, _ in problems}, key=ORDER.index)
        parts = []
        for kind in kinds:
            if kind == "damaged":
                parts.append(f"{n_bad} chunk(s) to recompute; the same atlas command recomputes their runs")
            elif kind == "incomplete":
                n = sum(v for k, v in problems if k == "incomplete")
                parts.append(f"{n} run(s) not computed yet; the same atlas command computes them")
            else:
                parts += list(dict.fromkeys(v for k, v in problems if k == kind))
        verdict = f"{path}: {WORD[kinds[0]]}: {'; '.join(parts)}"
    return {"path": path, "ok": ok, "reports": reports, "runs_verified": runs, "damaged_chunks": n_bad,
            "problems": [v if isinstance(v, str) else f"{k}: {v}" for k, v in problems], "verdict": verdict}


def level_lines(path: str):
    """The lines ``--verify`` says about one store (one level)'s files, and the integrity report."""
    rep = DS.verify(path)
    lines = []
    if rep.skeleton is None:
        lines.append("metadata: NO CHECKSUMS (made by an earlier spinviz, or its .checksums was deleted)")
    elif rep.skeleton:
        lines.append(f"metadata: DAMAGED ({summary(rep.skeleton, 4)})")
    else:
        lines.append("metadata: ok")
    if rep.skeleton_ok:
        by_var = {v: [] for v in rep.variables}
        records = []                                  # chunks whose record is missing or unreadable
        for prob in rep.problems():
            v = prob.file.split("/", 1)[0]
            (by_var[v] if v in by_var else records).append(prob)
        for v in rep.variables:
            ok, bad = rep.per_variable[v][0], by_var[v]
            lines.append(f"{v}: ok ({ok} chunk{'s' if ok != 1 else ''})" if not bad else
                         f"{v}: DAMAGED ({len(bad)} chunk{'s' if len(bad) != 1 else ''}: {summary(bad, 4)})")
        if records:
            lines.append(f"checksums: {len(records)} chunk{'s' if len(records) != 1 else ''} with runs marked done "
                         f"and no usable record ({summary(records, 4)})")
    if rep.leftovers:
        lines.append(f"leftovers: {len(rep.leftovers)} temporary file(s) of an interrupted write (removed on resume: "
                     f"{summary([str(x) for x in rep.leftovers], 3)})")
    return lines, rep
