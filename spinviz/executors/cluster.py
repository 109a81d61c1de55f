"""A Dask cluster for a command: the embedded LocalCluster or an existing cluster.

``Cluster(scheduler=None, workers=None)``: with no address, a ``LocalCluster`` with one
single-threaded worker process per core (at most one per core: more would only share them);
with an address (``tcp://HOST:8786``), a client of a cluster started with the stock ``dask
scheduler`` and ``dask worker`` commands.  ``warm``, a function, runs once in this process
before a LocalCluster starts (to fill on-disk caches its workers then load) and once in every
worker when it starts (``WorkerSetup``, also on a restarted worker); each worker is checked to
run this spinviz version.  Leaving the ``with`` block closes the client and stops the
LocalCluster -- at once on an exception or a stop signal: the worker processes are killed
(their work is not needed: only results the client holds are ever used), so the command
exits within a fraction of a second instead of waiting for the running tasks.

Signals.  Everything here blocks only in short waits that look at ``interrupt.check()``
(connecting, waiting for workers, registering the plugin and gathering run in helper
threads: ``polled``), so a stop signal -- recorded, never raised inside Dask, where a library
callback or a garbage-collection hook could swallow it -- is acted on within ~50 ms whatever
Dask is doing.  The LocalCluster's processes (its workers and multiprocessing's resource
tracker) are started with SIGINT, SIGTERM and SIGHUP blocked: a terminal's signal to the
whole process group reaches only the client, which stops them.

Start-up under load.  A LocalCluster's worker is a spawned interpreter that imports Dask and
the integrators: seconds on an idle machine, many times that on a loaded one.  The client
waits ``start_timeout()`` -- ``START_TIMEOUT_S`` stretched by the load average per core -- for
each next worker, and gives up in one line (``ClusterSlow``, exit status 75) only when none
has joined for that long; the processes being started are killed, none is left.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import signal
import threading
import time

from distributed.diagnostics.plugin import WorkerPlugin

from ..errors import OptionError, SpinvizError, printable
from ..interrupt import check
from .processes import deaf_children, usable_cores

__all__ = ["Cluster", "WorkerSetup", "GaveUp", "polled", "check_workers", "worker_info", "mapper"]

CONNECT_TIMEOUT_S = 10.0
START_TIMEOUT_S = 120.0          # LocalCluster workers (spawned Python, imports, the Taylor integrators loaded), idle machine
MAX_START_S = 3600.0             # however loaded the machine, no longer than this without a new worker
NO_WORKER_S = 60.0               # an existing cluster without any worker this long: the atlas gives up
POLL_S = 0.05                    # how often the client looks at a stop signal while it waits
HEALTH_S = 0.5                   # how often the monitor asks the scheduler how many workers it has
STALL_S = 10.0                   # nothing arrived this long: ask the scheduler whether a task erred unreported


def _load() -> str:
    try:
        return f"{os.getloadavg()[0]:.1f}"
    except (AttributeError, OSError):
        return "unknown"


def worker_info() -> dict:
    """Run on a worker: its pid and spinviz version."""
    from .. import __version__

    return {"pid": os.getpid(), "version": __version__}


class WorkerSetup(WorkerPlugin):
    """Dask ``WorkerPlugin``: run ``warm`` when a worker starts (also a restarted one).

    ``quiet_terminal``: for the LocalCluster's own worker processes, ignore SIGINT and SIGHUP
    (the terminal sends them to the whole process group; they are blocked from the start,
    this is the second line): the client stops the cluster itself."""

    name = "spinviz-worker-setup"
    idempotent = True

    def __init__(self, warm=None, quiet_terminal: bool = False):
        self.warm = warm
        self.quiet_terminal = quiet_terminal

    def setup(self, worker=None):
        """Quiet this worker's terminal signals (LocalCluster) and run ``warm``."""
        if self.quiet_terminal:
            if threading.current_thread() is threading.main_thread():
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                signal.signal(signal.SIGHUP, signal.SIG_IGN)
        if self.warm is not None:
            self.warm()


class GaveUp(Exception):
    """``polled``'s ``give_up`` said the call can no longer succeed."""


class ClusterSlow(SpinvizError):
    """The embedded cluster's workers did not start in time (a machine loaded far beyond its
    cores); nothing was computed, no process is left, and the same command works later: exit
    status 75, as a lost cluster."""

    exit_status = 75


