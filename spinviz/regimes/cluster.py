"""Running batches of runs on Dask: the embedded LocalCluster or an existing cluster.

* ``Cluster(scheduler=None, workers=None)``: with no address, a ``LocalCluster`` with one
  single-threaded worker process per core (the kernels hold the GIL-free compiled loop, but one
  process per core keeps each worker's memory and numba state its own); with an address
  (``tcp://HOST:8786``), a client of a cluster started with the stock ``dask scheduler`` and
  ``dask worker`` commands.  Leaving the ``with`` block closes the client and stops the
  LocalCluster, also on an exception or a stop signal.
* ``WarmUp``: a ``WorkerPlugin`` that loads the compiled kernel once per worker process
  (from numba's on-disk cache; the client compiles it first when the cluster is local), so
  no task pays for it, and that checks the worker runs the client's spinviz version.
* ``execute``: submits the batches in store order, keeps a bounded number in flight (so a
  stop cancels little and a big atlas does not flood the scheduler), hands each result to
  the store's writer as it arrives, records a batch that failed as failed runs with the
  reason, and draws the progress bar.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from distributed.diagnostics.plugin import WorkerPlugin

from ..errors import UsageError, printable
from ..interrupt import check
from . import classify as C
from . import runs as RN

CONNECT_TIMEOUT_S = 10.0


def worker_info() -> dict:
    """Run on a worker: its pid and spinviz version (``WarmUp`` has already loaded the kernel)."""
    from .. import __version__

    return {"pid": os.getpid(), "version": __version__}


class WarmUp(WorkerPlugin):
    """Dask ``WorkerPlugin``: load the kernel when a worker starts (also a restarted one).

    ``quiet_terminal``: for the LocalCluster's own worker processes, ignore SIGINT and SIGHUP
    (the terminal sends them to the whole process group): the client stops the cluster
    itself, cleanly, instead of every worker dying with a traceback."""

    name = "spinviz-atlas-warmup"
    idempotent = True

    def __init__(self, quiet_terminal: bool = False):
        self.quiet_terminal = quiet_terminal

    def setup(self, worker=None):
        if self.quiet_terminal:
            import signal
            import threading

            if threading.current_thread() is threading.main_thread():
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                signal.signal(signal.SIGHUP, signal.SIG_IGN)
        RN.warm()


class Cluster:
    """``with Cluster(scheduler, workers) as cl:`` -- ``cl.client``, ``cl.nthreads``, ``cl.describe``."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None, processes: bool = True,
                 connect_timeout: float | None = None):
        if scheduler is not None and workers is not None:
            raise UsageError("--workers: applies to the embedded cluster only; an existing cluster (--scheduler) "
                             "has the workers it was started with")
        if workers is not None and not 1 <= workers <= 1024:
            raise UsageError(f"--workers: must be 1..1024, got {workers}")
        self.scheduler, self.workers, self.processes = scheduler, workers, processes
        self.connect_timeout = CONNECT_TIMEOUT_S if connect_timeout is None else connect_timeout
        self.client = None
        self.cluster = None

    def __enter__(self) -> Cluster:
        from distributed import Client, LocalCluster

        logging.getLogger("distributed").setLevel(logging.ERROR)
        try:
            if self.scheduler is None:
                RN.warm()                            # compile once into numba's cache; the workers load it
                n = self.workers or os.cpu_count() or 1
                self.cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=self.processes,
                                            dashboard_address=None, silence_logs=logging.ERROR)
                self.client = Client(self.cluster)
                self.client.register_plugin(WarmUp(quiet_terminal=self.processes))
            else:
                try:
                    self.client = Client(self.scheduler, timeout=self.connect_timeout)
                except (OSError, TimeoutError, ValueError, TypeError) as e:
                    raise UsageError(f"--scheduler {printable(self.scheduler, 80)}: cannot connect "
                                     f"({printable(str(e) or type(e).__name__, 160)})") from None
                try:
                    self.client.wait_for_workers(1, timeout=self.connect_timeout)
                except (TimeoutError, OSError):
                    raise UsageError(f"--scheduler {printable(self.scheduler, 80)}: no worker joined within "
                                     f"{self.connect_timeout:g} s; start some with 'dask worker {self.scheduler}'") from None
                self.client.register_plugin(WarmUp(quiet_terminal=False))
                self._check_versions()
        except BaseException:
            self.close()
            raise
        return self

    def _check_versions(self) -> None:
        from .. import __version__

        for addr, info in self.client.run(worker_info).items():
            if info["version"] != __version__:
                raise UsageError(f"--scheduler: worker {addr} runs spinviz {info['version']}, this client "
                                 f"{__version__}; the atlas needs the same version everywhere")

    @property
    def nthreads(self) -> int:
        return max(1, sum(self.client.nthreads().values()))

    @property
    def describe(self) -> str:
        n = len(self.client.nthreads())
        where = "embedded LocalCluster" if self.scheduler is None else f"cluster at {self.scheduler}"
        return f"{where}, {n} worker{'s' if n != 1 else ''}, {self.nthreads} thread{'s' if self.nthreads != 1 else ''}"

    def close(self) -> None:
        with contextlib.suppress(Exception):
            if self.client is not None:
                self.client.close(timeout=5)
        with contextlib.suppress(Exception):
            if self.cluster is not None:
                self.cluster.close(timeout=10)
        self.client = self.cluster = None

    def __exit__(self, *exc) -> None:
        self.close()


