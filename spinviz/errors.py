"""The errors spinviz reports to people: each one's ``str()`` is the whole message, one line.

Kept in a module of their own with no imports, so that the command line can catch them
without loading numba, scipy or the rendering stack (``spinviz info`` stays instant).

* ``SceneError`` -- a scene (or atlas spec) file that cannot be used: file, key, reason.
* ``SpecError`` -- a bad value for a named setting (a key of ``[render]``, an argument);
  the scene layer turns it into a ``SceneError`` that also names the file.
* ``UsageError`` -- any other bad request (an output path, a combination of options).
* ``SimulationError`` -- a run that could not be completed (an integrator gave up, the
  solution ran away); says why and when.
* ``RenderError`` -- drawing or encoding failed.

The command line maps the first three to exit status 2, the last two to 1.

``printable`` and ``brief`` make any echoed text safe for a terminal: control characters
are shown escaped (``\\x1b``, ``\\n``) and long values are cut, so a message is always one
short line whatever a file or a key name holds.
"""

from __future__ import annotations

import reprlib

MAX_MESSAGE = 400          # characters of one error line
_brief = reprlib.Repr()
_brief.maxlist = _brief.maxtuple = 6
_brief.maxdict, _brief.maxstring, _brief.maxother, _brief.maxlevel = 4, 60, 60, 2


def printable(text, limit: int = MAX_MESSAGE) -> str:
    """``text`` with every control character escaped (one line, no terminal commands) and cut
    to ``limit`` characters."""
    out = []
    for ch in str(text):
        o = ord(ch)
        if o < 0x20 or 0x7F <= o < 0xA0 or o in (0x2028, 0x2029):
            out.append({"\n": "\\n", "\r": "\\r", "\t": "\\t"}.get(ch, f"\\x{o:02x}" if o < 0x100 else f"\\u{o:04x}"))
        else:
            out.append(ch)
        if len(out) > limit:
            break
    s = "".join(out)
    return s if len(s) <= limit else s[: limit - 1] + "\u2026"


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
        super().__init__(f"{key}: {reason}")


class SceneError(SpinvizError, ValueError):
    """A scene that cannot be used: ``path``, ``key`` and ``reason`` give the one line."""

    def __init__(self, path: str, key: str, reason: str):
        self.path, self.key, self.reason = str(path), key, reason
        super().__init__(f"{self.path}: {key}: {reason}")


class SimulationError(SpinvizError, RuntimeError):
    """An integrator gave up or the solution left the physical range; the message says which."""


class RenderError(SpinvizError, RuntimeError):
    """Rendering failed; the message says where (a worker's last traceback line included)."""