def start_timeout() -> float:
    """How long the embedded cluster waits for a worker: ``START_TIMEOUT_S`` on an idle machine,
    stretched in proportion to the load average per usable core (a worker's start-up is CPU
    work that a loaded machine shares out), at most ``MAX_START_S``."""
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        load = 0.0
    return min(MAX_START_S, START_TIMEOUT_S * max(1.0, load / usable_cores()))


def polled(fn, *args, give_up=None, **kwargs):
    """``fn(*args, **kwargs)`` in a helper thread while this one waits in ``POLL_S`` slices,
    looking at ``interrupt.check()``: a blocking Dask call (connect, gather, an RPC) never
    holds a stop signal back.  ``give_up()``, if given, is asked at each slice too: when it
    says so, ``GaveUp`` is raised.  An abandoned helper is a daemon thread: whatever it waits
    for returns or fails on its own (at the latest when the client closes)."""
    box: dict = {}
    done = threading.Event()

    def run():
        try:
            box["value"] = fn(*args, **kwargs)
        except BaseException as e:                 # handed to the caller
            box["error"] = e
        finally:
            done.set()

    threading.Thread(target=run, name="spinviz-dask-call", daemon=True).start()
    while not done.wait(POLL_S):
        check()
        if give_up is not None and give_up():
            raise GaveUp
    if "error" in box:
        raise box["error"]
    return box["value"]


@contextlib.contextmanager
def _children_deaf_to_terminal():
    """Threads (hence processes) started inside are born with SIGINT, SIGTERM and SIGHUP
    blocked; this thread's mask is restored after (a signal meanwhile stays pending, then
    arrives).  multiprocessing's resource tracker is started here first: started later, from
    Dask's thread, it would unblock SIGINT and SIGTERM in that thread (its own start-up
    does), and it would die of a SIGHUP to the group and be relaunched with tracebacks
    (``processes.deaf_children``)."""
    with deaf_children(tracker=True):
        yield


@contextlib.contextmanager
def _quiet_distributed():
    """Dask's own log lines (reconnect attempts, restarted workers) are not for the user:
    what matters is said in one line by the atlas."""
    names = ("distributed", "distributed.client", "distributed.nanny", "distributed.scheduler", "distributed.worker",
             "distributed.core", "distributed.comm", "distributed.deploy", "distributed.batched", "asyncio",
             "tornado.application", "tornado.general")
    loggers = [logging.getLogger(n) for n in names]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for lg, lv in zip(loggers, levels):
            lg.setLevel(lv)


def check_workers(workers, scheduler=None) -> None:
    """``workers=``: 1 .. the cores this process may use, and only for the embedded cluster --
    checked by the one schema (``inputs.atlas.check_cluster``; ``SpecError`` naming
    ``workers``), also for a ``Cluster`` made directly (the benchmark)."""
    from ..inputs.atlas import check_cluster

    check_cluster(workers, scheduler)


