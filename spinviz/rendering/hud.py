"""Paints a picture's overlay (``overlay.Overlay``) with Pillow and NumPy: nothing is decided here.

The constructor draws once what never changes (headings, legend, title, the time bar's two
looks, the inset's curves) into ``static``; ``draw(img, f)`` stamps frame f's text and marks.
Glyph masks are cached by text and alpha-blended (~1 ms a frame).
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from .overlay import Fill

INSET_SUPERSAMPLE = 2          # the inset's lines are drawn at twice the size, then reduced


class Hud:
    """Draws ``picture.overlay`` with ``fonts`` (``fonts.Fonts``): ``static`` (an (H, W, 3)
    uint8 frame of everything that does not change) once, ``draw(img, f)`` per frame."""

    def __init__(self, picture, fonts):
        self.overlay = ov = picture.overlay
        self.lay = picture.layout
        self.font = {"small": fonts.small, "main": fonts.main}
        self.stamp = TextStamp()
        self.static = np.empty((self.lay.H, self.lay.W, 3), dtype=np.uint8)
        self.static[:] = ov.background
        self._bar = None
        if not self.lay.text:
            return
        for mark in ov.static:
            if isinstance(mark, Fill):
                x0, y0, x1, y1 = mark.box
                self.static[y0:y1, x0:x1] = mark.color
            else:
                self.stamp.put(self.static, mark.xy, mark.text, self.font[mark.role], mark.color, mark.anchor, mark.clip)
        if ov.bar is not None:
            self._bar = [self._bar_look(color) for color in (ov.bar.track, ov.bar.fill)]
        if ov.inset is not None:
            self._inset(self.static)

    def _bar_look(self, color) -> Image.Image:
        """The bar in one colour, tick marks and labels on it."""
        bar = self.overlay.bar
        h = bar.h
        strip = np.empty((h, bar.x1 - bar.x0, 3), dtype=np.uint8)
        strip[:] = color
        for x, label, lx in bar.ticks:
            strip[h - max(2, h // 4):, max(0, x):x + 1] = bar.tick_color
            self.stamp.put(strip, (lx, h // 2), label, self.font["small"], bar.tick_color, anchor="lm")
        return Image.fromarray(strip)

    def _inset(self, img):
        """The inset's frames, grid rules, bands and curves, drawn at INSET_SUPERSAMPLE x and reduced,
        then its labels."""
        inset, ss = self.overlay.inset, INSET_SUPERSAMPLE
        y0, H = inset.y0, inset.height
        canvas = Image.new("RGB", (self.lay.W * ss, H * ss), tuple(self.overlay.background))
        d = ImageDraw.Draw(canvas)
        lw = max(1, int(round(self.lay.H / 360 * 1.5 * ss)))
        for kind, color, *geometry in inset.shapes:
            if kind == "frame":
                bx0, by0, bx1, by1 = geometry[0]
                d.rectangle([bx0 * ss, (by0 - y0) * ss, bx1 * ss - 1, (by1 - y0) * ss - 1], outline=tuple(color),
                            width=max(1, ss // 2))
            elif kind == "rule":
                rx0, ry0, rx1, ry1 = geometry[0]
                d.line([(rx0 * ss, (ry0 - y0) * ss), (rx1 * ss, (ry1 - y0) * ss)], fill=tuple(color), width=max(1, ss // 2))
            elif kind == "band":
                xs, lo, hi = geometry
                d.polygon(list(zip(xs * ss, (hi - y0) * ss)) + list(zip(xs[::-1] * ss, (lo[::-1] - y0) * ss)), fill=color)
            else:
                xs, ys = geometry
                d.line(list(zip(xs * ss, (ys - y0) * ss)), fill=tuple(color), width=lw, joint="curve")
        img[y0:y0 + H] = np.asarray(canvas.reduce(ss)).copy()
        for t in inset.labels:
            self.stamp.put(img, t.xy, t.text, self.font[t.role], t.color, t.anchor, t.clip)

    def draw(self, img: Image.Image, f: int) -> Image.Image:
        """Frame f's changing text and marks onto ``img`` (a PIL RGB image, in place)."""
        ov, small = self.overlay, self.font["small"]
        for line in ov.lines:
            self.stamp.put(img, line.xy, line.texts[f], small, line.color, line.anchor, line.clip)
        if self._bar is not None:
            bar = ov.bar
            cut = int(bar.cuts[f])
            empty, full = self._bar
            img.paste(full.crop((0, 0, cut, bar.h)), (bar.x0, bar.y))
            if bar.x0 + cut < bar.x1:
                img.paste(empty.crop((cut, 0, bar.x1 - bar.x0, bar.h)), (bar.x0 + cut, bar.y))
            img.paste(tuple(bar.cursor), (bar.x0 + cut - 1, bar.y, bar.x0 + cut, bar.y + bar.h))
        inset = ov.inset
        if inset is not None:
            r = inset.dot_radius
            for j, (_, by0, _, by1) in enumerate(inset.boxes):
                xc = int(inset.cursor[j, f])
                img.paste(tuple(inset.cursor_color), (xc, by0 + 1, xc + 1, by1 - 1))
            for color, j, rows in inset.dots:
                xc, yc = int(inset.cursor[j, f]), int(rows[f])
                img.paste(tuple(color), (xc - r, yc - r, xc + r + 1, yc + r + 1))
        return img


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
