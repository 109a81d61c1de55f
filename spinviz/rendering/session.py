"""Off-screen drawing of a ``picture.Picture``: one 3-D view per panel, the overlay around.

A thin layer: every decision -- layout, camera, poses, words, colours -- is in the picture;
this module turns it into pixels with VTK (``views``) and Pillow (``hud``).  Imports only
the drawing stack, NumPy and the plain-data planning modules: a render worker that receives
a pickled picture loads neither numba nor scipy.
"""

from __future__ import annotations

import numpy as np
from PIL import Image

from ..errors import RenderError
from .fonts import Fonts
from .hud import Hud
from .meshes import assemble
from .views import PanelView


class RenderSession:
    """Off-screen windows for a picture; ``frame(f)`` returns the finished RGB image (H, W, 3).

    Each panel has its own window (the size of its 3-D view times ``supersample``); all
    panels share the picture's camera, so the views compare directly.  One canvas is reused
    from frame to frame: only the boxes that per-frame text touched are restored from the
    static layer (a full copy of a 720p frame costs ~2.5 ms).
    """

    def __init__(self, picture, supersample: float = 2.0):
        self.picture = picture
        self.ss = float(supersample)
        x0, y0, x1, y1 = picture.layout.views[0]
        self.view_size = (x1 - x0, y1 - y0)
        window = (max(1, int(round(self.view_size[0] * self.ss))), max(1, int(round(self.view_size[1] * self.ss))))
        fonts, assembly = Fonts(picture.layout.sizes), assemble(picture)
        self.views = [PanelView(picture, k, assembly, window, self.ss) for k in range(len(picture.plan.panels))]
        self.hud = Hud(picture, fonts)
        self.static = Image.fromarray(self.hud.static)
        self._restore = [(self.static.crop(box), box[:2]) for box in picture.overlay.dynamic]   # constant: crop once
        self._canvas = None

    def frame(self, f: int) -> np.ndarray:
        """Frame f (0 .. F - 1) as an RGB uint8 array of shape (H, W, 3): the static layer
        (restored where the last frame's text went), the 3-D views, this frame's text."""
        if self._canvas is None:
            self._canvas = self.static.copy()
        else:
            for patch, corner in self._restore:
                self._canvas.paste(patch, corner)
        img = self._canvas
        for (x0, y0, _, _), view in zip(self.picture.layout.views, self.views):
            view.show(f)
            img.paste(view.image(self.view_size), (x0, y0))
        return np.asarray(self.hud.draw(img, f))

    def record(self, writer, frames, each=None) -> None:
        """Draw ``frames`` in order and write each to ``writer`` (an ``encode`` writer).
        ``each(f, img)`` runs after every frame (progress, poster); True from it stops there.
        A VTK or OpenGL failure (RuntimeError) becomes a one-line ``RenderError`` naming the frame."""
        for f in frames:
            try:
                img = self.frame(f)
                writer.write(img)
            except RuntimeError as e:
                why = str(e).strip().splitlines()[-1] if str(e).strip() else type(e).__name__
                raise RenderError(f"rendering frame {f} failed: {why}") from None
            if each is not None and each(f, img):
                return

    def project(self, panel: int, point) -> tuple[float, float]:
        """Pixel (column, row) in the output image of a world point (3,) seen in ``panel``."""
        xy = self.picture.project(panel, point)[0]
        return float(xy[0]), float(xy[1])

    def close(self):
        """Release the windows."""
        for view in self.views:
            view.close()