class Cluster:
    """``with Cluster(scheduler, workers) as cl:`` -- ``cl.client``, ``cl.nthreads``, ``cl.describe``,
    ``cl.problem()`` (why the cluster cannot go on, or None)."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None, processes: bool = True,
                 connect_timeout: float | None = None, warm=None):
        check_workers(workers, scheduler)
        self.scheduler, self.workers, self.processes, self.warm = scheduler, workers, processes, warm
        self.connect_timeout = CONNECT_TIMEOUT_S if connect_timeout is None else connect_timeout
        self.client = None
        self.cluster = None
        self._quiet = None
        self._monitor = None
        self._describe = None
        self._children_before: set | None = None      # this process's children before the LocalCluster

    def __enter__(self) -> Cluster:
        from distributed import Client

        self._quiet = _quiet_distributed()
        self._quiet.__enter__()
        try:
            if self.scheduler is None:
                self._start_local()
            else:
                try:
                    self.client = polled(Client, self.scheduler, timeout=self.connect_timeout)
                except (OSError, TimeoutError, ValueError, TypeError) as e:
                    raise OptionError("scheduler", self.scheduler, f"cannot connect "
                                      f"({printable(str(e) or type(e).__name__, 160)})") from None
                try:
                    polled(self.client.wait_for_workers, 1, timeout=self.connect_timeout)
                except (TimeoutError, OSError):
                    raise OptionError("scheduler", self.scheduler, f"no worker joined within {self.connect_timeout:g} s; "
                                      f"start some with 'dask worker {self.scheduler}'") from None
                polled(self.client.register_plugin, WorkerSetup(self.warm, quiet_terminal=False))
                self._check_versions()
            self.describe                            # noqa: B018 -- asked now, while the scheduler is surely there
            self._monitor = _Monitor(self.client)
        except BaseException:
            self.close(fast=True)
            raise
        return self

    def _start_local(self) -> None:
        from distributed import Client, LocalCluster

        if self.warm is not None:
            self.warm()                              # compile once into the on-disk caches; the workers load them
        self._children_before = {p.pid for p in multiprocessing.active_children()}
        n = self.workers or usable_cores()
        opts = dict(n_workers=0, threads_per_worker=1, processes=self.processes,
                    dashboard_address=None, silence_logs=logging.CRITICAL + 1,
                    # the scheduler's HTTP server (health routes) on a free port of localhost, not the
                    # default 8787 (whose "already in use" warning appeared though no dashboard was asked)
                    scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"})
        if self.processes:
            with _children_deaf_to_terminal():
                self.cluster = LocalCluster(host="127.0.0.1", **opts)
        else:
            self.cluster = LocalCluster(**opts)
        self.client = Client(self.cluster)
        self.cluster.scale(n)
        # the wait follows the load, and starts again with each worker that joins: a slow start is
        # waited for as long as it makes progress
        last, joined, limit = time.monotonic(), 0, start_timeout()
        while (now := len(self.cluster.scheduler.workers)) < n:
            check()
            if now > joined:
                last, joined, limit = time.monotonic(), now, start_timeout()
            elif time.monotonic() - last > limit:
                raise ClusterSlow(f"the embedded cluster's workers did not start: {joined} of {n} up, none more "
                                  f"for {time.monotonic() - last:.0f} s (the wait at load average {_load()} on "
                                  f"{usable_cores()} cores); nothing was computed: run it again when the machine is "
                                  f"less loaded, or with fewer workers")
            time.sleep(POLL_S)
        polled(self.client.register_plugin, WorkerSetup(self.warm, quiet_terminal=self.processes))

    def _check_versions(self) -> None:
        from .. import __version__

        for addr, info in polled(self.client.run, worker_info).items():
            if info["version"] != __version__:
                raise OptionError("scheduler", self.scheduler, f"worker {addr} runs spinviz {info['version']}, this "
                                  f"client {__version__}; the work needs the same version everywhere")

    @property
    def nthreads(self) -> int:
        """Threads over all the cluster's workers."""
        return max(1, sum(polled(self.client.nthreads).values()))

    @property
    def describe(self) -> str:
        """Where it runs, as found when the cluster was reached (asked once: the scheduler may
        be gone when the caller wants to say where it ran)."""
        if self._describe is None:
            n = polled(self.client.nthreads)
            threads = max(1, sum(n.values()))
            where = "embedded LocalCluster" if self.scheduler is None else f"cluster at {self.scheduler}"
            self._describe = (f"{where}, {len(n)} worker{'s' if len(n) != 1 else ''}, "
                              f"{threads} thread{'s' if threads != 1 else ''}")
        return self._describe

    @property
    def where(self) -> str:
        """The scheduler, for messages: its address, or "the embedded cluster"."""
        return f"the scheduler at {self.scheduler}" if self.scheduler else "the embedded cluster's scheduler"

    def problem(self) -> str | None:
        """Why the cluster cannot go on (the scheduler gone, no worker for ``NO_WORKER_S``), or None."""
        return self._monitor.problem(self.where) if self._monitor is not None else None

    def erred_unreported(self, keys) -> list:
        """Of ``keys`` (tasks this client still sees pending), those the scheduler has marked
        erred: the report of their error did not arrive (distributed can fail to read it --
        seen with a deep RecursionError's traceback -- and the future then waits forever).
        From the scheduler's transition log, an RPC that runs no code of ours there."""
        if not keys:
            return []
        try:
            story = polled(self.client.sync, self.client.scheduler.get_story, keys_or_stimuli=list(keys))
        except Exception:
            return []
        last = {}
        for entry in story:
            key, finish, stamp = entry[0], entry[2], entry[-1]
            if key not in last or stamp >= last[key][1]:
                last[key] = (finish, stamp)
        return [k for k in keys if last.get(k, ("", 0))[0] == "erred"]

    def close(self, fast: bool = False) -> None:
        """Close the client and stop the LocalCluster.  ``fast`` (an exception, a stop signal, a
        lost cluster): kill the LocalCluster's worker processes first instead of waiting for
        their running tasks, and give Dask little time."""
        if self._monitor is not None:
            self._monitor.stop()
        if fast and self.cluster is not None and self.processes:
            _kill_workers(self.cluster)
        with contextlib.suppress(BaseException):
            if self.client is not None:
                self.client.close(timeout=1 if fast else 5)
        with contextlib.suppress(BaseException):
            if self.cluster is not None:
                self.cluster.close(timeout=2 if fast else 10)
        if self._children_before is not None:
            _kill_new_children(self._children_before)
            self._children_before = None
        self.client = self.cluster = self._monitor = None
        if self._quiet is not None:
            self._quiet.__exit__(None, None, None)
            self._quiet = None

    def __exit__(self, kind, value, tb) -> None:
        self.close(fast=kind is not None)


