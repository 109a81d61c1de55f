"""The moving solids as plain arrays: points, triangles, normals and per-vertex colours.

Built in NumPy rather than from pyvista sources so that each part carries exactly what the
CPU lighting of ``views.Solids`` needs: flat normals per face, a colour per vertex, and a
flag for vertices that are not lit (outlines keep their dark tone whatever the light).
Shapes are in their own frame; arrows point along +x with unit shaft length (the view
stretches the shaft and moves the head, so arrow length can follow |Omega| and |L|).
Lengths in units of the dipole arrow; colours RGB floats in [0, 1].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .style import ARROW_COLORS, ARROWS, BODY_RADIUS, HODO_MARKER_COLOR, ROD_SECOND_COLOR

OUTLINE = 0.045          # width of a box's dark edge band, as a fraction of its shortest edge (min 0.02 radius)


@dataclass
class Assembly:
    """The solids of a panel joined into one part: ``part`` and, per solid part name ("body",
    "dipole_shaft", "dipole_head", ..., "hodo_marker"), its vertices' ``slices`` in it."""

    part: Part
    slices: dict


def assemble(picture) -> Assembly:
    """The solids ``picture.stage`` lists, built and joined in its order.

    Parameters
    ----------
    picture : picture.Picture
        Its stage names the solids ("body", arrow keys, "hodo_marker"); its plan gives the
        body's shape, its theme the body's colour.

    Returns
    -------
    Assembly
        One ``Part`` (the body in its body frame, each arrow as a shaft and a head along +x,
        the marker at the origin; dipole-arrow units) and each part's vertex slice in it.
    """
    stage, plan = picture.stage, picture.plan
    named = []
    for name in stage.solids:
        if name == "body":
            named.append(("body", body_part(plan.shape, picture.theme.body, stage.body_from_shape)))
        elif name == "hodo_marker":
            named.append(("hodo_marker", ball(stage.marker_radius, np.asarray(HODO_MARKER_COLOR))))
        else:
            shaft, head_len, head_r, _ = ARROWS[name]
            color = np.asarray(ARROW_COLORS[name])
            named += [(name + "_shaft", arrow_shaft(shaft, color)), (name + "_head", arrow_head(head_len, head_r, color))]
    offsets = np.cumsum([0] + [p.points.shape[0] for _, p in named])
    slices = {name: slice(int(lo), int(hi)) for (name, _), lo, hi in zip(named, offsets[:-1], offsets[1:])}
    return Assembly(Part.join([p for _, p in named]) if named else None, slices)


@dataclass
class Part:
    """A mesh in its own frame: points, normals (n, 3); triangles (m, 3) int; color (n, 3) in
    [0, 1]; lit (n,) bool (False: an outline vertex, drawn in its colour whatever the light)."""

    points: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray
    color: np.ndarray
    lit: np.ndarray

    @staticmethod
    def join(parts: list[Part]) -> Part:
        """One part of all ``parts``, in order (their triangles re-indexed)."""
        offs = np.cumsum([0] + [p.points.shape[0] for p in parts])
        return Part(np.vstack([p.points for p in parts]), np.vstack([p.normals for p in parts]),
                    np.vstack([p.triangles + o for p, o in zip(parts, offs[:-1])]),
                    np.vstack([p.color for p in parts]), np.concatenate([p.lit for p in parts]))


def _quads(corners, normal, color, lit=True) -> Part:
    """Quads given as (k, 4, 3) corner arrays (counter-clockwise seen from ``normal``)."""
    corners = np.asarray(corners, dtype=float).reshape(-1, 4, 3)
    k = corners.shape[0]
    pts = corners.reshape(-1, 3)
    base = 4 * np.arange(k)[:, None]
    tris = np.vstack([base + [0, 1, 2], base + [0, 2, 3]])
    n = np.broadcast_to(np.asarray(normal, dtype=float), pts.shape).copy()
    col = np.broadcast_to(np.asarray(color, dtype=float), pts.shape).copy()
    return Part(pts, n, tris, col, np.full(pts.shape[0], lit))


def box(half, color, edge_color) -> Part:
    """A box of half-edges ``half`` (3,) whose faces are framed by dark bands, so that its
    edges read whatever the light: each face is an inner quad and four edge strips."""
    half = np.asarray(half, dtype=float)
    w = max(OUTLINE * 2.0 * float(half.min()), 0.02 * BODY_RADIUS)
    parts = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            u, v = [(axis + 1) % 3, (axis + 2) % 3]
            if sign < 0:
                u, v = v, u                                   # keep the quads counter-clockwise
            n = np.zeros(3)
            n[axis] = sign
            c0 = n * half[axis]
            eu, ev = np.zeros(3), np.zeros(3)
            eu[u], ev[v] = half[u], half[v]
            iu, iv = eu * (1 - w / half[u]), ev * (1 - w / half[v])

            def q(a, b, c, d, c0=c0):
                """Four corners of a quad on this face (c0 its centre)."""
                return np.array([c0 + a, c0 + b, c0 + c, c0 + d])

            parts.append(_quads(q(-iu - iv, iu - iv, iu + iv, -iu + iv), n, color))
            rims = [q(-eu - ev, eu - ev, iu - iv, -iu - iv), q(eu - ev, eu + ev, iu + iv, iu - iv),
                    q(eu + ev, -eu + ev, -iu + iv, iu + iv), q(-eu + ev, -eu - ev, -iu - iv, -iu + iv)]
            parts.append(_quads(np.array(rims), n, edge_color, lit=False))
    return Part.join(parts)


def _ring(res, start=0.0, stop=2 * math.pi):
    t = np.linspace(start, stop, res + 1)
    return np.cos(t), np.sin(t)


