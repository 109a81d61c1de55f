"""The page's poster: the opening frame of each 3-D view as inline SVG, drawn by the browser
as soon as the markup arrives -- before the page's script has read its model -- and kept
where a browser cannot draw 3-D.

Pure NumPy and text (a planning module: no drawing library).  The view's camera is the page's
(``page_camera``): it looks at the model from the video's view direction at the video's panel
distance, with the video's up, and its field of view makes the square |x|, |y| <= ``R`` of the
image plane (tangent units: lateral offset / depth) fill the shorter side of the view, as the
SVG's ``viewBox`` does with ``preserveAspectRatio="xMidYMid meet"``; so the poster lies
exactly where the 3-D view then draws.  Painter's algorithm: the back half of the cage, the
axes, the solids' faces that face the camera, far to near, flat-shaded with the video's
lights (ambient + Lambert, ``camera.Camera.lights``), then the front half of the cage.
"""

from __future__ import annotations

import math

import numpy as np

from .camera import Camera
from .meshes import Part, arrow_head, arrow_shaft, body_part
from .stage import _circle_points, arrow_length, content_points, rotation_x_to
from .style import AMBIENT, ARROW_COLORS, ARROWS, AXIS_LENGTH, COLORS, body_color

__all__ = ["page_camera", "svg"]

MARGIN = 0.1               # of the view's half-side: the labels past the axes' and arrows' ends stay inside
SCALE = 1000.0             # viewBox units per R
SHAFT_PIECES = 8


