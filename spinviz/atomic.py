"""Atomic output: write to a temporary file beside the target, then rename over it.

A failed or interrupted write leaves nothing half-written at the output path and whatever
was there before untouched.  The finished file gets the usual permissions (0666 masked by
the umask), not mkstemp's private 0600.
"""

from __future__ import annotations

import contextlib
import os
import tempfile


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


class AtomicPath:
    """A temporary sibling of ``path`` with the same extension: write to ``tmp``, then
    ``commit()`` renames it over ``path``; ``discard()`` deletes it."""

    def __init__(self, path):
        self.path = os.fspath(path)
        d = os.path.dirname(os.path.abspath(self.path))
        self._created = []                     # directories made for this output, innermost first
        probe = d
        while not os.path.isdir(probe):
            self._created.append(probe)
            probe = os.path.dirname(probe)
        self.tmp = None
        try:
            os.makedirs(d, exist_ok=True)
            stem, ext = os.path.splitext(os.path.basename(self.path))
            fd, self.tmp = tempfile.mkstemp(prefix=f".{stem}.", suffix=f".partial{ext}", dir=d)
            os.close(fd)
        except BaseException:
            self.discard()
            raise

    def commit(self):
        os.chmod(self.tmp, 0o666 & ~_umask())
        os.replace(self.tmp, self.path)

    def discard(self):
        if self.tmp is not None and os.path.exists(self.tmp):
            os.unlink(self.tmp)
        for d in self._created:                # leave no new, empty directories behind
            try:
                os.rmdir(d)
            except OSError:
                break


@contextlib.contextmanager
def atomic_path(path):
    """``with atomic_path(p) as tmp:`` write ``tmp``; it becomes ``p`` only if the block succeeds."""
    target = AtomicPath(path)
    try:
        yield target.tmp
        target.commit()
    except BaseException:
        target.discard()
        raise


def write_text(path, text: str) -> None:
    """A text file written atomically."""
    with atomic_path(path) as tmp, open(tmp, "w") as fh:
        fh.write(text)


def write_json(path, data) -> None:
    """JSON written atomically (NumPy scalars as floats)."""
    import json

    write_text(path, json.dumps(data, indent=2, default=float) + "\n")
