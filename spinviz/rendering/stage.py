"""What the 3-D views hold, and where each thing is at each frame: ``Stage``, ``fit_camera``.

Pure NumPy.  The static lines (back half of the unit-sphere cage, the axes, or the
hodograph's axes and ticks), the solids to build (body, arrows, the hodograph's marker), the
camera fitted once to the content of *every* frame (``fit_camera``), the axis labels in
output pixels, and per frame the solids' poses and the curves' points.  World frame, lengths
in units of the dipole arrow; the hodograph is drawn in the body frame, in units of |omega(0)|.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..rotations import matrix_from_quat
from .camera import Camera, view_direction
from .captions import nice_step
from .style import ARROWS, AXIS_LENGTH, BODY_RADIUS, COLORS, TRAIL_POINTS, arrow_length

ARROW_KEYS = ("dipole", "L", "omega")                 # drawn in this order
ARROW_VECTORS = {"dipole": "d_world", "L": "L_world", "omega": "omega_world"}   # the Panel field of each arrow
EDGE_PX = 5.0             # drawn pixels keep this far from a 3-D view's edge


@dataclass
class Stage:
    """The 3-D content of the panels (the same in each panel but for the moving parts).

    view : (3,) unit, world, towards the camera; lines : [(points (n, 3), RGB floats)], the
    static polylines; solids : names of the solids to build, in order ("body", "dipole", "L",
    "omega", "hodo_marker"); marker_radius : of the hodograph's "now" ball; trail_rgb :
    (TRAIL_POINTS, 3) uint8, oldest first, or None without a trail; hodograph : whether the
    curve of omega_body is drawn; labels : [(text, (column, row))] axis names and tick values,
    output pixels; lights : [(unit direction (3,), world; intensity)]; background : RGB floats.
    """

    view: np.ndarray
    lines: list
    solids: tuple
    marker_radius: float
    trail_rgb: np.ndarray | None
    hodograph: bool
    labels: list
    lights: list
    background: tuple
    d_from_x: np.ndarray           # (3, 3): the dipole arrow (+x) into the body frame
    trail_frames: int

    # -- per frame ------------------------------------------------------------------------
    def poses(self, panel, f: int) -> dict:
        """Where each solid of ``panel`` is at frame ``f``: "body" -> rotation (3, 3), body ->
        world; an arrow key -> (rotation (3, 3) taking +x along the arrow, drawn length);
        "hodo_marker" -> position (3,) in the hodograph's frame."""
        out = {}
        if panel.q is not None:
            rot = matrix_from_quat(panel.q[f])
            out["body"] = rot
            out["dipole"] = (rot @ self.d_from_x, ARROWS["dipole"][3])
        for key in ("L", "omega"):
            v = getattr(panel, ARROW_VECTORS[key])
            if key in self.solids and v is not None:
                out[key] = (rotation_x_to(v[f]), arrow_length(key, float(np.linalg.norm(v[f]))))
        if "hodo_marker" in self.solids:
            out["hodo_marker"] = panel.omega_body[f]
        return out

    def trail_points(self, panel, f: int) -> np.ndarray:
        """(TRAIL_POINTS, 3) the dipole's tip over the last ``trail_seconds``, oldest first, world."""
        lo = max(0, f - self.trail_frames)
        idx = np.linspace(lo, f, TRAIL_POINTS).round().astype(int)
        return panel.d_world[idx]

    def hodograph_points(self, panel, f: int) -> np.ndarray:
        """(F, 3) the hodograph up to frame f (later points wait at the current one), body frame."""
        pts = panel.omega_body.copy()
        pts[f + 1:] = pts[f]
        return pts


