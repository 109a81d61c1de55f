"""The 3-D views: off-screen VTK windows that draw a picture's stage (``stage.Stage``).

What is cheap on software OpenGL (llvmpipe, 2 cores) decided the structure -- measured, see
``spinviz render --bench``:

* one window per panel, the size of the panel's 3-D view only (the text bands around it
  are a static layer, so no GL pixel is spent on them);
* per panel, one actor for every moving solid (body and arrows merged into one mesh whose
  vertices are turned and lit on the CPU -- a few hundred vertices -- and drawn unlit:
  fragment lighting costs ~11 ms per 720p frame, and every extra actor ~1 ms), one for the
  static lines (back half of the sphere cage and axes), one per curve (trail, hodograph);
* anti-aliasing by supersampling: the window is rendered at ``supersample`` x the output
  size and box-filtered down with PIL (2 = four samples per pixel); cheaper here than
  VTK's FXAA, SSAA or MSAA passes, and it smooths lines as well as edges.

Imports only the drawing stack and NumPy (VTK's render window directly, not
``pyvista.Plotter``, whose module imports matplotlib): a render worker is ready to draw
about a second after it starts.
"""

from __future__ import annotations

import os

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")   # no X server: go straight to EGL

import numpy as np
import pyvista as pv  # pyvista's meshes only: its plotting module imports matplotlib (~0.9 s)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL render window and mappers)
from PIL import Image
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkUnsignedCharArray
from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkRenderer, vtkRenderWindow

from .style import AMBIENT, ARROWS, HODO_COLOR, TRAIL_POINTS, VIEW_ANGLE


class Window:
    """One off-screen render window with one renderer, built from VTK directly (what a view
    needs of ``pyvista.Plotter``, without importing pyvista's plotting module and matplotlib
    in every render worker): unlit actors, per-point RGB or one colour."""

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
        """VTK's camera of the window's renderer."""
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

    def look(self, camera):
        """Point VTK's camera as the planned ``camera.Camera`` says."""
        cam = self.camera
        cam.SetFocalPoint(0.0, 0.0, 0.0)
        cam.SetPosition(*(camera.distance * camera.view))
        cam.SetViewUp(0.0, 0.0, 1.0)
        cam.SetViewAngle(VIEW_ANGLE)
        cam.SetWindowCenter(float(camera.center[0]), float(camera.center[1]))
        cam.SetClippingRange(max(1e-3, camera.distance - 2.0 * camera.rmax - 1.0),
                             camera.distance + 2.0 * camera.rmax + 1.0)

    def render(self):
        """Draw the window (off-screen)."""
        self.render_window.Render()

    def close(self):
        """Release the window and its actors."""
        self.renderer.RemoveAllViewProps()
        self.render_window.Finalize()


class Solids:
    """The moving solids of a panel as one mesh, turned and lit on the CPU each frame.

    Built from a ``meshes.Assembly`` (parts in their own frames, joined); ``place`` sets a
    part's linear map (a rotation, or a rotation times a stretch along the arrow), the
    rotation for its normals and a shift; ``commit`` writes points and colours once.
    Lambert shading from lights fixed in the world (the camera never moves); outline
    vertices are not lit.
    """

    def __init__(self, assembly, lights, window: Window):
        self.lights = lights
        self.part = assembly.part
        self.parts = {name: {"slice": sl, "lin": np.eye(3), "rot": np.eye(3), "shift": np.zeros(3)}
                      for name, sl in assembly.slices.items()}
        self.mesh = None
        if self.part is None:
            return
        faces = np.c_[np.full(len(self.part.triangles), 3), self.part.triangles].ravel()
        # a copy: the mesh's points are overwritten every frame, the assembly's are the parts at rest
        self.mesh = pv.PolyData(self.part.points.copy(), faces=faces)
        self.mesh.point_data["rgb"] = np.zeros((self.mesh.n_points, 3), dtype=np.uint8)
        self._rgb = self.mesh.point_data["rgb"]                  # shares memory with the VTK array
        self._vtk_rgb = self.mesh.GetPointData().GetArray("rgb")
        self._pts = self.mesh.points                             # so do the points: updated in place
        window.add_mesh(self.mesh, rgb=True)

    def place(self, name: str, rot3=None, shift=None, lin=None):
        """Set a part's rotation (3, 3) -- its normals turn with it --, its linear map (3, 3;
        default the rotation) and its shift (3,), world frame; None keeps a value."""
        p = self.parts[name]
        if rot3 is not None:
            p["rot"] = rot3
            p["lin"] = rot3 if lin is None else lin
        if shift is not None:
            p["shift"] = np.asarray(shift, dtype=float)

    def commit(self):
        """Write the placed, lit points and colours into the mesh."""
        pts = np.empty((self.mesh.n_points, 3))
        rgb = np.empty((self.mesh.n_points, 3))
        part = self.part
        for p in self.parts.values():
            sl = p["slice"]
            pts[sl] = part.points[sl] @ p["lin"].T + p["shift"]
            n = part.normals[sl] @ p["rot"].T
            k = np.full(n.shape[0], AMBIENT)
            for direction, intensity in self.lights:
                k += intensity * np.clip(n @ direction, 0.0, None)
            k = np.where(part.lit[sl], k, 1.0)
            rgb[sl] = part.color[sl] * k[:, None]
        self._pts[:] = pts
        self.mesh.GetPoints().Modified()
        self._rgb[:] = np.clip(rgb * 255.0, 0, 255).astype(np.uint8)
        self._vtk_rgb.Modified()


