"""The errors spinviz reports to people: each one's ``str()`` is the whole message, one line.

Kept in a module of their own with no imports, so that the command line can catch them
without loading numba, scipy or the rendering stack (``spinviz info`` stays instant).

* ``SceneError`` -- a scene (or atlas spec) file that cannot be used: file, key, reason.
* ``SpecError`` -- a bad value for a named setting (a key of a TOML table, a Python
  argument), named in the caller's terms; the scene layer turns it into a ``SceneError``
  that also names the file, the command line names its option.  ``SpecTypeError`` is the
  same for a value of the wrong kind (also a ``TypeError``).
* ``TrajectoryFileError`` -- a file that is not a readable spinviz trajectory: path, reason.
* ``UsageError`` -- any other bad request (an output path, a combination of options).
* ``SimulationError`` -- a run that could not be completed (an integrator gave up, the
  solution ran away); says why and when.
* ``RenderError`` -- drawing or encoding failed.

The command line maps the bad-input errors to exit status 2, the failed runs to 1.

``printable`` and ``brief`` make any echoed text safe for a terminal: every C0/C1 control,
bidi and other format character, line or paragraph separator, and undecodable byte is shown
escaped (``\\x1b``, ``\\n``, ``\\u202e``, ``\\xff``) and long values are cut, so a
message is always one short line in logical order, whatever a file or a key name holds.
"""

from __future__ import annotations

import reprlib
import unicodedata

MAX_MESSAGE = 400          # characters of one error line
_brief = reprlib.Repr()
_brief.maxlist = _brief.maxtuple = 6
_brief.maxdict, _brief.maxstring, _brief.maxother, _brief.maxlevel = 4, 60, 60, 2


_ESCAPED = {"Cc", "Cf", "Zl", "Zp", "Cs"}     # controls, format (bidi, zero-width), separators, lone surrogates
_SHORT = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def _escape(ch: str) -> str:
    o = ord(ch)
    if ch in _SHORT:
        return _SHORT[ch]
    if 0xDC80 <= o <= 0xDCFF:          # an undecodable byte of a file name (surrogateescape): show the byte
        return f"\\x{o - 0xDC00:02x}"
    return f"\\x{o:02x}" if o < 0x100 else (f"\\u{o:04x}" if o < 0x10000 else f"\\U{o:08x}")


def printable(text, limit: int = MAX_MESSAGE) -> str:
    """``text`` as one safe line: every control (C0, DEL, C1), format character (bidi
    overrides and isolates, zero-width marks), line or paragraph separator and undecodable
    byte escaped -- so nothing can colour, clear, split or reorder the terminal, and a
    strict UTF-8 stream can always encode it -- and cut to ``limit`` characters."""
    if isinstance(text, bytes):
        text = text.decode("utf-8", "surrogateescape")
    out = []
    n = 0
    for ch in str(text):
        piece = _escape(ch) if unicodedata.category(ch) in _ESCAPED else ch
        out.append(piece)
        n += len(piece)
        if n > limit:
            break
    s = "".join(out)
    return s if len(s) <= limit else s[: limit - 1] + "\u2026"


def shortened(text, limit: int = 160) -> str:
    """``text`` escaped as by ``printable`` and, when longer than ``limit``, cut in the middle
    (a path keeps its folder's start and its file name's end)."""
    s = printable(text, 10 * limit)
    if len(s) <= limit:
        return s
    half = (limit - 1) // 2
    return s[:half] + "\u2026" + s[len(s) - (limit - 1 - half):]


def brief(value) -> str:
    """A short, printable repr of a value from a file (long lists and strings cut)."""
    return printable(_brief.repr(value), 120)


class SpinvizError(Exception):
    """Base class: ``str(e)`` is one line for the user."""


class UsageError(SpinvizError, ValueError):
    """A request that cannot be carried out as asked (bad path, bad combination)."""


class SpecError(SpinvizError, ValueError):
    """A bad value for the setting ``key``; ``reason`` says what is wrong."""

    def __init__(self, key: str, reason: str):
        self.key, self.reason = key, reason
        # escaped: a key may be a caller's argument name, a reason quotes values (printable)
        super().__init__(f"{printable(key, 100)}: {printable(reason, 4 * MAX_MESSAGE)}")


class SpecTypeError(SpecError, TypeError):
    """A value of the wrong kind for ``key`` (a path where a body is expected, a string
    where a number is): both a ``SpecError`` (ValueError) and a ``TypeError``."""


class OptionError(SpecError):
    """``name=value`` refused; ``reason`` says why (a cluster's ``scheduler=`` that cannot be
    used: no scheduler there, no worker, another spinviz version).  A ``SpecError`` about the
    argument ``name``, so the command line names it by its option like any other."""

    def __init__(self, name: str, value, reason: str):
        super().__init__(name, f"{printable(value, 100)}: {reason}")
        self.value = value
        self.args = (f"{name}={printable(repr(value), 100)}: {reason}",)

    def __str__(self) -> str:
        return self.args[0]


class SceneError(SpinvizError, ValueError):
    """A scene that cannot be used: ``path``, ``key`` and ``reason`` give the one line."""

    def __init__(self, path: str, key: str, reason: str):
        self.path, self.key, self.reason = str(path), key, reason
        # escaped and cut in the middle: a path may hold any byte a file system allows
        super().__init__(f"{shortened(self.path, 300)}: {printable(key, 100)}: {printable(reason, 4 * MAX_MESSAGE)}")


class SimulationError(SpinvizError, RuntimeError):
    """An integrator gave up or the solution left the physical range; the message says which."""


class RenderError(SpinvizError, RuntimeError):
    """Rendering failed; the message says where (a worker's last traceback line included)."""


class TrajectoryFileError(SpinvizError, ValueError):
    """A file that is not a readable spinviz trajectory (missing, damaged, another format):
    ``path`` and ``reason`` give the one line."""

    def __init__(self, path, reason: str):
        self.path, self.reason = str(path), reason
        super().__init__(f"{printable(self.path, 200)}: {reason}")
