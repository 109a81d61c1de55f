"""Text and 2-D marks on the frames, drawn with Pillow and NumPy: where everything goes.

``Layout`` splits a frame into bands that never overlap: per panel a heading and a plain
subtitle on top, the 3-D view, the panel's numbers under it; across the frame a legend of
the arrows (each name in its arrow's colour), a time bar marked in Theta or T, notes on how
time and spin are shown, and the title.  Type scales with the frame height (15 px body text
at 360 rows); when a frame is too small for every band, the least needed bands are dropped
so that the 3-D view keeps at least ``MIN_VIEW`` of the height.

Text is drawn after the 3-D render at output resolution with DejaVu Sans (which has the
Greek letters).  Glyph masks are cached by text and alpha-blended with NumPy (~1 ms a frame);
everything that does not change is drawn once into a static layer.
"""

from __future__ import annotations

import importlib.util
import math
import os
from dataclasses import dataclass, field

import numpy as np
from PIL import Image, ImageFont

from .. import units as U
from .captions import MODEL_COLORS, Captions

_FONT_DIRS = ("/usr/share/fonts/truetype/dejavu",)
NOTE_SEP = "   ·   "
MIN_VIEW_INSET = 0.36     # ... or this, to make room for a requested inset
MIN_VIEW = 0.5           # the 3-D view keeps at least this fraction of the frame height
BODY_TEXT = 15 / 360      # body text size per frame row (15 px at 360 rows, 30 px at 720)
HEADING_TEXT = 18 / 360


def _font_path(name: str = "DejaVuSans.ttf") -> str | None:
    spec = importlib.util.find_spec("matplotlib")
    candidates = [os.path.join(d, name) for d in _FONT_DIRS]
    if spec is not None and spec.origin:
        candidates.insert(0, os.path.join(os.path.dirname(spec.origin), "mpl-data", "fonts", "ttf", name))
    for path in candidates:
        if os.path.exists(path):
            return path
    return None


class Fonts:
    """Fonts sized for a frame of height H: ``main`` (headings, bold), ``small`` (everything else)."""

    def __init__(self, height: int):
        self.size = max(8, int(round(height * BODY_TEXT)))
        self.heading_size = max(9, int(round(height * HEADING_TEXT)))
        regular, bold = _font_path(), _font_path("DejaVuSans-Bold.ttf") or _font_path()
        if regular:
            self.small = ImageFont.truetype(regular, self.size)
            self.main = ImageFont.truetype(bold, self.heading_size)
        else:                                   # Pillow's bundled font (no Greek glyphs)
            self.small = ImageFont.load_default(size=self.size)
            self.main = ImageFont.load_default(size=self.heading_size)
        self.line = int(math.ceil(self.size * 1.25))
        self.heading_line = int(math.ceil(self.heading_size * 1.3))

    def width(self, text: str, font=None) -> float:
        return float((font or self.small).getlength(text))


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

    def put(self, img, xy, text: str, font, fill, anchor: str = "la", clip=None):
        """Blend ``text`` into ``img`` in place -- an (H, W, 3) uint8 array, or a PIL RGB image
        (then Pillow blends in C) -- at ``xy`` with ``anchor``; ``clip`` = (x0, y0, x1, y1)
        keeps it inside a box."""
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


def wrap(text: str, font, width: float, lines: int = 2) -> list[str]:
    """Words of ``text`` on at most ``lines`` lines of ``width`` px (the last cut with "…")."""
    out, cur = [], ""
    for word in text.split():
        trial = f"{cur} {word}".strip()
        if font.getlength(trial) <= width or not cur:
            cur = trial
        else:
            out.append(cur)
            cur = word
    if cur:
        out.append(cur)
    if len(out) > lines:
        out = out[:lines]
        last = out[-1]
        while last and font.getlength(last + "…") > width:
            last = last[:-1]
        out[-1] = last.rstrip() + "…"
    return out


@dataclass
class Row:
    """A band of text across the frame: kind, its top y and height (px)."""

    kind: str
    height: int
    y: int = 0
    payload: object = None


