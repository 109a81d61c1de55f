"""Atomic output: write to a temporary file beside the target, then rename over it.

A failed or interrupted write leaves nothing half-written at the output path and whatever
was there before untouched.  The finished file gets the usual permissions (0666 masked by
the umask), not mkstemp's private 0600.

A command with several outputs (a video and its poster, two plots) uses ``Outputs``: every
path is checked before any work starts (``check_outputs``: not a directory, not one of the
command's inputs, in a writable place), all are written to temporary files, and they are
renamed into place together -- with stop signals held back for those few renames -- or all
discarded.

Reading is guarded the same way: ``open_regular`` opens a file only if it is a regular file
(a FIFO would block the reader forever, a device never end, a directory or a socket fail
deep inside a parser), and says at once what the path is instead; and ``loads_json`` parses
JSON only up to ``MAX_JSON_DEPTH`` levels of nesting (Python's parser recurses, and a file of
100 000 brackets ends it in a RecursionError that names nothing).
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import stat
import tempfile

from .errors import UsageError, shortened
from .interrupt import deferred


class NotRegularFile(OSError):
    """A path a reader refuses at once: a directory, FIFO, device or socket where a regular
    file is expected.  ``kind`` says which ("a named pipe (FIFO)", ...); ``strerror`` is the
    one-line reason ("is a named pipe (FIFO), not a regular file")."""

    def __init__(self, path, kind: str):
        self.kind = kind
        code = errno.EISDIR if kind == "a directory" else errno.EINVAL
        super().__init__(code, f"is {kind}, not a regular file", os.fspath(path))


def special_kind(mode: int) -> str | None:
    """None for a regular file's ``st_mode``; otherwise what the path is, in words."""
    if stat.S_ISREG(mode):
        return None
    for test, kind in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a named pipe (FIFO)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return kind
    return "not a regular file"


def open_regular(path, mode: str = "rb"):
    """``path`` opened for reading (a file object, binary unless ``mode`` says "r") if it is a
    regular file; ``NotRegularFile`` at once for a directory, FIFO, device or socket.

    The open itself never blocks (O_NONBLOCK: a FIFO without a writer would hold ``open``
    forever) and follows symbolic links as any reader does; the check is on the opened
    descriptor (``fstat``), so the file read is the file checked.  ``FileNotFoundError``,
    ``PermissionError`` and the rest are raised as ``open`` raises them."""
    if mode not in ("rb", "r"):
        raise ValueError(f"open_regular reads only ('rb' or 'r'), got {mode!r}")
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as e:
        if e.errno == errno.ENXIO:                  # a socket (or a device without its driver)
            try:
                kind = special_kind(os.stat(path).st_mode) or "not a regular file"
            except OSError:
                kind = "not a regular file"
            raise NotRegularFile(path, kind) from None
        raise
    try:
        kind = special_kind(os.fstat(fd).st_mode)
        if kind is not None:
            raise NotRegularFile(path, kind)
        os.set_blocking(fd, True)
        return os.fdopen(fd, mode, **({"encoding": "utf-8"} if mode == "r" else {}))
    except BaseException:
        os.close(fd)
        raise


def read_regular(path, limit: int | None = None) -> bytes:
    """The bytes of the regular file ``path`` (``open_regular``); with ``limit``, at most
    ``limit + 1`` bytes are read, so a caller can tell a file over its limit without reading
    all of it."""
    with open_regular(path) as fh:
        return fh.read() if limit is None else fh.read(limit + 1)


MAX_JSON_DEPTH = 32             # every JSON spinviz reads is 2-4 levels deep; a hostile one is refused, not recursed
_JSON_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.S)


class JsonTooDeep(ValueError):
    """A JSON document nested deeper than ``MAX_JSON_DEPTH``; ``str()`` says how deep."""


def json_depth(text) -> int:
    """How deeply the JSON ``text`` (str or bytes) nests its arrays and objects (0 for a
    scalar), counted without parsing it -- brackets inside strings do not count -- in one
    vectorised pass (a 16 MB file of brackets: ~0.15 s of CPU)."""
    import numpy as np

    raw = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else bytes(text)
    if raw.count(b"[") + raw.count(b"{") == 0:
        return 0
    if b'"' in raw:
        raw = _JSON_STRING.sub(b'""', raw)
    step = np.zeros(256, dtype=np.int8)                  # [ { open a level, ] } close one, all else nothing
    step[[0x5B, 0x7B]], step[[0x5D, 0x7D]] = 1, -1
    return int(np.max(np.cumsum(step[np.frombuffer(raw, dtype=np.uint8)], dtype=np.int32), initial=0))


