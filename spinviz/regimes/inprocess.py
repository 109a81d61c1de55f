"""Small work in this process: the atlas's batches in a few threads of the client, with no
cluster started (a LocalCluster costs ~3.5 s to start and stop, and importing Dask's
distributed stack ~1-2 s more: more than a small atlas's work).  The same store writes,
progress and stop signals as ``cluster.execute``; ``compute`` chooses it for small work
(``compute.SMALL_WORK_S``) when no scheduler and no worker count are asked for.
"""

from __future__ import annotations

import time

from ..errors import printable
from ..interrupt import check
from ..progress import Progress
from .engine import runs as RN
from .stats import Incomplete, Stats

POLL_S = 0.05                    # how often the client looks at a stop signal while it waits


class InProcess:
    """Small work in this process: the batches run in ``threads`` threads of the client, no
    cluster started (a LocalCluster costs ~3.5 s to start and stop: more than a small atlas's
    work).  The same writes, progress and stop signals as on a cluster."""

    def __init__(self, threads: int):
        self.threads = max(1, int(threads))
        self.nthreads = self.threads

    @property
    def describe(self) -> str:
        """Where it runs."""
        return f"this process, {self.threads} thread{'s' if self.threads != 1 else ''} (small work: no cluster started)"

    def problem(self) -> str | None:
        """Nothing to lose: always None."""
        return None

    def close(self, fast: bool = False) -> None:
        """Nothing to stop."""


def execute(cluster: InProcess, batches: list, keys: list, writer, progress: Progress, on_result=None) -> Stats:
    """``execute`` in this process: the batches in a thread pool, results written in this
    (the main) thread as they arrive; a stop signal stops at once (a running batch, well under
    a second of small work, finishes in its thread and is not written)."""
    from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

    stats = Stats(threads=cluster.threads)
    t0 = time.perf_counter()
    todo = list(range(len(batches)))[::-1]
    in_flight: dict = {}
    not_done, cause = 0, None
    pool = ThreadPoolExecutor(cluster.threads, thread_name_prefix="spinviz-atlas")
    try:
        for _ in range(min(2 * cluster.threads + 2, len(todo))):
            i = todo.pop()
            in_flight[pool.submit(RN.run_batch, batches[i])] = i
        while in_flight:
            check()
            done, _ = wait(list(in_flight), timeout=POLL_S, return_when=FIRST_COMPLETED)
            for f in done:
                i = in_flight.pop(f)
                try:
                    res = f.result()
                except Exception as e:             # a task raising outside its runs: as on a cluster
                    cause = cause or f"a task raised {type(e).__name__}: {printable(str(e), 160)}"
                    not_done += batches[i].runs
                    stats.failed_tasks += 1
                    res = None
                if res is not None:
                    stats.compute_s += res["compute_s"]
                    stats.classify_s += res.get("classify_s", 0.0)
                    stats.cpu_s += res.get("cpu_s", 0.0)
                    stats.task_compute_s.append(res["compute_s"])
                    stats.max_rss_mb[res["worker_pid"]] = max(stats.max_rss_mb.get(res["worker_pid"], 0.0),
                                                              res["max_rss_mb"])
                    writer.add(keys[i], res)
                    stats.runs += batches[i].runs
                stats.tasks += 1
                progress.update(stats.runs + not_done)
                if on_result is not None and res is not None:
                    on_result(stats.tasks, res)
                if todo:
                    j = todo.pop()
                    in_flight[pool.submit(RN.run_batch, batches[j])] = j
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
        stats.wall_s = time.perf_counter() - t0
    if cause is not None:
        stats.incomplete = Incomplete(cause, not_done + sum(batches[i].runs for i in todo), False)
    return stats
