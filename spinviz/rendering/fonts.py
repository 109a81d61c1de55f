"""Fonts and text stamping with Pillow: the drawing side of the text the overlay plans.

``Fonts`` measures text for the layout (it is the planning layer's ``layout.TextMetrics``)
and holds the Pillow fonts that draw it: DejaVu Sans (which has the Greek letters), from
matplotlib's data or the system.  ``TextStamp`` caches glyph masks by text and blends them
into a frame (~1 ms a frame).
"""

from __future__ import annotations

import importlib.util
import os

import numpy as np
from PIL import Image, ImageFont

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


class TextStamp:
    """Glyph masks of a font, cached by text: a frame's static labels are rasterized once."""

    def __init__(self):
        self._cache: dict = {}

    def mask(self, text: str, font, anchor: str):
        """(alpha (h, w) uint16, (dx, dy) offset of its top-left corner from the anchor point)."""
        key = (text, id(font), anchor)
        hit = self._cache.get(key)
        if hit is None:
            m, offset = font.getmask2(text, mode="L", anchor=anchor)
            alpha = np.asarray(m, dtype=np.uint16).reshape(m.size[1], m.size[0])
            hit = (alpha, offset)
            if len(self._cache) > 512:
                self._cache.clear()
            self._cache[key] = hit
        return hit

    def put(self, img, xy, text: str, font, fill, anchor: str = "la", clip=None):
        """Blend ``text`` into ``img`` in place -- an (H, W, 3) uint8 array, or a PIL RGB image
        (then Pillow blends in C) -- at ``xy`` (column, row) with ``anchor``; ``clip`` =
        (x0, y0, x1, y1) keeps it inside a box."""
        if not text:
            return
        alpha, (ox, oy) = self.mask(text, font, anchor)
        h, w = alpha.shape
        x0, y0 = int(xy[0]) + ox, int(xy[1]) + oy
        if isinstance(img, np.ndarray):
            H, W = img.shape[:2]
        else:
            W, H = img.size
        bx0, by0, bx1, by1 = clip if clip is not None else (0, 0, W, H)
        cx0, cy0, cx1, cy1 = max(bx0, 0, x0), max(by0, 0, y0), min(bx1, W, x0 + w), min(by1, H, y0 + h)
        if cx1 <= cx0 or cy1 <= cy0:
            return
        if not isinstance(img, np.ndarray):
            key = (text, id(font), anchor, "pil")
            m = self._cache.get(key)
            if m is None:
                m = self._cache[key] = Image.fromarray(alpha.astype(np.uint8), "L")
            if (cx0, cy0, cx1, cy1) != (x0, y0, x0 + w, y0 + h):
                m = m.crop((cx0 - x0, cy0 - y0, cx1 - x0, cy1 - y0))
            img.paste(tuple(int(c) for c in fill), (cx0, cy0, cx1, cy1), m)
            return
        a = alpha[cy0 - y0:cy1 - y0, cx0 - x0:cx1 - x0, None]
        region = img[cy0:cy1, cx0:cx1].astype(np.uint16)
        img[cy0:cy1, cx0:cx1] = ((region * (255 - a) + np.asarray(fill, dtype=np.uint16) * a + 127) // 255).astype(np.uint8)