def _kill_workers(cluster, wait_s: float = 0.5) -> None:
    """SIGKILL the LocalCluster's worker processes, after telling their nannies not to restart
    them, and wait (at most ``wait_s``) until they are reaped (Dask's watcher threads join
    them): no process of the command outlives it, not even as a zombie."""
    pids = []
    for nanny in list(getattr(cluster, "workers", {}).values()):
        with contextlib.suppress(Exception):
            nanny.close_gracefully()
        with contextlib.suppress(Exception):
            pid = nanny.process.process.pid if nanny.process is not None and nanny.process.process is not None else None
            if pid:
                os.kill(pid, signal.SIGKILL)
                pids.append(pid)
    end = time.monotonic() + wait_s
    while pids and time.monotonic() < end:
        pids = [p for p in pids if os.path.exists(f"/proc/{p}")]
        if pids:
            time.sleep(0.01)


def _kill_new_children(before: set, wait_s: float = 2.0) -> None:
    """SIGKILL and reap the worker processes the LocalCluster started that are still alive
    after it closed (a worker being started when the stop came, one a nanny restarted): they
    block the stop signals, so nothing else ends them, and multiprocessing's exit hook would
    wait for them forever.  Only children started since the cluster was made (``before``:
    the ones there were) are touched; repeated until none is left or ``wait_s`` passed."""
    end = time.monotonic() + wait_s
    while True:
        left = [p for p in multiprocessing.active_children() if p.pid not in before]
        if not left or time.monotonic() > end:
            return
        for p in left:
            with contextlib.suppress(Exception):
                p.kill()
        for p in left:
            with contextlib.suppress(Exception):
                p.join(max(0.0, min(0.5, end - time.monotonic())))


class _Monitor:
    """A daemon thread asking the scheduler, every ``HEALTH_S``, how many workers it has (an
    RPC that may block: never in the main thread); ``problem()`` reads what it saw."""

    def __init__(self, client):
        self.client = client
        self.last_worker = time.monotonic()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="spinviz-cluster-monitor", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(HEALTH_S):
            if self.client.status != "running":
                continue
            with contextlib.suppress(Exception):
                if self.client.scheduler_info(n_workers=0).get("n_workers", 0) > 0:
                    self.last_worker = time.monotonic()

    def problem(self, where: str) -> str | None:
        if self.client.status not in ("running", "newly-created"):
            return f"{where} went away"
        idle = time.monotonic() - self.last_worker
        if idle > NO_WORKER_S:
            return f"no worker at {where} for {idle:.0f} s"
        return None

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(0.2)                     # an RPC in progress fails when the client closes


def mapper(cluster: Cluster):
    """``map(fn, items)`` over the cluster, in order, every wait polled (a stop signal is acted
    on within ~50 ms): the counterpart of ``processes.ProcessMapper`` on Dask."""

    def run(fn, items):
        return polled(cluster.client.gather, cluster.client.map(fn, items, pure=False))

    return run
