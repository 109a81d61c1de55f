"""Physics: bodies and materials, the equations of motion, invariants and closed forms.

Never imports the integrators, the scene layer or rendering.
"""

from . import bodies, closed_forms, equations
from .bodies import PRESETS, Body, BodyError
from .equations import MODELS, System

__all__ = ["bodies", "closed_forms", "equations", "Body", "BodyError", "System", "MODELS", "PRESETS"]
