"""Scene or trajectories -> frame plan -> video or frames: ``spinviz.render``, ``render_frame``.

A scene is simulated once per model, with the frame times as output instants and with the
orientation only when something shown needs it; trajectories are used as they are (the
renderer never steps physics).  Rendering (the heavy optional stack) is imported only
when a picture is asked for.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from .atomic import check_outputs
from .driver import simulate_request
from .errors import SpecError, SpecTypeError, UsageError
from .inputs.render import MODEL_FORMATS, RenderArguments, RenderSpec, default_output, poster_for
from .inputs.scene_spec import Scene, load_scene
from .rendering.timeline import FramePlan, frame_times, plan_frames
from .trajectory import Trajectory

__all__ = ["render", "render_frame", "frame_at", "Renderer", "plan", "require_render_stack", "default_output"]

OPTIONAL_RENDER_MODULES = {"pyvista", "vtk", "vtkmodules", "imageio", "imageio_ffmpeg", "PIL"}
MAX_STORED_TURN = np.pi / 2         # slerp between stored orientations needs neighbours closer than this

Source = Scene | str | os.PathLike | Trajectory | Sequence[Trajectory]


class MissingRenderStack(UsageError, ImportError):
    """The rendering extra is not installed; str() says what to install."""


def require_render_stack():
    """The drawing layer's front door, ``spinviz.rendering.video``, imported.

    The drawing stack itself (pyvista, VTK) is only looked up here, not imported: with
    worker processes the parent never draws, and importing VTK would cost it a second.

    Raises
    ------
    MissingRenderStack
        An optional package of the ``render`` extra is missing; the message says which.
    """
    import importlib.util

    try:
        for name in ("imageio_ffmpeg", "PIL", "pyvista", "vtkmodules"):
            if importlib.util.find_spec(name) is None:
                raise ImportError(f"No module named {name!r}", name=name)
        from .rendering import video
    except ImportError as e:
        name = (e.name or "").split(".")[0]
        if name in OPTIONAL_RENDER_MODULES:
            raise MissingRenderStack(
                f"rendering needs the optional package {name!r}: pip install 'spinviz[render]'"
            ) from None
        raise
    return video


# --- what to draw ------------------------------------------------------------------------
SOURCE_KINDS = "a Scene, the path of a scene file, a Trajectory or a list of one or two Trajectories"


def _as_source(source: Source):
    """(scene or None, trajectories or None) from any accepted source; ``SpecTypeError``
    naming ``source`` otherwise."""
    if isinstance(source, (str, os.PathLike)):
        return load_scene(source), None
    if isinstance(source, Scene):
        return source, None
    if isinstance(source, Trajectory):
        return None, [source]
    if isinstance(source, (list, tuple)) and 1 <= len(source) <= 2 and all(isinstance(t, Trajectory) for t in source):
        return None, list(source)
    raise SpecTypeError("source", f"must be {SOURCE_KINDS}, got {type(source).__name__}")


def _horizon(scene, trajs) -> float:
    """The end of the run (scene time unit): the scene's horizon or the first trajectory's end."""
    return scene.t_end if scene is not None else float(trajs[0].t[-1])


def resolve_spec(source: Source, **overrides) -> tuple[Scene | None, list[Trajectory] | None, RenderSpec]:
    """The source and its render spec.

    Parameters
    ----------
    source : Scene, path, Trajectory or list of one or two Trajectories
        A scene (loaded here if a path) or stored trajectories (one panel each).
    **overrides
        ``RenderSpec`` fields (size, fps, duration, show, ...) replacing a scene's
        ``[render]`` table, or the defaults for trajectories; None keeps a field.

    Returns
    -------
    (scene or None, trajectories or None, RenderSpec)
        The spec is validated, including its log knee against the run's horizon.
    """
    scene, trajs = _as_source(source)
    base = scene.render if scene is not None else RenderSpec()
    spec = base.with_(**overrides)
    spec.check_horizon(_horizon(scene, trajs))
    return scene, trajs, spec


def scene_trajectories(scene: Scene, spec: RenderSpec, t_end: float | None = None) -> list[Trajectory]:
    """One trajectory per model of ``scene``, stored at the frame times of ``spec`` over
    [0, t_end] (scene time unit, default the scene's horizon); the orientation is integrated
    only when something shown needs it (quaternion kinematics, else none)."""
    _, sim_t, _ = frame_times(spec, scene.t_end if t_end is None else t_end)
    kinematics = "quaternion" if spec.needs_orientation else "none"
    return [simulate_request(scene.request(m, kinematics=kinematics, t_eval=sim_t)) for m in scene.models]


def _check_drawable(trajs: list[Trajectory] | None, spec: RenderSpec) -> None:
    """Frames are interpolated between stored instants: orientations must be stored closely
    enough for slerp (or carry the slow geometry of a ``secular`` run).  None (a scene, to be
    simulated at the frame times) passes."""
    if trajs is None or not spec.needs_orientation:
        return
    for tr in trajs:
        if tr.q is None:
            raise SpecError("source", f"this {tr.model} trajectory has no orientation; simulate with "
                                      f"kinematics=\"quaternion\" or show only the hodograph")
        if tr.slow is not None:
            continue
        turn = float(np.max(tr.omega_magnitude[:-1] * np.diff(tr.t))) if tr.t.size > 1 else 0.0
        if turn > MAX_STORED_TURN:
            raise SpecError("source", f"the {tr.model} trajectory is stored too coarsely to draw (up to "
                                      f"{np.degrees(turn):.0f} deg between samples); simulate it at more instants")


def plan(source: Source, t_end: float | None = None, frames: int | None = None, **overrides) -> FramePlan:
    """The frame plan of a video of ``source``: what each frame shows, independent of the
    frame size (a scene is simulated at the frame times; no drawing library is loaded).

    Parameters
    ----------
    source : Scene, path, Trajectory or list of one or two Trajectories
    t_end : float, optional
        The video ends at this simulation time (scene time unit); default the whole run.
    frames : int, optional
        Number of frames F; default ``duration * fps`` of the spec.
    **overrides
        ``RenderSpec`` fields replacing ``[render]`` settings.

    Returns
    -------
    FramePlan
        Frame times (F,), and per panel the shown orientation (F, 4), world-frame vectors
        (F, 3) and readouts; see ``rendering.frameplan``.
    """
    args = RenderArguments(t_end=t_end, frames=frames)
    scene, trajs, spec = resolve_spec(source, **overrides)
    return _plan(scene, trajs, spec, args.t_end, args.frames)


def _plan(scene, trajs, spec: RenderSpec, t_end=None, frames=None) -> FramePlan:
    """Trajectories at the frame times -- a scene simulated at them, given trajectories
    checked and, for a shorter video, sampled at them -- and their frame plan."""
    end = _within("t_end", t_end, _horizon(scene, trajs))
    _check_drawable(trajs, spec)
    if scene is not None:
        trajs = scene_trajectories(scene, spec, end)
    elif t_end is not None:
        trajs = [tr.sample(frame_times(spec, end, frames)[1]) for tr in trajs]
    return plan_frames(spec, trajs, frames)


def _within(name: str, t, horizon: float, start_open: bool = True) -> float:
    """``t`` (argument ``name``) checked against the run: in (0, horizon] (or [0, horizon]
    with ``start_open`` False); the horizon when None."""
    if t is None:
        return horizon
    if not ((0.0 < t) if start_open else (0.0 <= t)) or not t <= horizon:
        raise SpecError(name, f"must lie in {'(' if start_open else '['}0, {horizon:g}] (the run's time, in its unit), "
                              f"got {t:g}")
    return t


# --- pictures ------------------------------------------------------------------------------
class Renderer:
    """Off-screen windows drawing the frames of one plan; use as a context manager so that
    the windows are released::

        with spinviz.Renderer("scenes/default.toml", size=(640, 360)) as r:
            img = r.frame(r.frames - 1)        # (360, 640, 3) uint8

    Parameters
    ----------
    source : Scene, path, Trajectory or list of one or two Trajectories
        One panel per model or trajectory.
    t_end : float, optional
        The video ends at this simulation time (scene time unit); default the whole run.
    **overrides
        ``RenderSpec`` fields (size, fps, duration, show, ...).
    """

    def __init__(self, source: Source, t_end: float | None = None, **overrides):
        video = require_render_stack()
        self.plan = plan(source, t_end=t_end, **overrides)
        self._session = None
        self._render_frames = video.render_frames

    @property
    def frames(self) -> int:
        """F, the number of frames of the plan."""
        return self.plan.frames

    def frame(self, f: int) -> np.ndarray:
        """Frame ``f`` (0 .. frames - 1) as an RGB array, shape (H, W, 3), uint8."""
        f = RenderArguments(frame=f).frame
        if not 0 <= f < self.frames:
            raise SpecError("frame", f"must lie in 0..{self.frames - 1}, got {f}")
        if self._session is None:
            imgs, self._session = self._render_frames(self.plan, [f])
            return imgs[0]
        return self._session.frame(f)

    def close(self) -> None:
        """Release the off-screen windows (the next ``frame`` opens new ones)."""
        if self._session is not None:
            self._session.close()
            self._session = None

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def frame_at(plan: FramePlan, t: float) -> int:
    """The frame of ``plan`` that shows simulation time ``t`` (scene time unit): the one whose
    place on the video's time map is nearest t (t = 0 the first frame, the plan's end the last)."""
    s = plan.spec.video_fraction(float(t), plan.t_end)
    return int(min(max(round(s * (plan.frames - 1)), 0), plan.frames - 1))


def render_frame(source: Source, t: float | None = None, *, size=(640, 360), **overrides) -> np.ndarray:
    """The video's frame at physical time ``t`` as an RGB array, shape (H, W, 3), uint8.

    The video is the source's own -- its plan over the whole run, with its duration, frame
    rate, time map and spin slowdown: the video ``render`` writes, and the one the glTF model
    and the page animate -- and the frame is the one that shows ``t``, the frame whose place
    on the time map is nearest t (``frame_at``; ``t = 0`` the first frame, the end of the
    run the last).  So a slowed spin shows the same phase here as in the video, the model and
    the page.  (The last frame of a shorter video, one that ends at t, is ``r.frame(r.frames
    - 1)`` of ``r = Renderer(source, t_end=t)``.)  Shows nicely in Jupyter with
    ``PIL.Image.fromarray(img)`` or ``matplotlib.pyplot.imshow(img)``.

    Parameters
    ----------
    source : Scene, path, Trajectory or list of one or two Trajectories
    t : float, optional
        Simulation time (the trajectory's, scene time unit) in [0, end of the run]; default
        the end of the run.
    size : (int, int)
        (width, height) px.
    **overrides
        ``RenderSpec`` fields (duration, fps and the time map change which frame shows t).
    """
    t = RenderArguments(t=t).t
    scene, trajs = _as_source(source)
    t = _within("t", t, _horizon(scene, trajs), start_open=False)
    if isinstance(size, list):
        size = tuple(size)
    with Renderer(scene if scene is not None else trajs, size=size, **overrides) as r:
        return r.frame(frame_at(r.plan, t))


def render(source: Source, out: str | None = None, *, size=None, fps=None, duration=None, workers=None,
           progress: bool = False, pool=None, **overrides):
    """Render ``source`` to a video and a PNG poster beside it, atomically.

    Parameters
    ----------
    source : Scene, path, Trajectory or list of one or two Trajectories
        A scene (``Scene`` or the path of its TOML) is simulated at the frame times.
    out : str, optional
        The .mp4 or .gif path; default ``renders/<scene>.mp4`` for a scene.  A .glb or .gltf
        path writes the animated glTF model instead, a .html path the self-contained page
        that shows it (``rendering.export``; no poster, no render processes).
    size : (int, int), optional
        (width, height) px.
    fps : int, optional
    duration : float, optional
        Video seconds.
    workers : int, optional
        Render processes for an MP4 (default one per core, at most 4; never more than the
        cores this process may use).
    progress : bool
        A progress bar on stderr.
    pool : rendering.video.WorkerPool, optional
        Render processes started earlier (e.g. before the scene was even read); used for an
        MP4 and closed here in any case.
    **overrides
        Other ``RenderSpec`` fields (show, time_map, captions, ...).

    Returns
    -------
    rendering.video.RenderResult or rendering.export.ExportResult
        Path, poster, frames, size, seconds, fps; for a model or page: path, bytes,
        keyframes, the stated tolerance and the largest measured error.
    """
    args = RenderArguments(out=out, workers=workers, progress=progress)
    scene, trajs, spec = resolve_spec(source, size=size, fps=fps, duration=duration, **overrides)
    out, workers = (default_output(scene if scene is not None else trajs) if args.out is None else args.out), args.workers
    spec.check_output(out, len(scene.models) if scene is not None else len(trajs))
    inputs = [scene.path] if scene is not None and os.path.exists(scene.path) else []
    if os.path.splitext(os.fspath(out))[1].lower() in MODEL_FORMATS:
        # an animated glTF model (and its Blender script) or the page that shows it: the same plan, no drawing stack
        from .rendering.blender import script_path

        check_outputs([out] + ([] if os.fspath(out).lower().endswith(".html") else [script_path(out)]), inputs)
        import importlib.util

        if importlib.util.find_spec("pygltflib") is None:
            raise MissingRenderStack("a glTF model or page needs the optional package 'pygltflib': "
                                     "pip install 'spinviz[render]'")
        from .rendering.export import export

        return export(_plan(scene, trajs, spec), out)
    check_outputs([out, poster_for(out)], inputs)        # before any work: nothing to undo later
    video = require_render_stack()
    # the render processes start now and import the drawing stack while this one simulates
    pool = video.open_pool(spec, out, workers, pool)
    try:
        frame_plan = _plan(scene, trajs, spec)
        return video.render_video(frame_plan, out, workers=workers, progress=progress, inputs=inputs, pool=pool)
    finally:
        if pool is not None:
            pool.close()


def contact_sheet(sources: Sequence[Source], out: str, *, size=(640, 360), columns: int = 2, at: float = 0.5,
                  colors: int = 96) -> str:
    """One frame of each source (at fraction ``at`` of its video) in a grid, as a small PNG:
    the docs' overview of every scene (docs/scenes.md).  ``colors`` limits the palette (the sheet stays small)."""
    from PIL import Image

    from .atomic import atomic_path

    W, H = size
    frames = []
    for src in sources:
        with Renderer(src, size=tuple(size)) as r:
            frames.append(r.frame(int(round(at * (r.frames - 1)))))
    rows = -(-len(frames) // columns)
    sheet = Image.new("RGB", (columns * W + (columns - 1) * 4, rows * H + (rows - 1) * 4), (200, 200, 205))
    for i, img in enumerate(frames):
        sheet.paste(Image.fromarray(img), ((i % columns) * (W + 4), (i // columns) * (H + 4)))
    with atomic_path(out) as tmp:
        sheet.quantize(colors=colors, method=Image.Quantize.MEDIANCUT).save(tmp, format="PNG", optimize=True)
    return out
