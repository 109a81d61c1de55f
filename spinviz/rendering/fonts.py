"""The fonts, with Pillow: they measure text for the layout and draw it in the HUD.

``Fonts`` is the planning layer's ``layout.TextMetrics`` (type sizes and text widths) and
holds the Pillow fonts: DejaVu Sans (which has the Greek letters), from matplotlib's data
or the system.
"""

from __future__ import annotations

import importlib.util
import os

from PIL import ImageFont

from .layout import TextSizes

_FONT_DIRS = ("/usr/share/fonts/truetype/dejavu",)


def _font_path(name: str = "DejaVuSans.ttf") -> str | None:
    # matplotlib is only looked up (its data folder holds DejaVu), never imported
    spec = importlib.util.find_spec("matplotlib")
    candidates = [os.path.join(d, name) for d in _FONT_DIRS]
    if spec is not None and spec.origin:
        candidates.insert(0, os.path.join(os.path.dirname(spec.origin), "mpl-data", "fonts", "ttf", name))
    for path in candidates:
        if os.path.exists(path):
            return path
    return None


class Fonts:
    """The fonts of a frame: ``small`` (body text) and ``main`` (bold headings), at ``sizes``.

    Use ``Fonts.for_height(H)`` for a frame H rows high; ``width`` is what the layout measures with.
    """

    def __init__(self, sizes: TextSizes):
        self.sizes = sizes
        regular, bold = _font_path(), _font_path("DejaVuSans-Bold.ttf") or _font_path()
        if regular:
            self.small = ImageFont.truetype(regular, sizes.size)
            self.main = ImageFont.truetype(bold, sizes.heading_size)
        else:                                   # Pillow's bundled font (no Greek glyphs)
            self.small = ImageFont.load_default(size=sizes.size)
            self.main = ImageFont.load_default(size=sizes.heading_size)

    @classmethod
    def for_height(cls, height: int) -> Fonts:
        """The fonts for a frame ``height`` rows high (``layout.TextSizes.for_height``)."""
        return cls(TextSizes.for_height(height))

    def font(self, role: str):
        """The Pillow font of a role: "main" (headings) or "small" (everything else)."""
        return self.main if role == "main" else self.small

    def width(self, text: str, role: str = "small") -> float:
        """Advance width of ``text`` in the role's font, px."""
        return float(self.font(role).getlength(text))
