"""The atlas on a Dask cluster: its cluster (``executors.cluster.Cluster`` with the Taylor
integrators warmed in every worker) and the loop that runs its batches.

* ``atlas_cluster(scheduler, workers)``: the cluster, whose workers load the Taylor integrators
  (heyoka, from spinviz's on-disk cache; the client builds them first when the cluster is
  local) once per worker process, so no task pays for them.
* ``execute``: submits the batches in store order, keeps a bounded number in flight (so a
  stop cancels little and a big atlas does not flood the scheduler), hands each result to
  the store's writer as it arrives, and draws the progress bar.  A task that did not finish
  (its workers killed, the scheduler gone, cancelled, an exception outside the runs) is
  counted, never written: ``Stats.incomplete`` says what and why.

Every wait looks at ``interrupt.check()`` (results arrive through a queue), so a stop signal
is acted on within ~50 ms whatever Dask is doing.
"""

from __future__ import annotations

import contextlib
import os
import queue
import time

from ..errors import printable
from ..executors.cluster import POLL_S, STALL_S, Cluster, polled
from ..interrupt import check
from ..progress import Progress
from .engine import runs as RN
from .stats import Incomplete, Stats


def atlas_cluster(scheduler: str | None = None, workers: int | None = None, processes: bool = True,
                  connect_timeout: float | None = None) -> Cluster:
    """The atlas's cluster: ``executors.cluster.Cluster`` whose workers load the Taylor
    integrators when they start (``engine.runs.warm``)."""
    return Cluster(scheduler, workers, processes=processes, connect_timeout=connect_timeout, warm=RN.warm)


# --- execution -------------------------------------------------------------------------------
def _why_not_finished(f) -> str:
    """One phrase for a task that did not finish: its workers killed, cancelled (by the
    scheduler's loss), or the exception it raised outside the runs."""
    from distributed.scheduler import KilledWorker

    if f.status == "error":
        try:
            err = f.exception(timeout=5)
        except Exception as e:                     # the error could not even be fetched
            return f"a task's error could not be fetched ({type(e).__name__})"
        if isinstance(err, KilledWorker):
            n = err.allowed_failures + 1
            return f"a task killed the worker{'s' if n != 1 else ''} that ran it ({n} time{'s' if n != 1 else ''})"
        return f"a task raised {type(err).__name__}: {printable(str(err), 160)}"
    return f"a task was {f.status}"


def execute(cluster: Cluster, batches: list, keys: list, writer, progress: Progress, on_result=None) -> Stats:
    """Run ``batches`` (``keys[i]``: the storage chunk of batch i) and write each result.

    Only finished results are written.  A task that did not finish is counted in
    ``Stats.incomplete`` (its runs stay "not computed") and the others go on; when the
    cluster itself fails (``cluster.problem()``) the execution ends there.

    ``on_result(n_done_batches, result)`` is called after each result is handed to the writer
    (tests use it to interrupt, or to kill the worker that ran it)."""
    # Long on purpose: the client's one loop (submit, receive, write, watch the cluster and the
    # stop flag) reads as one story; its pieces share a dozen counters
    client = cluster.client
    stats = Stats(threads=cluster.nthreads)
    t0 = time.perf_counter()
    window = 4 * stats.threads + 4
    todo = list(range(len(batches)))
    todo.reverse()
    in_flight = {}
    relost = {}                                   # futures whose result was lost after it finished
    arrived: queue.Queue = queue.Queue()
    not_done = 0                                  # runs of tasks that did not finish
    cause = None
    cluster_lost = False
    last_seen = time.monotonic()                  # when a task last came back

    def submit_one():
        i = todo.pop()
        f = client.submit(RN.run_batch, batches[i], key=f"spinviz-atlas-{keys[i]}-{i}-{os.getpid()}", pure=False)
        in_flight[f.key] = (f, i)
        f.add_done_callback(arrived.put)           # in Dask's callback thread: only a hand-over

    try:
        for _ in range(min(window, len(todo))):
            submit_one()
        done_runs = 0
        while in_flight:
            check()
            try:
                f = arrived.get(timeout=POLL_S)
            except queue.Empty:
                f = next((g for g in relost.values() if g.status in ("finished", "error", "cancelled")), None)
                if f is None:
                    problem = cluster.problem()
                    if problem:
                        cause, cluster_lost = problem, True
                        break
                    if time.monotonic() - last_seen > STALL_S:
                        last_seen = time.monotonic()
                        pending = [k for k, (g, _) in in_flight.items() if g.status == "pending"]
                        for key in cluster.erred_unreported(pending):
                            i = in_flight.pop(key)[1]
                            cause = cause or "a task failed on the cluster and its error never reached this client"
                            not_done += batches[i].runs
                            stats.failed_tasks += 1
                            stats.tasks += 1
                            if todo:
                                submit_one()
                    continue
            last_seen = time.monotonic()
            if f.key not in in_flight:
                continue
            relost.pop(f.key, None)
            res = None
            if f.status == "finished":
                try:                               # its worker may die before the gather
                    res = polled(f.result, give_up=lambda f=f: f.status != "finished" or cluster.problem())
                except Exception:
                    res = None
            if res is None and f.status not in ("error", "cancelled"):
                # the result was lost with its worker: the scheduler recomputes it (we hold the
                # future); it is "lost" or "pending" until then, and its callback has fired already
                relost[f.key] = f
                continue
            i = in_flight.pop(f.key)[1]
            if res is None:
                problem = cluster.problem()
                if problem:                        # the scheduler went away: every task in flight is lost
                    cause, cluster_lost = problem, True
                    not_done += batches[i].runs
                    break
                cause = cause or _why_not_finished(f)
                not_done += batches[i].runs
                stats.failed_tasks += 1
            else:
                stats.compute_s += res["compute_s"]
                stats.classify_s += res.get("classify_s", 0.0)
                stats.cpu_s += res.get("cpu_s", 0.0)
                stats.task_compute_s.append(res["compute_s"])
                stats.max_rss_mb[res["worker_pid"]] = max(stats.max_rss_mb.get(res["worker_pid"], 0.0), res["max_rss_mb"])
                writer.add(keys[i], res)
                done_runs += batches[i].runs
            stats.tasks += 1
            stats.runs = done_runs
            progress.update(done_runs + not_done)
            if on_result is not None and res is not None:
                on_result(stats.tasks, res)
            if todo and not cluster_lost:
                submit_one()
    finally:
        stats.wall_s = time.perf_counter() - t0
    if cause is not None:
        missing = not_done + sum(batches[i].runs for _, i in in_flight.values()) + sum(batches[i].runs for i in todo)
        stats.incomplete = Incomplete(cause, missing, cluster_lost)
        with contextlib.suppress(BaseException):
            if in_flight and not cluster_lost:
                client.cancel([f for f, _ in in_flight.values()])
    return stats