# --- progress ------------------------------------------------------------------------------
class Progress:
    """Runs done, runs per second and the time left, on stderr (a bar on a terminal, a line
    every 10 % otherwise); silent when ``enabled`` is False."""

    def __init__(self, total: int, label: str, enabled: bool = True, stream=None):
        self.total, self.label, self.enabled = max(1, total), label, enabled
        self.stream = stream or sys.stderr
        self.tty = enabled and getattr(self.stream, "isatty", lambda: False)()
        self.t0 = time.perf_counter()
        self.last = 0.0
        self.next_mark = 0.1
        self.done = 0

    def update(self, done: int) -> None:
        self.done = done
        if not self.enabled:
            return
        now = time.perf_counter()
        rate = done / (now - self.t0) if now > self.t0 else 0.0
        left = (self.total - done) / rate if rate > 0 else math.inf
        frac = done / self.total
        eta = f"{left:5.0f} s left" if math.isfinite(left) else "  ?   s left"
        if self.tty and (now - self.last > 0.2 or done >= self.total):
            self.last = now
            bar = "#" * int(30 * frac)
            self.stream.write(f"\r{self.label} [{bar:<30}] {done}/{self.total} runs {rate:7.1f} runs/s {eta} ")
            if done >= self.total:
                self.stream.write("\n")
            self.stream.flush()
        elif not self.tty and (frac >= self.next_mark or done >= self.total):
            self.stream.write(f"{self.label}: {done}/{self.total} runs ({100 * frac:.0f} %), {rate:.1f} runs/s, {eta}\n")
            self.stream.flush()
            while self.next_mark <= frac:
                self.next_mark += 0.1

    def finish(self) -> None:
        if self.enabled and self.tty and self.done < self.total:
            self.stream.write("\n")
            self.stream.flush()


# --- execution -------------------------------------------------------------------------------
@dataclass
class Stats:
    """What an execution measured (for the benchmark and the summary line)."""

    runs: int = 0
    tasks: int = 0
    failed_tasks: int = 0
    wall_s: float = 0.0
    compute_s: float = 0.0
    cpu_s: float = 0.0
    threads: int = 0
    max_rss_mb: dict = field(default_factory=dict)        # worker pid -> peak RSS, MiB
    task_compute_s: list = field(default_factory=list)

    @property
    def overhead_share(self) -> float:
        """1 - (time inside the tasks) / (wall time x threads): scheduling, transfer, writing,
        start-up and the idle tail together."""
        cap = self.wall_s * max(1, self.threads)
        return 1.0 - self.compute_s / cap if cap > 0 else math.nan

    @property
    def cpu_share(self) -> float:
        """CPU time / wall time inside the tasks: 1 when the workers had their cores to
        themselves, less when other work on the machine took them."""
        return self.cpu_s / self.compute_s if self.compute_s > 0 else math.nan


