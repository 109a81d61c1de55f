"""Heads-up text drawn onto finished frames with Pillow.

Text is drawn after the 3-D render, at output resolution, with DejaVu Sans (which has the
Greek letters the labels need).  VTK's corner annotation re-fits its font each time the
text changes, which costs ~25 ms per frame on software OpenGL; here glyph masks (cached
for text that repeats) are alpha-blended into the frame with NumPy (~1 ms per frame).
"""

from __future__ import annotations

import importlib.util
import os

import numpy as np
from PIL import ImageFont

_FONT_CANDIDATES = ("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",)


def _font_path() -> str | None:
    spec = importlib.util.find_spec("matplotlib")
    candidates = list(_FONT_CANDIDATES)
    if spec is not None and spec.origin:
        candidates.insert(0, os.path.join(os.path.dirname(spec.origin), "mpl-data", "fonts", "ttf", "DejaVuSans.ttf"))
    for path in candidates:
        if os.path.exists(path):
            return path
    return None


class Fonts:
    """Fonts sized for a frame of height H."""

    def __init__(self, height: int):
        path = _font_path()
        main = max(9, int(round(height * 0.028)))
        small = max(8, int(round(height * 0.022)))
        if path:
            self.main = ImageFont.truetype(path, main)
            self.small = ImageFont.truetype(path, small)
        else:                                   # Pillow's bundled font (no Greek glyphs)
            self.main = ImageFont.load_default(size=main)
            self.small = ImageFont.load_default(size=small)
        self.line = int(main * 1.3)


class TextStamp:
    """Glyph masks of a font, cached by text: a frame's static labels are rasterized once."""

    def __init__(self):
        self._cache: dict = {}

    def mask(self, text: str, font, anchor: str):
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

    def put(self, img: np.ndarray, xy, text: str, font, fill, anchor: str = "la"):
        """Blend ``text`` into ``img`` (H, W, 3 uint8, in place) at ``xy`` with ``anchor``."""
        if not text:
            return
        alpha, (ox, oy) = self.mask(text, font, anchor)
        h, w = alpha.shape
        x0, y0 = int(xy[0]) + ox, int(xy[1]) + oy
        H, W = img.shape[:2]
        cx0, cy0, cx1, cy1 = max(0, x0), max(0, y0), min(W, x0 + w), min(H, y0 + h)
        if cx1 <= cx0 or cy1 <= cy0:
            return
        a = alpha[cy0 - y0:cy1 - y0, cx0 - x0:cx1 - x0, None]
        region = img[cy0:cy1, cx0:cx1].astype(np.uint16)
        img[cy0:cy1, cx0:cx1] = ((region * (255 - a) + np.asarray(fill, dtype=np.uint16) * a + 127) // 255).astype(np.uint8)


def draw(img: np.ndarray, plan, f: int, fonts: Fonts, stamp: TextStamp, fg, labels, show_text: bool = True) -> np.ndarray:
    """Panel heads-up lines, the footer and the axis labels, onto ``img`` (returned)."""
    if not img.flags.writeable:
        img = img.copy()
    H, W = img.shape[:2]
    n = len(plan.panels)
    pad = max(4, W // 160)
    for name, (x, y) in labels:
        stamp.put(img, (x, y), name, fonts.small, fg, anchor="mm")
    if show_text:
        for k in range(n):
            x0 = k * W // n + pad
            for i, line in enumerate(plan.hud_lines(k, f)):
                stamp.put(img, (x0, pad + i * fonts.line), line, fonts.main if i == 0 else fonts.small, fg)
        stamp.put(img, (W // 2, H - pad), plan.footer(), fonts.small, fg, anchor="md")
        if n > 1:
            grey = np.array([int(0.6 * c + 0.4 * (255 - c)) for c in fg], dtype=np.uint8)
            for k in range(1, n):
                img[pad:H - 3 * pad, k * W // n] = grey
    return img
