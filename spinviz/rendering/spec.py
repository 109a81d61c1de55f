"""What a video shows and how simulation time maps to video time: ``RenderSpec``.

The class and its limits are declared with every other input in the one schema,
``spinviz.inputs.render`` (below both the scenes and rendering, so that a scene checks its
``[render]`` table without importing this package); this module is their name inside the
rendering package.  Pure Python: importing it loads no drawing library.
"""

from __future__ import annotations

from ..inputs.render import (  # noqa: F401  (re-exported)
    DEFAULT_SHOW,
    MAX_DURATION_S,
    MAX_FPS,
    MAX_FRAMES,
    MAX_GIF_BYTES,
    MAX_KNEE_RATIO,
    MAX_SIZE,
    MAX_TITLE,
    MIN_SIZE,
    MODEL_FORMATS,
    ORIENTATION_ITEMS,
    SHOW_ITEMS,
    VIDEO_FORMATS,
    ZOOM_RANGE,
    RenderSpec,
    poster_for,
)
