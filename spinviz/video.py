"""Scene -> trajectories -> frame plan -> video: the orchestration behind ``spinviz render``.

Each model is simulated once, with the frame times as output instants, and only with the
orientation when something shown needs it.  Rendering (the heavy optional stack) is
imported only here, only when a video is asked for.
"""

from __future__ import annotations

import os
from dataclasses import replace

from .scene import RenderSpec, Scene
from .simulate import simulate
from .timeline import frame_times, plan_frames

OPTIONAL_RENDER_MODULES = {"pyvista", "vtk", "vtkmodules", "imageio", "imageio_ffmpeg", "PIL"}


class MissingRenderStack(ImportError):
    """The rendering extra is not installed; str() says what to install."""


def require_render_stack():
    """Import spinviz.render, or explain in one line which optional package is missing."""
    try:
        import imageio_ffmpeg  # noqa: F401
        import PIL  # noqa: F401
        import pyvista  # noqa: F401
        import vtk  # noqa: F401

        from . import render  # noqa: F401
    except ImportError as e:
        name = (e.name or "").split(".")[0]
        if name in OPTIONAL_RENDER_MODULES:
            raise MissingRenderStack(
                f"rendering needs the optional package {name!r}: pip install 'spinviz[render]'"
            ) from None
        raise
    from . import render

    return render


def spec_with(scene: Scene, size=None, fps=None, duration=None) -> RenderSpec:
    """The scene's render spec with command-line overrides."""
    kw = {}
    if size is not None:
        kw["size"] = tuple(int(x) for x in size)
        if len(kw["size"]) != 2 or min(kw["size"]) < 16:
            raise ValueError(f"size must be (width, height) of at least 16 px, got {size!r}")
    if fps is not None:
        kw["fps"] = int(fps)
        if not 1 <= kw["fps"] <= 240:
            raise ValueError(f"fps must be between 1 and 240, got {fps!r}")
    if duration is not None:
        kw["duration"] = float(duration)
        if not 0.0 < kw["duration"] < 3600.0:
            raise ValueError(f"duration must be between 0 and 3600 s, got {duration!r}")
    return replace(scene.render, **kw)


def scene_trajectories(scene: Scene, spec: RenderSpec):
    """One trajectory per model, stored at the frame times (kinematics only if shown)."""
    _, sim_t, _ = frame_times(spec, scene.t_end)
    kw = scene.simulation_kwargs(kinematics="quaternion" if spec.needs_orientation else "none", t_eval=sim_t)
    return [simulate(scene.body, m, **kw) for m in scene.models]


def plan_scene(scene: Scene, spec: RenderSpec):
    return plan_frames(spec, scene_trajectories(scene, spec))


def default_output(scene: Scene, directory: str = "renders") -> str:
    stem = os.path.splitext(os.path.basename(scene.path))[0]
    return os.path.join(directory, f"{stem}.mp4")
