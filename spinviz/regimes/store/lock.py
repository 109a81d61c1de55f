"""One writer at a time: an advisory lock on an atlas store.

A second ``spinviz atlas`` on a store that another is writing would interleave chunk writes
and checksum records, and ``--verify`` during a write would report chunks in the middle of
their write as damaged.  So every command that writes a store (the atlas, its resume,
``evidence convergence --out``) takes an exclusive lock first, ``--verify`` a shared one,
and a command that cannot have its lock at once is refused with one line (``StoreBusy``):
it never waits, never interleaves.

The lock is ``flock(2)`` on a file beside the store, ``.NAME.lock`` in its parent directory
(beside, not inside: the store does not exist yet while its creation is under way, and a
lock inside would be left behind with it), named after the store's real path: a symbolic
link to the store, or to a folder above it, names the same store and so the same lock.  The
kernel releases it when the process ends, however it ends -- a ``kill -9`` leaves no stale
lock.  The file holds the writer's pid (for the message) and is removed by the last holder;
a process that locked a file another just removed sees the path no longer names its file and
starts again (the usual check of lock-file protocols).  Where the lock file cannot be made
(a read-only place) the shared lock is skipped -- no one can write there either -- and the
exclusive one is refused by the writability check before.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os

from ...errors import SpinvizError, printable
from ..faults import StoreBusy


def lock_path(store: str) -> str:
    """``.NAME.lock`` beside the store ``store``, the path resolved first (``os.path.realpath``:
    every symbolic link in it, the store's own included, followed -- also to a store not made
    yet): the lock belongs to the store, not to the spelling of its path, so a link to it or
    to its folder takes the same lock."""
    parent, name = os.path.split(os.path.realpath(store))
    return os.path.join(parent, f".{name}.lock")


def _holder(path: str) -> str:
    """"another spinviz (pid N)" from the lock file's content, or "another spinviz"."""
    from ...atomic import read_regular

    try:
        pid = int(read_regular(path, 32).decode("ascii", "replace").strip() or "x")
        return f"another spinviz (pid {pid})"
    except (OSError, ValueError):
        return "another spinviz"


class StoreLock:
    """``with StoreLock(store, exclusive=True, what="--verify"):`` -- the lock held for the block.

    Refused at once (``StoreBusy``, exit status 75: the same command works once the other one
    has finished) when another process holds a conflicting lock."""

    def __init__(self, store: str, exclusive: bool = True, what: str = ""):
        self.store, self.exclusive, self.what = os.fspath(store), exclusive, what
        self.path = lock_path(self.store)
        self.fd: int | None = None

    def __enter__(self) -> StoreLock:
        mode = fcntl.LOCK_EX if self.exclusive else fcntl.LOCK_SH
        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
            except OSError as e:
                if not self.exclusive and e.errno in (errno.EACCES, errno.EROFS, errno.EPERM):
                    return self                     # a read-only place: nobody writes the store there
                raise SpinvizError(f"{printable(self.store, 200)}: cannot make its lock file {printable(self.path, 200)}: "
                                   f"{e.strerror or e}") from None
            try:
                fcntl.flock(fd, mode | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                raise self._busy() from None
            except BaseException:
                os.close(fd)
                raise
            try:
                same = os.path.samestat(os.fstat(fd), os.stat(self.path, follow_symlinks=False))
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)                            # the previous holder removed this file: lock the new one
        self.fd = fd
        if self.exclusive:
            with contextlib.suppress(OSError):
                os.ftruncate(fd, 0)
                os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        return self

    def _busy(self) -> StoreBusy:
        who = _holder(self.path)
        verb = "is writing" if not self.exclusive else "is using"
        doing = f"{self.what} " if self.what else ""
        return StoreBusy(f"{printable(self.store, 200)}: {who} {verb} this store; {doing}refused (never two at once): "
                         f"run it again when that command has finished")

    def __exit__(self, *exc) -> None:
        self.release()

    def release(self) -> None:
        """Give the lock back; the last holder removes the lock file."""
        fd, self.fd = self.fd, None
        if fd is None:
            return
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)      # alone on it: remove the file, then let go
            with contextlib.suppress(OSError):
                if os.path.samestat(os.fstat(fd), os.stat(self.path, follow_symlinks=False)):
                    os.unlink(self.path)
        except OSError:
            pass                                                # another holder (a shared lock) removes it
        finally:
            os.close(fd)
