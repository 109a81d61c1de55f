"""Off-screen pyvista windows that draw the frames of a ``timeline.FramePlan``.

Only the items listed in the scene's ``show`` are built.  What is cheap on software
OpenGL (llvmpipe, 2 cores) decided the structure -- measured, see ``spinviz render --bench``:

* one window per panel (two renderers in one window cost twice the per-frame overhead);
* per panel, one actor for every moving solid (body and arrows merged into one mesh whose
  vertices are turned and lit on the CPU -- a few hundred vertices -- and drawn unlit:
  fragment lighting costs ~11 ms per 720p frame, and every extra actor ~1 ms), one for the
  static lines (sphere and axes), one per curve (trail, hodograph);
* anti-aliasing by supersampling: the window is rendered at ``supersample`` x the output
  size and box-filtered down with PIL (2 = four samples per pixel); cheaper here than
  VTK's FXAA, SSAA or MSAA passes, and it smooths lines as well as edges;
* heads-up text drawn on the final frame with Pillow (``hud``).
"""

from __future__ import annotations

import math
import os

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")   # no X server: go straight to EGL

import numpy as np
import pyvista as pv
import vtk
from PIL import Image
from vtkmodules.util.numpy_support import vtk_to_numpy

from .. import rotations as R
from . import hud

COLORS = {
    "white": {"bg": "white", "fg": (20, 20, 20), "sphere": (0.62, 0.64, 0.69), "axes": (0.25, 0.25, 0.28),
              "trail": (0.86, 0.08, 0.24)},
    "black": {"bg": "black", "fg": (235, 235, 235), "sphere": (0.42, 0.44, 0.50), "axes": (0.80, 0.80, 0.82),
              "trail": (1.0, 0.3, 0.4)},
}
BODY_COLORS = {"DAST": (0.95, 0.55, 0.22), "cellulose": (0.86, 0.80, 0.62)}
BODY_COLOR = (0.78, 0.70, 0.58)
DIPOLE_COLOR = (0.86, 0.08, 0.24)
OMEGA_COLOR = (0.12, 0.35, 0.85)
L_COLOR = (0.10, 0.60, 0.25)
HODO_COLOR = (0.12, 0.35, 0.85)
BODY_RADIUS = 0.62       # the body's bounding radius, in units of the dipole arrow (tip on the unit sphere)
ARROW_LENGTH = {"omega": 1.45, "L": 1.65}   # direction arrows, longer than the dipole; magnitudes are in the HUD
AXIS_LENGTH = 1.35
TRAIL_POINTS = 64
AMBIENT = 0.32


def _matrix(rot3) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = rot3
    return m


def _rotation_x_to(v) -> np.ndarray:
    """3x3 rotation taking +x to the direction of v (identity for v = 0)."""
    if float(np.linalg.norm(v)) == 0.0:
        return np.eye(3)
    return R.matrix_from_quat(R.quat_between((1.0, 0.0, 0.0), v))


def body_mesh(shape) -> pv.PolyData:
    """The body in its own shape frame, true proportions, bounding radius BODY_RADIUS."""
    if shape is None:
        return pv.Sphere(radius=0.3)
    if shape.kind == "rod":
        length, diameter = shape.dims
        k = BODY_RADIUS / math.hypot(0.5 * length, 0.5 * diameter)
        return pv.Cylinder(center=(0, 0, 0), direction=(0, 0, 1), radius=0.5 * diameter * k, height=length * k,
                           resolution=48, capping=True)
    a, b, c = shape.dims
    k = BODY_RADIUS / (0.5 * math.sqrt(a * a + b * b + c * c))
    return pv.Box(bounds=(-0.5 * a * k, 0.5 * a * k, -0.5 * b * k, 0.5 * b * k, -0.5 * c * k, 0.5 * c * k))


def rod_stripe(shape) -> pv.PolyData | None:
    """A thin darker stripe along a rod's side, so that its spin about its own axis shows."""
    if shape is None or shape.kind != "rod":
        return None
    length, diameter = shape.dims
    k = BODY_RADIUS / math.hypot(0.5 * length, 0.5 * diameter)
    r, half = 0.5 * diameter * k, 0.5 * length * k
    return pv.Box(bounds=(0.9 * r, 1.08 * r, -0.3 * r, 0.3 * r, -0.97 * half, 0.97 * half))


def body_color(name: str):
    for key, color in BODY_COLORS.items():
        if key.lower() in name.lower():
            return color
    return BODY_COLOR