def failed_result(batch: RN.Batch, message: str) -> dict:
    """A batch whose task failed as a whole (a worker died repeatedly, an error outside the
    runs): every run recorded as failed with the reason."""
    nd, nc, nm = len(batch.deltas), len(batch.chis), len(batch.omega0)
    shape = (nd, nc, nm)
    data = {
        "regime": np.full(shape, C.CODE["failed"], dtype=np.int8), "regime_early": np.full(shape, C.CODE["failed"], np.int8),
        "candidate": np.full(shape, C.CODE["other"], dtype=np.int8), "status": np.full(shape, RN.ERROR, dtype=np.int8),
        "method": np.zeros(shape, dtype=np.int8), "confidence": np.zeros(shape), "tau_reached": np.full(shape, np.nan),
        "run_seconds": np.full(shape, np.nan), "nsteps": np.zeros(shape, dtype=np.int64), "nfev": np.zeros(shape, np.int64),
        "evidence": np.full(shape + (len(C.EVIDENCE),), np.nan), "omega_final": np.full(shape + (3,), np.nan),
        "reason": np.full(shape, f"task failed: {message}"[:RN.REASON_CHARS], dtype=f"<U{RN.REASON_CHARS}"),
    }
    return {"region": batch.region, "data": data, "worker_pid": -1, "compute_s": 0.0, "cpu_s": 0.0, "max_rss_mb": math.nan}


def execute(cluster: Cluster, batches: list, keys: list, writer, progress: Progress, on_result=None) -> Stats:
    """Run ``batches`` (``keys[i]``: the storage chunk of batch i) and write each result.

    ``on_result(n_done_batches, result)`` is called after each result is handed to the writer
    (tests use it to interrupt, or to kill the worker that ran it)."""
    from distributed import as_completed

    client = cluster.client
    stats = Stats(threads=cluster.nthreads)
    t0 = time.perf_counter()
    window = 4 * stats.threads + 4
    queue = list(range(len(batches)))
    queue.reverse()
    by_future = {}
    ac = as_completed()

    def submit_one():
        i = queue.pop()
        f = client.submit(RN.run_batch, batches[i], key=f"spinviz-atlas-{keys[i]}-{i}-{os.getpid()}", pure=False)
        by_future[f] = i
        ac.add(f)

    try:
        for _ in range(min(window, len(queue))):
            submit_one()
        done_runs = 0
        while by_future:
            check()
            try:
                f = next(ac)
            except StopIteration:
                break
            i = by_future.pop(f)
            if f.status == "finished":
                res = f.result()
                stats.compute_s += res["compute_s"]
                stats.cpu_s += res.get("cpu_s", 0.0)
                stats.task_compute_s.append(res["compute_s"])
                stats.max_rss_mb[res["worker_pid"]] = max(stats.max_rss_mb.get(res["worker_pid"], 0.0), res["max_rss_mb"])
            else:
                try:
                    err = f.exception()
                    msg = f"{type(err).__name__}: {err}"
                except Exception as e:                    # cancelled, lost
                    msg = f"{type(e).__name__}"
                res = failed_result(batches[i], msg)
                stats.failed_tasks += 1
            writer.add(keys[i], res)
            stats.tasks += 1
            done_runs += batches[i].runs
            stats.runs = done_runs
            progress.update(done_runs)
            if on_result is not None:
                on_result(stats.tasks, res)
            if queue:
                submit_one()
    finally:
        stats.wall_s = time.perf_counter() - t0
        pending = list(by_future)
        if pending:
            with contextlib.suppress(Exception):
                client.cancel(pending)
    return stats