@dataclass
class Layout:
    """Where everything goes in a W x H frame with n side-by-side panels.

    views : per panel (x0, y0, x1, y1) of the 3-D view (output pixels, x1/y1 exclusive);
    headings : per panel [(text, font key, y)], subtitle lines included; readout_y : top of
    the panel numbers; rows : the shared bands under them; divider : (y0, y1) of the line
    between panels.
    """

    W: int
    H: int
    n: int
    pad: int
    fonts: Fonts
    views: list = field(default_factory=list)
    headings: list = field(default_factory=list)
    readout_y: int = 0
    readout_lines: int = 0
    rows: list = field(default_factory=list)
    divider: tuple = (0, 0)
    text: bool = True

    @property
    def panel_width(self) -> int:
        return self.W // self.n

    def panel_x(self, k: int) -> int:
        return k * self.W // self.n


def make_layout(plan, W: int, H: int, show) -> Layout:
    """The bands of a frame for ``plan``: text bands are dropped, least needed first
    (title, notes, subtitle, legend, time bar, numbers, headings), until the 3-D view keeps
    ``MIN_VIEW`` of the height."""
    n = len(plan.panels)
    fonts = Fonts(H)
    pad = max(4, int(round(H * 0.012)))
    hud_on = "hud" in show
    cap = Captions(plan)
    pw = W // n
    legend = cap.legend(show) + _body_chip(plan, show)
    subtitles = [wrap(cap.subtitle(k), fonts.small, pw - 2 * pad) for k in range(n)]
    readout_lines = max(len(cap.readouts(k, 0)) for k in range(n))
    notes_n = len(cap.notes(0))
    F = plan.frames
    sample = sorted(set(np.linspace(0, F - 1, min(F, 24)).round().astype(int)))
    joined = max(fonts.width(NOTE_SEP.join(cap.notes(f))) for f in sample) if notes_n else 0.0
    notes_rows = 1 if joined <= W - 2 * pad else notes_n
    wanted = {"headings": hud_on, "subtitle": hud_on, "readouts": hud_on, "legend": hud_on and bool(legend),
              "timebar": hud_on, "notes": hud_on and notes_n > 0, "title": hud_on and bool(cap.footer()),
              "inset": "inset" in show}
    sub_lines = 2
    steps = ("title", "subtitle2", "inset", "notes2", "subtitle", "notes", "legend", "timebar", "readouts", "headings")
    if not wanted["inset"]:
        steps = tuple(x for x in steps if x != "subtitle2")
    for drop in (None, *steps):
        if drop == "subtitle2":
            sub_lines = 1
        elif drop == "notes2":
            notes_rows = 1
        elif drop:
            wanted[drop] = False
        subtitles = [s[:sub_lines] for s in subtitles]
        top = pad
        if wanted["headings"]:
            top += fonts.heading_line
        if wanted["subtitle"]:
            top += fonts.line * max(len(s) for s in subtitles)
        top += pad if top > pad else 0
        bottom = pad
        bottom += fonts.line * readout_lines if wanted["readouts"] else 0
        rows = []
        if wanted["inset"]:
            rows.append(Row("inset", 3 * fonts.line + pad))
        if wanted["legend"]:
            rows.append(Row("legend", fonts.line + pad // 2, payload=legend))
        if wanted["timebar"]:
            rows.append(Row("timebar", fonts.line + pad // 2))
        if wanted["notes"]:
            rows.append(Row("notes", fonts.line * notes_rows, payload=notes_rows))
        if wanted["title"]:
            rows.append(Row("title", fonts.line))
        bottom += sum(r.height for r in rows) + (pad if rows else 0)
        # a requested inset may take the view down to MIN_VIEW_INSET of the height
        if H - top - bottom >= (MIN_VIEW_INSET if wanted["inset"] else MIN_VIEW) * H:
            break
    lay = Layout(W=W, H=H, n=n, pad=pad, fonts=fonts, text=hud_on)
    view_y1 = H - bottom
    for k in range(n):
        x0 = lay.panel_x(k)
        lay.views.append((x0, top, x0 + pw, view_y1))
        items = []
        y = pad
        if wanted["headings"]:
            head, eq = cap.heading(k)
            items.append((head, "main", y, eq))
            y += fonts.heading_line
        if wanted["subtitle"]:
            for line in subtitles[k]:
                items.append((line, "small", y, ""))
                y += fonts.line
        lay.headings.append(items)
    lay.readout_y = view_y1
    lay.readout_lines = readout_lines if wanted["readouts"] else 0
    y = view_y1 + lay.readout_lines * fonts.line + (pad if rows else 0)
    for r in rows:
        r.y = y
        y += r.height
    lay.rows = rows
    lay.divider = (pad, view_y1 + lay.readout_lines * fonts.line)
    return lay


def _body_chip(plan, show):
    """A legend entry for a drawn body that is not the real crystal's shape."""
    if "body" in show and plan.shape is not None and "inertia" in plan.shape.label:
        return [("body", "box", "with the top's inertia")]
    return []


# --- the time bar ---------------------------------------------------------------------------
def _nice_step(span: float, most: int) -> float:
    raw = span / max(1, most)
    e = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * e >= raw:
            return m * e
    return 10.0 * e


def _fmt_tick(x: float) -> str:
    return f"{x:g}" if abs(x) >= 1e-3 or x == 0 else f"{x:.0e}"


def bar_ticks(plan) -> list[tuple[float, str]]:
    """(position 0..1 along the bar, label) of the time bar's marks: multiples of Theta or T
    (linear map) or their decades (log map); in the scene's time unit when there is no scale."""
    spec, t_end = plan.spec, plan.t_end
    if plan.time_scale is not None:
        sym, unit = plan.time_scale
        suffix = f" {sym}"
    elif plan.units == "cgs":
        unit, sym = _people_unit(t_end)
        suffix = f" {sym}"
    else:
        unit, suffix = 1.0, " τ₀"
    end = t_end / unit
    if spec.time_map == "linear":
        step = _nice_step(end, 6)
        vals = np.arange(step, end * (1 + 1e-9), step)
    else:
        k = spec.knee(t_end) / unit
        lo = math.floor(math.log10(k))
        vals = np.array([10.0 ** e for e in range(lo, math.ceil(math.log10(end)) + 1) if 10.0 ** e <= end * (1 + 1e-9)])
        vals = vals[vals >= k * 0.5]
    out = []
    for v in vals:
        out.append((float(_bar_position(plan, v * unit)), _fmt_tick(float(v)) + suffix))
    return out


def _people_unit(t_end: float) -> tuple[float, str]:
    for unit, name in ((U.YEAR, "yr"), (U.DAY, "d"), (U.HOUR, "h"), (U.MINUTE, "min")):
        if t_end >= 2 * unit:
            return unit, name
    return 1.0, "s"


def _bar_position(plan, t: float) -> float:
    """Fraction of the video at which simulation time t is shown (the time map's inverse)."""
    spec, t_end = plan.spec, plan.t_end
    if spec.time_map == "linear":
        return t / t_end
    k = spec.knee(t_end)
    return math.log1p(t / k) / math.log1p(t_end / k)


# --- drawing -------------------------------------------------------------------------------
@dataclass
class Palette:
    fg: tuple
    bg: tuple
    muted: tuple
    track: tuple
    fill: tuple
    divider: tuple


def palette(background: str) -> Palette:
    if background == "black":
        return Palette(fg=(235, 235, 235), bg=(0, 0, 0), muted=(165, 165, 170), track=(45, 45, 52),
                       fill=(70, 92, 130), divider=(90, 90, 96))
    return Palette(fg=(25, 25, 28), bg=(255, 255, 255), muted=(105, 105, 112), track=(232, 233, 237),
                   fill=(190, 205, 230), divider=(175, 175, 180))


class Hud:
    """Draws a plan's text and 2-D marks: ``static()`` once, ``draw(img, f)`` per frame."""

    def __init__(self, plan, layout: Layout, pal: Palette, arrow_colors: dict, axis_labels=()):
        self.plan, self.lay, self.pal = plan, layout, pal
        self.cap = Captions(plan)
        self.fonts = layout.fonts
        self.stamp = TextStamp()
        self.arrow_colors = arrow_colors
        self.axis_labels = list(axis_labels)
        self._bar = None
        self._inset = None
        self.dirty = self._dirty_boxes()

    def _dirty_boxes(self):
        """The boxes per-frame drawing touches outside the 3-D views: the panels' numbers,
        the time and notes rows, and the axis labels (which may reach past a view's edge)."""
        lay, fonts = self.lay, self.fonts
        out = []
        if lay.readout_lines:
            out.append((0, lay.readout_y, lay.W, min(lay.H, lay.readout_y + lay.readout_lines * fonts.line)))
        for row in lay.rows:
            if row.kind in ("timebar", "notes", "inset"):
                out.append((0, row.y, lay.W, min(lay.H, row.y + row.height)))
        r = fonts.size
        for _, (x, y) in self.axis_labels:
            out.append((max(0, int(x - 2 * r)), max(0, int(y - r)), min(lay.W, int(x + 2 * r)), min(lay.H, int(y + r))))
        return out

    # -- once ------------------------------------------------------------------------------
    def static(self) -> np.ndarray:
        lay, pal, fonts, st = self.lay, self.pal, self.fonts, self.stamp
        img = np.empty((lay.H, lay.W, 3), dtype=np.uint8)
        img[:] = pal.bg
        if not lay.text:
            return img
        for k, items in enumerate(lay.headings):
            x0 = lay.panel_x(k) + lay.pad
            right = lay.panel_x(k) + lay.panel_width - lay.pad
            model_color = MODEL_COLORS.get(self.plan.panels[k].model, pal.fg) if pal.bg[0] > 128 else pal.fg
            for text, which, y, extra in items:
                font = fonts.main if which == "main" else fonts.small
                color = model_color if which == "main" else pal.muted
                clip = (x0, 0, right, lay.H)
                st.put(img, (x0, y), text, font, color, clip=clip)
                if extra:
                    xe = x0 + fonts.width(text, font) + 0.5 * fonts.size
                    if xe + fonts.width(extra) <= right:
                        st.put(img, (xe, y + (fonts.heading_size - fonts.size)), extra, fonts.small, pal.muted, clip=clip)
        if lay.n > 1:
            y0, y1 = lay.divider
            for k in range(1, lay.n):
                img[y0:y1, lay.panel_x(k)] = pal.divider
        for row in lay.rows:
            if row.kind == "legend":
                self._legend(img, row)
            elif row.kind == "title":
                st.put(img, (lay.W // 2, row.y), self.cap.footer(), fonts.small, pal.muted, anchor="ma",
                       clip=(lay.pad, 0, lay.W - lay.pad, lay.H))
            elif row.kind == "timebar":
                self._bar = self._make_bar(row)
            elif row.kind == "inset":
                self._inset = Inset(self.plan, lay, row, pal, self.stamp)
                self._inset.draw_static(img)
        return img

    def _legend(self, img, row):
        """Chips in a row, centred: the symbol and name in white on the arrow's colour."""
        lay, fonts = self.lay, self.fonts
        gap = fonts.size
        items = []
        for key, sym, name in row.payload:
            text = f"{sym}  {name}"
            items.append((key, text, fonts.width(text) + fonts.size))
        total = sum(w for _, _, w in items) + gap * (len(items) - 1)
        x = max(lay.pad, (lay.W - total) / 2)
        h = fonts.line
        for key, text, w in items:
            x0, x1 = int(x), int(min(lay.W - lay.pad, x + w))
            color = self.arrow_colors.get(key, self.pal.muted)
            img[row.y:row.y + h, x0:x1] = color
            self.stamp.put(img, ((x0 + x1) // 2, row.y + h // 2), text, fonts.small, (255, 255, 255), anchor="mm",
                           clip=(x0, row.y, x1, row.y + h))
            x += w + gap

    def _make_bar(self, row):
        """The bar's two looks (empty and filled, ticks labelled on both) and its extent."""
        lay, fonts, pal = self.lay, self.fonts, self.pal
        F = self.plan.frames
        sample = sorted(set(np.linspace(0, F - 1, min(F, 40)).round().astype(int)))
        text_w = max(fonts.width(self.cap.time_text(f)) for f in sample)
        scale = self.cap.scale_text()
        x0 = lay.pad + int(text_w) + fonts.size // 2
        x1 = lay.W - lay.pad - (int(fonts.width(scale)) + fonts.size // 2 if scale else 0)
        h = fonts.line
        y = row.y
        if x1 - x0 < 4 * fonts.size:
            return None
        looks = []
        for color in (pal.track, pal.fill):
            strip = np.empty((h, x1 - x0, 3), dtype=np.uint8)
            strip[:] = color
            last = -1e9
            for pos, label in bar_ticks(self.plan):
                x = int(round(pos * (x1 - x0 - 1)))
                strip[h - max(2, h // 4):, max(0, x - 0):x + 1] = pal.muted
                w = fonts.width(label)
                lx = x - w - 3
                if lx > last + fonts.size // 2 and lx > 2:
                    self.stamp.put(strip, (lx, h // 2), label, fonts.small, pal.muted, anchor="lm")
                    last = x
            looks.append(Image.fromarray(strip))
        return {"x0": x0, "x1": x1, "y": y, "h": h, "empty": looks[0], "full": looks[1], "scale": scale}

    # -- per frame -------------------------------------------------------------------------
    def draw(self, img: Image.Image, f: int) -> Image.Image:
        """Frame f's changing text and marks onto ``img`` (a PIL RGB image, in place)."""
        lay, fonts, pal, st = self.lay, self.fonts, self.pal, self.stamp
        for text, (x, y) in self.axis_labels:
            st.put(img, (x, y), text, fonts.small, pal.muted, anchor="mm")
        if not lay.text:
            return img
        for k in range(lay.n):
            x0 = lay.panel_x(k) + lay.pad
            clip = (x0, 0, lay.panel_x(k) + lay.panel_width - lay.pad, lay.H)
            for i, line in enumerate(self.cap.readouts(k, f)[:lay.readout_lines]):
                st.put(img, (x0, lay.readout_y + i * fonts.line), line, fonts.small, pal.fg, clip=clip)
        for row in lay.rows:
            if row.kind == "timebar":
                self._draw_bar(img, row, f)
            elif row.kind == "inset" and self._inset is not None:
                self._inset.draw(img, f)
            elif row.kind == "notes":
                notes = self.cap.notes(f)
                lines = [NOTE_SEP.join(notes)] if row.payload == 1 else notes
                for i, text in enumerate(lines[:row.payload]):
                    st.put(img, (lay.W // 2, row.y + i * fonts.line), text, fonts.small, pal.muted, anchor="ma",
                           clip=(lay.pad, 0, lay.W - lay.pad, lay.H))
        return img

    def _draw_bar(self, img, row, f):
        st, fonts, pal = self.stamp, self.fonts, self.pal
        text = self.cap.time_text(f)
        bar = self._bar
        if bar is None:
            st.put(img, (self.lay.pad, row.y), text, fonts.small, pal.fg)
            return
        yc = bar["y"] + bar["h"] // 2
        st.put(img, (self.lay.pad, yc), text, fonts.small, pal.fg, anchor="lm")
        x0, x1, y, h = bar["x0"], bar["x1"], bar["y"], bar["h"]
        cut = int(round(float(self.plan.video_t[f]) / float(self.plan.video_t[-1]) * (x1 - x0 - 1))) + 1
        img.paste(bar["full"].crop((0, 0, cut, h)), (x0, y))
        if x0 + cut < x1:
            img.paste(bar["empty"].crop((cut, 0, x1 - x0, h)), (x0 + cut, y))
        img.paste(tuple(pal.fg), (x0 + cut - 1, y, x0 + cut, y + h))
        if bar["scale"]:
            st.put(img, (x1 + fonts.size // 2, yc), bar["scale"], fonts.small, pal.muted, anchor="lm")


# --- the live inset -------------------------------------------------------------------------


class Inset:
    """Two small plots across the frame, against video time like the time bar: the angle
    between d and L (its swing over a turn as a band where the phases are re-timed) and
    |Omega| / |Omega(0)|, one colour per model, with a cursor and a dot on each curve."""

    def __init__(self, plan, lay, row, pal, stamp):
        self.plan, self.lay, self.row, self.pal, self.stamp = plan, lay, row, pal, stamp
        fonts = lay.fonts
        gap = 2 * lay.pad
        label_w = int(fonts.width("180°")) + lay.pad
        w = (lay.W - 2 * lay.pad - gap) // 2
        top = row.y + fonts.line
        bottom = row.y + row.height - lay.pad
        self.boxes = []
        for i in range(2):
            x0 = lay.pad + i * (w + gap) + label_w
            self.boxes.append((x0, top, lay.pad + i * (w + gap) + w, bottom))
        F = plan.frames
        self.x = np.arange(F) / max(1, F - 1)
        w0 = float(plan.panels[0].omega_mag[0]) or 1.0
        self.series = []                    # per panel: (color, angle (F,), band (F, 2) or None, omega ratio (F,))
        for p in plan.panels:
            band = p.angle_dL_range_deg
            ang = p.angle_dL_deg if p.angle_dL_deg is not None else (band.mean(axis=1) if band is not None else None)
            self.series.append((MODEL_COLORS.get(p.model, pal.fg), ang, band, p.omega_mag / w0))
        angles = [a for _, a, b, _ in self.series if a is not None] + [b[:, 1] for _, _, b, _ in self.series
                                                                      if b is not None]
        top_deg = max([float(np.max(a)) for a in angles] + [1.0])
        self.deg_max = min(180.0, 15.0 * math.ceil(top_deg / 15.0))
        self.w_max = max(1.0, float(max(np.max(s[3]) for s in self.series)))

    def _xy(self, box, x, y, ymax):
        x0, y0, x1, y1 = box
        return x0 + x * (x1 - x0 - 1), y1 - 1 - np.clip(y / ymax, 0.0, 1.0) * (y1 - y0 - 1)

    def draw_static(self, img):
        from PIL import ImageDraw

        lay, pal, fonts, st = self.lay, self.pal, self.lay.fonts, self.stamp
        ss = 2                                             # lines drawn at twice the size, then reduced
        y0 = self.row.y
        H = self.row.height
        canvas = Image.new("RGB", (lay.W * ss, H * ss), tuple(pal.bg))
        d = ImageDraw.Draw(canvas)
        lw = max(1, int(round(lay.H / 360 * 1.5 * ss)))
        for j, (box, ymax) in enumerate(zip(self.boxes, (self.deg_max, self.w_max))):
            bx0, by0, bx1, by1 = box
            d.rectangle([bx0 * ss, (by0 - y0) * ss, bx1 * ss - 1, (by1 - y0) * ss - 1], outline=tuple(pal.divider),
                        width=max(1, ss // 2))
            for color, ang, band, wr in self.series:
                if j == 0 and band is not None:
                    xs, lo = self._xy(box, self.x, band[:, 0], ymax)
                    _, hi = self._xy(box, self.x, band[:, 1], ymax)
                    poly = list(zip(xs * ss, (hi - y0) * ss)) + list(zip(xs[::-1] * ss, (lo[::-1] - y0) * ss))
                    light = tuple(int(c + 0.75 * (b - c)) for c, b in zip(color, pal.bg))
                    d.polygon(poly, fill=light)
                y = ang if j == 0 else wr
                if y is None:
                    continue
                xs, ys = self._xy(box, self.x, y, ymax)
                d.line(list(zip(xs * ss, (ys - y0) * ss)), fill=tuple(color), width=lw, joint="curve")
        small = np.asarray(canvas.reduce(ss)).copy()
        img[y0:y0 + H] = small
        names = ("∠(d, L)", "|Ω| / |Ω₀|") if self.plan.units == "cgs" else ("∠(d, L)", "|ω| / |ω₀|")
        tops = (f"{self.deg_max:.0f}°", f"{self.w_max:g}")
        for box, name, top in zip(self.boxes, names, tops):
            bx0, by0, bx1, by1 = box
            st.put(img, (bx0, self.row.y), name, fonts.small, pal.fg)
            st.put(img, (bx0 - lay.pad // 2, by0), top, fonts.small, pal.muted, anchor="ra")
            st.put(img, (bx0 - lay.pad // 2, by1), "0", fonts.small, pal.muted, anchor="rd")
        # which colour is which model, right-aligned on the title line of the second plot
        x = lay.W - lay.pad
        for p in reversed(self.plan.panels):
            color = MODEL_COLORS.get(p.model, pal.fg)
            st.put(img, (x, self.row.y), p.model, fonts.small, color, anchor="ra")
            x -= int(fonts.width(p.model)) + fonts.size

    def draw(self, img, f: int):
        """The cursor and a dot on each curve at frame f (img: PIL RGB image, in place)."""
        r = max(2, self.lay.H // 180)
        for j, (box, ymax) in enumerate(zip(self.boxes, (self.deg_max, self.w_max))):
            bx0, by0, bx1, by1 = box
            xc = int(round(bx0 + self.x[f] * (bx1 - bx0 - 1)))
            img.paste(tuple(self.pal.muted), (xc, by0 + 1, xc + 1, by1 - 1))
            for color, ang, _, wr in self.series:
                y = ang if j == 0 else wr
                if y is None:
                    continue
                _, yy = self._xy(box, self.x[f:f + 1], y[f:f + 1], ymax)
                yc = int(round(yy[0]))
                img.paste(tuple(color), (xc - r, yc - r, xc + r + 1, yc + r + 1))
