"""Off-screen pyvista windows that draw the frames of a ``frameplan.FramePlan``.

Only the items listed in the scene's ``show`` are built.  What is cheap on software
OpenGL (llvmpipe, 2 cores) decided the structure -- measured, see ``spinviz render --bench``:

* one window per panel, the size of the panel's 3-D view only (the text bands around it
  are drawn by ``hud`` into a static layer, so no GL pixel is spent on them);
* per panel, one actor for every moving solid (body and arrows merged into one mesh whose
  vertices are turned and lit on the CPU -- a few hundred vertices -- and drawn unlit:
  fragment lighting costs ~11 ms per 720p frame, and every extra actor ~1 ms), one for the
  static lines (back half of the sphere cage and axes), one per curve (trail, hodograph);
* anti-aliasing by supersampling: the window is rendered at ``supersample`` x the output
  size and box-filtered down with PIL (2 = four samples per pixel); cheaper here than
  VTK's FXAA, SSAA or MSAA passes, and it smooths lines as well as edges;
* the camera is fitted once to everything any frame draws (both panels share it, so the
  views compare directly): nothing is clipped and no band of the view stays empty.

Imports only the drawing stack and NumPy (``geometry``, not ``spinviz.rotations``; VTK's
render window directly, not ``pyvista.Plotter``, whose module imports matplotlib): a render
worker is ready to draw about a second after it starts.
"""

from __future__ import annotations

import math
import os

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")   # no X server: go straight to EGL

import numpy as np
import pyvista as pv  # pyvista's meshes only: its plotting module imports matplotlib (~0.9 s)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL render window and mappers)
from PIL import Image
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkUnsignedCharArray
from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkRenderer, vtkRenderWindow

from . import hud, meshes
from .geometry import matrix_from_quat, rotation_x_to
from .meshes import BODY_RADIUS, Part

COLORS = {
    "white": {"bg": "white", "sphere": (0.70, 0.72, 0.77), "limb": (0.55, 0.57, 0.63), "axes": (0.30, 0.30, 0.34),
              "trail": (0.86, 0.08, 0.24), "bg_rgb": (1.0, 1.0, 1.0)},
    "black": {"bg": "black", "sphere": (0.30, 0.32, 0.38), "limb": (0.45, 0.47, 0.53), "axes": (0.75, 0.75, 0.78),
              "trail": (1.0, 0.3, 0.4), "bg_rgb": (0.0, 0.0, 0.0)},
}
BODY_COLORS = {"DAST": (0.96, 0.52, 0.16), "cellulose": (0.93, 0.74, 0.38)}
ROD_SECOND_COLOR = (0.28, 0.16, 0.07)      # the rod's dark half: its axial spin shows
BODY_COLOR = (0.72, 0.66, 0.58)
DIPOLE_COLOR = (0.86, 0.08, 0.24)
OMEGA_COLOR = (0.12, 0.35, 0.85)
L_COLOR = (0.10, 0.58, 0.25)
HODO_COLOR = (0.12, 0.35, 0.85)            # omega's curve: the colour of the Omega arrow
HODO_MARKER_COLOR = (0.10, 0.10, 0.12)      # "now" on the curve
ARROW_COLORS = {"dipole": DIPOLE_COLOR, "omega": OMEGA_COLOR, "L": L_COLOR}
# arrow geometry, in units of the dipole arrow: shaft radius, head length, head radius, and the
# length at full magnitude; the part beyond ARROW_BASE (about the body's surface) grows with
# |Omega| and |L| relative to their start, so the braking shows in the arrows.  Omega is thin
# and longer than L: for a sphere they are parallel and both stay visible.
ARROWS = {"dipole": (0.024, 0.20, 0.065, 1.0), "L": (0.034, 0.21, 0.08, 1.35), "omega": (0.016, 0.17, 0.052, 1.6)}
ARROW_BASE = 0.55
AXIS_LENGTH = 1.25
TRAIL_POINTS = 64
AMBIENT = 0.30
VIEW_ANGLE = 30.0


def body_color(name: str):
    for key, color in BODY_COLORS.items():
        if key.lower() in name.lower():
            return color
    return BODY_COLOR