def _circle_points():
    t = np.linspace(0.0, 2.0 * np.pi, 121)
    for lat in (-60, -30, 0, 30, 60):
        c, s = math.cos(math.radians(lat)), math.sin(math.radians(lat))
        yield np.c_[c * np.cos(t), c * np.sin(t), np.full_like(t, s)]
    for lon in range(0, 180, 30):
        c, s = math.cos(math.radians(lon)), math.sin(math.radians(lon))
        yield np.c_[np.cos(t) * c, np.cos(t) * s, np.sin(t)]


def static_lines(sphere: bool, axes: bool, colors) -> pv.PolyData:
    """The faint unit sphere (latitudes, meridians) and the world axes as one line mesh with
    per-point colours.  Built with lines= in the constructor: PolyData(points) alone adds a
    vertex cell per point, drawn as dots along every circle."""
    curves, rgbs = [], []
    if sphere:
        for c in _circle_points():
            curves.append(c)
            rgbs.append(colors["sphere"])
    if axes:
        for i in range(3):
            e = np.zeros(3)
            e[i] = AXIS_LENGTH
            curves.append(np.array([np.zeros(3), e]))
            rgbs.append(colors["axes"])
    pts, lines, col, start = [], [], [], 0
    for c, rgb in zip(curves, rgbs):
        pts.append(c)
        lines.append(np.r_[len(c), np.arange(start, start + len(c))])
        col.append(np.tile(np.asarray(rgb) * 255, (len(c), 1)))
        start += len(c)
    mesh = pv.PolyData(np.vstack(pts), lines=np.concatenate(lines))
    mesh.point_data["rgb"] = np.vstack(col).astype(np.uint8)
    return mesh


class Solids:
    """The moving solids of a panel as one mesh, turned and lit on the CPU each frame.

    Parts are added with their own vertices (in their own frame) and a colour; ``place``
    sets one part's rotation and translation; ``commit`` writes points and colours once.
    Lambert shading from fixed directional lights (the camera never moves) per vertex, with
    normals split at sharp edges so box faces stay flat.
    """

    def __init__(self, lights):
        self.lights = lights
        self.parts: dict[str, dict] = {}
        self.mesh = None

    def add(self, name: str, mesh: pv.PolyData, color):
        mesh = mesh.triangulate().compute_normals(point_normals=True, cell_normals=False, split_vertices=True,
                                                  feature_angle=40.0, auto_orient_normals=False,
                                                  consistent_normals=False)
        self.parts[name] = {"mesh": mesh, "color": np.asarray(color, dtype=float),
                            "normals": np.asarray(mesh.point_data["Normals"], dtype=float),
                            "points": np.asarray(mesh.points, dtype=float), "rot": np.eye(3), "shift": np.zeros(3)}

    def build(self, plotter):
        if not self.parts:
            return None
        meshes = [p["mesh"] for p in self.parts.values()]
        offsets = np.cumsum([0] + [m.n_points for m in meshes])
        faces = []
        for m, off in zip(meshes, offsets[:-1]):
            f = m.faces.reshape(-1, 4).copy()
            f[:, 1:] += off
            faces.append(f.ravel())
        for p, lo, hi in zip(self.parts.values(), offsets[:-1], offsets[1:]):
            p["slice"] = slice(int(lo), int(hi))
        self.mesh = pv.PolyData(np.vstack([p["points"] for p in self.parts.values()]), faces=np.concatenate(faces))
        self.mesh.point_data["rgb"] = np.zeros((self.mesh.n_points, 3), dtype=np.uint8)
        self._rgb = self.mesh.point_data["rgb"]                  # shares memory with the VTK array
        self._vtk_rgb = self.mesh.GetPointData().GetArray("rgb")
        self.commit()
        return plotter.add_mesh(self.mesh, scalars="rgb", rgb=True, lighting=False, show_scalar_bar=False)

    def place(self, name: str, rot3=None, shift=None):
        p = self.parts[name]
        if rot3 is not None:
            p["rot"] = rot3
        if shift is not None:
            p["shift"] = np.asarray(shift, dtype=float)

    def commit(self):
        pts = np.empty((self.mesh.n_points, 3))
        rgb = np.empty((self.mesh.n_points, 3))
        for p in self.parts.values():
            r = p["rot"]
            pts[p["slice"]] = p["points"] @ r.T + p["shift"]
            n = p["normals"] @ r.T
            k = np.full(n.shape[0], AMBIENT)
            for direction, intensity in self.lights:
                k += intensity * np.clip(n @ direction, 0.0, None)
            rgb[p["slice"]] = p["color"][None, :] * k[:, None]
        self.mesh.points = pts
        self._rgb[:] = np.clip(rgb * 255.0, 0, 255).astype(np.uint8)
        self._vtk_rgb.Modified()


