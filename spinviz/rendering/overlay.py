"""The text and 2-D marks over the frame, as plain data: what each says, where, in which colour.

``make_overlay`` turns a layout's bands and a video's words (``captions.Texts``) into
drawing instructions, for every frame at once: ``Text`` items and ``Fill`` boxes for the
static layer (headings, divider, legend chips, title), ``Line`` items whose text changes
from frame to frame (axis labels, the panels' numbers, the time, the notes), the
``TimeBar`` (ticks, and how much of it is filled at each frame) and the ``Inset`` (live plots
of angle(d, L), |Omega| and the radiated power against video time, their cursor and dots at
each frame).  The
drawing layer only stamps them.

Pure: widths come from the drawing layer's ``layout.TextMetrics``.  Output pixels (x right,
y down; boxes (x0, y0, x1, y1), x1 and y1 exclusive); colours RGB 0..255.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..presentation import style as model_style
from .captions import decade
from .layout import NOTE_SEP, PLOT_LABEL_SAMPLE, Layout, TextMetrics
from .style import Palette

WHITE = (255, 255, 255)
POWER_DECADES = 12      # the power plot's depth: a reduced run's P may fall to 0 (its residual rotation is dark)


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
class Line:
    """Text at one place whose words change: ``texts[f]`` at frame f ("" = nothing), drawn
    like a ``Text`` with the other fields."""

    texts: list
    xy: tuple[float, float]
    color: tuple
    anchor: str = "la"
    clip: tuple | None = None


@dataclass
class TimeBar:
    """The time bar: its box, its two looks (``track`` before and ``fill`` after now), tick
    marks [(x from the bar's left, label, label's left x)] (label "" where it would crowd the
    previous one), and ``cuts`` (F,): the filled columns at each frame (the last one is the
    cursor, drawn in ``cursor`` colour)."""

    x0: int
    x1: int
    y: int
    h: int
    ticks: list
    track: tuple
    fill: tuple
    tick_color: tuple
    cursor: tuple
    cuts: np.ndarray


@dataclass
class Inset:
    """Small live plots side by side across the frame, against video time like the time bar
    (a log-mapped video has a log time axis here too), one colour per model, with a cursor and
    a dot on each curve: the angle between d and L (its swing over a turn as a band where the
    phases are re-timed), |Omega| / |Omega(0)|, and the radiated power P on a log scale.

    y0, height : the row, px; plots : the plots' names (``layout.INSET_PLOTS``), left to right;
    boxes : their boxes, in the same order; scales : per plot ("linear", 0, top) in its unit
    (deg, ratio) or ("log", lo, hi): decades of P in W (CGS) or I1/tau0^3 (dimensionless), the
    box's bottom and top rows; shapes : in drawing order, ("frame", colour, box), ("rule",
    colour, (x0, y0, x1, y1)) a one-pixel grid line, ("band", fill colour, xs, lo, hi) the
    swing band between two rows per column, ("curve", colour, xs, ys) a polyline, all in output
    pixels; labels : static ``Text``; cursor : (n, F) the cursor's column in each plot; dots :
    [(colour, plot j, rows (F,))]; dot_radius, px.
    """

    y0: int
    height: int
    boxes: list
    plots: tuple = ("angle", "omega")
    scales: list = field(default_factory=list)
    shapes: list = field(default_factory=list)
    labels: list = field(default_factory=list)
    cursor: np.ndarray | None = None
    cursor_color: tuple = (0, 0, 0)
    dots: list = field(default_factory=list)
    dot_radius: int = 2


@dataclass
class Overlay:
    """Everything 2-D on a frame: ``static`` marks (``Text`` and ``Fill``, in drawing order),
    the per-frame ``lines``, the ``bar`` and ``inset`` (None when not shown), ``background``,
    and ``dynamic``: the boxes that per-frame drawing touches outside the 3-D views (restored
    from the static layer before each frame)."""

    background: tuple
    static: list
    lines: list
    bar: TimeBar | None
    inset: Inset | None
    dynamic: list


def make_overlay(plan, layout: Layout, texts, theme, metrics: TextMetrics, axis_labels=()) -> Overlay:
    """Everything 2-D on the frames of ``plan``, for every frame at once.

    Parameters
    ----------
    plan : FramePlan
    layout : layout.Layout
        The bands (output px).
    texts : captions.Texts
        The words, per frame where they change.
    theme : style.Theme
        HUD palette and legend chip colours (RGB 0..255).
    metrics : layout.TextMetrics
        Text widths, px (headings' equation numbers, legend chips, time bar, inset).
    axis_labels : list of (str, (float, float))
        Axis names and tick values at output pixels (column, row), from the stage.

    Returns
    -------
    Overlay
        Static marks in drawing order, per-frame lines, time bar, inset, dynamic boxes.
    """
    pal, F = theme.hud, plan.frames
    labels = [Line([text] * F, xy, pal.muted, anchor="mm") for text, xy in axis_labels]
    static, bar, inset = [], None, None
    if not layout.text:
        return Overlay(pal.bg, static, labels, None, None, _dynamic_boxes(layout, axis_labels))
    static += _headings(plan, layout, pal, metrics)
    y0, y1 = layout.divider
    static += [Fill((layout.panel_x(k), y0, layout.panel_x(k) + 1, y1), pal.divider) for k in range(1, layout.n)]
    lines = labels + _readouts(layout, texts, pal)
    inset_row = None
    for row in layout.rows:
        if row.kind == "legend":
            static += _legend(layout, row, metrics, theme.chips, pal)
        elif row.kind == "title":
            static.append(Text(texts.footer, (layout.W // 2, row.y), pal.muted, anchor="ma",
                               clip=(layout.pad, 0, layout.W - layout.pad, layout.H)))
        elif row.kind == "timebar":
            bar = _time_bar(plan, texts, layout, row, metrics, pal)
            lines += _time_lines(texts, layout, row, bar, pal)
        elif row.kind == "notes":
            lines += _note_lines(texts, layout, row, pal)
        elif row.kind == "inset":
            inset_row = row
    if inset_row is not None:                  # after the time bar: a power plot alone lines up with it
        inset = _inset(plan, texts, layout, inset_row, bar, metrics, pal)
    return Overlay(pal.bg, static, lines, bar, inset, _dynamic_boxes(layout, axis_labels))


def _headings(plan, lay: Layout, pal: Palette, metrics: TextMetrics) -> list[Text]:
    """Each panel's heading in its model's colour (on a light background), the equation numbers
    after it where they fit, and the subtitle lines, all kept inside the panel."""
    out = []
    sizes = lay.sizes
    for k, items in enumerate(lay.headings):
        x0 = lay.panel_x(k) + lay.pad
        right = lay.panel_x(k) + lay.panel_width - lay.pad
        model_color = model_style(plan.panels[k].model).color if pal.bg[0] > 128 else pal.fg
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
        out.append(Text(text, ((x0 + x1) // 2, row.y + h // 2), WHITE, anchor="mm", clip=(x0, row.y, x1, row.y + h)))
        x += w + size
    return out


def _readouts(lay: Layout, texts, pal: Palette) -> list[Line]:
    """Each panel's numbers under its view, one ``Line`` per line, kept inside the panel."""
    out = []
    for k in range(lay.n):
        x0 = lay.panel_x(k) + lay.pad
        clip = (x0, 0, lay.panel_x(k) + lay.panel_width - lay.pad, lay.H)
        for i in range(lay.readout_lines):
            words = [lines[i] if i < len(lines) else "" for lines in texts.readouts[k]]
            out.append(Line(words, (x0, lay.readout_y + i * lay.sizes.line), pal.fg, clip=clip))
    return out


def _time_lines(texts, lay: Layout, row, bar: TimeBar | None, pal: Palette) -> list[Line]:
    """The time left of the bar (or alone on its row), and the bar's unit right of it."""
    if bar is None:
        return [Line(list(texts.time), (lay.pad, row.y), pal.fg)]
    yc = row.y + bar.h // 2
    out = [Line(list(texts.time), (lay.pad, yc), pal.fg, anchor="lm")]
    if texts.scale:
        out.append(Line([texts.scale] * len(texts.time), (bar.x1 + lay.sizes.size // 2, yc), pal.muted, anchor="lm"))
    return out


def _note_lines(texts, lay: Layout, row, pal: Palette) -> list[Line]:
    """How time and spin are shown, centred: all on one line, or one line each."""
    per_frame = [[NOTE_SEP.join(notes)] if row.payload == 1 else notes for notes in texts.notes]
    clip = (lay.pad, 0, lay.W - lay.pad, lay.H)
    return [Line([lines[i] if i < len(lines) else "" for lines in per_frame], (lay.W // 2, row.y + i * lay.sizes.line),
                 pal.muted, anchor="ma", clip=clip) for i in range(row.payload)]


def _time_bar(plan, texts, lay: Layout, row, metrics: TextMetrics, pal: Palette) -> TimeBar | None:
    """The bar between the time text (as wide as its widest sample) and the scale text; None
    when less than four characters' width is left for it.  A tick's label goes left of its
    mark, and only where it clears the previous label."""
    size, h = lay.sizes.size, lay.sizes.line
    F = plan.frames
    sample = sorted(set(np.linspace(0, F - 1, min(F, 40)).round().astype(int)))
    text_w = max(metrics.width(texts.time[f]) for f in sample)
    x0 = lay.pad + int(text_w) + size // 2
    x1 = lay.W - lay.pad - (int(metrics.width(texts.scale)) + size // 2 if texts.scale else 0)
    if x1 - x0 < 4 * size:
        return None
    ticks, last = [], -1e9
    for pos, label in texts.bar_ticks:
        x = int(round(pos * (x1 - x0 - 1)))
        lx = x - metrics.width(label) - 3
        shown = lx > last + size // 2 and lx > 2
        ticks.append((x, label if shown else "", lx))
        last = x if shown else last
    video_t = plan.video_t
    cuts = np.array([int(round(float(video_t[f]) / float(video_t[-1]) * (x1 - x0 - 1))) + 1 for f in range(F)])
    return TimeBar(x0=x0, x1=x1, y=row.y, h=h, ticks=ticks, track=pal.track, fill=pal.fill, tick_color=pal.muted,
                   cursor=pal.fg, cuts=cuts)


def _inset(plan, texts, lay: Layout, row, bar: TimeBar | None, metrics: TextMetrics, pal: Palette) -> Inset:
    """The plots' boxes (a label column left of each), scales, curves and marks per frame.

    Scales: angles up to the next 15 deg (180 at most), ratios up to max(1, highest), the power
    over whole decades (at most ``POWER_DECADES``, counted down from the highest value).  The
    plots share the row equally; a power plot alone spans the time bar's columns instead, so
    its cursor stands right above the bar's."""
    plots = tuple(row.payload or ("angle", "omega"))
    pad, line = lay.pad, lay.sizes.line
    y0, y1 = row.y + line, row.y + row.height - pad
    series = {name: _plot_series(name, plan, pal) for name in plots}
    scales = {name: _plot_scale(name, series[name]) for name in plots}
    ticks = {name: _scale_labels(name, scales[name]) for name in plots}
    # a label column as wide as "180°" (angle, ratio) or the widest decade (power)
    label_w = {name: int(max(metrics.width(t) for t in (*ticks[name], PLOT_LABEL_SAMPLE))) + pad for name in plots}
    if plots == ("power",) and bar is not None and label_w["power"] <= bar.x0 - pad:
        boxes = [(bar.x0, y0, bar.x1, y1)]
    else:
        gap = 2 * pad
        w = (lay.W - 2 * pad - (len(plots) - 1) * gap) // len(plots)
        boxes = [(pad + i * (w + gap) + label_w[name], y0, pad + i * (w + gap) + w, y1) for i, name in enumerate(plots)]
    inset = Inset(y0=row.y, height=row.height, boxes=boxes, plots=plots, scales=[scales[n] for n in plots],
                  cursor_color=pal.muted, dot_radius=max(2, lay.H // 180))
    _inset_marks(inset, plan.frames, [series[n] for n in plots], texts, pal)
    titles = texts.plot_titles
    for (bx0, by0, _, by1), name in zip(boxes, plots):
        top, bottom = ticks[name]
        inset.labels += [Text(titles[name], (bx0, row.y), pal.fg), Text(top, (bx0 - pad // 2, by0), pal.muted, anchor="ra"),
                         Text(bottom, (bx0 - pad // 2, by1), pal.muted, anchor="rd")]
    # which colour is which model, right-aligned on the title line of the last plot, where it
    # clears that plot's title (the panels' headings say it in the same colours anyway)
    names = [(p.model, model_style(p.model).color) for p in plan.panels]
    width = sum(metrics.width(m) for m, _ in names) + lay.sizes.size * (len(names) - 1)
    x = boxes[-1][2]
    if x - width >= boxes[-1][0] + metrics.width(titles[plots[-1]]) + lay.sizes.size:
        for model, color in reversed(names):
            inset.labels.append(Text(model, (x, row.y), color, anchor="ra"))
            x -= int(metrics.width(model)) + lay.sizes.size
    return inset


def _plot_series(name: str, plan, pal: Palette) -> list:
    """Per panel (colour, values (F,) in the plot's unit, swing band (F, 2) or None): degrees,
    |Omega| / |Omega(0)| of the first panel, or P in W (CGS; the plan keeps erg/s) or I1/tau0^3."""
    out = []
    w0 = float(plan.panels[0].omega_mag[0]) or 1.0
    to_display = U.ERG_PER_S_IN_W if plan.units == "cgs" else 1.0
    for p in plan.panels:
        color = model_style(p.model).color
        if name == "angle":
            band = p.angle_dL_range_deg
            ang = p.angle_dL_deg if p.angle_dL_deg is not None else (band.mean(axis=1) if band is not None else None)
            out.append((color, ang, band))
        elif name == "omega":
            out.append((color, p.omega_mag / w0, None))
        else:
            out.append((color, None if p.power is None else np.asarray(p.power, dtype=float) * to_display, None))
    return out


def _plot_scale(name: str, series) -> tuple:
    """("linear", 0, top) or ("log", lo, hi) (decades) for a plot's values."""
    if name == "angle":
        angles = [v for _, v, _ in series if v is not None] + [b[:, 1] for _, _, b in series if b is not None]
        top_deg = max([float(np.max(a)) for a in angles] + [1.0])
        return ("linear", 0.0, min(180.0, 15.0 * math.ceil(top_deg / 15.0)))
    if name == "omega":
        return ("linear", 0.0, max(1.0, max(float(np.max(v)) for _, v, _ in series)))
    values = np.concatenate([v for _, v, _ in series if v is not None] or [np.zeros(0)])
    values = values[np.isfinite(values) & (values > 0.0)]
    if values.size == 0:                    # nothing radiates (a free top): an empty decade
        return ("log", -1, 0)
    hi = math.ceil(math.log10(float(values.max())))
    lo = max(math.floor(math.log10(float(values.min()))), hi - POWER_DECADES)
    return ("log", min(lo, hi - 1), hi)


def _scale_labels(name: str, scale) -> tuple[str, str]:
    """The (top, bottom) tick labels of a plot's scale: "45°" and "0" for angles, "1" and "0"
    for ratios, decades ("10⁻¹⁶", "10⁻²³") for the power."""
    kind, lo, hi = scale
    if kind == "log":
        return decade(hi), decade(lo)
    return (f"{hi:.0f}°" if name == "angle" else f"{hi:g}"), "0"


def _inset_marks(inset: Inset, F: int, series, texts, pal: Palette) -> None:
    """The inset's frames, grid rules, bands and curves in pixels, and its cursor and dots at
    every frame."""
    x = np.arange(F) / max(1, F - 1)
    faint = tuple(int(c + 0.6 * (b - c)) for c, b in zip(pal.divider, pal.bg))

    def xy(j, xs, ys):
        """Pixel columns and rows of points (video fraction, value in plot j's unit) in plot j."""
        x0, y0, x1, y1 = inset.boxes[j]
        kind, lo, hi = inset.scales[j]
        if kind == "log":
            with np.errstate(divide="ignore", invalid="ignore"):
                frac = (np.log10(np.where(ys > 0.0, ys, np.nan)) - lo) / (hi - lo)
            frac = np.nan_to_num(frac, nan=0.0)      # P = 0 (no radiation) sits on the bottom edge
        else:
            frac = ys / hi
        return x0 + xs * (x1 - x0 - 1), y1 - 1 - np.clip(frac, 0.0, 1.0) * (y1 - y0 - 1)

    cursor = []
    for j, box in enumerate(inset.boxes):
        inset.shapes.append(("frame", pal.divider, box))
        x0, y0, x1, y1 = box
        cursor.append([int(round(x0 + x[f] * (x1 - x0 - 1))) for f in range(F)])
        kind, lo, hi = inset.scales[j]
        if kind == "log":
            # one rule per decade (where they stay 3 px apart), and one at each of the time bar's ticks
            if (y1 - y0 - 1) / (hi - lo) >= 3.0:
                for e in range(lo + 1, hi):
                    yr = int(round(xy(j, np.zeros(1), np.array([10.0 ** e]))[1][0]))
                    inset.shapes.append(("rule", faint, (x0 + 1, yr, x1 - 2, yr)))
            for pos, _ in texts.bar_ticks:
                col = int(round(x0 + pos * (x1 - x0 - 1)))
                if x0 < col < x1 - 1:
                    inset.shapes.append(("rule", faint, (col, y0 + 1, col, y1 - 2)))
        for color, y, band in series[j]:
            if band is not None:
                xs, lo_rows = xy(j, x, band[:, 0])
                _, hi_rows = xy(j, x, band[:, 1])
                inset.shapes.append(("band", tuple(int(c + 0.75 * (b - c)) for c, b in zip(color, pal.bg)), xs,
                                     lo_rows, hi_rows))
            if y is None:
                continue
            inset.shapes.append(("curve", color) + xy(j, x, y))
            rows = np.rint(xy(j, x, y)[1]).astype(int)
            inset.dots.append((color, j, rows))
    inset.cursor = np.array(cursor)


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
