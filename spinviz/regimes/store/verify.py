"""``spinviz atlas --verify STORE``: what the store's checksums say, as lines for people and as
a record -- for the store and each refinement level kept inside it (``levelK``).  Nothing is
decoded: every file is checked against its record (``integrity``)."""

from __future__ import annotations

import os

from ...errors import UsageError, printable
from . import dataset as ST
from .integrity import summary


def report(path: str) -> dict:
    """The verdict on the store at ``path``: ``ok``, ``reports`` (per level: path, level, ok,
    lines, runs_verified, damaged_chunks, skeleton_ok), ``runs_verified``, ``damaged_chunks``
    and the closing ``verdict`` line.  ``UsageError`` when ``path`` is not an atlas store."""
    if not os.path.isdir(path) or not os.path.exists(os.path.join(path, ".zgroup")):
        raise UsageError(f"--verify {printable(path, 200)}: not an atlas store (no such directory, or no .zgroup in it)")
    reports = []
    for k, where in enumerate(ST.stored_levels(path)):
        lines, rep = level_lines(where)
        reports.append({"path": where, "level": k, "ok": rep.clean, "lines": lines, "runs_verified": rep.runs_done,
                        "damaged_chunks": len(rep.bad_keys), "skeleton_ok": rep.skeleton_ok})
    clean = all(r["ok"] for r in reports)
    n_bad = sum(r["damaged_chunks"] for r in reports)
    runs = sum(r["runs_verified"] for r in reports)
    levels = f" over {len(reports)} refinement levels" if len(reports) > 1 else ""
    tail = (f"{runs} runs verified{levels}" if clean else
            f"{n_bad} chunk(s) to recompute; the same atlas command recomputes their runs"
            if all(r["skeleton_ok"] for r in reports) else
            "the metadata cannot be recomputed; compute the atlas again into a new store")
    return {"path": path, "ok": clean, "reports": reports, "runs_verified": runs, "damaged_chunks": n_bad,
            "verdict": f"{path}: {'ok' if clean else 'DAMAGED'}: {tail}"}


def level_lines(path: str):
    """The lines ``--verify`` says about one store (one level), and the integrity report."""
    rep = ST.verify(path)
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
        lines.append(f"leftovers: {len(rep.leftovers)} temporary file(s) of an interrupted write (removed on resume)")
    return lines, rep
