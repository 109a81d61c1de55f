"""The render-and-encode pipeline: a ``FramePlan`` to an MP4 or GIF and a PNG poster.

``render_video(plan, out)`` lays the plan out on its frame once (``picture_of``: the
planning layer's ``plan_picture`` with this stack's fonts), then draws every frame and
encodes it; ``render_frames`` draws chosen frames in this process (tests, stills).  The
renderer consumes frames planned from stored trajectories and never steps physics.

Parallel MP4: the frames are split into contiguous segments, one per worker process (one
per core); each worker renders its segment and encodes it with its own single-threaded
x264 (H.264, yuv420p), and the segments are joined by ffmpeg's concat demuxer without
re-encoding.  Only the poster frame crosses a process boundary, so the parent costs
nothing per frame.
GIFs (small by nature) are rendered in-process.

Start-up overlaps the work: ``WorkerPool`` starts the render processes before the plan
exists (``pipeline.render`` opens it before simulating), and each worker imports only the
drawing stack -- pyvista, the VTK modules it uses, Pillow, imageio-ffmpeg -- while the
parent integrates; the picture reaches them as one pickled message.
"""

from __future__ import annotations

import os
import queue as _queue
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass, field

import numpy as np

from .. import interrupt
from ..atomic import Outputs
from ..errors import RenderError, printable
from .encode import Mp4Writer, open_writer, save_png
from .fonts import Fonts
from .picture import Picture, plan_picture
from .spec import poster_for

__all__ = ["render_video", "render_frames", "picture_of", "RenderResult", "RenderError", "WorkerPool", "plan_workers"]


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
    """Frames (list of indices) as RGB arrays (H, W, 3) uint8 at the plan's size, rendered in
    this process; also returns the session (``session.picture`` holds the layout and camera,
    ``session.project`` maps world points to pixels).  The caller closes the session."""
    from .session import RenderSession

    session = RenderSession(picture_of(plan), supersample or SUPERSAMPLE)
    return [session.frame(f) for f in frames], session


class _Progress:
    def __init__(self, label: str, total: int, enabled: bool):
        self.label, self.total, self.enabled = label, total, enabled
        self.tty = enabled and sys.stderr.isatty()
        self.t0 = time.perf_counter()
        self.last = 0.0
        self.next_mark = 0.25

    def update(self, done: int):
        if not self.enabled:
            return
        now = time.perf_counter()
        frac = done / self.total
        if self.tty and (now - self.last > 0.2 or done == self.total):
            self.last = now
            rate = done / (now - self.t0) if now > self.t0 else 0.0
            eta = (self.total - done) / rate if rate > 0 else 0.0
            bar = "#" * int(30 * frac)
            sys.stderr.write(f"\r{self.label} [{bar:<30}] {done}/{self.total} frames {rate:5.1f} fps  {eta:4.0f} s left ")
            if done == self.total:
                sys.stderr.write("\n")
            sys.stderr.flush()
        elif not self.tty and frac >= self.next_mark:
            sys.stderr.write(f"{self.label}: {int(100 * frac)} % ({done}/{self.total} frames)\n")
            while self.next_mark <= frac:
                self.next_mark += 0.25


