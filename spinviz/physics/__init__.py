"""Physics: bodies and presets, the equations of motion, free-top motion, closed forms and
the paper's reference cases, the radiation (``radiation``), the whole dipole field at any
distance (``dipole_field``) and the one line of a top with d along its axis (``longitudinal``).

Never imports the integrators, the scene layer or rendering.
"""

from . import bodies, closed_forms, equations, presets
from .bodies import Body, BodyError
from .equations import MODELS, System
from .presets import PRESETS

__all__ = ["bodies", "closed_forms", "equations", "presets", "Body", "BodyError", "System", "MODELS", "PRESETS"]