def loads_json(text, max_depth: int = MAX_JSON_DEPTH):
    """``json.loads(text)``, refusing at once (``JsonTooDeep``, a ValueError) a document nested
    deeper than ``max_depth`` levels: "nested N levels deep; a JSON input takes at most M"."""
    import json

    if isinstance(text, str):
        raw = text.encode("utf-8", "surrogatepass")
    elif isinstance(text, bytes | bytearray):
        raw = bytes(text)
    else:
        raise TypeError(f"the JSON object must be str or bytes, not {type(text).__name__}")
    depth = 0 if raw.count(b"[") + raw.count(b"{") <= max_depth else json_depth(raw)
    if depth > max_depth:
        raise JsonTooDeep(f"nested {depth} levels deep; a JSON input takes at most {max_depth}")
    return json.loads(text)


_WRITTEN: list[str] = []       # outputs renamed into place since ``forget_written`` (the command's start)


def written() -> tuple[str, ...]:
    """The outputs committed since ``forget_written()`` that are still there, in order: what a
    command stopped by a signal had written (its line says so, rather than "nothing was
    written").  A file written whole into a group's temporary file, and renamed from there
    with the group, is named once, by its final path."""
    return tuple(dict.fromkeys(p for p in _WRITTEN if os.path.lexists(p)))


def forget_written() -> None:
    """Start a new record of committed outputs (the command line calls it as a command starts)."""
    _WRITTEN.clear()


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
            # cut: the temporary name must fit where the output's own name just fits
            fd, self.tmp = tempfile.mkstemp(prefix=f".{stem[:64]}.", suffix=f".partial{ext[:16]}", dir=d)
            os.close(fd)
        except BaseException:
            self.discard()
            raise

    def commit(self):
        """Rename the finished temporary file over ``path`` (one atomic ``os.replace``), with the
        permissions a new file would get.  Never over a FIFO, device or socket (a rename would
        replace the node itself: /dev/null, for one): ``UsageError``."""
        refuse_special_output(self.path)
        os.chmod(self.tmp, 0o666 & ~_umask())
        os.replace(self.tmp, self.path)
        _WRITTEN.append(self.path)

    def discard(self):
        """Delete the temporary file, if any, and the directories made for it while they are empty."""
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


