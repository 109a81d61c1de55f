"""The atlas of one crystal's boxes: where a box a x b x c's spin ends as tau -> oo.

For each box of edge ratios (b/a, c/a) -- edges along the body axes e1, e2, e3, moments
(b^2 + c^2, a^2 + c^2, a^2 + b^2), the dipole the crystal's own (DAST: 35 deg from a in the a-c
plane, the same for every box of the crystal) -- the shape flow (``shape``) gives the
attractors, and spin directions spread evenly over the sphere give how often a start ends in
each: about which crystal edge the spin settles, and at which angle d then stands from L (for
DAST: 35 or 145 deg about a, 90 about b, 55 or 125 about c).  The two families of the paper's
figure 5 are the lines a = b (family 1: a symmetric top about c, chi = 55 deg) and b = c
(family 2: about a, chi = 35 deg); on them the atlas reproduces the symmetric top's
averaged flow (``physics.averaged``: ``symmetric_check``).

``atlas(...)`` returns an ``xarray.Dataset`` (dims model, c_over_a, b_over_a, axis);
``write`` stores it atomically as netCDF; ``figure`` draws it.  Each cell costs ~0.1-0.3 s of
one core (the flow sampled at ~100 shapes, each averaged over its polhode), so the plane is
computed here in-process; cells that are a sphere (the cube) have no polhode and are left NaN.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ...physics import averaged as AV
from ...physics.polhode import NoPolhode
from ...physics.presets import DAST
from . import shape as SH

AXES = ("a", "b", "c")
DOMINANT = {"a": 0, "b": 1, "c": 2, "polhode": 3, "separatrix": 4}
STARTS = 600


def box_body(b_over_a: float, c_over_a: float, dipole) -> tuple[np.ndarray, np.ndarray]:
    """(J, d): the moments of the box 1 x b/a x c/a (any density: only ratios matter) and the dipole."""
    a, b, c = 1.0, float(b_over_a), float(c_over_a)
    J = np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    d = np.asarray(dipole, dtype=float)
    return J / J.max(), d / np.linalg.norm(d)


def cell(b_over_a: float, c_over_a: float, model: str, dipole, starts: np.ndarray) -> dict:
    """One box: the attractors and the shares of the starts (module docstring)."""
    J, d = box_body(b_over_a, c_over_a, dipole)
    out = {"axis_share": np.zeros(3), "polhode_share": 0.0, "separatrix_share": 0.0, "acute_share": 0.0,
           "alpha": np.full(3, np.nan), "forced": np.zeros(3, dtype=bool), "attracting": np.zeros(3, dtype=bool),
           "polhode_angles": (math.nan, math.nan), "ok": False}
    try:
        sh = SH.shape_flow(J, d, model)
    except NoPolhode:
        return out
    for a in sh.attractors:
        if a.kind == "axis":
            out["alpha"][a.axis] = a.alpha
            out["forced"][a.axis] = a.label == "1"
            out["attracting"][a.axis] = True
        elif a.kind == "polhode":
            out["polhode_angles"] = a.angles_deg
    for (k, sign), p in SH.shares(sh, starts).items():
        if k < 0:
            continue
        a = sh.attractors[k]
        if a.kind == "axis":
            out["axis_share"][a.axis] += p
            # d . L > 0 where the spin ends along +e_c with d_c > 0 (or along -e_c with d_c < 0)
            if sign * d[a.axis] >= 0.0:
                out["acute_share"] += p
        elif a.kind == "polhode":
            out["polhode_share"] += p
        else:
            out["separatrix_share"] += p
    out["ok"] = True
    return out


def atlas(b_over_a, c_over_a, models=("reduced", "truncated"), dipole=None, starts: int = STARTS, progress=None):
    """The atlas over the grid ``b_over_a`` x ``c_over_a`` (1-D arrays of edge ratios) for each
    model; ``dipole`` the crystal frame's dipole direction (default DAST's); ``starts`` spin
    directions per cell.  Returns an ``xarray.Dataset`` (module docstring); its attrs hold the
    crystal's dipole, the starts, the cost in seconds and cells per second."""
    import xarray as xr

    bx, cy = np.asarray(b_over_a, dtype=float), np.asarray(c_over_a, dtype=float)
    d = np.asarray(DAST.dipole_direction_crystal if dipole is None else dipole, dtype=float)
    pts = SH.isotropic_starts(int(starts))
    shape = (len(models), cy.size, bx.size)
    ax_share = np.full(shape + (3,), np.nan)
    alpha = np.full(shape + (3,), np.nan)
    forced = np.zeros(shape + (3,), dtype=bool)
    pol_share, sep_share, acute = (np.full(shape, np.nan) for _ in range(3))
    pol_lo, pol_hi = np.full(shape, np.nan), np.full(shape, np.nan)
    t0, cpu0 = time.perf_counter(), time.process_time()
    for m, model in enumerate(models):
        for i, c in enumerate(cy):
            for j, b in enumerate(bx):
                r = cell(b, c, model, d, pts)
                if r["ok"]:
                    ax_share[m, i, j] = r["axis_share"]
                    alpha[m, i, j] = r["alpha"]
                    forced[m, i, j] = r["forced"]
                    pol_share[m, i, j], sep_share[m, i, j] = r["polhode_share"], r["separatrix_share"]
                    acute[m, i, j] = r["acute_share"]
                    pol_lo[m, i, j], pol_hi[m, i, j] = r["polhode_angles"]
                if progress:
                    progress()
    seconds, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    stack = np.concatenate([ax_share, pol_share[..., None], sep_share[..., None]], axis=-1)
    dom = np.where(np.all(np.isnan(stack), axis=-1), -1, np.argmax(np.nan_to_num(stack, nan=-1.0), axis=-1))
    dims = ("model", "c_over_a", "b_over_a")
    ds = xr.Dataset(
        {"axis_share": (dims + ("axis",), ax_share, {"long_name": "share of starts ending about the edge"}),
         "alpha": (dims + ("axis",), alpha, {"long_name": "omega_perp ~ tau^alpha about an attracting edge"}),
         "forced": (dims + ("axis",), forced, {"long_name": "forced tilt outlives the polhode (type 1)"}),
         "polhode_share": (dims, pol_share, {"long_name": "share ending on a fixed polhode (type 3)"}),
         "separatrix_share": (dims, sep_share, {"long_name": "share carried onto the separatrix"}),
         "acute_share": (dims, acute, {"long_name": "share ending about an edge with d . L > 0"}),
         "polhode_angle_lo_deg": (dims, pol_lo), "polhode_angle_hi_deg": (dims, pol_hi),
         "dominant": (dims, dom.astype("int8"), {"codes": "0 a, 1 b, 2 c, 3 fixed polhode, 4 separatrix, -1 none"})},
        coords={"model": list(models), "c_over_a": cy, "b_over_a": bx, "axis": list(AXES)},
        attrs={"dipole_crystal": d.tolist(), "starts": int(starts), "seconds": seconds, "cpu_seconds": cpu,
               "cells": int(np.prod(shape)), "description": __doc__.split("\n\n")[0]})
    return ds