def _set_points(mesh, pts):
    """Move a mesh's points in place (no new VTK array per frame)."""
    view = mesh.points
    view[:] = pts
    mesh.GetPoints().Modified()


def lines_mesh(curves_rgb) -> pv.PolyData | None:
    """Polylines [(points (n, 3), RGB floats)] with per-point colours as one mesh.  Built with
    lines= in the constructor: PolyData(points) alone adds a vertex cell per point, drawn as
    dots along every curve."""
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


class PanelView:
    """One panel's 3-D view: its window, solids and curves, built from ``picture.stage``;
    ``show(f)`` poses them for frame f, ``image()`` renders at output resolution.

    k : the panel's index; assembly : the solids (``meshes.assemble``); window_size : px
    (the view's size times the supersampling factor ``supersample``)."""

    def __init__(self, picture, k: int, assembly, window_size, supersample: float):
        stage = picture.stage
        self.poses, self.ss = stage.poses[k], float(supersample)
        self.window = Window(window_size, picture.theme.scene["bg_rgb"])
        lw = max(1, int(round(self.ss)))
        mesh = lines_mesh(stage.lines)
        if mesh is not None:
            # 1-pixel lines at the supersampled size: wider GL lines are drawn as extra
            # triangles and cost ~2.5 ms per panel on llvmpipe
            self.window.add_mesh(mesh, rgb=True, line_width=1)
        self.solids = Solids(assembly, stage.lights, self.window)
        self.curves = {}
        panel = picture.plan.panels[k]
        if stage.trail_rgb is not None:
            self.trail = (panel.d_world, stage.trail_frames)
            self.curves["trail"] = pv.lines_from_points(np.zeros((TRAIL_POINTS, 3)))
            self.curves["trail"].point_data["rgb"] = stage.trail_rgb
            self.window.add_mesh(self.curves["trail"], rgb=True, line_width=2 * lw)
        if stage.hodograph:
            self.hodograph = panel.omega_body
            self.curves["hodograph"] = pv.lines_from_points(np.zeros((picture.frames, 3)))
            self.window.add_mesh(self.curves["hodograph"], color=HODO_COLOR, line_width=2 * lw)
        self.window.look(picture.camera)
        self._pixels = vtkUnsignedCharArray()                 # one per window: numpy views share it

    def show(self, f: int):
        """Pose the solids and curves for frame f (the stage's poses; the trail over its last
        ``trail_frames`` frames; the hodograph up to f, later points waiting at the current one)."""
        solids = self.solids
        for name, pose in self.poses.items():
            if name == "body" and "body" in solids.parts:
                solids.place("body", pose[f])
            elif name == "hodo_marker":
                solids.place("hodo_marker", shift=pose[f])
            elif name + "_shaft" in solids.parts:
                r, length = pose[0][f], pose[1][f]
                head_len = ARROWS[name][1]
                solids.place(name + "_shaft", r, lin=r @ np.diag([length - head_len, 1.0, 1.0]))
                solids.place(name + "_head", r, shift=r[:, 0] * (length - head_len))
        if solids.mesh is not None:
            solids.commit()
        if "trail" in self.curves:
            d_world, n = self.trail
            idx = np.linspace(max(0, f - n), f, TRAIL_POINTS).round().astype(int)
            _set_points(self.curves["trail"], d_world[idx])
        if "hodograph" in self.curves:
            pts = self.hodograph.copy()
            pts[f + 1:] = pts[f]
            _set_points(self.curves["hodograph"], pts)

    def image(self, view_size) -> Image.Image:
        """The view at output resolution ``view_size`` (PIL RGB image), without text."""
        w, h = self.window.render_window.GetSize()
        self.window.render()
        self.window.render_window.GetPixelData(0, 0, w - 1, h - 1, 1, self._pixels, 0)
        # rows come bottom-up: PIL flips (raw decoder, negative stride) and filters in C
        im = Image.frombuffer("RGB", (w, h), vtk_to_numpy(self._pixels), "raw", "RGB", 0, -1)
        if self.ss == 2.0:
            return im.reduce(2)
        if self.ss != 1.0:
            return im.resize(view_size, Image.BOX)
        return im

    def close(self):
        """Release the window."""
        self.window.close()
