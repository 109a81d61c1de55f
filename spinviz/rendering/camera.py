"""The camera: one perspective view, fitted once to everything any frame draws.

Pure NumPy.  The camera never moves during a video (the views of two panels compare
directly, and the fixed lights stay fixed relative to it), so "the camera path" is one
pose, solved for so that the content of every frame fills the 3-D view within a margin
(``fit``).  World frame: z up; the camera looks at the origin.
"""

from __future__ import annotations

import math

import numpy as np

from .style import VIEW_ANGLE


class Camera:
    """A perspective camera looking at the origin from ``view`` (unit, world), fitted so that
    given points fill a viewport of aspect ``aspect`` within ``margin`` (in units of the
    half-viewport) -- its distance and the window centre (an off-axis shift) are solved for.

    Parameters
    ----------
    view : array_like, shape (3,) -- unit vector from the origin to the camera, world frame.
    aspect : float -- width / height of the viewport.
    points : array_like, shape (N, 3) -- world points that must be in view (dipole-arrow units).
    margin_xy : (float, float) -- free border at the sides and at top and bottom, in units of the
        half-viewport.
    zoom : float -- > 1 moves the camera closer after the fit (content may then leave the view).

    Attributes: ``distance`` (from the origin), ``center`` (2,) window centre in normalized
    device coordinates, ``right`` and ``up`` (3,) the screen axes in the world frame, ``rmax``.
    """

    def __init__(self, view, aspect: float, points, margin_xy, zoom: float = 1.0):
        self.view = np.asarray(view, dtype=float)
        self.right = np.cross(-self.view, [0.0, 0.0, 1.0])
        self.right /= np.linalg.norm(self.right)
        self.up = np.cross(self.right, -self.view)
        self.aspect = aspect
        self.tan = math.tan(math.radians(VIEW_ANGLE / 2))
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        rmax = float(np.max(np.linalg.norm(pts, axis=1))) or 1.0
        target = np.array([1.0 - margin_xy[0], 1.0 - margin_xy[1]])
        D = 3.0 * rmax / self.tan
        for _ in range(30):
            lo, hi = self.extent(pts, D)
            need = float(np.max((hi - lo) / 2.0 / target))
            if abs(need - 1.0) < 1e-4:
                break
            # the extent shrinks roughly as 1/D; keep the camera outside every point
            D = max(D * need, 1.05 * rmax + 1e-6)
        self.distance = D / zoom
        lo, hi = self.extent(pts, self.distance)
        self.center = 0.5 * (lo + hi)
        self.rmax = rmax

    def ndc(self, pts, D: float) -> np.ndarray:
        """Normalized device coordinates (N, 2) of world points (N, 3) seen from distance D."""
        depth = D - pts @ self.view
        x = (pts @ self.right) / (depth * self.tan * self.aspect)
        y = (pts @ self.up) / (depth * self.tan)
        return np.c_[x, y]

    def extent(self, pts, D: float) -> tuple[np.ndarray, np.ndarray]:
        """(lowest, highest) normalized device coordinates (2,) of world points (N, 3) from distance D."""
        ndc = self.ndc(pts, D)
        return ndc.min(axis=0), ndc.max(axis=0)

    def to_pixels(self, pts, box) -> np.ndarray:
        """Output pixels (N, 2) as (column, row) of world points (N, 3) in the viewport ``box``
        = (x0, y0, x1, y1), output pixels, x1 and y1 exclusive."""
        ndc = self.ndc(np.atleast_2d(np.asarray(pts, dtype=float)), self.distance) - self.center
        x0, y0, x1, y1 = box
        return np.c_[x0 + (ndc[:, 0] + 1.0) * 0.5 * (x1 - x0), y0 + (1.0 - ndc[:, 1]) * 0.5 * (y1 - y0)]

    def lights(self) -> list[tuple[np.ndarray, float]]:
        """(unit direction (3,), world frame; intensity) of a key light from the upper left, a
        weaker fill from the right and a head light -- fixed relative to the fixed camera, so
        that adjacent faces of a box get different tones."""
        v, r, u = self.view, self.right, self.up

        def unit(x):
            """x / |x|."""
            return x / np.linalg.norm(x)

        return [(unit(-0.55 * r + 0.75 * u + 0.45 * v), 0.55), (unit(0.85 * r - 0.15 * u + 0.35 * v), 0.22),
                (v, 0.25)]


def fit(view, points, size, border, zoom: float = 1.0) -> tuple[Camera, int]:
    """The camera that shows ``points`` in a view, and the view width the content needs.

    GL pixels are the cost of a frame, so a view narrower than its panel is drawn that
    narrow (unless zoomed in).

    Parameters
    ----------
    view : array_like, shape (3,)
        Unit vector from the origin towards the camera, world frame.
    points : array_like, shape (N, 3)
        Every world point any frame draws (dipole-arrow units).
    size : (int, int)
        (width, height) of the view, px.
    border : (float, float)
        Pixels kept free at the sides and at top and bottom.
    zoom : float
        > 1 moves the camera closer after the fit.

    Returns
    -------
    camera : Camera
        Fitted to the returned width.
    width : int
        Even, at most ``size[0]``, px.
    """
    vw, vh = size
    cam = Camera(view, vw / vh, points, _margins(border, vw, vh), zoom)
    lo, hi = cam.extent(points, cam.distance)
    need = ((hi[0] - lo[0]) / 2.0 * vw + 2 * border[0]) / 0.98
    w2 = int(min(vw, 2 * math.ceil(need / 2.0 + 1)))
    if w2 < vw and zoom <= 1.0:
        return Camera(view, w2 / vh, points, _margins(border, w2, vh), zoom), w2
    return cam, vw


def _margins(border, vw, vh) -> tuple[float, float]:
    """A border in px as margins in units of the half-view (at most half of it)."""
    bx, by = border
    return (min(0.5, 0.02 + 2 * bx / vw), min(0.5, 0.02 + 2 * by / vh))