def _worker_signals(parent: int) -> None:
    """A render worker leaves stopping to its parent: the terminal's SIGINT and SIGHUP (sent to
    the whole process group) are ignored, so no frame is torn in half on its way to ffmpeg;
    the parent sets ``stop`` and the worker finishes its frame and closes its encoder.  A
    SIGTERM (the parent's last resort) unwinds through the same clean-up."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)

    def leave(signum, frame):
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, leave)
    if os.getppid() != parent:                          # the parent died before we started
        raise SystemExit(1)


def _pool_worker(index, tasks, msgs, stop, parent):
    """A render process: import the drawing stack at once (while the parent simulates),
    then wait for one segment to render (``_render_segment``), or for the pool to close."""
    try:
        _worker_signals(parent)
        # one rasterizer thread per worker: the workers already fill the cores
        os.environ.setdefault("LP_NUM_THREADS", "1")
        from . import encode, session  # noqa: F401  (the import is the point: it overlaps the simulation)

        msgs.put(("imported", index, None))
        while True:
            if stop.is_set() or os.getppid() != parent:
                return
            try:
                task = tasks.get(timeout=0.2)
            except _queue.Empty:
                continue
            if task is None:
                return
            _render_segment(index, *task, msgs, stop, parent)
            return
    except BaseException:
        msgs.put(("error", index, traceback.format_exc()))


def _render_segment(index, picture, size, supersample, lo, hi, path, poster_f, msgs, stop, parent):
    """Render frames lo..hi-1 of ``picture`` into the MP4 segment ``path``; report progress on
    ``msgs``.  Stops between frames when ``stop`` is set or the parent process has gone."""
    from .session import RenderSession

    session = RenderSession(picture, supersample)
    writer = Mp4Writer(path, size, picture.plan.spec.fps, threads=1)
    msgs.put(("ready", index, None))
    done = 0
    for f in range(lo, hi):
        if stop.is_set() or os.getppid() != parent:
            break
        img = session.frame(f)
        writer.write(img)
        if f == poster_f:
            msgs.put(("poster", index, img.tobytes()))
        done += 1
        if done % 4 == 0 or f == hi - 1:
            msgs.put(("progress", index, done))
    writer.close()
    session.close()
    msgs.put(("done", index, None))


class WorkerPool:
    """Render processes started ahead of the plan; a context manager (closing stops them).

    ``WorkerPool(n)`` spawns n fresh interpreters that import the drawing stack and wait;
    ``render_video(plan, out, pool=pool)`` hands each a segment.  One video per pool."""

    def __init__(self, workers: int):
        import multiprocessing as mp

        ctx = mp.get_context("spawn")                   # fresh interpreters: no GL state shared by fork
        self.workers = workers
        self.stop = ctx.Event()
        self.msgs = ctx.Queue()
        self.tasks = [ctx.Queue() for _ in range(workers)]
        self.procs = [ctx.Process(target=_pool_worker, daemon=True,
                                  args=(k, self.tasks[k], self.msgs, self.stop, os.getpid()))
                      for k in range(workers)]
        self.used = False
        self._closed = False
        try:
            for p in self.procs:
                p.start()
        except BaseException:
            self.close()
            raise

    def close(self):
        if self._closed:
            return
        self._closed = True
        self.stop.set()                                 # workers finish their frame and close their encoder
        for q in self.tasks:
            try:
                q.put(None)
            except (OSError, ValueError):
                pass
        for p in self.procs:
            if p.pid is None:
                continue
            p.join(timeout=5)
            if p.is_alive():
                p.terminate()
                p.join(timeout=5)
        for q in (*self.tasks, self.msgs):
            # a task (the pickled picture, ~100 kB: more than a pipe holds) that a worker never
            # read -- it failed to start, or was stopped first -- must not block us here
            q.cancel_join_thread()
            q.close()

    def __enter__(self) -> WorkerPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def plan_workers(spec, out: str, workers: int | None = None, frames: int | None = None) -> int:
    """How many processes ``render_video`` uses: one per core (at most 4) for an MP4 long
    enough to split (4 frames per worker at least); 1 (in-process) otherwise."""
    workers = workers or default_workers()
    F = frames or spec.frames
    if os.path.splitext(out)[1].lower() != ".mp4" or F < 4 * workers:
        return 1
    return workers


def render_video(plan, out: str, workers: int | None = None, supersample: float | None = None,
                 progress: bool = True, poster: bool = True, max_frames: int | None = None,
                 inputs=(), pool: WorkerPool | None = None) -> RenderResult:
    """Render ``plan`` to ``out`` (.mp4 or .gif) and a PNG poster beside it; atomically, as a
    group (``atomic.Outputs``: neither lands unless both are complete).

    workers : render processes for MP4 (default: one per core, at most 4); 1 renders in-process.
    max_frames : stop after this many frames (benchmarks).
    inputs : files the outputs must not overwrite (the scene).
    pool : render processes already started (``WorkerPool``); closed by the caller.
    """
    plan.spec.check_output(out, len(plan.panels))          # the format's rules live in the spec
    size = plan.spec.size
    supersample = supersample or SUPERSAMPLE
    F = plan.frames if max_frames is None else min(plan.frames, max_frames)
    workers = plan_workers(plan.spec, out, pool.workers if pool is not None else workers, F)
    poster_f = min(int(round(plan.spec.poster * (plan.frames - 1))), F - 1)
    paths = [out, poster_for(out)] if poster else [out]
    bar = _Progress(f"rendering {printable(out, 80)}", F, progress)
    start = time.perf_counter()
    picture = picture_of(plan)                          # laid out once, here: the workers only draw
    with Outputs(paths, inputs) as tmps:                # video and poster land together, or neither does
        if workers == 1:
            poster_img, startup = _render_in_process(picture, tmps[0], size, supersample, F, poster_f, bar)
        elif pool is not None:
            poster_img, startup = _render_segments(picture, tmps[0], size, supersample, F, poster_f, pool, bar, start)
        else:
            with WorkerPool(workers) as own:
                poster_img, startup = _render_segments(picture, tmps[0], size, supersample, F, poster_f, own, bar,
                                                       start)
        if poster:
            save_png(tmps[1], poster_img)
        interrupt.check()                               # a stop swallowed on the way still counts
    seconds = time.perf_counter() - start
    return RenderResult(path=out, poster=paths[1] if poster else None, frames=F, size=size, seconds=seconds,
                        startup_seconds=startup, workers=workers, notes=list(plan.notes))


def _render_in_process(picture, path, size, supersample, F, poster_f, bar):
    """Render and encode frames 0..F-1 of ``picture`` here; returns (poster image, start-up seconds)."""
    from .session import RenderSession

    t0 = time.perf_counter()
    session = RenderSession(picture, supersample)
    startup = time.perf_counter() - t0
    writer = open_writer(path, size, picture.plan.spec.fps)
    poster_img = None
    finished = False
    try:
        for f in range(F):
            interrupt.check()                   # VTK may have swallowed the signal's exception
            img = session.frame(f)
            writer.write(img)
            if f == poster_f:
                poster_img = img
            bar.update(f + 1)
        finished = True
    except RuntimeError as e:                   # VTK / OpenGL failures: one line, as from the workers
        why = str(e).strip().splitlines()[-1] if str(e).strip() else type(e).__name__
        raise RenderError(f"rendering frame {f} failed: {why}") from None
    finally:
        if finished:
            writer.close()
        else:                                   # interrupted or failed: no GIF is quantized for nothing
            writer.abort()
        session.close()
    return poster_img, startup


def _render_segments(picture, path, size, supersample, F, poster_f, pool: WorkerPool, bar, start):
    """Hand each worker of ``pool`` a contiguous segment of ``picture``, follow their progress, join the
    segments.  Returns (poster image, start-up seconds: until every worker drew its first
    frame, counted from ``start``)."""
    if pool.used:
        raise RenderError("a worker pool renders one video")
    pool.used = True
    workers = pool.workers
    bounds = np.linspace(0, F, workers + 1).round().astype(int)
    tmpdir = tempfile.mkdtemp(prefix=".spinviz-segments-", dir=os.path.dirname(os.path.abspath(path)))
    segs = [os.path.join(tmpdir, f"part{k}.mp4") for k in range(workers)]
    startup = None
    poster_img = None
    counts = [0] * workers
    try:
        for k in range(workers):
            pool.tasks[k].put((picture, size, supersample, int(bounds[k]), int(bounds[k + 1]), segs[k], poster_f))
        pending = set(range(workers))
        ready = 0
        while pending:
            interrupt.check()
            try:
                kind, k, payload = pool.msgs.get(timeout=0.5)
            except _queue.Empty:
                dead = [i for i in pending if not pool.procs[i].is_alive()]
                if dead:
                    raise RenderError(f"render worker {dead[0]} exited with status {pool.procs[dead[0]].exitcode}") from None
                continue
            if kind == "error":
                raise RenderError(f"render worker {k} failed: {payload.strip().splitlines()[-1]}")
            if kind == "ready":
                ready += 1
                if ready == workers:
                    startup = time.perf_counter() - start
            elif kind == "progress":
                counts[k] = payload
                bar.update(sum(counts))
            elif kind == "poster":
                poster_img = np.frombuffer(payload, dtype=np.uint8).reshape(size[1], size[0], 3)
            elif kind == "done":
                pending.discard(k)
        _concat(segs, path)
    finally:
        try:
            pool.close()                                # workers finish their frame and close their encoder
        finally:
            shutil.rmtree(tmpdir, ignore_errors=True)
    return poster_img, startup or 0.0


def _concat(segments, path):
    """Join MP4 segments by stream copy (no re-encoding) with ffmpeg's concat demuxer."""
    import imageio_ffmpeg

    folder = os.path.dirname(segments[0])
    listing = os.path.join(folder, "segments.txt")
    with open(listing, "w") as fh:
        # names relative to the listing (the demuxer resolves them there): a folder whose name
        # holds a quote or a newline never appears inside the list
        for s in segments:
            fh.write(f"file '{os.path.basename(s)}'\n")
    cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-y", "-f", "concat", "-safe", "0",
           "-i", listing, "-c", "copy", "-movflags", "+faststart", "-f", "mp4", path]
    r = subprocess.run(cmd, capture_output=True, text=True, start_new_session=True)   # the terminal's Ctrl-C is ours
    if r.returncode != 0:
        raise RenderError(f"joining the video segments failed: {r.stderr.strip().splitlines()[-1] if r.stderr else r.returncode}")