def plain(x):
    """NumPy scalars and arrays, tuples and nested containers as built-in JSON types, recursively
    (lists of mixed numbers and strings stay mixed)."""
    import numpy as np

    if isinstance(x, dict):
        return {str(k): plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return plain(x.tolist())
    if isinstance(x, np.generic):
        return x.item()
    return x


def write_json(path, data) -> None:
    """JSON written atomically (NumPy scalars as floats)."""
    import json

    write_text(path, json.dumps(data, indent=2, default=float) + "\n")


def _backup(path: str) -> str | None:
    """A hard link to an existing output beside it (so that a failed group commit can put it
    back), or None when there is nothing to keep or links are not possible here."""
    if not os.path.isfile(path):
        return None
    d, name = os.path.split(os.path.abspath(path))
    fd, b = tempfile.mkstemp(prefix=f".{name[:64]}.", suffix=".old", dir=d)
    os.close(fd)
    os.unlink(b)
    try:
        os.link(path, b)
    except OSError:
        return None
    return b


def check_name(p) -> None:
    """Every part of the path ``p`` fits the file system (NAME_MAX bytes, usually 255, for a
    name; PATH_MAX for the whole) and holds no NUL: otherwise the write would fail only at
    the end, after the work."""
    raw = os.fsencode(p)
    if b"\0" in raw:
        raise UsageError(f"{shortened(p)}: a path cannot hold a NUL byte")
    probe = os.path.dirname(os.path.abspath(p))
    while not os.path.exists(probe):
        probe = os.path.dirname(probe)
    try:
        name_max = os.pathconf(probe, "PC_NAME_MAX")
        path_max = os.pathconf(probe, "PC_PATH_MAX")
    except (OSError, ValueError, AttributeError):
        name_max, path_max = 255, 4096
    for part in raw.split(b"/"):
        if len(part) > name_max:
            raise UsageError(f"{shortened(p)}: a name of {len(part)} bytes; the file system takes at most {name_max}")
    if len(os.fsencode(os.path.abspath(p))) >= path_max:
        raise UsageError(f"{shortened(p)}: the path is {len(raw)} bytes; the file system takes at most {path_max - 1}")


def check_parent_writable(p: str) -> None:
    """``p``'s names fit the file system and the nearest existing folder above it (created
    folders go below it) is a directory this process may write in; otherwise one line
    naming ``p``."""
    check_name(p)
    d = os.path.dirname(os.path.abspath(p))
    while not os.path.exists(d):
        d = os.path.dirname(d)
    if not os.path.isdir(d):
        raise UsageError(f"{p}: {d} is not a directory")
    if not os.access(d, os.W_OK | os.X_OK):
        raise UsageError(f"{p}: cannot write in {d} (permission denied)")


def refuse_special_output(p) -> None:
    """``UsageError`` for an output path that names a FIFO, device or socket: an output is a
    new regular file renamed into place, and renaming over such a node would replace the node
    (as root, /dev/null itself)."""
    try:
        kind = special_kind(os.lstat(p).st_mode)
    except OSError:
        return                                         # nothing there (or not reachable: said when written)
    if kind is not None and kind != "a directory" and not os.path.islink(p):
        raise UsageError(f"{shortened(p)}: {kind}, not a regular file; an output is a file written whole and renamed "
                         f"into place: choose a file path")
    if os.path.islink(p):
        try:
            kind = special_kind(os.stat(p).st_mode)
        except OSError:
            return
        if kind is not None and kind != "a directory":
            raise UsageError(f"{shortened(p)}: links to {kind}, not a regular file; an output is a file written whole and "
                             f"renamed into place: choose a file path")


def check_outputs(paths, inputs=()) -> list[str]:
    """Refuse, before any work, an output that cannot be written or must not be: a
    directory, one of the command's own inputs, a path named twice, a place without write
    permission.  Returns the paths as strings."""
    paths = [os.fspath(p) for p in paths]
    seen = set()
    for p in paths:
        check_name(p)
        real = os.path.realpath(p)
        if real in seen:
            raise UsageError(f"{p}: named twice as an output")
        seen.add(real)
        if os.path.isdir(p):
            raise UsageError(f"{p}: is a directory; an output must be a file path")
        refuse_special_output(p)
        for i in inputs:
            i = os.fspath(i)
            if os.path.exists(p) and os.path.exists(i) and os.path.samefile(p, i):
                raise UsageError(f"{p}: is an input of this command ({i}); choose another output path")
        check_parent_writable(p)
        if os.path.exists(p) and not os.access(p, os.W_OK) and not os.access(os.path.dirname(os.path.abspath(p)), os.W_OK):
            raise UsageError(f"{p}: cannot be replaced (permission denied)")
    return paths


class Outputs:
    """Files that land together or not at all::

        with Outputs([video, poster], inputs=[scene]) as (tmp_video, tmp_poster):
            ...write the temporary files...
        # both renamed into place here; on any exception (or signal) both discarded

    The paths are checked when the group is made (``check_outputs``)."""

    def __init__(self, paths, inputs=()):
        self.paths = check_outputs(paths, inputs)
        self.targets: list[AtomicPath] = []

    def __enter__(self) -> list[str]:
        try:
            for p in self.paths:
                self.targets.append(AtomicPath(p))
        except BaseException:
            self.discard()
            raise
        return [t.tmp for t in self.targets]

    def __exit__(self, kind, value, tb) -> None:
        if kind is not None:
            self.discard()
            return
        try:
            self.commit()
        except BaseException:
            self.discard()
            raise

    def commit(self) -> None:
        """Rename every temporary file into place, or none: the old files are kept as hard
        links until the last rename succeeded, and put back if one fails."""
        with deferred():
            for t in self.targets:                     # the world may have changed since the check
                if os.path.isdir(t.path):
                    raise UsageError(f"{t.path}: is a directory; an output must be a file path")
            backups = {t.path: _backup(t.path) for t in self.targets}
            done = []
            try:
                for t in self.targets:
                    t.commit()
                    done.append(t.path)
            except BaseException:
                for path in done:                      # undo: the old file back, or no file
                    if backups[path]:
                        os.replace(backups.pop(path), path)
                    else:
                        os.unlink(path)
                raise
            finally:
                for b in backups.values():
                    if b and os.path.exists(b):
                        os.unlink(b)

    def discard(self) -> None:
        """Discard every temporary file of the group (``AtomicPath.discard``), the last first."""
        for t in reversed(self.targets):
            t.discard()