def body_part(shape, name: str) -> Part:
    """The body in its body frame, true proportions, bounding radius BODY_RADIUS: a two-tone
    rod or a box with dark edges (a small sphere when the shape is unknown)."""
    color = np.asarray(body_color(name))
    if shape is None:
        return meshes.ball(0.3, color)
    if shape.kind == "rod":
        length, diameter = shape.dims
        k = BODY_RADIUS / math.hypot(0.5 * length, 0.5 * diameter)
        # a thin rod is drawn at least a sixth of its length thick, so that its painted halves
        # -- and with them its spin about its own axis -- can be seen (the true L/D is in the title)
        r = max(0.5 * diameter * k, 0.085 * length * k)
        part = meshes.two_tone_rod(r, 0.5 * length * k, color, np.asarray(ROD_SECOND_COLOR))
    else:
        # a needle-thin box (a slender inertia-equivalent body) is drawn at least 1/8 as thick
        # as it is long, so that it can be seen turning
        a, b, c = np.maximum(np.asarray(shape.dims, dtype=float), 0.125 * max(shape.dims))
        k = BODY_RADIUS / (0.5 * math.sqrt(a * a + b * b + c * c))
        part = meshes.box(0.5 * k * np.array([a, b, c]), color, 0.35 * color)
    m = matrix_from_quat(np.asarray(shape.q_body_from_shape, dtype=float))
    return Part(part.points @ m.T, part.normals @ m.T, part.triangles, part.color, part.lit)


def _circle_points():
    t = np.linspace(0.0, 2.0 * np.pi, 145)
    for lat in (-60, -30, 0, 30, 60):
        c, s = math.cos(math.radians(lat)), math.sin(math.radians(lat))
        yield np.c_[c * np.cos(t), c * np.sin(t), np.full_like(t, s)]
    for lon in range(0, 180, 30):
        c, s = math.cos(math.radians(lon)), math.sin(math.radians(lon))
        yield np.c_[np.cos(t) * c, np.cos(t) * s, np.sin(t)]


def _back_runs(curve, view):
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


def static_lines(curves_rgb) -> pv.PolyData | None:
    """Polylines with per-point colours as one mesh.  Built with lines= in the constructor:
    PolyData(points) alone adds a vertex cell per point, drawn as dots along every curve."""
    if not curves_rgb:
        return None
    pts, lines, col, start = [], [], [], 0
    for c, rgb in curves_rgb:
        pts.append(c)
        lines.append(np.r_[len(c), np.arange(start, start + len(c))])
        col.append(np.tile(np.asarray(rgb) * 255, (len(c), 1)))
        start += len(c)
    mesh = pv.PolyData(np.vstack(pts), lines=np.concatenate(lines))
    mesh.point_data["rgb"] = np.vstack(col).astype(np.uint8)
    return mesh


