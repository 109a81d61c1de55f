"""Integrators behind the one ``simulate`` driver, chosen by lower-case name.

Importing this package registers the built-in methods; ``get(name)`` returns one and
``names()`` lists them.  Never imports the scene layer or rendering.
"""

from . import (
    polhode,  # noqa: F401  (registers polhode)
    scipy_ivp,  # noqa: F401  (registers rk45, dop853, radau, bdf, lsoda)
    secular,  # noqa: F401  (registers secular)
    splitting,  # noqa: F401  (registers split2, split4, split6, split8)
    taylor,  # noqa: F401  (registers taylor, taylor-long; heyoka loads on first use)
)
from .base import KINEMATICS, Integrator, Problem, Solution, get, names, register

__all__ = ["Integrator", "Problem", "Solution", "KINEMATICS", "get", "names", "register"]
