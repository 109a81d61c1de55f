"""What an execution of the atlas's batches measured, wherever it ran (``cluster`` on Dask,
``inprocess`` here), and what it could not compute."""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass
class Incomplete:
    """Runs an execution did not compute (none of them written): why, and how many."""

    cause: str                   # one phrase: the first reason met
    runs: int                    # runs not computed (tasks failed or lost, and batches never submitted)
    cluster_lost: bool           # the cluster itself failed (not only some tasks)


@dataclass
class Stats:
    """What an execution measured (for the benchmark and the summary line)."""

    runs: int = 0
    tasks: int = 0
    failed_tasks: int = 0
    wall_s: float = 0.0
    compute_s: float = 0.0
    classify_s: float = 0.0                               # of compute_s: the classifier
    cpu_s: float = 0.0
    threads: int = 0
    max_rss_mb: dict = field(default_factory=dict)        # worker pid -> peak RSS, MiB
    task_compute_s: list = field(default_factory=list)
    incomplete: Incomplete | None = None
    write_s: float = 0.0                                  # the client writing the store (data, done, checksums)
    checksum_s: float = 0.0                               # of which: hashing the chunk files, recording the sums
    chunk_writes: int = 0

    def merged(self, other: Stats | None) -> Stats:
        """The measurements of two executions one after the other (refinement levels on one
        cluster): counts and times added, the later one's incomplete state kept."""
        if other is None:
            return self
        out = Stats(threads=max(self.threads, other.threads), incomplete=other.incomplete)
        for name in ("runs", "tasks", "failed_tasks", "wall_s", "compute_s", "classify_s", "cpu_s", "write_s", "checksum_s",
                     "chunk_writes"):
            setattr(out, name, getattr(self, name) + getattr(other, name))
        out.task_compute_s = self.task_compute_s + other.task_compute_s
        out.max_rss_mb = {pid: max(self.max_rss_mb.get(pid, 0), other.max_rss_mb.get(pid, 0))
                          for pid in {*self.max_rss_mb, *other.max_rss_mb}}
        return out

    def breakdown(self) -> dict:
        """Where the time went: shares of the workers' time (wall x threads) spent integrating,
        classifying, and in neither (scheduling, transfer, start-up, the idle tail), and the
        client's store writes (seconds, and as a share of the wall time)."""
        cap = self.wall_s * max(1, self.threads)
        if cap <= 0:
            return {}
        return {"integrate_share": (self.compute_s - self.classify_s) / cap, "classify_share": self.classify_s / cap,
                "overhead_share": self.overhead_share, "write_s": self.write_s,
                "write_share_of_wall": self.write_s / self.wall_s}

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
