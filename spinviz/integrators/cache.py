"""The on-disk cache of built integrators: heyoka caches machine code itself, but rebuilds the
expression decomposition at every construction (~45 ms for the 7-variable reduced system);
a built integrator pickled here loads in ~6 ms.

Entries are keyed by a digest of everything that makes the object (the system's own
expressions, the tolerance, heyoka's version) and of this CPU's features (the pickle holds
code compiled for this CPU).  The folder is $SPINVIZ_CACHE_DIR, else $XDG_CACHE_HOME/spinviz or
~/.cache/spinviz (a sub-folder ``taylor``).  Writes are atomic; a damaged entry, or one from
an incompatible heyoka, is removed and rebuilt; a folder that cannot be written is skipped.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import os
import pickle
import tempfile
import threading

from ..atomic import open_regular


def cache_dir() -> str:
    """Where built integrators are kept: $SPINVIZ_CACHE_DIR, else $XDG_CACHE_HOME/spinviz or
    ~/.cache/spinviz (a sub-folder ``taylor``)."""
    base = os.environ.get("SPINVIZ_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "spinviz")
    return os.path.join(base, "taylor")


def cpu_features() -> str:
    """This CPU's feature flags (/proc/cpuinfo), or its machine and processor names."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    return line
    except OSError:
        pass
    import platform

    return platform.machine() + platform.processor()


def digest(*parts: str) -> str:
    """The key of an entry: sha256 of ``parts`` and this CPU's features."""
    return hashlib.sha256("\n".join([cpu_features(), *parts]).encode()).hexdigest()


def load(key: str):
    """The object stored under ``key``, or None (absent; damaged or unreadable: removed)."""
    path = os.path.join(cache_dir(), key + ".pickle")
    try:
        with open_regular(path) as f:            # a FIFO or device planted in the cache is refused, never waited on
            return pickle.load(f)
    except FileNotFoundError:
        return None
    except Exception:                            # damaged or from an incompatible heyoka: rebuild
        with contextlib.suppress(OSError):
            os.remove(path)
        return None


def store(key: str, obj) -> None:
    """Keep ``obj`` under ``key``, atomically (temporary file, then rename); a cache that cannot
    be written is skipped."""
    folder = cache_dir()
    try:
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".", suffix=".partial")
        with os.fdopen(fd, "wb") as f:
            pickle.dump(obj, f, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, os.path.join(folder, key + ".pickle"))
    except OSError:
        with contextlib.suppress(OSError, UnboundLocalError):
            os.remove(tmp)


_local = threading.local()


def working(template):
    """This thread's working copy of a built integrator (copying one costs ~2 ms: a batch
    reuses it, setting every field it uses)."""
    cache = getattr(_local, "copies", None)
    if cache is None:
        cache = _local.copies = {}
    ta = cache.get(id(template))
    if ta is None:
        ta = cache[id(template)] = (template, copy.copy(template))
    return ta[1]
