"""The drawing layer's front door: a ``FramePlan`` to an MP4 or GIF and a PNG poster.

``render_video(plan, out)`` lays the plan out on its frame once (the planning layer's
``plan_picture``, measured with this stack's fonts), then has the frames drawn and encoded
-- here, or by a pool of render processes (``workers``) -- and writes video and poster
atomically; ``render_frames`` draws chosen frames in this process (tests, stills).  The
renderer consumes frames planned from stored trajectories and never steps physics.
GIFs (small by nature) are rendered in-process.

Start-up overlaps the work: ``WorkerPool`` starts the render processes before the plan
exists (``pipeline.render`` opens it before simulating), and each worker imports only the
drawing stack -- pyvista, the VTK modules it uses, Pillow, imageio-ffmpeg -- while the
parent integrates.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

from .. import interrupt
from ..atomic import Outputs
from ..errors import RenderError, printable
from ..inputs.render import poster_for
from ..progress import Progress
from .encode import save_png
from .fonts import Fonts
from .picture import Picture, plan_picture
from .workers import WorkerPool, render_here, render_segments

__all__ = ["render_video", "render_frames", "picture_of", "RenderResult", "RenderError", "WorkerPool", "open_pool",
           "plan_workers"]


@dataclass
class RenderResult:
    """What ``render_video`` wrote: paths, frames, size (width, height) px, wall-clock seconds
    (start-up apart), worker processes, and the plan's notes."""

    path: str
    poster: str | None
    frames: int
    size: tuple[int, int]
    seconds: float
    startup_seconds: float
    workers: int
    notes: list = field(default_factory=list)        # what the plan chose and why (spin mode)

    @property
    def fps(self) -> float:
        """Frames per second, start-up and encoding included."""
        return self.frames / self.seconds if self.seconds > 0 else float("inf")

    @property
    def steady_fps(self) -> float:
        """Frames per second once the workers are up (encoding and joining included)."""
        dt = self.seconds - self.startup_seconds
        return self.frames / dt if dt > 0 else float("inf")


def default_workers() -> int:
    """One render process per core, at most 4."""
    return max(1, min(4, os.cpu_count() or 1))


SUPERSAMPLE = 2.0      # 2 x 2 supersampling: four samples per pixel (see views.py)


def picture_of(plan) -> Picture:
    """The plan laid out on its frame (``picture.plan_picture``), measured with this stack's fonts."""
    return plan_picture(plan, Fonts.for_height(plan.spec.size[1]))


def render_frames(plan, frames, supersample: float | None = None):
    """Chosen frames of ``plan``, drawn in this process.

    Parameters
    ----------
    plan : FramePlan
    frames : sequence of int
        Frame indices, 0 .. F - 1.
    supersample : float, optional
        Samples per pixel and axis of the 3-D views (default 2).

    Returns
    -------
    images : list of ndarray, shape (H, W, 3), uint8
    session : session.RenderSession
        Still open (``session.picture`` holds the layout and camera, ``session.project`` maps
        world points to output pixels); the caller closes it.
    """
    from .session import RenderSession

    session = RenderSession(picture_of(plan), supersample or SUPERSAMPLE)
    return [session.frame(f) for f in frames], session


def plan_workers(spec, out: str, workers: int | None = None, frames: int | None = None) -> int:
    """How many processes ``render_video`` uses: one per core (at most 4) for an MP4 long
    enough to split (4 frames per worker at least); 1 (in-process) otherwise."""
    workers = workers or default_workers()
    F = frames or spec.frames
    if os.path.splitext(out)[1].lower() != ".mp4" or F < 4 * workers:
        return 1
    return workers


def open_pool(spec, out: str, workers: int | None = None, pool: WorkerPool | None = None) -> WorkerPool | None:
    """The render processes for a video of ``spec`` to ``out``: ``pool`` (processes started
    earlier) or a new ``WorkerPool`` when the video is split between processes
    (``plan_workers``), None when it renders in this process (then ``pool`` is closed).
    Started early, the processes import the drawing stack while the caller simulates."""
    n = plan_workers(spec, out, workers if pool is None else pool.workers)
    if pool is not None and n == 1:
        pool.close()                                     # a GIF or a very short video renders in-process
        return None
    if pool is None and n > 1:
        return WorkerPool(n)
    return pool


def render_video(plan, out: str, workers: int | None = None, supersample: float | None = None,
                 progress: bool = True, poster: bool = True, max_frames: int | None = None,
                 inputs=(), pool: WorkerPool | None = None) -> RenderResult:
    """Render ``plan`` to ``out`` and a PNG poster beside it; atomically, as a group
    (``atomic.Outputs``: neither lands unless both are complete).

    Parameters
    ----------
    plan : FramePlan
        What each frame shows; laid out here once (``plan_picture``) at ``plan.spec.size``.
    out : str
        The .mp4 or .gif path.
    workers : int, optional
        Render processes for MP4 (default: one per core, at most 4); 1 renders in-process.
    supersample : float, optional
        Samples per pixel and axis of the 3-D views (default 2: four per pixel).
    progress, poster : bool
        A progress bar on stderr; the PNG poster at ``spec.poster`` of the video.
    max_frames : int, optional
        Stop after this many frames (benchmarks).
    inputs : sequence of str
        Files the outputs must not overwrite (the scene).
    pool : WorkerPool, optional
        Render processes already started; closed by the caller.

    Returns
    -------
    RenderResult
    """
    size = plan.spec.size
    supersample = supersample or SUPERSAMPLE
    F = plan.frames if max_frames is None else min(plan.frames, max_frames)
    workers = plan_workers(plan.spec, out, pool.workers if pool is not None else workers, F)
    poster_f = min(int(round(plan.spec.poster * (plan.frames - 1))), F - 1)
    bar = Progress(F, f"rendering {printable(out, 80)}", unit="frames", rate_unit="fps", enabled=progress, every=0.25)
    plan.spec.check_output(out, len(plan.panels))          # the format's rules live in the spec
    paths = [out, poster_for(out)] if poster else [out]
    start = time.perf_counter()
    # laid out once, here: the workers only draw
    picture = plan_picture(plan, Fonts.for_height(size[1]))
    with Outputs(paths, inputs) as tmps:                # video and poster land together, or neither does
        if workers == 1:
            poster_img, startup = render_here(picture, tmps[0], size, supersample, F, poster_f, bar)
        elif pool is not None:
            poster_img, startup = render_segments(picture, tmps[0], size, supersample, F, poster_f, pool, bar, start)
        else:
            with WorkerPool(workers) as own:
                poster_img, startup = render_segments(picture, tmps[0], size, supersample, F, poster_f, own, bar,
                                                      start)
        if poster:
            save_png(tmps[1], poster_img)
        interrupt.check()                               # a stop swallowed on the way still counts
    seconds = time.perf_counter() - start
    return RenderResult(path=out, poster=paths[1] if poster else None, frames=F, size=size, seconds=seconds,
                        startup_seconds=startup, workers=workers, notes=list(plan.notes))
