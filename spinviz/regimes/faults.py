"""How the atlas fails, in one line each (kept apart from ``spinviz.errors``: these are the
atlas's own, and their text names library parameters, never command-line flags).

* ``StoreDamaged`` -- a store whose metadata do not match their checksums (or carry none):
  runs can be recomputed, a damaged catalogue cannot.
* ``AtlasIncomplete`` -- the atlas ended with runs not computed because the cluster failed
  (the scheduler went away, no worker left) or tasks failed as a whole (a task that killed
  its workers, an exception outside the runs).  Nothing of those runs was written: the
  store holds exactly the finished ones and the same call completes it.
* ``StoreBusy`` -- another spinviz holds the store's lock (it is writing it, or verifying
  it): refused at once, exit status 75 like a lost cluster (the same command works once the
  other has finished).
* ``ForeignLevel`` -- a refinement level inside the store carries another atlas's identity:
  not mixed, not deleted; the one line says how to remove it.

A run that fails *physically* (a runaway, a singular start, the step budget) is not an error
here: it is a result, recorded in the store with its reason.
"""

from __future__ import annotations

from ..errors import SpinvizError, UsageError, printable

EXIT_CLUSTER_LOST = 75         # sysexits.h EX_TEMPFAIL: the cluster failed, the same command again resumes
EXIT_TASKS_FAILED = 1          # tasks failed as a whole: rerunning retries them, but they may fail again


class StoreDamaged(UsageError):
    """The store's metadata are damaged or unverifiable; it is not resumed."""


class StoreBusy(SpinvizError):
    """Another process holds the store's lock; nothing was done."""

    exit_status = EXIT_CLUSTER_LOST


class ForeignLevel(UsageError):
    """A refinement level of the store is a whole store of another atlas; it is not resumed."""


class AtlasIncomplete(SpinvizError):
    """Runs not computed (``missing`` of ``total``), with why (``cause``), none written as done.

    cluster_lost : the cluster itself failed (exit status 75, EX_TEMPFAIL: try again);
    otherwise tasks failed as a whole (exit status 1)."""

    def __init__(self, path: str, cause: str, missing: int, total: int, finished: int, cluster_lost: bool):
        self.path, self.cause, self.missing, self.total, self.finished = path, cause, missing, total, finished
        self.cluster_lost = cluster_lost
        super().__init__(f"{cause}: {missing} of {total} runs not computed; the store {printable(path, 200)} holds "
                         f"the {finished} finished, and the same call computes only what is missing")

    @property
    def exit_status(self) -> int:
        """75 when the cluster was lost (the same command resumes), else 1."""
        return EXIT_CLUSTER_LOST if self.cluster_lost else EXIT_TASKS_FAILED

    def cli_message(self) -> str:
        """The same, in the command line's words (what to run to resume)."""
        return (f"atlas incomplete: {self.cause}: {self.missing} of {self.total} runs not computed; "
                f"{printable(self.path, 200)} holds the {self.finished} finished; rerun the same command to resume")
