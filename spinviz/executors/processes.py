"""Worker processes on this machine: how many cores there are, and a pool that maps in order
and stops clean.

A pool's workers ignore SIGINT, SIGTERM and SIGHUP: a terminal (or ``kill`` of the process
group) sends them to every process of the command, and only the parent may answer -- with
one line and its exit status -- after it has stopped the pool; a worker that took the
signal itself would print its own traceback.  Two details make that hold at every instant:

* the workers are born deaf (``deaf_children``: the signals blocked in the parent while it
  forks them, so a signal between the fork and the worker's own ``quiet_worker`` cannot run
  the parent's Python handler in the child);
* the pool is stopped by SIGKILL, not by ``multiprocessing``'s SIGTERM, which its workers
  ignore (``Pool.terminate`` would wait for them forever); their work is not needed, only
  results the parent holds are ever used.

Standard library only.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys

__all__ = ["usable_cores", "quiet_worker", "deaf_children", "ProcessMapper", "STOP_SIGNALS"]

POLL_S = 0.05                    # how often a waiting parent looks at a stop signal
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def usable_cores() -> int:
    """The cores this process may run on (its affinity mask, else the machine's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


@contextlib.contextmanager
def deaf_children(tracker: bool = False):
    """Processes and threads started inside the block are born with SIGINT, SIGTERM and SIGHUP
    blocked (a signal mask is inherited through fork and exec); this thread's mask is restored
    after, and a signal that arrived meanwhile is delivered then (or already was, to another
    thread: Python runs its handler in the main thread either way).

    ``tracker``: start multiprocessing's resource tracker here first (spawned processes and
    their queues need it).  Started later, from wherever a queue is made, it would be born
    hearing SIGHUP (its own start-up blocks only SIGINT and SIGTERM, and unblocks them after),
    die of a hang-up to the process group and be relaunched, printing KeyErrors.  It is started
    with its own warnings off: the semaphores of workers killed on a stop are its to clean up,
    and it would say so on the terminal after the command had ended."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    try:
        if tracker:
            quiet = "ignore::UserWarning:multiprocessing.resource_tracker"
            sys.warnoptions.append(quiet)       # the tracker's command line repeats this process's -W options
            try:
                with contextlib.suppress(Exception):
                    from multiprocessing import resource_tracker

                    resource_tracker.ensure_running()
            finally:
                sys.warnoptions.remove(quiet)
            signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)      # ensure_running unblocked SIGINT, SIGTERM
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def quiet_worker() -> None:
    """A worker process leaves SIGINT, SIGTERM and SIGHUP to its parent, which stops it: they
    are ignored (and then unblocked: it was born with them blocked, ``deaf_children``)."""
    for sig in STOP_SIGNALS:
        signal.signal(sig, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)


def _pool_class():
    """``multiprocessing.pool.Pool`` whose own ``terminate`` kills its workers: they ignore the
    SIGTERM it would send (also the workers it starts in place of ones that died)."""
    from multiprocessing.pool import Pool

    class KillingPool(Pool):
        @staticmethod
        def Process(ctx, *args, **kwds):
            p = ctx.Process(*args, **kwds)
            p.terminate = p.kill
            return p

    return KillingPool


class ProcessMapper:
    """``with ProcessMapper(n) as m: m(fn, items)``: ``map`` over ``n`` worker processes, in order,
    waiting in short slices that look at ``interrupt.check()``; the pool is killed on any
    exception (a stop signal included), so nothing keeps running after the command.

    ``fn`` and the items travel by fork (``fn`` may be a closure or a ``functools.partial``)."""

    def __init__(self, workers: int):
        self.workers = int(workers)
        self.pool = None

    def __enter__(self) -> ProcessMapper:
        import multiprocessing

        with deaf_children():
            self.pool = _pool_class()(self.workers, initializer=quiet_worker, context=multiprocessing.get_context("fork"))
        return self

    def __call__(self, fn, items) -> list:
        from ..interrupt import check

        job = self.pool.map_async(fn, items, chunksize=1)
        while not job.ready():
            check()
            job.wait(POLL_S)
        return job.get()

    def __exit__(self, kind, value, tb) -> None:
        if kind is None:
            self.pool.close()
        else:
            self.pool.terminate()
        self.pool.join()