def make_stage(plan, layout, camera: Camera) -> Stage:
    """The stage of ``plan`` seen by ``camera`` in ``layout``'s views (see ``Stage``)."""
    spec = plan.spec
    show = set(spec.show)
    colors = COLORS[spec.background]
    hodo = "hodograph" in show
    lines, ticks = [], []
    if "sphere" in show and not hodograph_only(spec):
        lines += sphere_cage(camera.view, colors)
    if "axes" in show:
        if hodo or hodograph_only(spec):
            axes, ticks = hodograph_axes(plan, colors["axes"])
            lines += axes
        else:
            for i in range(3):
                e = np.zeros(3)
                e[i] = AXIS_LENGTH
                lines.append((np.array([np.zeros(3), e]), colors["axes"]))
    solids = (("body",) if "body" in show else ()) + tuple(k for k in ARROW_KEYS if k in show)
    marker = 0.0
    if hodo:
        solids += ("hodo_marker",)
        marker = 0.022 * hodograph_range(plan)[2]
    trail_rgb = None
    if "trail" in show:
        # opaque on purpose (a translucent actor sends every frame down the depth-sorting path,
        # ~50 ms per 1440p frame on llvmpipe): the fade is a per-point colour that runs from the
        # background (oldest) to the trail colour (newest)
        age = np.linspace(0.0, 1.0, TRAIL_POINTS) ** 1.5
        bg, tc = np.asarray(colors["bg_rgb"]), np.asarray(colors["trail"])
        trail_rgb = ((bg + (tc - bg) * (0.06 + 0.94 * age)[:, None]) * 255).astype(np.uint8)
    return Stage(view=camera.view, lines=lines, solids=solids, marker_radius=marker, trail_rgb=trail_rgb,
                 hodograph=hodo, labels=axis_labels(plan, layout, camera, ticks), lights=camera.lights(),
                 background=colors["bg_rgb"], d_from_x=rotation_x_to(plan.d_body),
                 trail_frames=int(round(spec.trail_seconds * spec.fps)))


def hodograph_only(spec) -> bool:
    """A scene that shows the hodograph and nothing that needs the orientation."""
    return "hodograph" in spec.show and not spec.needs_orientation


# --- the camera ------------------------------------------------------------------------------
def fit_camera(plan, layout) -> tuple[Camera, object]:
    """The camera fitted to the content of every frame, and the layout with its 3-D views
    narrowed to the width the content needs (GL pixels are the cost; the rest of the panel
    is static background), centred in their panels.  Both panels share the camera."""
    x0, y0, x1, y1 = layout.views[0]
    vw, vh = x1 - x0, y1 - y0
    pts = content_points(plan)
    spec = plan.spec
    view, zoom = view_direction(spec.azimuth_deg, spec.elevation_deg), spec.zoom
    border = _border(layout, spec.show)
    cam = Camera(view, vw / vh, pts, _margins(border, vw, vh), zoom)
    lo, hi = cam.extent(pts, cam.distance)
    need = ((hi[0] - lo[0]) / 2.0 * vw + 2 * border[0]) / 0.98
    w2 = int(min(vw, 2 * math.ceil(need / 2.0 + 1)))
    if w2 < vw and zoom <= 1.0:
        views = []
        for (a, b, c, d) in layout.views:
            left = a + (c - a - w2) // 2
            views.append((left, b, left + w2, d))
        layout = replace(layout, views=views)
        cam = Camera(view, w2 / vh, pts, _margins(border, w2, vh), zoom)
    return cam, layout


def _border(layout, show) -> tuple[float, float]:
    """Pixels kept free at the sides and at top and bottom of a view (labels reach out there)."""
    label = layout.sizes.size * 0.9 if "axes" in show else 0.0
    return EDGE_PX + 1.4 * label, EDGE_PX + 0.6 * label


def _margins(border, vw, vh) -> tuple[float, float]:
    bx, by = border
    return (min(0.5, 0.02 + 2 * bx / vw), min(0.5, 0.02 + 2 * by / vh))


