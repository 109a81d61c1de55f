"""Paints a picture's overlay (``overlay.Overlay``) with Pillow and NumPy: nothing is decided here.

``static()`` draws once what never changes (headings, legend, title, the time bar's two
looks, the inset's curves); ``draw(img, f)`` stamps frame f's text and marks onto the frame.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from .fonts import Fonts, TextStamp
from .overlay import Fill, Text

INSET_SUPERSAMPLE = 2          # the inset's lines are drawn at twice the size, then reduced


class Hud:
    """Draws ``picture.overlay``: ``static()`` once, ``draw(img, f)`` per frame."""

    def __init__(self, picture):
        self.overlay = picture.overlay
        self.video_t = picture.plan.video_t
        self.lay = picture.layout
        self.fonts = Fonts(self.lay.sizes)
        self.stamp = TextStamp()
        self._bar = None

    def _put(self, img, item: Text):
        self.stamp.put(img, item.xy, item.text, self.fonts.font(item.role), item.color, anchor=item.anchor,
                       clip=item.clip)

    # -- once ------------------------------------------------------------------------------
    def static(self) -> np.ndarray:
        """The static layer: an (H, W, 3) uint8 frame of everything that does not change."""
        lay, ov = self.lay, self.overlay
        img = np.empty((lay.H, lay.W, 3), dtype=np.uint8)
        img[:] = ov.palette.bg
        if not lay.text:
            return img
        for mark in ov.static:
            if isinstance(mark, Fill):
                x0, y0, x1, y1 = mark.box
                img[y0:y1, x0:x1] = mark.color
            else:
                self._put(img, mark)
        if ov.bar is not None:
            self._bar = [self._bar_look(color) for color in (ov.bar.track, ov.bar.fill)]
        if ov.inset is not None:
            self._inset_static(img)
        return img

    def _bar_look(self, color) -> Image.Image:
        """The bar in one colour, tick marks and labels on it."""
        bar = self.overlay.bar
        h = bar.h
        strip = np.empty((h, bar.x1 - bar.x0, 3), dtype=np.uint8)
        strip[:] = color
        for x, label, lx in bar.ticks:
            strip[h - max(2, h // 4):, max(0, x):x + 1] = bar.tick_color
            if label:
                self.stamp.put(strip, (lx, h // 2), label, self.fonts.small, bar.tick_color, anchor="lm")
        return Image.fromarray(strip)

    def _inset_static(self, img):
        """The inset's frames, bands and curves, drawn at INSET_SUPERSAMPLE x and reduced, then its labels."""
        inset, pal, ss = self.overlay.inset, self.overlay.palette, INSET_SUPERSAMPLE
        y0, H = inset.y0, inset.height
        canvas = Image.new("RGB", (self.lay.W * ss, H * ss), tuple(pal.bg))
        d = ImageDraw.Draw(canvas)
        lw = max(1, int(round(self.lay.H / 360 * 1.5 * ss)))
        for j, (bx0, by0, bx1, by1) in enumerate(inset.boxes):
            d.rectangle([bx0 * ss, (by0 - y0) * ss, bx1 * ss - 1, (by1 - y0) * ss - 1], outline=tuple(pal.divider),
                        width=max(1, ss // 2))
            for k, (color, _, band, _) in enumerate(inset.series):
                if j == 0 and band is not None:
                    xs, lo = inset.xy(j, inset.x, band[:, 0])
                    _, hi = inset.xy(j, inset.x, band[:, 1])
                    poly = list(zip(xs * ss, (hi - y0) * ss)) + list(zip(xs[::-1] * ss, (lo[::-1] - y0) * ss))
                    d.polygon(poly, fill=tuple(int(c + 0.75 * (b - c)) for c, b in zip(color, pal.bg)))
                y = inset.curve(j, k)
                if y is None:
                    continue
                xs, ys = inset.xy(j, inset.x, y)
                d.line(list(zip(xs * ss, (ys - y0) * ss)), fill=tuple(color), width=lw, joint="curve")
        img[y0:y0 + H] = np.asarray(canvas.reduce(ss)).copy()
        for item in inset.labels:
            self._put(img, item)

    # -- per frame -------------------------------------------------------------------------
    def draw(self, img: Image.Image, f: int) -> Image.Image:
        """Frame f's changing text and marks onto ``img`` (a PIL RGB image, in place)."""
        ov = self.overlay
        for item in ov.texts(f):
            self._put(img, item)
        if not self.lay.text:
            return img
        if self._bar is not None:
            bar = ov.bar
            cut = bar.cut(self.video_t, f)
            empty, full = self._bar
            img.paste(full.crop((0, 0, cut, bar.h)), (bar.x0, bar.y))
            if bar.x0 + cut < bar.x1:
                img.paste(empty.crop((cut, 0, bar.x1 - bar.x0, bar.h)), (bar.x0 + cut, bar.y))
            img.paste(tuple(ov.palette.fg), (bar.x0 + cut - 1, bar.y, bar.x0 + cut, bar.y + bar.h))
        if ov.inset is not None:
            for mark in ov.inset.marks(f, max(2, self.lay.H // 180), ov.palette.muted):
                img.paste(tuple(mark.color), mark.box)
        return img
