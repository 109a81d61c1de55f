"""Physics: bodies and presets, the equations of motion, free-top motion, closed forms and
the paper's reference cases.

Never imports the integrators, the scene layer or rendering.
"""

from . import bodies, closed_forms, equations, presets
from .bodies import Body, BodyError
from .equations import MODELS, System
from .presets import PRESETS

__all__ = ["bodies", "closed_forms", "equations", "presets", "Body", "BodyError", "System", "MODELS", "PRESETS"]