def content_points(plan) -> np.ndarray:
    """(N, 3) every world point any frame of any panel draws (or places a label at): the
    sphere cage, the axes, the body's bounding sphere, each arrow's tip at every frame; for a
    hodograph, its curve and axes (body frame, units of |omega(0)|)."""
    show = set(plan.spec.show)
    pts = []
    if "hodograph" in show:
        for panel in plan.panels:
            pts.append(panel.omega_body)
        if "axes" in show:
            lo, hi, span = hodograph_range(plan)
            for i in range(3):
                e = np.zeros(3)
                e[i] = hi[i] + 0.1 * span
                pts.append(e[None, :])
                e = np.zeros(3)
                e[i] = lo[i]
                pts.append(e[None, :])
        if hodograph_only(plan.spec):
            return np.vstack(pts)
    if "sphere" in show or "trail" in show:
        pts.append(np.vstack(list(_circle_points())))
    if "axes" in show:
        pts.append(np.eye(3) * AXIS_LENGTH)
    if "body" in show:
        pts.append(np.vstack(list(_circle_points())) * BODY_RADIUS)
    for panel in plan.panels:
        if panel.d_world is not None and "dipole" in show:
            pts.append(panel.d_world * (ARROWS["dipole"][3] + 0.02))
        for key in ("omega", "L"):
            v = getattr(panel, ARROW_VECTORS[key])
            if v is None:
                continue
            n = np.linalg.norm(v, axis=1, keepdims=True)
            u = np.divide(v, n, out=np.zeros_like(v), where=n > 0)
            ln = np.array([arrow_length(key, float(x)) for x in n[:, 0]])
            pts.append(u * (ln[:, None] + 0.02))
    return np.vstack(pts) if pts else np.eye(3)


# --- static lines ----------------------------------------------------------------------------
def _circle_points():
    """Latitudes (every 30 deg) and meridians of the unit sphere, 145 points each."""
    t = np.linspace(0.0, 2.0 * np.pi, 145)
    for lat in (-60, -30, 0, 30, 60):
        c, s = math.cos(math.radians(lat)), math.sin(math.radians(lat))
        yield np.c_[c * np.cos(t), c * np.sin(t), np.full_like(t, s)]
    for lon in range(0, 180, 30):
        c, s = math.cos(math.radians(lon)), math.sin(math.radians(lon))
        yield np.c_[np.cos(t) * c, np.cos(t) * s, np.sin(t)]


def _back_runs(curve, view) -> list[np.ndarray]:
    """The runs of a closed curve on the unit sphere that lie on the far side from the camera."""
    back = curve @ view <= 0.0
    runs, cur = [], []
    for p, b in zip(curve, back):
        if b:
            cur.append(p)
        elif cur:
            runs.append(np.array(cur))
            cur = []
    if cur:
        runs.append(np.array(cur))
    return [r for r in runs if len(r) > 1]


