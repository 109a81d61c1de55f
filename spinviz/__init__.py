"""spinviz: rotation of a dipolar nanocrystal under the radiation-reaction torque.

The reduced (2.2)+(2.3) and truncated (2.5) Euler equations of A. Duviryak, "Asymptotical
dynamics of askew-polarized spinning top under the radiation reaction torque", with
quaternion kinematics, checked against the paper's closed forms, rendered off-screen.

The public API (see docs/getting_started.md, "Python")::

    import spinviz
    sc = spinviz.load_scene("scenes/askew_example.toml")
    tr = spinviz.simulate(sc.body, "reduced", sc.omega0, t_end=10, samples=5)   # -> Trajectory
    tr = spinviz.simulate_request(sc.request("reduced"))                        # the scene's own run, typed
    tr.save("run.npz"); tr = spinviz.Trajectory.load("run.npz")
    img = spinviz.render_frame(sc, t=0.0)                                       # RGB array: the first frame
    spinviz.render("scenes/default.toml", out="renders/default.mp4")
    c = spinviz.compare("scenes/default.toml")                                 # the two models side by side
    obs = spinviz.observe("scenes/dast_cube.toml", distance_cm=20)              # what a receiver records
    spinviz.show(sc)                                                            # turnable, inline in Jupyter

Importing the package is light: every name loads its module on first use (PEP 562), and
nothing here imports numba, pyvista, vtk or imageio.  No public name is also a submodule
name, so a name always means the same object however often it is used.
"""

from __future__ import annotations

import importlib

__version__ = "0.2.0"

# public name -> (module, attribute)
_API = {
    "load_scene": ("inputs.scene_spec", "load_scene"),
    "Scene": ("inputs.scene_spec", "Scene"),
    "simulate": ("driver", "simulate"),
    "Trajectory": ("trajectory", "Trajectory"),
    "render": ("pipeline", "render"),
    "render_frame": ("pipeline", "render_frame"),
    "show": ("notebook", "show"),
    "Renderer": ("pipeline", "Renderer"),
    "Body": ("physics.bodies", "Body"),
    "symmetric_top": ("physics.bodies", "symmetric_top"),
    "PRESETS": ("physics.presets", "PRESETS"),
    "SimulationRequest": ("inputs.simulation", "SimulationRequest"),
    "simulate_request": ("driver", "simulate_request"),
    "SpinvizError": ("errors", "SpinvizError"),
    "SceneError": ("errors", "SceneError"),
    "SpecError": ("errors", "SpecError"),
    "SpecTypeError": ("errors", "SpecTypeError"),
    "TrajectoryFileError": ("errors", "TrajectoryFileError"),
    "SimulationError": ("errors", "SimulationError"),
    "atlas": ("regimes.api", "atlas"),
    "compare": ("experiment", "compare"),
    "observe": ("experiment", "observe"),
    "decide": ("experiment", "decide"),
    "requirements": ("experiment", "requirements"),
    "Environment": ("inputs.environment", "EnvironmentSpec"),
    "listen": ("experiment", "listen"),
}
_SUBMODULES = {
    "units", "rotations", "errors", "atomic", "plotting", "presentation", "physics", "integrators", "inputs", "driver",
    "trajectory", "rendering", "pipeline", "notebook", "executors", "experiment", "analysis", "validation", "regimes",
    "commands",
}

__all__ = sorted(_API) + ["__version__"]


def __getattr__(name: str):
    if name in _API:
        mod, attr = _API[name]
        value = getattr(importlib.import_module(f".{mod}", __name__), attr)
        globals()[name] = value            # later uses skip this hook
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'spinviz' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | _SUBMODULES | set(_API))