class RenderSession:
    """Off-screen windows for a plan; ``frame(f)`` returns the finished RGB image (H, W, 3).

    Each panel has its own window; all panels get the same camera, so the views are
    directly comparable.  ``project`` maps world points to output pixels (for tests).
    """

    def __init__(self, plan, supersample: float = 2.0):
        self.plan = plan
        spec = plan.spec
        self.size = spec.size                  # validated by the spec (RenderSpec.check_output)
        self.ss = float(supersample)
        self.colors = COLORS[spec.background]
        n = len(plan.panels)
        W, H = self.size
        self.panel_width = W // n
        self.window = (int(round(self.panel_width * self.ss)), int(round(H * self.ss)))
        self.show = set(spec.show)
        self.plotters, self.solids, self.curves = [], [], []
        for panel in plan.panels:
            p = pv.Plotter(off_screen=True, window_size=self.window, lighting="none")
            p.disable_anti_aliasing()
            p.set_background(self.colors["bg"])
            self._build_panel(p, panel)
            self._set_camera(p)
            p.show(auto_close=False)
            self.plotters.append(p)
        self._pixels = [vtk.vtkUnsignedCharArray() for _ in self.plotters]    # one each: numpy views share them
        self.labels = self._axis_labels()
        self.fonts = hud.Fonts(H)
        self.stamp = hud.TextStamp()

    # -- building ---------------------------------------------------------------------------
    def _view_direction(self) -> np.ndarray:
        spec = self.plan.spec
        az, el = math.radians(spec.azimuth_deg), math.radians(spec.elevation_deg)
        return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])

    def _lights(self):
        """Directional lights fixed in the world: a head light from the camera, a key light from above."""
        key = np.array([1.0, -2.0, 4.0]) / math.sqrt(21.0)
        return [(self._view_direction(), 0.5), (key, 0.45)]

    def _build_panel(self, p, panel):
        lw = max(1, int(round(self.ss)))
        plan, show = self.plan, self.show
        curves = {}
        hodo_only = "hodograph" in show and not plan.spec.needs_orientation
        sphere, axes = "sphere" in show and not hodo_only, "axes" in show
        if sphere or axes:
            # 1-pixel lines at the supersampled size: wider GL lines are drawn as extra
            # triangles and cost ~2.5 ms per panel on llvmpipe
            p.add_mesh(static_lines(sphere, axes, self.colors), scalars="rgb", rgb=True, line_width=1, lighting=False,
                       show_scalar_bar=False)
        solids = Solids(self._lights())
        if "body" in show:
            qs = np.asarray(plan.shape.q_body_from_shape if plan.shape is not None else (1.0, 0.0, 0.0, 0.0))
            to_body = _matrix(R.matrix_from_quat(qs))
            color = body_color(plan.body_name)
            solids.add("body", body_mesh(plan.shape).transform(to_body, inplace=False), color)
            stripe = rod_stripe(plan.shape)
            if stripe is not None:
                solids.add("stripe", stripe.transform(to_body, inplace=False), tuple(0.55 * c for c in color))
        if "dipole" in show:
            solids.add("dipole", pv.Arrow(start=(0, 0, 0), direction=plan.dipole_body, tip_length=0.22, tip_radius=0.06,
                                          shaft_radius=0.022, scale=1.0), DIPOLE_COLOR)
        for key, color in (("omega", OMEGA_COLOR), ("L", L_COLOR)):
            if key in show:
                L = ARROW_LENGTH[key]
                solids.add(key, pv.Arrow(start=(0, 0, 0), direction=(1, 0, 0), tip_length=0.18 / L, tip_radius=0.045 / L,
                                         shaft_radius=0.016 / L, scale=L), color)
        if "hodograph" in show:
            solids.add("hodo_marker", pv.Sphere(radius=0.035, theta_resolution=16, phi_resolution=12), DIPOLE_COLOR)
        solids.build(p)
        if "trail" in show:
            # opaque on purpose: a translucent actor sends every frame down the depth-sorting
            # path, which costs ~50 ms per frame at 2560x1440 on llvmpipe
            curves["trail"] = pv.lines_from_points(np.zeros((TRAIL_POINTS, 3)))
            p.add_mesh(curves["trail"], color=self.colors["trail"], line_width=2 * lw, lighting=False)
        if "hodograph" in show:
            curves["hodograph"] = pv.lines_from_points(np.zeros((plan.frames, 3)))
            p.add_mesh(curves["hodograph"], color=HODO_COLOR, line_width=2 * lw, lighting=False)
        self.solids.append(solids)
        self.curves.append(curves)

    def _set_camera(self, p):
        spec = self.plan.spec
        aspect = self.panel_width / self.size[1]
        view_angle = 30.0
        radius = 1.45                                   # unit sphere, axes and arrows
        dist = radius / math.sin(math.radians(view_angle / 2)) / min(1.0, aspect) / spec.zoom
        cam = p.camera
        cam.focal_point = (0.0, 0.0, 0.0)
        cam.position = tuple(dist * self._view_direction())
        cam.up = (0.0, 0.0, 1.0)
        cam.view_angle = view_angle
        cam.clipping_range = (0.1 * dist, 3.0 * dist)

    def _axis_labels(self):
        if "axes" not in self.show:
            return []
        names = ("x", "y", "z") if self.plan.spec.needs_orientation else ("\u03c91", "\u03c92", "\u03c93")
        out = []
        for k in range(len(self.plan.panels)):
            for i in range(3):
                e = np.zeros(3)
                e[i] = AXIS_LENGTH * 1.06
                out.append((names[i], self.project(k, e)))
        return out

    # -- per frame --------------------------------------------------------------------------
    def update(self, f: int):
        plan = self.plan
        for k, panel in enumerate(plan.panels):
            solids, curves = self.solids[k], self.curves[k]
            if panel.q is not None:
                rot = R.matrix_from_quat(panel.q[f])
                for key in ("body", "stripe", "dipole"):
                    if key in solids.parts:
                        solids.place(key, rot)
            for key in ("omega", "L"):
                if key in solids.parts:
                    solids.place(key, _rotation_x_to(getattr(panel, key)[f]))
            if "hodo_marker" in solids.parts:
                solids.place("hodo_marker", shift=panel.omega_body[f])
            if solids.mesh is not None:
                solids.commit()
            if "trail" in curves:
                lo = max(0, f - int(round(plan.spec.trail_seconds * plan.spec.fps)))
                idx = np.linspace(lo, f, TRAIL_POINTS).round().astype(int)
                curves["trail"].points = panel.dipole[idx]
            if "hodograph" in curves:
                pts = panel.omega_body.copy()
                pts[f + 1:] = pts[f]
                curves["hodograph"].points = pts

    def render_raw(self) -> np.ndarray:
        """The supersampled renders, side by side at the output size, without text."""
        w, h = self.window
        out_size = (self.panel_width, self.size[1])
        parts = []
        for p, buf in zip(self.plotters, self._pixels):
            p.render()
            p.render_window.GetPixelData(0, 0, w - 1, h - 1, 1, buf, 0)
            # rows come bottom-up: PIL flips (raw decoder, negative stride) and filters in C
            im = Image.frombuffer("RGB", (w, h), vtk_to_numpy(buf), "raw", "RGB", 0, -1)
            if self.ss == 2.0:
                im = im.reduce(2)
            elif self.ss != 1.0:
                im = im.resize(out_size, Image.BOX)
            parts.append(np.asarray(im))
        return parts[0].copy() if len(parts) == 1 else np.concatenate(parts, axis=1)

    def frame(self, f: int) -> np.ndarray:
        """Frame f as an RGB uint8 array of shape (H, W, 3)."""
        self.update(f)
        img = self.render_raw()
        if "hud" in self.show or self.labels:
            img = hud.draw(img, self.plan, f, self.fonts, self.stamp, self.colors["fg"], self.labels,
                           show_text="hud" in self.show)
        return img

    def project(self, panel: int, point) -> tuple[float, float]:
        """Pixel (column, row) in the output image of a world point seen in ``panel``."""
        c = vtk.vtkCoordinate()
        c.SetCoordinateSystemToWorld()
        c.SetValue(*map(float, point))
        x, y = c.GetComputedDoubleDisplayValue(self.plotters[panel].renderer)
        sx = self.panel_width / self.window[0]
        sy = self.size[1] / self.window[1]
        return (panel * self.panel_width + x * sx, (self.window[1] - y) * sy)

    def close(self):
        for p in self.plotters:
            p.close()
