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
"""

from __future__ import annotations


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
