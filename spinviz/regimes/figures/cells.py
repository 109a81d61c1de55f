"""An atlas's cells as plain data, for the PNG diagram and the web page alike: which type each
run counts for, the shares of the types in a cell, coexistence, and the cells of every
refinement level composed coarse to fine.  No drawing library."""

from __future__ import annotations

import json

import numpy as np

from ..engine import classify as C
from .style import COEXIST, ORDER, WORDS


def cell_types(ds, model: str):
    """(types, approaching): per (delta, chi, member) the type a run counts for in the diagram
    -- its type as tau -> oo (``limit_label``) where the store has it, else its label at
    tau_end; an "approaching X" run counts for X -- as label strings, and whether it is still
    approaching."""
    lab = ds["limit_label" if "limit_label" in ds else "label"].sel(model=model).values
    appr = lab == "approaching"
    if appr.any():
        names = {v: k for k, v in C.CODE.items()}
        cand = np.vectorize(lambda c: names.get(int(c), "other"))(ds["candidate"].sel(model=model).values)
        lab = np.where(appr, cand, lab)
    lab = np.where(np.isin(lab, ["1|2", "4|5"]), "other", lab)
    return lab, appr


def shares(ds, model: str) -> dict:
    """type -> array (delta, chi) of the share of the members of that type (an approaching run
    counted for the type it approaches; how many are still approaching: ``cell_types``).
    The shares of a cell add up to 1."""
    lab, _ = cell_types(ds, model)
    n = lab.shape[-1]
    out = {}
    for name in ORDER:
        s = (lab == name).sum(axis=-1) / n
        if np.any(s > 0):
            out[name] = s
    return out


def coexisting(ds, model: str) -> np.ndarray:
    """(delta, chi) bool: cells where two settled types each hold >= ``COEXIST`` of the members."""
    lab, appr = cell_types(ds, model)
    settled = np.where(appr | np.isin(lab, ["other", "failed", "missing"]), "", lab)
    n = lab.shape[-1]
    count = np.zeros(lab.shape[:-1], dtype=int)
    for name in ORDER:
        if name in WORDS:
            count += ((settled == name).sum(axis=-1) / n >= COEXIST)
    return count >= 2


def _edges(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Cell edges around the centres ``v`` (midpoints; the outer ones reflected, clipped to [lo, hi])."""
    if len(v) == 1:
        w = 0.1 * (hi - lo)
        return np.array([max(lo, v[0] - w / 2), min(hi, v[0] + w / 2)])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[max(lo, 2 * v[0] - mid[0])], mid, [min(hi, 2 * v[-1] - mid[-1])]])


def compose(ds, model: str, level: int = 0) -> list[dict]:
    """The diagram's cells of one model, as plain data for the PNG and the HTML page: each a
    dict with ``i``, ``j``, ``level``, ``id`` ("model:level:i:j"), the rectangle ``x0, x1``
    (delta) and ``y0, y1`` (chi, deg), the ``bars`` -- (type, width fraction, hatched) left to
    right in ``ORDER`` -- ``coexist`` and ``counts`` (type or "->type" -> members).  On a
    refinement level (``level`` > 0) only the cells it computed."""
    deltas, chis = ds["delta"].values, np.degrees(ds["chi"].values)
    de, ce = _edges(deltas, -1.0, 1.0), _edges(chis, 0.0, 90.0)
    lab, appr = cell_types(ds, model)
    co = coexisting(ds, model)
    n = lab.shape[-1]
    cells = []
    for i in range(len(deltas)):
        for j in range(len(chis)):
            if level and (lab[i, j] == "missing").all():
                continue
            bars, counts = [], {}
            for name in ORDER:
                m = lab[i, j] == name
                k = int(m.sum())
                if name == "approaching" or not k:
                    continue
                ka = int((m & appr[i, j]).sum())
                if k - ka:
                    bars.append((name, (k - ka) / n, False))
                    counts[name] = k - ka
                if ka:
                    bars.append((name, ka / n, True))
                    counts["->" + name] = ka
            cells.append({"i": i, "j": j, "level": level, "id": f"{model}:{level}:{i}:{j}", "delta": float(deltas[i]),
                          "chi_deg": float(chis[j]), "x0": float(de[i]), "x1": float(de[i + 1]), "y0": float(ce[j]),
                          "y1": float(ce[j + 1]), "bars": bars, "coexist": bool(co[i, j]), "counts": counts})
    return cells


def compose_levels(levels: list, model: str) -> list[dict]:
    """``compose`` of every refinement level, coarse first, without the cells a finer level
    computed again (its four children cover each of them whole)."""
    per = [compose(ds, model, level=k) for k, ds in enumerate(levels)]
    out = []
    for k, cells in enumerate(per):
        finer = {(c["i"], c["j"]) for c in per[k + 1]} if k + 1 < len(per) else set()
        out += [c for c in cells if (2 * c["i"], 2 * c["j"]) not in finer]
    return out


def limit_diagram(ds) -> bool:
    """Whether the store holds the types as tau -> oo (the hand-over engine's ``label_inf``)."""
    return "limit_label" in ds and json.loads(ds.attrs["spec"]).get("run", {}).get("engine") == "handover"


def spec_of(ds) -> dict:
    """The store's canonical spec (``ds.attrs["spec"]``) as a dict."""
    return json.loads(ds.attrs["spec"])