def write(ds, path: str) -> None:
    """The atlas as netCDF at ``path``, atomically (nothing half-written on failure)."""
    from ...atomic import atomic_path

    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp)


def symmetric_check(model: str, family: int, ratio: float, dipole=None) -> dict:
    """On a family line: the box's own shape flow against the symmetric top's averaged flow
    (``physics.averaged``) at its (delta, chi) -- family 1: a = b, ratio = c/a, the symmetric
    axis c, chi the dipole's angle from c; family 2: b = c, ratio = a/b, the axis a.
    Returns {"delta", "chi", "expected": the stable LV state ("axial", "balanced", "transverse"
    or None), "found": the shape flow's attractors' kinds, "alpha": (LV's, found) on the axial
    state, "D": (LV's, found) on the balanced one}."""
    d = np.asarray(DAST.dipole_direction_crystal if dipole is None else dipole, dtype=float)
    if family == 1:
        J, dd = box_body(1.0, ratio, d)
        axis, chi = 2, math.acos(abs(d[2]) / np.linalg.norm(d))
    else:
        J, dd = box_body(1.0 / ratio, 1.0 / ratio, d)
        axis, chi = 0, math.acos(abs(d[0]) / np.linalg.norm(d))
    others = [k for k in range(3) if k != axis]
    delta = 1.0 - J[axis] / J[others[0]]
    flow = AV.Flow(model, delta, chi)
    state = flow.stable_state()
    sh = SH.shape_flow(J, dd, model)
    out = {"delta": delta, "chi": chi, "expected": None if state is None else state.name,
           "found": [a.kind for a in sh.attractors], "alpha": None, "D": None}
    if state is not None and state.name == "axial":
        a = next((x for x in sh.attractors if x.kind == "axis" and x.axis == axis), None)
        out["alpha"] = (state.exponent, None if a is None else a.alpha)
    if state is not None and state.name == "balanced":
        J3 = 1.0 - delta
        Dlv = (state.A + J3 * J3 * state.B) / (state.A + J3 * state.B) * J[others[0]]
        a = next((x for x in sh.attractors if x.kind == "polhode"), None)
        out["D"] = (Dlv, None if a is None else a.D)
    return out


def run(request, progress=None):
    """The boxes atlas of a ``inputs.boxes.BoxesRequest`` (or its fields as keywords): computed,
    written to ``request.out`` (netCDF) and drawn to ``request.plot`` when given; returns the
    Dataset.  The DAST crystal's own dipole; the 100 x 80 x 60 nm box marked."""
    from ...atomic import Outputs
    from ...inputs.boxes import BoxesRequest

    if not isinstance(request, BoxesRequest):
        request = BoxesRequest(**request)
    paths = [str(request.out)] + ([str(request.plot)] if request.plot is not None else [])
    group = Outputs(paths)                     # checked before any work, landed together after it
    g = np.geomspace(request.lo, request.hi, request.grid)
    ds = atlas(g, g, request.models, starts=request.starts, progress=progress)
    with group as tmps:
        ds.to_netcdf(tmps[0])
        if request.plot is not None:
            from .figure import figure

            figure(ds, tmps[1], f"DAST boxes a x b x c ({request.grid} x {request.grid}, {request.starts} starts "
                                f"each)", mark=(0.8, 0.6, "100 x 80 x 60 nm"))
    return ds
