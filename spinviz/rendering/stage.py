"""What the 3-D views hold, and where each thing is at each frame: ``plan_stage`` -> ``Stage``.

Pure NumPy.  The static lines (back half of the unit-sphere cage, the axes, or the
hodograph's axes and ticks), the solids to build (body, arrows, the hodograph's marker) and
their poses at every frame, the camera fitted once to the content of *every* frame, the
3-D views narrowed to that content, and the axis labels in output pixels.  World frame,
lengths in units of the dipole arrow; the hodograph is drawn in the body frame, in units
of |omega(0)|.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .camera import Camera, fit
from .captions import nice_step
from .style import ARROW_BASE, ARROWS, AXIS_LENGTH, BODY_RADIUS, TRAIL_POINTS

ARROW_KEYS = ("dipole", "L", "omega")                 # drawn in this order
ARROW_VECTORS = {"dipole": "d_world", "L": "L_world", "omega": "omega_world"}   # the Panel field of each arrow
EDGE_PX = 5.0             # drawn pixels keep this far from a 3-D view's edge


@dataclass
class Stage:
    """The 3-D content of the panels, the same in each but for the poses.

    view : (3,) unit, world, towards the camera; lines : [(points (n, 3), RGB floats)], the
    static polylines; solids : names of the solids to build, in order ("body", "dipole", "L",
    "omega", "hodo_marker"); body_from_shape : (3, 3) the drawn body's own axes in the body
    frame; marker_radius : of the hodograph's "now" ball; trail_rgb : (TRAIL_POINTS, 3) uint8,
    oldest first, or None without a trail; trail_frames : frames the trail spans; hodograph :
    whether the curve of omega_body is drawn; labels : [(text, (column, row))] axis names and
    tick values, output pixels; lights : [(unit direction (3,), world; intensity)].
    poses : per panel, per solid, at every frame (F first): "body" -> (F, 3, 3) body -> world;
    an arrow key -> ((F, 3, 3) rotations taking +x along the arrow, (F,) drawn lengths);
    "hodo_marker" -> (F, 3) positions in the hodograph's frame.
    """

    view: np.ndarray
    lines: list
    solids: tuple
    body_from_shape: np.ndarray
    marker_radius: float
    trail_rgb: np.ndarray | None
    trail_frames: int
    hodograph: bool
    labels: list
    lights: list
    poses: list


def plan_stage(plan, layout, theme):
    """The 3-D content of ``plan``, its poses at every frame, and the camera fitted to it.

    Parameters
    ----------
    plan : FramePlan
    layout : layout.Layout
        The bands; its 3-D views (output px) give the viewport the camera fills.
    theme : style.Theme
        The scene colours (cage, axes, trail, background).

    Returns
    -------
    stage : Stage
        Lines, solids, poses (per panel, per frame), labels (output px), lights (world).
    camera : camera.Camera
        Fitted once to everything any frame draws, shared by the panels.
    layout : layout.Layout
        With its 3-D views narrowed to the width the content needs, centred in their panels.
    """
    spec = plan.spec
    show = set(spec.show)
    x0, y0, x1, y1 = layout.views[0]
    solids = (("body",) if "body" in show else ()) + tuple(k for k in ARROW_KEYS if k in show)
    solids += ("hodo_marker",) if "hodograph" in show else ()
    d_from_x = rotation_x_to(plan.d_body)
    stage = Stage(view=_view_direction(spec), lines=[], solids=solids,
                  body_from_shape=np.asarray(plan.shape.R_body_from_shape if plan.shape else np.eye(3), dtype=float),
                  marker_radius=0.022 * hodograph_range(plan)[2] if "hodograph" in show else 0.0,
                  trail_rgb=_trail_colors(theme.scene) if "trail" in show else None,
                  trail_frames=int(round(spec.trail_seconds * spec.fps)), hodograph="hodograph" in show,
                  labels=[], lights=[], poses=[_poses(panel, solids, d_from_x) for panel in plan.panels])
    points, border = content_points(plan), _border(layout, show)
    stage.lines, ticks = static_lines(plan, stage.view, theme.scene)
    camera, width = fit(stage.view, points, (x1 - x0, y1 - y0), border, spec.zoom)
    stage.lights = camera.lights()
    if width < x1 - x0:
        views = [(a + (c - a - width) // 2, b, a + (c - a - width) // 2 + width, d) for (a, b, c, d) in layout.views]
        layout = replace(layout, views=views)
    stage.labels = axis_labels(plan, layout, camera, ticks)
    return stage, camera, layout


def hodograph_only(spec) -> bool:
    """A scene that shows the hodograph and nothing that needs the orientation."""
    return "hodograph" in spec.show and not spec.needs_orientation


def _view_direction(spec) -> np.ndarray:
    """Unit vector (3,), world frame, from the origin towards the camera (``azimuth_deg``, ``elevation_deg``)."""
    az, el = math.radians(spec.azimuth_deg), math.radians(spec.elevation_deg)
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


def arrow_length(key: str, ratio: float) -> float:
    """Drawn length of an arrow whose quantity is ``ratio`` times its reference magnitude.

    key : "dipole", "omega" or "L"; ratio : |x(t)| / |x(0)| of the reference panel (the dipole
    arrow keeps its length).  Returns a length in units of the dipole arrow."""
    full = ARROWS[key][3]
    if key == "dipole":
        return full
    return ARROW_BASE + (full - ARROW_BASE) * min(max(ratio, 0.0), 1.5)


def _poses(panel, solids, d_from_x) -> dict:
    """Every frame's pose of each solid of ``panel`` (see ``Stage.poses``).  The arrows are
    turned frame by frame, as they were when drawn one frame at a time (same numbers)."""
    out = {}
    for key in ("L", "omega"):
        v = getattr(panel, ARROW_VECTORS[key])
        if key in solids and v is not None:
            out[key] = (np.array([rotation_x_to(x) for x in v]),
                        np.array([arrow_length(key, float(np.linalg.norm(x))) for x in v]))
    if panel.R_world_from_body is not None:
        rot = panel.R_world_from_body
        out["body"] = rot
        out["dipole"] = (rot @ d_from_x, np.full(rot.shape[0], ARROWS["dipole"][3]))
    if "hodo_marker" in solids:
        out["hodo_marker"] = panel.omega_body
    return out


def _trail_colors(colors) -> np.ndarray:
    """(TRAIL_POINTS, 3) uint8, oldest first: from near the background (6 %) to the trail colour.
    Opaque on purpose (a translucent actor sends every frame down the depth-sorting path,
    ~50 ms per 1440p frame on llvmpipe): the fade is a per-point colour."""
    age = np.linspace(0.0, 1.0, TRAIL_POINTS) ** 1.5
    bg, tc = np.asarray(colors["bg_rgb"]), np.asarray(colors["trail"])
    return ((bg + (tc - bg) * (0.06 + 0.94 * age)[:, None]) * 255).astype(np.uint8)


def static_lines(plan, view, colors) -> tuple[list, list]:
    """(lines [(points (n, 3), RGB floats)], hodograph ticks [(axis, value, point (3,))]): the
    back of the sphere cage as seen from ``view`` and the axes -- or the hodograph's axes with
    tick marks."""
    show = set(plan.spec.show)
    lines, ticks = [], []
    if "sphere" in show and not hodograph_only(plan.spec):
        lines += sphere_cage(view, colors)
    if "axes" in show and "hodograph" not in show:
        for i in range(3):
            e = np.zeros(3)
            e[i] = AXIS_LENGTH
            lines.append((np.array([np.zeros(3), e]), colors["axes"]))
    elif "axes" in show:
        axes, ticks = hodograph_axes(plan, colors["axes"])
        lines += axes
    return lines, ticks


# --- the camera's content ------------------------------------------------------------------
def _border(layout, show) -> tuple[float, float]:
    """Pixels kept free at the sides and at top and bottom of a view (labels reach out there)."""
    label = layout.sizes.size * 0.9 if "axes" in show else 0.0
    return EDGE_PX + 1.4 * label, EDGE_PX + 0.6 * label


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
