"""Who draws the frames: this process (``render_here``), or a pool of render processes that
each draw and encode a contiguous segment (``WorkerPool``, ``render_segments``).

Parallel MP4: the frames are split into contiguous segments, one per worker process (one
per core); each worker renders its segment and encodes it with its own single-threaded
x264 (H.264, yuv420p), and the segments are joined by ffmpeg's concat demuxer without
re-encoding.  Only the poster frame crosses a process boundary, so the parent costs
nothing per frame.  The workers are spawned before the picture exists (``pipeline.render``
opens the pool before simulating) and import only the drawing stack while the parent
integrates; the picture reaches them as one pickled message.
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

import numpy as np

from .. import interrupt
from ..errors import RenderError
from .encode import Mp4Writer, open_writer


def render_here(picture, path, size, supersample, F, poster_f, bar):
    """Render and encode frames 0..F-1 of ``picture`` into ``path`` in this process (GIFs, short
    videos, ``workers=1``).  Returns (the poster frame ``poster_f`` as an (H, W, 3) uint8
    array, start-up seconds)."""
    from .session import RenderSession

    t0 = time.perf_counter()
    session = RenderSession(picture, supersample)
    startup = time.perf_counter() - t0
    writer = open_writer(path, size, picture.plan.spec.fps)
    shot = {}

    def each(f, img) -> bool:
        """Keep the poster, show progress, honour a pending stop."""
        if f == poster_f:
            shot["poster"] = img
        bar.update(f + 1)
        interrupt.check()                   # VTK may have swallowed the signal's exception
        return False

    finished = False
    try:
        interrupt.check()
        session.record(writer, range(F), each)
        finished = True
    finally:
        if finished:
            writer.close()
        else:                               # interrupted or failed: no GIF is quantized for nothing
            writer.abort()
        session.close()
    return shot.get("poster"), startup


def _worker_signals(parent: int) -> None:
    """A render worker leaves stopping to its parent: the terminal's SIGINT and SIGHUP (sent to
    the whole process group) are ignored, so no frame is torn in half on its way to ffmpeg;
    the parent sets ``stop`` and the worker finishes its frame and closes its encoder.  A
    SIGTERM (the parent's last resort) unwinds through the same clean-up."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)

    def leave(signum, frame):
        """Unwind through the worker's clean-up."""
        raise SystemExit(128 + signum)

    def unraisable(u):
        """A SIGTERM that lands inside a callback Python cannot unwind through (a weak
        reference's, as the import machinery's module locks are) would be printed as "Exception
        ignored" and swallowed: the worker leaves at once instead, silent (its output is
        discarded: the parent writes nothing after a stop)."""
        if isinstance(u.exc_value, SystemExit):
            os._exit(u.exc_value.code if isinstance(u.exc_value.code, int) else 1)
        default_unraisable(u)

    default_unraisable = sys.unraisablehook
    sys.unraisablehook = unraisable
    signal.signal(signal.SIGTERM, leave)
    if hasattr(signal, "pthread_sigmask"):              # born with them blocked (WorkerPool): handled from here on
        signal.pthread_sigmask(signal.SIG_UNBLOCK, (signal.SIGINT, signal.SIGTERM, signal.SIGHUP))
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

    def each(f, img) -> bool:
        """Report the poster and progress; True when told to stop."""
        nonlocal done
        if f == poster_f:
            msgs.put(("poster", index, img.tobytes()))
        done += 1
        if done % 4 == 0 or f == hi - 1:
            msgs.put(("progress", index, done))
        return stop.is_set() or os.getppid() != parent

    if not (stop.is_set() or os.getppid() != parent):
        session.record(writer, range(lo, hi), each)
    writer.close()
    session.close()
    msgs.put(("done", index, None))


class WorkerPool:
    """Render processes started ahead of the plan; a context manager (closing stops them).

    ``WorkerPool(n)`` spawns n fresh interpreters that import the drawing stack and wait;
    ``render_video(plan, out, pool=pool)`` hands each a segment.  One video per pool."""

    def __init__(self, workers: int):
        import multiprocessing as mp

        from ..executors.processes import deaf_children

        ctx = mp.get_context("spawn")                   # fresh interpreters: no GL state shared by fork
        self.workers = workers
        self.used = False
        self._closed = False
        self.procs = []
        # born with the stop signals blocked (they, and the resource tracker the queues start, never
        # take the terminal's signals; a worker sets its own handling first thing, _worker_signals)
        with deaf_children(tracker=True):
            self.stop = ctx.Event()
            self.msgs = ctx.Queue()
            self.tasks = [ctx.Queue() for _ in range(workers)]
            self.procs = [ctx.Process(target=_pool_worker, daemon=True,
                                      args=(k, self.tasks[k], self.msgs, self.stop, os.getpid()))
                          for k in range(workers)]
            try:
                for p in self.procs:
                    p.start()
            except BaseException:
                self.close()
                raise

    def close(self):
        """Stop the workers (each finishes its frame and closes its encoder) and release the queues."""
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
            # a task (the pickled picture, ~0.4-0.6 MB at 360-480 frames: more than a pipe holds) that a worker never
            # read -- it failed to start, or was stopped first -- must not block us here
            q.cancel_join_thread()
            q.close()

    def __enter__(self) -> WorkerPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def render_segments(picture, path, size, supersample, F, poster_f, pool: WorkerPool, bar, start):
    """Hand each worker of ``pool`` a contiguous segment of frames 0..F-1 of ``picture``, follow
    their progress (``bar.update``), join the segments into ``path``.  Returns (the poster frame
    ``poster_f`` as an (H, W, 3) uint8 array, start-up seconds: until every worker drew its
    first frame, counted from ``start``).  Closes the pool."""
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