def sphere_cage(view, colors):
    """The back half of the unit-sphere cage (latitudes and meridians) and its outline circle
    (the limb, seen edge-on): lines that never cross in front of the body."""
    out = []
    for c in _circle_points():
        out += [(r, colors["sphere"]) for r in _back_runs(c, view)]
    a = np.cross(view, [0.0, 0.0, 1.0] if abs(view[2]) < 0.9 else [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(view, a)
    t = np.linspace(0.0, 2 * np.pi, 181)
    out.append((np.outer(np.cos(t), a) + np.outer(np.sin(t), b), colors["limb"]))
    return out


class Window:
    """One off-screen render window with one renderer, built from VTK directly (what the
    session needs of ``pyvista.Plotter``, without importing pyvista's plotting module and
    matplotlib in every render worker): unlit actors, per-point RGB or one colour."""

    def __init__(self, size, background):
        self.render_window = vtkRenderWindow()
        self.render_window.SetOffScreenRendering(1)
        self.render_window.SetMultiSamples(0)
        self.render_window.SetSize(int(size[0]), int(size[1]))
        self.renderer = vtkRenderer()
        self.renderer.SetBackground(*background)
        self.renderer.AutomaticLightCreationOff()
        self.render_window.AddRenderer(self.renderer)
        self.actors = []

    @property
    def camera(self):
        return self.renderer.GetActiveCamera()

    def add_mesh(self, mesh, rgb: bool = False, color=None, line_width: float = 1.0):
        """An unlit actor: coloured by the point array "rgb" (uint8) or by one ``color``."""
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(mesh)
        if rgb:
            mapper.SetScalarModeToUsePointFieldData()
            mapper.SelectColorArray("rgb")
            mapper.SetColorModeToDirectScalars()
            mapper.ScalarVisibilityOn()
        else:
            mapper.ScalarVisibilityOff()
        actor = vtkActor()
        actor.SetMapper(mapper)
        prop = actor.GetProperty()
        prop.LightingOff()
        prop.SetLineWidth(float(line_width))
        if color is not None:
            prop.SetColor(*color)
        self.renderer.AddActor(actor)
        self.actors.append(actor)
        return actor

    def render(self):
        self.render_window.Render()

    def close(self):
        self.renderer.RemoveAllViewProps()
        self.render_window.Finalize()


class Solids:
    """The moving solids of a panel as one mesh, turned and lit on the CPU each frame.

    Parts (``meshes.Part``) are added in their own frame; ``place`` sets a part's linear map
    (a rotation, or a rotation times a stretch along the arrow), the rotation for its
    normals and a shift; ``commit`` writes points and colours once.  Lambert shading from a
    key, a fill and a head light fixed in the world (the camera never moves); outline
    vertices are not lit.
    """

    def __init__(self, lights):
        self.lights = lights
        self.parts: dict[str, dict] = {}
        self.mesh = None

    def add(self, name: str, part: Part):
        self.parts[name] = {"part": part, "lin": np.eye(3), "rot": np.eye(3), "shift": np.zeros(3)}

    def build(self, plotter):
        if not self.parts:
            return None
        parts = [p["part"] for p in self.parts.values()]
        offsets = np.cumsum([0] + [p.points.shape[0] for p in parts])
        for p, lo, hi in zip(self.parts.values(), offsets[:-1], offsets[1:]):
            p["slice"] = slice(int(lo), int(hi))
        joined = Part.join(parts)
        faces = np.c_[np.full(len(joined.triangles), 3), joined.triangles].ravel()
        self.mesh = pv.PolyData(joined.points, faces=faces)
        self.mesh.point_data["rgb"] = np.zeros((self.mesh.n_points, 3), dtype=np.uint8)
        self._rgb = self.mesh.point_data["rgb"]                  # shares memory with the VTK array
        self._vtk_rgb = self.mesh.GetPointData().GetArray("rgb")
        self._pts = self.mesh.points                             # so do the points: updated in place
        self.commit()
        return plotter.add_mesh(self.mesh, rgb=True)

    def place(self, name: str, rot3=None, shift=None, lin=None):
        p = self.parts[name]
        if rot3 is not None:
            p["rot"] = rot3
            p["lin"] = rot3 if lin is None else lin
        if shift is not None:
            p["shift"] = np.asarray(shift, dtype=float)

    def commit(self):
        pts = np.empty((self.mesh.n_points, 3))
        rgb = np.empty((self.mesh.n_points, 3))
        for p in self.parts.values():
            part, sl = p["part"], p["slice"]
            pts[sl] = part.points @ p["lin"].T + p["shift"]
            n = part.normals @ p["rot"].T
            k = np.full(n.shape[0], AMBIENT)
            for direction, intensity in self.lights:
                k += intensity * np.clip(n @ direction, 0.0, None)
            k = np.where(part.lit, k, 1.0)
            rgb[sl] = part.color * k[:, None]
        self._pts[:] = pts
        self.mesh.GetPoints().Modified()
        self._rgb[:] = np.clip(rgb * 255.0, 0, 255).astype(np.uint8)
        self._vtk_rgb.Modified()


def _set_points(mesh, pts):
    """Move a mesh's points in place (no new VTK array per frame)."""
    view = mesh.points
    view[:] = pts
    mesh.GetPoints().Modified()


def arrow_length(key: str, ratio: float) -> float:
    """Drawn length of an arrow whose quantity is ``ratio`` times its reference magnitude."""
    full = ARROWS[key][3]
    if key == "dipole":
        return full
    return ARROW_BASE + (full - ARROW_BASE) * min(max(ratio, 0.0), 1.5)


class Camera:
    """A perspective camera looking at the origin from ``view`` (unit, world), fitted so that
    given points fill a viewport of aspect ``aspect`` within ``margin`` (in units of the
    half-viewport) -- its distance and the window centre (an off-axis shift) are solved for."""

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
            lo, hi = self._extent(pts, D)
            need = float(np.max((hi - lo) / 2.0 / target))
            if abs(need - 1.0) < 1e-4:
                break
            # the extent shrinks roughly as 1/D; keep the camera outside every point
            D = max(D * need, 1.05 * rmax + 1e-6)
        self.distance = D / zoom
        lo, hi = self._extent(pts, self.distance)
        self.center = 0.5 * (lo + hi)
        self.rmax = rmax

    def _ndc(self, pts, D):
        depth = D - pts @ self.view
        x = (pts @ self.right) / (depth * self.tan * self.aspect)
        y = (pts @ self.up) / (depth * self.tan)
        return np.c_[x, y]

    def _extent(self, pts, D):
        ndc = self._ndc(pts, D)
        return ndc.min(axis=0), ndc.max(axis=0)

    def apply(self, window):
        cam = window.camera
        cam.SetFocalPoint(0.0, 0.0, 0.0)
        cam.SetPosition(*(self.distance * self.view))
        cam.SetViewUp(0.0, 0.0, 1.0)
        cam.SetViewAngle(VIEW_ANGLE)
        cam.SetWindowCenter(float(self.center[0]), float(self.center[1]))
        cam.SetClippingRange(max(1e-3, self.distance - 2.0 * self.rmax - 1.0), self.distance + 2.0 * self.rmax + 1.0)

    def to_pixels(self, pts, box):
        """Output pixel (column, row) of world points in the viewport ``box`` (x0, y0, x1, y1)."""
        ndc = self._ndc(np.atleast_2d(np.asarray(pts, dtype=float)), self.distance) - self.center
        x0, y0, x1, y1 = box
        return np.c_[x0 + (ndc[:, 0] + 1.0) * 0.5 * (x1 - x0), y0 + (1.0 - ndc[:, 1]) * 0.5 * (y1 - y0)]


class RenderSession:
    """Off-screen windows for a plan; ``frame(f)`` returns the finished RGB image (H, W, 3).

    Each panel has its own window (the size of its 3-D view); all panels get the same
    camera, so the views compare directly.  ``project`` maps world points to output pixels
    (for tests); ``layout`` says where the text bands are.
    """

    def __init__(self, plan, supersample: float = 2.0):
        self.plan = plan
        self._d_from_x = rotation_x_to(plan.dipole_body)       # the dipole arrow in the body frame
        self._trail_frames = int(round(plan.spec.trail_seconds * plan.spec.fps))
        spec = plan.spec
        self.size = spec.size                  # validated by the spec (RenderSpec.check_output)
        self.ss = float(supersample)
        self.colors = COLORS[spec.background]
        self.show = set(spec.show)
        W, H = self.size
        self.layout = hud.make_layout(plan, W, H, self.show)
        self.hodo_only = "hodograph" in self.show and not spec.needs_orientation
        self.camera = self._fit_camera()
        x0, y0, x1, y1 = self.layout.views[0]
        self.view_size = (x1 - x0, y1 - y0)
        self.window = (max(1, int(round(self.view_size[0] * self.ss))), max(1, int(round(self.view_size[1] * self.ss))))
        self.plotters, self.solids, self.curves = [], [], []
        self.ticks = []
        for panel in plan.panels:
            p = Window(self.window, self.colors["bg_rgb"])
            self._build_panel(p, panel)
            self.camera.apply(p)
            self.plotters.append(p)
        self._pixels = [vtkUnsignedCharArray() for _ in self.plotters]    # one each: numpy views share them
        self.labels = self._axis_labels()
        colors = {k: tuple(int(round(255 * c)) for c in v) for k, v in ARROW_COLORS.items()}
        colors["body"] = tuple(int(round(255 * 0.6 * c)) for c in body_color(plan.body_name))
        self.hud = hud.Hud(plan, self.layout, hud.palette(spec.background), colors, self.labels)
        self.static = Image.fromarray(self.hud.static())
        self._restore = [(self.static.crop(box), box[:2]) for box in self.hud.dirty]   # constant: crop once
        self._canvas = None

    # -- building ---------------------------------------------------------------------------
    def _view_direction(self) -> np.ndarray:
        spec = self.plan.spec
        az, el = math.radians(spec.azimuth_deg), math.radians(spec.elevation_deg)
        return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])

    def _lights(self):
        """Key light from the upper left, a weaker fill from the right and a head light, fixed
        in the world (relative to the fixed camera): adjacent faces get different tones."""
        v, r, u = self.camera.view, self.camera.right, self.camera.up

        def unit(x):
            return x / np.linalg.norm(x)

        return [(unit(-0.55 * r + 0.75 * u + 0.45 * v), 0.55), (unit(0.85 * r - 0.15 * u + 0.35 * v), 0.22),
                (v, 0.25)]

    def _hodo_range(self):
        """Per axis (lo, hi) spanned by the hodographs, 0 included, with a 10 % border."""
        w = np.vstack([p.omega_body for p in self.plan.panels])
        lo, hi = np.minimum(w.min(axis=0), 0.0), np.maximum(w.max(axis=0), 0.0)
        span = float(np.max(hi - lo)) or 1.0
        return lo - 0.08 * span, hi + 0.08 * span, span

    def _hodo_axes(self):
        """Axis lines across the hodographs' range and tick marks at round values: (curves, ticks)
        with ticks [(axis, value, world point)]."""
        lo, hi, span = self._hodo_range()
        step = hud._nice_step(span, 6)
        size = 0.025 * span
        curves, ticks = [], []
        for i in range(3):
            a, b = np.zeros(3), np.zeros(3)
            a[i], b[i] = lo[i], hi[i]
            curves.append((np.array([a, b]), self.colors["axes"]))
            j = (i + 1) % 3 if i != 2 else 0
            for v in np.arange(math.ceil(lo[i] / step) * step, hi[i] + 1e-12, step):
                if abs(v) < 1e-12:
                    continue
                p = np.zeros(3)
                p[i] = v
                d = np.zeros(3)
                d[j] = size
                curves.append((np.array([p - d, p + d]), self.colors["axes"]))
                ticks.append((i, float(v), p))
        return curves, ticks

    def _content_points(self) -> np.ndarray:
        """Every world point any frame draws (or places a label at), both panels."""
        plan, show = self.plan, self.show
        pts = []
        if self.hodo_only or "hodograph" in show:
            for panel in plan.panels:
                pts.append(panel.omega_body)
            if "axes" in show:
                lo, hi, span = self._hodo_range()
                for i in range(3):
                    e = np.zeros(3)
                    e[i] = hi[i] + 0.1 * span
                    pts.append(e[None, :])
                    e = np.zeros(3)
                    e[i] = lo[i]
                    pts.append(e[None, :])
            if self.hodo_only:
                return np.vstack(pts)
        if "sphere" in show or "trail" in show:
            pts.append(np.vstack(list(_circle_points())))
        if "axes" in show:
            pts.append(np.eye(3) * AXIS_LENGTH)
        if "body" in show:
            d = np.vstack(list(_circle_points()))
            pts.append(d * BODY_RADIUS)
        for panel in plan.panels:
            if panel.dipole is not None and "dipole" in show:
                pts.append(panel.dipole * (ARROWS["dipole"][3] + 0.02))
            for key in ("omega", "L"):
                v = getattr(panel, key)
                if v is None:
                    continue
                n = np.linalg.norm(v, axis=1, keepdims=True)
                u = np.divide(v, n, out=np.zeros_like(v), where=n > 0)
                ln = np.array([arrow_length(key, float(x)) for x in n[:, 0]])
                pts.append(u * (ln[:, None] + 0.02))
        return np.vstack(pts) if pts else np.eye(3)

    def _border(self):
        """Pixels kept free at the sides and at top and bottom of a view (labels reach out there)."""
        px = 5.0                                              # keep drawn pixels this far from the view's edge
        label = self.layout.fonts.size * 0.9 if "axes" in self.show else 0.0
        return px + 1.4 * label, px + 0.6 * label

    def _margins(self, vw, vh):
        bx, by = self._border()
        return (min(0.5, 0.02 + 2 * bx / vw), min(0.5, 0.02 + 2 * by / vh))

    def _fit_camera(self) -> Camera:
        """The camera fitted to the content of every frame, and the 3-D views narrowed to the
        width the content needs (GL pixels are the cost; the rest of the panel is the static
        background), centred in their panels."""
        x0, y0, x1, y1 = self.layout.views[0]
        vw, vh = x1 - x0, y1 - y0
        pts = self._content_points()
        view, zoom = self._view_direction(), self.plan.spec.zoom
        cam = Camera(view, vw / vh, pts, self._margins(vw, vh), zoom)
        lo, hi = cam._extent(pts, cam.distance)
        need = ((hi[0] - lo[0]) / 2.0 * vw + 2 * self._border()[0]) / 0.98
        w2 = int(min(vw, 2 * math.ceil(need / 2.0 + 1)))
        if w2 < vw and zoom <= 1.0:
            views = []
            for (a, b, c, d) in self.layout.views:
                left = a + (c - a - w2) // 2
                views.append((left, b, left + w2, d))
            self.layout.views = views
            cam = Camera(view, w2 / vh, pts, self._margins(w2, vh), zoom)
        return cam

    def _build_panel(self, p, panel):
        lw = max(1, int(round(self.ss)))
        plan, show = self.plan, self.show
        curves = {}
        lines = []
        if "sphere" in show and not self.hodo_only:
            lines += sphere_cage(self._view_direction(), self.colors)
        if "axes" in show:
            if self.hodo_only or "hodograph" in show:
                axes, self.ticks = self._hodo_axes()
                lines += axes
            else:
                for i in range(3):
                    e = np.zeros(3)
                    e[i] = AXIS_LENGTH
                    lines.append((np.array([np.zeros(3), e]), self.colors["axes"]))
        mesh = static_lines(lines)
        if mesh is not None:
            # 1-pixel lines at the supersampled size: wider GL lines are drawn as extra
            # triangles and cost ~2.5 ms per panel on llvmpipe
            p.add_mesh(mesh, rgb=True, line_width=1)
        solids = Solids(self._lights())
        if "body" in show:
            solids.add("body", body_part(plan.shape, plan.body_name))
        for key in ("dipole", "L", "omega"):
            if key in show:
                shaft, head_len, head_r, _ = ARROWS[key]
                color = np.asarray(ARROW_COLORS[key])
                solids.add(key + "_shaft", meshes.arrow_shaft(shaft, color))
                solids.add(key + "_head", meshes.arrow_head(head_len, head_r, color))
        if "hodograph" in show:
            lo, hi, span = self._hodo_range()
            solids.add("hodo_marker", meshes.ball(0.022 * span, np.asarray(HODO_MARKER_COLOR)))
        self._place_arrows(solids, panel, 0)
        solids.build(p)
        if "trail" in show:
            # opaque on purpose (a translucent actor sends every frame down the depth-sorting
            # path, ~50 ms per 1440p frame on llvmpipe): the fade is a per-point colour that
            # runs from the background (oldest) to the trail colour (newest)
            curves["trail"] = pv.lines_from_points(np.zeros((TRAIL_POINTS, 3)))
            age = np.linspace(0.0, 1.0, TRAIL_POINTS) ** 1.5
            bg, tc = np.asarray(self.colors["bg_rgb"]), np.asarray(self.colors["trail"])
            curves["trail"].point_data["rgb"] = ((bg + (tc - bg) * (0.06 + 0.94 * age)[:, None]) * 255).astype(np.uint8)
            p.add_mesh(curves["trail"], rgb=True, line_width=2 * lw)
        if "hodograph" in show:
            curves["hodograph"] = pv.lines_from_points(np.zeros((plan.frames, 3)))
            p.add_mesh(curves["hodograph"], color=HODO_COLOR, line_width=2 * lw)
        self.solids.append(solids)
        self.curves.append(curves)

    def _place_arrows(self, solids, panel, f):
        if panel.q is not None:
            rot = matrix_from_quat(panel.q[f])
            if "body" in solids.parts:
                solids.place("body", rot)
            d_rot = rot @ self._d_from_x
        for key in ("dipole", "L", "omega"):
            if key + "_shaft" not in solids.parts:
                continue
            if key == "dipole":
                if panel.q is None:
                    continue
                r, length = d_rot, ARROWS["dipole"][3]
            else:
                v = getattr(panel, key)[f]
                r, length = rotation_x_to(v), arrow_length(key, float(np.linalg.norm(v)))
            head_len = ARROWS[key][1]
            solids.place(key + "_shaft", r, lin=r @ np.diag([length - head_len, 1.0, 1.0]))
            solids.place(key + "_head", r, shift=r[:, 0] * (length - head_len))

    def _axis_labels(self):
        """(text, output pixel) of the axis names and the hodograph's tick values; an axis name
        sits beside its axis's end, off the line, where an arrow along the axis leaves it free."""
        if "axes" not in self.show:
            return []
        out = []
        size = self.layout.fonts.size
        for k in range(len(self.plan.panels)):
            box = self.layout.views[k]
            if self.ticks:
                lo, hi, span = self._hodo_range()
                names = ("ω₁", "ω₂", "ω₃")
                for i in range(3):
                    e = np.zeros(3)
                    e[i] = hi[i] + 0.06 * span
                    out.append((names[i], tuple(self.camera.to_pixels(e, box)[0])))
                last = {}
                origin = self.camera.to_pixels(np.zeros(3), box)[0]
                # values on the axis that looks longest only: short axes near the origin would
                # crowd their labels together
                reach = [float(np.linalg.norm(self.camera.to_pixels(np.eye(3)[i] * (hi[i] - lo[i]), box)[0] - origin))
                         for i in range(3)]
                for i, v, p in self.ticks:
                    if i != int(np.argmax(reach)):
                        continue
                    # beside the axis, off the curve's side: left of a steep axis, under a flat one
                    e = np.zeros(3)
                    e[i] = 1.0
                    d = self.camera.to_pixels(e, box)[0] - origin
                    d /= np.linalg.norm(d) or 1.0
                    side = np.array([-d[1], d[0]])
                    if (abs(d[1]) > abs(d[0]) and side[0] > 0) or (abs(d[1]) <= abs(d[0]) and side[1] < 0):
                        side = -side
                    xy = self.camera.to_pixels(p, box)[0] + side * 1.1 * size
                    if i in last and np.linalg.norm(xy - last[i]) < 2.2 * size:
                        continue
                    last[i] = xy
                    out.append((f"{v:g}", tuple(xy)))
                continue
            origin = self.camera.to_pixels(np.zeros(3), box)[0]
            for i, name in enumerate(("x", "y", "z")):
                e = np.zeros(3)
                e[i] = AXIS_LENGTH
                end = self.camera.to_pixels(e, box)[0]
                d = end - origin
                d /= np.linalg.norm(d) or 1.0
                side = np.array([-d[1], d[0]])                       # perpendicular on screen
                if side[0] < 0:
                    side = -side
                xy = end + 0.8 * size * side
                out.append((name, tuple(xy)))
        return out

    # -- per frame --------------------------------------------------------------------------
    def update(self, f: int):
        plan = self.plan
        for k, panel in enumerate(plan.panels):
            solids, curves = self.solids[k], self.curves[k]
            self._place_arrows(solids, panel, f)
            if "hodo_marker" in solids.parts:
                solids.place("hodo_marker", shift=panel.omega_body[f])
            if solids.mesh is not None:
                solids.commit()
            if "trail" in curves:
                lo = max(0, f - self._trail_frames)
                idx = np.linspace(lo, f, TRAIL_POINTS).round().astype(int)
                _set_points(curves["trail"], panel.dipole[idx])
            if "hodograph" in curves:
                pts = panel.omega_body.copy()
                pts[f + 1:] = pts[f]
                _set_points(curves["hodograph"], pts)

    def render_views(self) -> list[Image.Image]:
        """Each panel's 3-D view at output resolution (PIL RGB images), without text."""
        w, h = self.window
        out = []
        for p, buf in zip(self.plotters, self._pixels):
            p.render()
            p.render_window.GetPixelData(0, 0, w - 1, h - 1, 1, buf, 0)
            # rows come bottom-up: PIL flips (raw decoder, negative stride) and filters in C
            im = Image.frombuffer("RGB", (w, h), vtk_to_numpy(buf), "raw", "RGB", 0, -1)
            if self.ss == 2.0:
                im = im.reduce(2)
            elif self.ss != 1.0:
                im = im.resize(self.view_size, Image.BOX)
            out.append(im)
        return out

    def compose(self) -> Image.Image:
        """The static layer with the 3-D views pasted in (a PIL image: the per-frame text is
        blended in C by Pillow, with no NumPy round trip).  One canvas is reused: only the
        boxes that per-frame text touched are restored from the static layer (a full copy
        of a 720p frame costs ~2.5 ms)."""
        if self._canvas is None:
            self._canvas = self.static.copy()
        else:
            for patch, corner in self._restore:
                self._canvas.paste(patch, corner)
        img = self._canvas
        for (x0, y0, _, _), view in zip(self.layout.views, self.render_views()):
            img.paste(view, (x0, y0))
        return img

    def frame(self, f: int) -> np.ndarray:
        """Frame f as an RGB uint8 array of shape (H, W, 3)."""
        self.update(f)
        return np.asarray(self.hud.draw(self.compose(), f))

    def project(self, panel: int, point) -> tuple[float, float]:
        """Pixel (column, row) in the output image of a world point seen in ``panel``."""
        xy = self.camera.to_pixels(point, self.layout.views[panel])[0]
        return float(xy[0]), float(xy[1])

    def close(self):
        for p in self.plotters:
            p.close()
