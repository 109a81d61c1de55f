"""A body's surface, as the gas meets it: flat and curved patches in the body frame, with
quadrature nodes (for the gas's mean torque and its fluctuations, ``physics.gas``) and
uniform points (for single collisions, ``integrators.collisions``).

The surface is the body's drawn ``Shape`` in physical units -- a box (a x b x c, edges along
the shape's axes, turned into the body frame by ``q_body_from_shape``), a rod (a solid
cylinder along e3) or a sphere (diameter) -- centred on the centre of mass, as the uniform
solids of ``physics.bodies`` are.  A body given only by its moments (``bodies.custom``) has no
surface: ``surface_of`` says so.

Patches, one row each of ``Surface.geometry`` (body frame, cm):

* ``RECT``: centre c, normal n, in-plane unit axes e1, e2, half-sizes h1, h2;
* ``SIDE``: a cylinder's side: centre c, axis a (in the normal's slot), e1, e2 across it,
  half-length h1, radius R (in h2's slot);
* ``DISK``: centre c, normal n, e1, e2, radius R (h2's slot);
* ``SPHERE``: centre c, radius R (h2's slot).

Columns: c 0:3, n (or a) 3:6, e1 6:9, e2 9:12, h1 12, h2 (or R) 13.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import SpecError
from ..rotations import matrix_from_quat

RECT, SIDE, DISK, SPHERE = 0, 1, 2, 3


@dataclass(frozen=True)
class Surface:
    """A closed surface in the body frame (module docstring): ``kind`` (P,), ``geometry``
    (P, 14), ``area`` (P,) cm^2, ``label`` in words, and the radius of the smallest sphere
    about the centre of mass holding it (``r_max``, cm)."""

    kind: np.ndarray
    geometry: np.ndarray
    area: np.ndarray
    label: str
    r_max: float

    @property
    def total_area(self) -> float:
        """The whole surface, cm^2."""
        return float(np.sum(self.area))

    @property
    def size(self) -> float:
        """Its largest extent (cm): the length that sets the Knudsen number."""
        return 2.0 * self.r_max

    def nodes(self, k: int = 16):
        """Quadrature of the surface: (r (M, 3), n (M, 3), weight (M,)) in the body frame, cm and
        cm^2, exact for polynomials of degree < 2k along each flat coordinate (Gauss-Legendre)
        and for trigonometric polynomials of degree < 2k around curved ones."""
        rs, ns, ws = [], [], []
        x, w = np.polynomial.legendre.leggauss(k)
        phi = 2.0 * math.pi * (np.arange(2 * k) + 0.5) / (2 * k)
        for kind, g in zip(self.kind, self.geometry):
            c, n, e1, e2, h1, h2 = g[0:3], g[3:6], g[6:9], g[9:12], g[12], g[13]
            if kind == RECT:
                a, b = np.meshgrid(x * h1, x * h2, indexing="ij")
                r = c + a.reshape(-1, 1) * e1 + b.reshape(-1, 1) * e2
                rs.append(r)
                ns.append(np.broadcast_to(n, r.shape))
                ws.append((np.outer(w, w) * h1 * h2).reshape(-1))
            elif kind == SIDE:
                z, p = np.meshgrid(x * h1, phi, indexing="ij")
                radial = np.cos(p).reshape(-1, 1) * e1 + np.sin(p).reshape(-1, 1) * e2
                rs.append(c + h2 * radial + z.reshape(-1, 1) * n)
                ns.append(radial)
                ws.append((np.outer(w * h1, np.full(phi.size, 2.0 * math.pi / phi.size)) * h2).reshape(-1))
            elif kind == DISK:
                rho, p = np.meshgrid(0.5 * h2 * (x + 1.0), phi, indexing="ij")
                r = c + (rho * np.cos(p)).reshape(-1, 1) * e1 + (rho * np.sin(p)).reshape(-1, 1) * e2
                rs.append(r)
                ns.append(np.broadcast_to(n, r.shape))
                ws.append((np.outer(0.5 * h2 * w, np.full(phi.size, 2.0 * math.pi / phi.size)) * rho).reshape(-1))
            else:
                z, p = np.meshgrid(x, phi, indexing="ij")
                s = np.sqrt(1.0 - z * z)
                nn = np.stack([(s * np.cos(p)).ravel(), (s * np.sin(p)).ravel(), z.ravel()], axis=-1)
                rs.append(c + h2 * nn)
                ns.append(nn)
                ws.append((np.outer(w, np.full(phi.size, 2.0 * math.pi / phi.size)) * h2 * h2).reshape(-1))
        return np.concatenate(rs), np.concatenate(ns), np.concatenate(ws)


def _row(c, n, e1, e2, h1, h2) -> np.ndarray:
    return np.concatenate([c, n, e1, e2, [h1, h2]]).astype(float)


def box_surface(a: float, b: float, c: float, R=None, label: str = "box") -> Surface:
    """The six faces of an a x b x c box (cm) centred at the origin, edges along the axes of the
    frame rotated by the matrix ``R`` (body from shape; identity when None)."""
    R = np.eye(3) if R is None else np.asarray(R, dtype=float)
    half = (0.5 * a, 0.5 * b, 0.5 * c)
    rows, areas = [], []
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        for sign in (1.0, -1.0):
            n = sign * R[:, i]
            rows.append(_row(half[i] * n, n, R[:, j], R[:, k], half[j], half[k]))
            areas.append(4.0 * half[j] * half[k])
    r_max = math.sqrt(sum(h * h for h in half))
    return Surface(np.full(6, RECT), np.array(rows), np.array(areas), label, r_max)


def rod_surface(length: float, diameter: float, label: str = "cylinder") -> Surface:
    """A solid cylinder (cm) along e3, centred: its side and its two end caps."""
    R, h = 0.5 * diameter, 0.5 * length
    ex, ey, ez = np.eye(3)
    rows = [_row(np.zeros(3), ez, ex, ey, h, R), _row(h * ez, ez, ex, ey, 0.0, R), _row(-h * ez, -ez, ex, -ey, 0.0, R)]
    areas = [2.0 * math.pi * R * length, math.pi * R * R, math.pi * R * R]
    return Surface(np.array([SIDE, DISK, DISK]), np.array(rows), np.array(areas), label, math.hypot(R, h))


def sphere_surface(diameter: float, label: str = "sphere") -> Surface:
    """A sphere (cm) centred at the origin."""
    R = 0.5 * diameter
    row = _row(np.zeros(3), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), 0.0, R)
    return Surface(np.array([SPHERE]), row[None, :], np.array([4.0 * math.pi * R * R]), label, R)


def surface_of(body) -> Surface:
    """The surface of a CGS body with a physical shape (a box, a rod or a sphere: presets and
    ``shape = "rod"/"box"``); ``SpecError("body", ...)`` for one given only by its moments."""
    shape = body.shape
    if body.units != "cgs" or shape is None or shape.label == "inertia-equivalent box":
        raise SpecError("body", "the gas meets the body's surface, and this body has none: give it by a preset or by "
                                "shape = \"rod\" / \"box\" (a body given by its moments has no size)")
    if shape.kind == "box":
        R = matrix_from_quat(np.asarray(shape.q_body_from_shape, dtype=float))
        return box_surface(*shape.dims, R=R, label=shape.label or "box")
    if shape.kind == "rod":
        return rod_surface(*shape.dims, label=shape.label or "cylinder")
    if shape.kind == "sphere":
        return sphere_surface(shape.dims[0], label=shape.label or "sphere")
    raise SpecError("body", f"the gas model knows boxes, rods and spheres, not a {shape.kind!r}")
