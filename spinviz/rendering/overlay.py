"""The text and 2-D marks over the frame, as plain data: what each says, where, in which colour.

``make_overlay`` turns a layout's bands into drawing instructions: ``Text`` items (text,
position, anchor, font role, colour, clip box) and ``Fill`` boxes, once for the static layer
and per frame for the changing parts (the panels' numbers, the time, the notes, the axis
labels), a ``TimeBar`` (ticks and the part filled at each frame) and an ``Inset`` (live plots
of angle(d, L) and |Omega| against video time).  The drawing layer only stamps them.

Pure: widths come from the drawing layer's ``layout.TextMetrics``.  Output pixels; colours RGB 0..255.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .captions import Captions
from .layout import NOTE_SEP, Layout, TextMetrics
from .style import MODEL_COLORS, Palette, chip_colors, palette


@dataclass(frozen=True)
class Text:
    """One line of text: ``xy`` (column, row) px, placed by ``anchor`` (Pillow's two letters:
    l/m/r horizontally, a/m/d = ascender / middle / descender vertically), in the ``role``
    font ("small" body text, "main" bold heading), ``color`` RGB 0..255, kept inside ``clip``
    (x0, y0, x1, y1) or the frame."""

    text: str
    xy: tuple[float, float]
    color: tuple
    anchor: str = "la"
    role: str = "small"
    clip: tuple | None = None


@dataclass(frozen=True)
class Fill:
    """A box (x0, y0, x1, y1) px filled with ``color`` RGB 0..255."""

    box: tuple[int, int, int, int]
    color: tuple


@dataclass
class TimeBar:
    """The time bar: its box, its two looks (``track`` before and ``fill`` after now), tick
    marks [(x from the bar's left, label or "", label's left x or None)], and the scale text
    ("Θ = 3.2 days") after it.  ``text_xy`` is where the time ("after 9.5 days") goes."""

    x0: int
    x1: int
    y: int
    h: int
    ticks: list
    scale: str
    track: tuple
    fill: tuple
    tick_color: tuple
    text_xy: tuple[int, int]

    def cut(self, video_t: np.ndarray, f: int) -> int:
        """How many columns of the bar are filled at frame f (at least the cursor's one)."""
        return int(round(float(video_t[f]) / float(video_t[-1]) * (self.x1 - self.x0 - 1))) + 1


@dataclass
class Inset:
    """Two small plots across the frame, against video time like the time bar: the angle
    between d and L (its swing over a turn as a band where the phases are re-timed) and
    |Omega| / |Omega(0)|, one colour per model, with a cursor and a dot on each curve.

    boxes : the two plot boxes, px; x : (F,) video time 0..1; series : per panel (color,
    angle_deg (F,) or None, band_deg (F, 2) or None, |Omega|/|Omega_0| (F,)); ymax : top of
    each plot (deg, ratio); y0, height : the row, px; labels : its static texts."""

    boxes: list
    x: np.ndarray
    series: list
    ymax: tuple[float, float]
    y0: int
    height: int
    labels: list = field(default_factory=list)

    def xy(self, j: int, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Pixel columns and rows of points (x 0..1, y in plot j's unit) in plot j."""
        x0, y0, x1, y1 = self.boxes[j]
        return x0 + x * (x1 - x0 - 1), y1 - 1 - np.clip(y / self.ymax[j], 0.0, 1.0) * (y1 - y0 - 1)

    def curve(self, j: int, k: int):
        """Series k's values in plot j: the angle (deg) or the |Omega| ratio (None if not shown)."""
        _, ang, _, ratio = self.series[k]
        return ang if j == 0 else ratio

    def marks(self, f: int, r: int, cursor_color) -> list[Fill]:
        """The cursor line and a dot (half size ``r`` px) on each curve at frame f."""
        out = []
        for j, (bx0, by0, bx1, by1) in enumerate(self.boxes):
            xc = int(round(bx0 + self.x[f] * (bx1 - bx0 - 1)))
            out.append(Fill((xc, by0 + 1, xc + 1, by1 - 1), cursor_color))
            for k, (color, *_rest) in enumerate(self.series):
                y = self.curve(j, k)
                if y is None:
                    continue
                _, yy = self.xy(j, self.x[f:f + 1], y[f:f + 1])
                yc = int(round(yy[0]))
                out.append(Fill((xc - r, yc - r, xc + r + 1, yc + r + 1), color))
        return out


@dataclass
class Overlay:
    """Everything 2-D on a frame: ``static`` marks (``Text`` and ``Fill``, in drawing order),
    the ``bar`` and ``inset`` (None when not shown), ``dynamic`` boxes that per-frame drawing
    touches (restored from the static layer before each frame), and ``texts(f)``."""

    plan: object
    layout: Layout
    palette: Palette
    static: list
    bar: TimeBar | None
    inset: Inset | None
    axis_labels: list
    dynamic: list

    def texts(self, f: int) -> list[Text]:
        """The changing text of frame f: axis labels, each panel's numbers, the time (and the
        bar's scale), the notes."""
        lay, pal, cap = self.layout, self.palette, Captions(self.plan)
        out = [Text(text, xy, pal.muted, anchor="mm") for text, xy in self.axis_labels]
        if not lay.text:
            return out
        for k in range(lay.n):
            x0 = lay.panel_x(k) + lay.pad
            clip = (x0, 0, lay.panel_x(k) + lay.panel_width - lay.pad, lay.H)
            for i, line in enumerate(cap.readouts(k, f)[:lay.readout_lines]):
                out.append(Text(line, (x0, lay.readout_y + i * lay.sizes.line), pal.fg, clip=clip))
        for row in lay.rows:
            if row.kind == "timebar":
                out += self._time(cap, row, f)
            elif row.kind == "notes":
                notes = cap.notes(f)
                lines = [NOTE_SEP.join(notes)] if row.payload == 1 else notes
                for i, text in enumerate(lines[:row.payload]):
                    out.append(Text(text, (lay.W // 2, row.y + i * lay.sizes.line), pal.muted, anchor="ma",
                                    clip=(lay.pad, 0, lay.W - lay.pad, lay.H)))
        return out

    def _time(self, cap: Captions, row, f: int) -> list[Text]:
        text, bar, pal = cap.time_text(f), self.bar, self.palette
        if bar is None:
            return [Text(text, (self.layout.pad, row.y), pal.fg)]
        out = [Text(text, bar.text_xy, pal.fg, anchor="lm")]
        if bar.scale:
            out.append(Text(bar.scale, (bar.x1 + self.layout.sizes.size // 2, bar.text_xy[1]), pal.muted, anchor="lm"))
        return out


def make_overlay(plan, layout: Layout, metrics: TextMetrics, axis_labels=()) -> Overlay:
    """The overlay of ``plan`` (a ``FramePlan``) in ``layout``: static marks in drawing order
    (headings, divider, then the rows), the time bar, the inset, the dynamic boxes."""
    pal = palette(plan.spec.background)
    cap = Captions(plan)
    static, bar, inset = [], None, None
    if layout.text:
        static += _headings(plan, layout, pal, metrics)
        y0, y1 = layout.divider
        static += [Fill((layout.panel_x(k), y0, layout.panel_x(k) + 1, y1), pal.divider) for k in range(1, layout.n)]
        for row in layout.rows:
            if row.kind == "legend":
                static += _legend(layout, row, metrics, chip_colors(plan.body_name), pal)
            elif row.kind == "title":
                static.append(Text(cap.footer(), (layout.W // 2, row.y), pal.muted, anchor="ma",
                                   clip=(layout.pad, 0, layout.W - layout.pad, layout.H)))
            elif row.kind == "timebar":
                bar = _time_bar(plan, cap, layout, row, metrics, pal)
            elif row.kind == "inset":
                inset = _inset(plan, layout, row, metrics, pal)
    labels = list(axis_labels)
    return Overlay(plan=plan, layout=layout, palette=pal, static=static, bar=bar, inset=inset, axis_labels=labels,
                   dynamic=_dynamic_boxes(layout, labels))


def _headings(plan, lay: Layout, pal: Palette, metrics: TextMetrics) -> list[Text]:
    """Each panel's heading in its model's colour (on a light background), the equation numbers
    after it where they fit, and the subtitle lines, all kept inside the panel."""
    out = []
    sizes = lay.sizes
    for k, items in enumerate(lay.headings):
        x0 = lay.panel_x(k) + lay.pad
        right = lay.panel_x(k) + lay.panel_width - lay.pad
        model_color = MODEL_COLORS.get(plan.panels[k].model, pal.fg) if pal.bg[0] > 128 else pal.fg
        clip = (x0, 0, right, lay.H)
        for text, role, y, extra in items:
            out.append(Text(text, (x0, y), model_color if role == "main" else pal.muted, role=role, clip=clip))
            if extra:
                xe = x0 + metrics.width(text, role) + 0.5 * sizes.size
                if xe + metrics.width(extra) <= right:
                    out.append(Text(extra, (xe, y + (sizes.heading_size - sizes.size)), pal.muted, clip=clip))
    return out


def _legend(lay: Layout, row, metrics: TextMetrics, colors: dict, pal: Palette) -> list:
    """Chips in a row, centred: the symbol and name in white on the arrow's colour."""
    size, h = lay.sizes.size, lay.sizes.line
    items = [(key, f"{sym}  {name}") for key, sym, name in row.payload]
    widths = [metrics.width(text) + size for _, text in items]
    x = max(lay.pad, (lay.W - (sum(widths) + size * (len(items) - 1))) / 2)
    out = []
    for (key, text), w in zip(items, widths):
        x0, x1 = int(x), int(min(lay.W - lay.pad, x + w))
        out.append(Fill((x0, row.y, x1, row.y + h), colors.get(key, pal.muted)))
        out.append(Text(text, ((x0 + x1) // 2, row.y + h // 2), (255, 255, 255), anchor="mm",
                        clip=(x0, row.y, x1, row.y + h)))
        x += w + size
    return out


def _time_bar(plan, cap: Captions, lay: Layout, row, metrics: TextMetrics, pal: Palette) -> TimeBar | None:
    """The bar between the time text (as wide as its widest sample) and the scale text; None
    when less than four characters' width is left for it.  A tick's label goes left of its
    mark, and only where it clears the previous label."""
    size, h = lay.sizes.size, lay.sizes.line
    F = plan.frames
    sample = sorted(set(np.linspace(0, F - 1, min(F, 40)).round().astype(int)))
    text_w = max(metrics.width(cap.time_text(f)) for f in sample)
    scale = cap.scale_text()
    x0 = lay.pad + int(text_w) + size // 2
    x1 = lay.W - lay.pad - (int(metrics.width(scale)) + size // 2 if scale else 0)
    if x1 - x0 < 4 * size:
        return None
    ticks, last = [], -1e9
    for pos, label in cap.bar_ticks():
        x = int(round(pos * (x1 - x0 - 1)))
        lx = x - metrics.width(label) - 3
        if lx > last + size // 2 and lx > 2:
            ticks.append((x, label, lx))
            last = x
        else:
            ticks.append((x, "", None))
    return TimeBar(x0=x0, x1=x1, y=row.y, h=h, ticks=ticks, scale=scale, track=pal.track, fill=pal.fill,
                   tick_color=pal.muted, text_xy=(lay.pad, row.y + h // 2))


def _inset(plan, lay: Layout, row, metrics: TextMetrics, pal: Palette) -> Inset:
    """The two plots' boxes (a label column left of each), series and scales: angles up to the
    next 15 deg (180 at most), ratios up to max(1, highest)."""
    pad, line = lay.pad, lay.sizes.line
    gap = 2 * pad
    label_w = int(metrics.width("180°")) + pad
    w = (lay.W - 2 * pad - gap) // 2
    boxes = [(pad + i * (w + gap) + label_w, row.y + line, pad + i * (w + gap) + w, row.y + row.height - pad)
             for i in range(2)]
    F = plan.frames
    w0 = float(plan.panels[0].omega_mag[0]) or 1.0
    series = []
    for p in plan.panels:
        band = p.angle_dL_range_deg
        ang = p.angle_dL_deg if p.angle_dL_deg is not None else (band.mean(axis=1) if band is not None else None)
        series.append((MODEL_COLORS.get(p.model, pal.fg), ang, band, p.omega_mag / w0))
    angles = [a for _, a, b, _ in series if a is not None] + [b[:, 1] for _, _, b, _ in series if b is not None]
    top_deg = max([float(np.max(a)) for a in angles] + [1.0])
    ymax = (min(180.0, 15.0 * math.ceil(top_deg / 15.0)), max(1.0, float(max(np.max(s[3]) for s in series))))
    inset = Inset(boxes=boxes, x=np.arange(F) / max(1, F - 1), series=series, ymax=ymax, y0=row.y, height=row.height)
    names = ("∠(d, L)", "|Ω| / |Ω₀|") if plan.units == "cgs" else ("∠(d, L)", "|ω| / |ω₀|")
    tops = (f"{ymax[0]:.0f}°", f"{ymax[1]:g}")
    for (bx0, by0, _, by1), name, top in zip(boxes, names, tops):
        inset.labels += [Text(name, (bx0, row.y), pal.fg), Text(top, (bx0 - pad // 2, by0), pal.muted, anchor="ra"),
                         Text("0", (bx0 - pad // 2, by1), pal.muted, anchor="rd")]
    # which colour is which model, right-aligned on the title line of the second plot
    x = lay.W - pad
    for p in reversed(plan.panels):
        inset.labels.append(Text(p.model, (x, row.y), MODEL_COLORS.get(p.model, pal.fg), anchor="ra"))
        x -= int(metrics.width(p.model)) + lay.sizes.size
    return inset


def _dynamic_boxes(lay: Layout, axis_labels) -> list[tuple[int, int, int, int]]:
    """The boxes per-frame drawing touches outside the 3-D views: the panels' numbers, the
    time, notes and inset rows, and the axis labels (which may reach past a view's edge)."""
    out = []
    if lay.readout_lines:
        out.append((0, lay.readout_y, lay.W, min(lay.H, lay.readout_y + lay.readout_lines * lay.sizes.line)))
    for row in lay.rows:
        if row.kind in ("timebar", "notes", "inset"):
            out.append((0, row.y, lay.W, min(lay.H, row.y + row.height)))
    r = lay.sizes.size
    for _, (x, y) in axis_labels:
        out.append((max(0, int(x - 2 * r)), max(0, int(y - r)), min(lay.W, int(x + 2 * r)), min(lay.H, int(y + r))))
    return out
