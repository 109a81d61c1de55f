"""Worker processes on this machine: how many cores there are, and a pool that maps in order
and stops clean.

A pool's workers ignore SIGINT, SIGTERM and SIGHUP: a terminal (or ``kill`` of the process
group) sends them to every process of the command, and only the parent may answer -- with
one line and its exit status -- after it has terminated the pool; a worker that took the
signal itself would print its own traceback.  Standard library only.
"""

from __future__ import annotations

import os
import signal

__all__ = ["usable_cores", "quiet_worker", "ProcessMapper"]

POLL_S = 0.05                    # how often a waiting parent looks at a stop signal


def usable_cores() -> int:
    """The cores this process may run on (its affinity mask, else the machine's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def quiet_worker() -> None:
    """A worker process leaves SIGINT, SIGTERM and SIGHUP to its parent, which stops it."""
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)


class ProcessMapper:
    """``with ProcessMapper(n) as m: m(fn, items)``: ``map`` over ``n`` worker processes, in order,
    waiting in short slices that look at ``interrupt.check()``; the pool is terminated on any
    exception (a stop signal included), so nothing keeps running after the command.

    ``fn`` and the items travel by fork (``fn`` may be a closure or a ``functools.partial``)."""

    def __init__(self, workers: int):
        self.workers = int(workers)
        self.pool = None

    def __enter__(self) -> ProcessMapper:
        import multiprocessing

        self.pool = multiprocessing.get_context("fork").Pool(self.workers, initializer=quiet_worker)
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