def cylinder_z(radius, half_length, res, color, start=0.0, stop=2 * math.pi, caps=True) -> Part:
    """The side (and end caps) of a cylinder along z, over the azimuths [start, stop]."""
    c, s = _ring(res, start, stop)
    lo = np.c_[radius * c, radius * s, np.full_like(c, -half_length)]
    hi = lo + [0.0, 0.0, 2 * half_length]
    nrm = np.c_[c, s, np.zeros_like(c)]
    pts = np.vstack([lo, hi])
    normals = np.vstack([nrm, nrm])
    i = np.arange(res)
    j = i + res + 1
    tris = np.vstack([np.c_[i, i + 1, j + 1], np.c_[i, j + 1, j]])
    parts = [Part(pts, normals, tris, np.tile(color, (pts.shape[0], 1)), np.ones(pts.shape[0], bool))]
    if caps:
        for z, sign in ((half_length, 1.0), (-half_length, -1.0)):
            rim = np.c_[radius * c, radius * s, np.full_like(c, z)]
            centre = np.array([[0.0, 0.0, z]])
            pts = np.vstack([centre, rim])
            k = np.arange(1, res + 1)
            tris = np.c_[np.zeros(res, int), k, k + 1] if sign > 0 else np.c_[np.zeros(res, int), k + 1, k]
            parts.append(Part(pts, np.tile([0.0, 0.0, sign], (pts.shape[0], 1)), tris,
                              np.tile(color, (pts.shape[0], 1)), np.ones(pts.shape[0], bool)))
    return Part.join(parts)


def two_tone_rod(radius, half_length, color, second_color, res=24) -> Part:
    """A rod along z painted in two halves (azimuth 0..pi and pi..2 pi): its spin about its
    own axis shows as the dark half turning into and out of view."""
    return Part.join([cylinder_z(radius, half_length, res, color, 0.0, math.pi),
                      cylinder_z(radius, half_length, res, second_color, math.pi, 2 * math.pi)])


def arrow_shaft(radius, color, res=12) -> Part:
    """A cylinder along +x from 0 to 1 (the view stretches it), without caps."""
    p = cylinder_z(radius, 0.5, res, color, caps=False)
    rot = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])   # z -> x, x -> y, y -> z
    return Part((p.points + [0.0, 0.0, 0.5]) @ rot.T, p.normals @ rot.T, p.triangles, p.color, p.lit)


def arrow_head(length, radius, color, res=16) -> Part:
    """A cone along +x from 0 (base) to ``length`` (tip), with its base disk."""
    c, s = _ring(res)
    base = np.c_[np.zeros_like(c), radius * c, radius * s]
    slope = radius / length
    side_n = np.c_[np.full_like(c, slope), c, s] / math.sqrt(1.0 + slope * slope)
    tip = np.tile([length, 0.0, 0.0], (res, 1))
    tip_n = 0.5 * (side_n[:-1] + side_n[1:])
    i = np.arange(res)
    side = Part(np.vstack([base, tip]), np.vstack([side_n, tip_n]), np.c_[i, i + 1, res + 1 + i],
                np.tile(color, (2 * res + 1, 1)), np.ones(2 * res + 1, bool))
    centre = np.zeros((1, 3))
    disk = Part(np.vstack([centre, base]), np.tile([-1.0, 0.0, 0.0], (res + 2, 1)),
                np.c_[np.zeros(res, int), i + 2, i + 1], np.tile(color, (res + 2, 1)), np.ones(res + 2, bool))
    return Part.join([side, disk])


def ball(radius, color, res=12) -> Part:
    """A UV sphere (the hodograph's moving point)."""
    th = np.linspace(0.0, math.pi, res + 1)
    ph = np.linspace(0.0, 2 * math.pi, 2 * res + 1)
    T, P = np.meshgrid(th, ph, indexing="ij")
    n = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    cols = 2 * res + 1
    tris = []
    for a in range(res):
        for b in range(2 * res):
            i0, i1 = a * cols + b, (a + 1) * cols + b
            tris += [(i0, i1, i1 + 1), (i0, i1 + 1, i0 + 1)]
    return Part(radius * n, n, np.array(tris), np.tile(color, (n.shape[0], 1)), np.ones(n.shape[0], bool))


def body_part(shape, color, m) -> Part:
    """The body in its body frame, true proportions, bounding radius BODY_RADIUS: a two-tone
    rod or a box with dark edges (a small sphere when the shape is unknown).

    shape : ``frameplan.ShapeInfo`` or None; color : RGB floats; m : (3, 3) the rotation from
    the shape's own axes to the body frame.
    """
    color = np.asarray(color)
    if shape is None:
        return ball(0.3, color)
    if shape.kind == "rod":
        length, diameter = shape.dims
        k = BODY_RADIUS / math.hypot(0.5 * length, 0.5 * diameter)
        # a thin rod is drawn at least a sixth of its length thick, so that its painted halves
        # -- and with them its spin about its own axis -- can be seen (the true L/D is in the title)
        r = max(0.5 * diameter * k, 0.085 * length * k)
        part = two_tone_rod(r, 0.5 * length * k, color, np.asarray(ROD_SECOND_COLOR))
    else:
        # a needle-thin box (a slender inertia-equivalent body) is drawn at least 1/8 as thick
        # as it is long, so that it can be seen turning
        a, b, c = np.maximum(np.asarray(shape.dims, dtype=float), 0.125 * max(shape.dims))
        k = BODY_RADIUS / (0.5 * math.sqrt(a * a + b * b + c * c))
        part = box(0.5 * k * np.array([a, b, c]), color, 0.35 * color)
    return Part(part.points @ m.T, part.normals @ m.T, part.triangles, part.color, part.lit)
