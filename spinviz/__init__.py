"""spinviz: rotation of a dipolar nanocrystal under the radiation-reaction torque.

The reduced (2.2)+(2.3) and truncated (2.5) Euler equations of A. Duviryak, "Asymptotical
dynamics of askew-polarized spinning top under the radiation reaction torque", with
quaternion kinematics, checked against the paper's closed forms, rendered off-screen.

Importing the package is light: submodules load on first use (PEP 562), and nothing
here imports pyvista, vtk or imageio.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_SUBMODULES = {
    "units", "rotations", "physics", "integrators", "simulate", "trajectory", "scene", "checks", "info", "cli",
}
_ATTRS = {"simulate": ("simulate", "simulate"), "load_scene": ("scene", "load_scene"), "Trajectory": ("trajectory", "Trajectory")}


def __getattr__(name: str):
    if name in _ATTRS:
        mod, attr = _ATTRS[name]
        return getattr(importlib.import_module(f".{mod}", __name__), attr)
    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'spinviz' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | _SUBMODULES | set(_ATTRS))