def sphere_cage(view, colors) -> list[tuple[np.ndarray, tuple]]:
    """The back half of the unit-sphere cage (latitudes and meridians) and its outline circle
    (the limb, seen edge-on): lines that never cross in front of the body.  view : (3,) unit,
    world, towards the camera; returns [(points (n, 3), RGB floats)]."""
    out = []
    for c in _circle_points():
        out += [(r, colors["sphere"]) for r in _back_runs(c, view)]
    a = np.cross(view, [0.0, 0.0, 1.0] if abs(view[2]) < 0.9 else [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(view, a)
    t = np.linspace(0.0, 2 * np.pi, 181)
    out.append((np.outer(np.cos(t), a) + np.outer(np.sin(t), b), colors["limb"]))
    return out


def hodograph_range(plan) -> tuple[np.ndarray, np.ndarray, float]:
    """Per axis (lo (3,), hi (3,)) spanned by the hodographs, 0 included, with an 8 % border,
    and the largest span; body frame, units of |omega(0)|."""
    w = np.vstack([p.omega_body for p in plan.panels])
    lo, hi = np.minimum(w.min(axis=0), 0.0), np.maximum(w.max(axis=0), 0.0)
    span = float(np.max(hi - lo)) or 1.0
    return lo - 0.08 * span, hi + 0.08 * span, span


def hodograph_axes(plan, color) -> tuple[list, list]:
    """Axis lines across the hodographs' range and tick marks at round values:
    (curves [(points (2, 3), color)], ticks [(axis index, value, point (3,))])."""
    lo, hi, span = hodograph_range(plan)
    step = nice_step(span, 6)
    size = 0.025 * span
    curves, ticks = [], []
    for i in range(3):
        a, b = np.zeros(3), np.zeros(3)
        a[i], b[i] = lo[i], hi[i]
        curves.append((np.array([a, b]), color))
        j = (i + 1) % 3 if i != 2 else 0
        for v in np.arange(math.ceil(lo[i] / step) * step, hi[i] + 1e-12, step):
            if abs(v) < 1e-12:
                continue
            p = np.zeros(3)
            p[i] = v
            d = np.zeros(3)
            d[j] = size
            curves.append((np.array([p - d, p + d]), color))
            ticks.append((i, float(v), p))
    return curves, ticks


# --- labels ----------------------------------------------------------------------------------
def axis_labels(plan, layout, camera: Camera, ticks) -> list[tuple[str, tuple[float, float]]]:
    """(text, output pixel (column, row)) of the axis names, and of the hodograph's tick
    values; an axis name sits beside its axis's end, off the line, where an arrow along the
    axis leaves it free."""
    if "axes" not in plan.spec.show:
        return []
    out = []
    for box in layout.views[:len(plan.panels)]:
        if ticks:
            out += _hodograph_labels(plan, camera, box, ticks, layout.sizes.size)
            continue
        origin = camera.to_pixels(np.zeros(3), box)[0]
        for i, name in enumerate(("x", "y", "z")):
            e = np.zeros(3)
            e[i] = AXIS_LENGTH
            end = camera.to_pixels(e, box)[0]
            d = end - origin
            d /= np.linalg.norm(d) or 1.0
            side = np.array([-d[1], d[0]])                       # perpendicular on screen
            if side[0] < 0:
                side = -side
            out.append((name, tuple(end + 0.8 * layout.sizes.size * side)))
    return out


def _hodograph_labels(plan, camera: Camera, box, ticks, size: int) -> list:
    """The names ω₁, ω₂, ω₃ past the axes' ends, and the values on the axis that looks longest
    only (short axes near the origin would crowd their labels together)."""
    lo, hi, span = hodograph_range(plan)
    out = []
    for i, name in enumerate(("ω₁", "ω₂", "ω₃")):
        e = np.zeros(3)
        e[i] = hi[i] + 0.06 * span
        out.append((name, tuple(camera.to_pixels(e, box)[0])))
    last = {}
    origin = camera.to_pixels(np.zeros(3), box)[0]
    reach = [float(np.linalg.norm(camera.to_pixels(np.eye(3)[i] * (hi[i] - lo[i]), box)[0] - origin)) for i in range(3)]
    for i, v, p in ticks:
        if i != int(np.argmax(reach)):
            continue
        # beside the axis, off the curve's side: left of a steep axis, under a flat one
        e = np.zeros(3)
        e[i] = 1.0
        d = camera.to_pixels(e, box)[0] - origin
        d /= np.linalg.norm(d) or 1.0
        side = np.array([-d[1], d[0]])
        if (abs(d[1]) > abs(d[0]) and side[0] > 0) or (abs(d[1]) <= abs(d[0]) and side[1] < 0):
            side = -side
        xy = camera.to_pixels(p, box)[0] + side * 1.1 * size
        if i in last and np.linalg.norm(xy - last[i]) < 2.2 * size:
            continue
        last[i] = xy
        out.append((f"{v:g}", tuple(xy)))
    return out


def rotation_x_to(v) -> np.ndarray:
    """The smallest rotation (3, 3) taking +x to the direction of ``v`` (3,) (identity for
    v = 0; a half turn about z for v along -x)."""
    v = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(v))
    if n == 0.0:
        return np.eye(3)
    b = v / n
    c = float(b[0])                                   # cos of the angle from +x
    axis = np.array([0.0, -b[2], b[1]])               # x cross b
    s = float(np.linalg.norm(axis))
    if s < 1e-12:
        return np.eye(3) if c > 0 else np.diag([-1.0, -1.0, 1.0])
    k = axis / s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)    # Rodrigues
