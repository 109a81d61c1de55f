"""Physics: bodies and presets, the equations of motion and their registry (``models``), free-top motion, closed forms and
the paper's reference cases, the radiation (``radiation``), the whole dipole field at any
distance (``dipole_field``) and the one line of a top with d along its axis (``longitudinal``).

Never imports the integrators, the scene layer or rendering.
"""

from . import bodies, closed_forms, equations, models, presets
from .bodies import Body, BodyError
from .models import Model, System
from .presets import PRESETS

__all__ = ["bodies", "closed_forms", "equations", "models", "presets", "Body", "BodyError", "Model", "System", "PRESETS"]