def _frame(view) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    v = np.asarray(view, dtype=float)
    right = np.cross(-v, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return v, right, np.cross(right, -v)


def view_direction(spec) -> np.ndarray:
    """(3,) unit, spinviz world: from the origin towards the camera (``azimuth_deg``, ``elevation_deg``)."""
    az, el = math.radians(spec.azimuth_deg), math.radians(spec.elevation_deg)
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


def page_camera(plan) -> tuple[float, float]:
    """(distance D, half-extent R) of the page's view camera: D the video's panel distance
    (dipole-arrow units), R the largest |x| or |y| of any drawn point of any frame on the
    image plane (tangent units), with a margin."""
    view = view_direction(plan.spec)
    pts = content_points(plan)
    D = Camera(view, 1.0, pts, (MARGIN, MARGIN), plan.spec.zoom).distance
    xy = _project(pts, view, D)
    return float(D), float(np.max(np.abs(xy)) / (1.0 - MARGIN))


def _project(p, view, D) -> np.ndarray:
    v, right, up = _frame(view)
    p = np.atleast_2d(p)
    depth = D - p @ v
    return np.c_[(p @ right) / depth, (p @ up) / depth]


def _shade(rgb, normal, lit, view) -> np.ndarray:
    """The video's flat shading of faces (rgb, normal: (m, 3); lit: (m,) bool): colour x
    (ambient + Lambert of its three lights); an unlit face keeps its colour."""
    v, r, u = _frame(view)
    k = np.full(len(normal), AMBIENT)
    for d, w in ((-0.55 * r + 0.75 * u + 0.45 * v, 0.55), (0.85 * r - 0.15 * u + 0.35 * v, 0.22), (v, 0.25)):
        k += w * np.maximum(0.0, normal @ (d / np.linalg.norm(d)))
    return np.where(np.asarray(lit)[:, None], np.clip(np.asarray(rgb) * k[:, None], 0.0, 1.0), rgb)


def _hex(rgb) -> str:
    return "#{:02x}{:02x}{:02x}".format(*(int(round(255 * float(c))) for c in rgb))


def _solids(plan, k: int, f: int) -> list[tuple[Part, np.ndarray, np.ndarray]]:
    """(part, rotation (3, 3) world from part, translation (3,)) of the solids of panel k at frame f."""
    show = set(plan.spec.show)
    panel = plan.panels[k]
    out = []
    R = panel.R_world_from_body[f] if panel.R_world_from_body is not None else np.eye(3)
    if "body" in show and panel.R_world_from_body is not None:
        m = np.asarray(plan.shape.R_body_from_shape if plan.shape else np.eye(3), dtype=float)
        out.append((body_part(plan.shape, body_color(plan.body_name), m), R, np.zeros(3)))
    arrows = []
    if "dipole" in show and panel.R_world_from_body is not None:
        arrows.append(("dipole", R @ rotation_x_to(plan.d_body), ARROWS["dipole"][3]))
    for key, field in (("L", "L_world"), ("omega", "omega_world")):
        vec = getattr(panel, field)
        if key in show and vec is not None:
            arrows.append((key, rotation_x_to(vec[f]), arrow_length(key, float(np.linalg.norm(vec[f])))))
    for key, rot, length in arrows:
        shaft_r, head_len, head_r, _ = ARROWS[key]
        color = np.asarray(ARROW_COLORS[key])
        # the shaft in pieces, so that the part inside the body is sorted behind its faces
        unit, pieces = arrow_shaft(shaft_r, color), SHAFT_PIECES
        step = (length - head_len) / pieces
        shaft = Part.join([Part(unit.points * [step, 1.0, 1.0] + [i * step, 0.0, 0.0], unit.normals, unit.triangles,
                                unit.color, unit.lit) for i in range(pieces)])
        head = arrow_head(head_len, head_r, color)
        head = Part(head.points + [length - head_len, 0.0, 0.0], head.normals, head.triangles, head.color, head.lit)
        out += [(shaft, rot, np.zeros(3)), (head, rot, np.zeros(3))]
    return out


def svg(plan, k: int, D: float, R: float, f: int = 0, label_id: str = "alt") -> str:
    """Panel k's frame f as an inline SVG element (role img, labelled by the element
    ``label_id``), for a view camera at distance ``D`` whose image-plane square |x|, |y| <= R
    fills the view's shorter side."""
    view = view_direction(plan.spec)
    colors = COLORS[plan.spec.background]
    show = set(plan.spec.show)
    s = SCALE / R
    cam = view * D

    def xy(p):
        q = _project(p, view, D) * [s, -s]
        return " ".join(f"{a:.1f},{b:.1f}" for a, b in q)

    back, front = [], []
    if "sphere" in show:
        for c in _circle_points():
            c = c[::2]
            side = c @ view > 0.0
            for want, bucket in ((False, back), (True, front)):
                for run in _runs(c, side == want):
                    bucket.append(f'<polyline points="{xy(run)}" stroke="{_hex(colors["sphere"])}"/>')
    axes = []
    if "axes" in show:
        for i in range(3):
            e = np.zeros(3)
            e[i] = AXIS_LENGTH
            axes.append(f'<polyline points="{xy(np.array([np.zeros(3), e]))}" stroke="{_hex(colors["axes"])}"/>')
    faces = []
    for part, rot, shift in _solids(plan, k, f):
        p3 = (part.points @ rot.T + shift)[part.triangles]                     # (m, 3 corners, 3)
        n = (part.normals @ rot.T)[part.triangles].mean(axis=1)
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        centre = p3.mean(axis=1)
        seen = np.einsum("ij,ij->i", n, cam - centre) > 0.0                    # facing the camera
        rgb = _shade(part.color[part.triangles[:, 0]], n, part.lit[part.triangles[:, 0]], view)
        dist = np.linalg.norm(cam - centre, axis=1)
        faces += [(float(dist[i]), _hex(rgb[i]), xy(p3[i])) for i in np.flatnonzero(seen)]
    faces.sort(key=lambda x: -x[0])
    polys = [f'<polygon points="{p}" fill="{c}" stroke="{c}"/>' for _, c, p in faces]
    # stroke widths in viewBox units (2000 across a 300-600 px view): lines about a pixel, and the
    # faces' own colour drawn thinly along their edges, over the seams between them
    body = ("".join(back + axes) + '<g stroke-width="2.5" stroke-linejoin="round">' + "".join(polys) + "</g>"
            + "".join(front))
    return (f'<svg class="poster" id="poster-{k}" role="img" aria-labelledby="{label_id}" '
            f'viewBox="{-SCALE:.0f} {-SCALE:.0f} {2 * SCALE:.0f} {2 * SCALE:.0f}" preserveAspectRatio="xMidYMid meet" '
            f'xmlns="http://www.w3.org/2000/svg"><g fill="none" stroke-width="4">'
            f"{body}</g></svg>")


def _runs(c, mask) -> list[np.ndarray]:
    """The runs of consecutive points of the closed curve c (n, 3) where ``mask`` holds (two
    points at least), each extended by one point into its neighbours so that runs meet."""
    n = len(c)
    out = []
    idx = list(range(n))
    if mask.all():
        return [np.vstack([c, c[:1]])]
    # start at a point where the mask turns on
    first = next(i for i in idx if mask[i] and not mask[i - 1]) if mask.any() else None
    if first is None:
        return []
    order = idx[first:] + idx[:first]
    run = []
    for i in order:
        if mask[i]:
            run.append(i)
        elif run:
            out.append(run)
            run = []
    if run:
        out.append(run)
    return [c[[(r[0] - 1) % n] + r + [(r[-1] + 1) % n]] for r in out if len(r) >= 1]
