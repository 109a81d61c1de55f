"""Where everything goes on a frame: bands that never overlap, in output pixels.

Per panel a heading and a plain subtitle on top, the 3-D view, the panel's numbers under it;
across the frame an inset of live plots (angle(d, L) and |Omega| for "inset", the radiated
power for "power", side by side in one row), a legend of the arrows, a time bar, notes on how
time and spin are shown, and the title.  Type scales with the frame height (15 px body text
at 360 rows, never below 8 px); when a frame is too small for every band, the least needed
bands are dropped so that the 3-D view keeps at least ``MIN_VIEW`` of the height.

Pure: text widths come from a ``TextMetrics`` the drawing layer provides (it owns the fonts),
so the whole layout is computed -- and tested -- without loading a drawing library.
Pixels: x to the right, y down, boxes (x0, y0, x1, y1) with x1 and y1 exclusive.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

NOTE_SEP = "   ·   "
MIN_VIEW = 0.5            # the 3-D view keeps at least this fraction of the frame height
MIN_VIEW_INSET = 0.36     # ... or this, to make room for a requested inset
BODY_TEXT = 15 / 360      # body text size per frame row (15 px at 360 rows, 30 px at 720)
HEADING_TEXT = 18 / 360
MIN_BODY_TEXT_PX, MIN_HEADING_TEXT_PX = 8, 9
# bands dropped in this order until the 3-D view is tall enough (least needed first);
# "subtitle2" and "notes2" take a band down to one line before it goes
# the live plots of the inset row, per ``[render].show`` item, left to right; each needs a
# label column (as wide as PLOT_LABEL_SAMPLE, or its widest tick label), then room for its
# title and at least PLOT_MIN_WIDTH body-text sizes of plot
INSET_PLOTS = {"inset": ("angle", "omega"), "power": ("power",)}
PLOT_LABEL_SAMPLE = "180°"
PLOT_TICK_SAMPLE = {"power": "10⁻²⁰"}
PLOT_MIN_WIDTH = 4
DROP_ORDER = ("title", "subtitle2", "inset", "notes2", "subtitle", "notes", "legend", "timebar", "readouts", "headings")


@dataclass(frozen=True)
class TextSizes:
    """Type sizes of a frame, px: ``size`` (body text), ``heading_size`` (bold headings), and
    the line pitch of each (``line``, ``heading_line``)."""

    size: int
    heading_size: int
    line: int
    heading_line: int

    @classmethod
    def for_height(cls, height: int) -> TextSizes:
        """The sizes for a frame ``height`` rows high: 15 px body text at 360 rows, in proportion."""
        size = max(MIN_BODY_TEXT_PX, int(round(height * BODY_TEXT)))
        heading = max(MIN_HEADING_TEXT_PX, int(round(height * HEADING_TEXT)))
        return cls(size=size, heading_size=heading, line=int(math.ceil(size * 1.25)),
                   heading_line=int(math.ceil(heading * 1.3)))


class TextMetrics(Protocol):
    """What the layout needs of the fonts: their ``sizes`` and the advance width, px, of a
    text in the body font (role "small") or the heading font (role "main")."""

    sizes: TextSizes

    def width(self, text: str, role: str = "small") -> float:
        """Advance width of ``text``, px, in the body ("small") or heading ("main") font."""
        ...


def wrap(text: str, metrics: TextMetrics, width: float, lines: int = 2) -> list[str]:
    """Words of ``text`` on at most ``lines`` lines of ``width`` px (the last cut with "…")."""
    out, cur = [], ""
    for word in text.split():
        trial = f"{cur} {word}".strip()
        if metrics.width(trial) <= width or not cur:
            cur = trial
        else:
            out.append(cur)
            cur = word
    if cur:
        out.append(cur)
    if len(out) > lines:
        out = out[:lines]
        last = out[-1]
        while last and metrics.width(last + "…") > width:
            last = last[:-1]
        out[-1] = last.rstrip() + "…"
    return out


@dataclass
class Row:
    """A band across the frame: ``kind`` ("inset", "legend", "timebar", "notes", "title"),
    its ``height`` and top ``y`` (px); ``payload``: the inset's plots (``INSET_PLOTS`` names,
    left to right), the legend's chips, the notes' line count."""

    kind: str
    height: int
    y: int = 0
    payload: object = None


@dataclass
class Layout:
    """Where everything goes in a W x H frame with n side-by-side panels (output pixels).

    views : per panel (x0, y0, x1, y1) of the 3-D view;
    headings : per panel [(text, role, y, secondary text)], subtitle lines included (role
        "main" for the heading, "small" for a subtitle line; the secondary text is the
        equation numbers shown after a heading);
    readout_y, readout_lines : top of the panels' numbers and how many lines they keep;
    rows : the shared bands under them; divider : (y0, y1) of the line between panels;
    text : False when the scene shows no HUD (then no text is drawn at all).
    """

    W: int
    H: int
    n: int
    pad: int
    sizes: TextSizes
    views: list = field(default_factory=list)
    headings: list = field(default_factory=list)
    readout_y: int = 0
    readout_lines: int = 0
    rows: list = field(default_factory=list)
    divider: tuple = (0, 0)
    text: bool = True

    @property
    def panel_width(self) -> int:
        """Width of one panel, px."""
        return self.W // self.n

    def panel_x(self, k: int) -> int:
        """Left edge of panel k, px."""
        return k * self.W // self.n


@dataclass
class _Wants:
    """What the bands need, measured once: which are wanted, the wrapped subtitles (on up to
    two lines, and on one), the lines of numbers and notes, the legend's chips and the inset's
    plots."""

    wanted: dict
    subtitles: list
    readout_lines: int
    notes_rows: int
    legend: list
    sub_lines: int = 2
    plots: tuple = ()
    short_subtitles: list = field(default_factory=list)


def make_layout(plan, texts, metrics: TextMetrics) -> Layout:
    """The bands of a frame: text bands are dropped, least needed first (``DROP_ORDER``),
    until the 3-D view keeps ``MIN_VIEW`` of the height (``MIN_VIEW_INSET`` with an inset).

    Parameters
    ----------
    plan : FramePlan
        Its spec gives the frame size (W, H) px and what is shown.
    texts : captions.Texts
        The words the bands must hold (subtitles are wrapped to the panel's width).
    metrics : TextMetrics
        Type sizes and text widths, px.

    Returns
    -------
    Layout
        Output pixels; the views span their panels' width (the stage may narrow them).
    """
    W, H = plan.spec.size
    show = set(plan.spec.show)
    sizes = metrics.sizes
    pad = max(4, int(round(H * 0.012)))
    want = _measure(plan, texts, metrics, show, W, pad)
    steps = DROP_ORDER if want.wanted["inset"] else tuple(x for x in DROP_ORDER if x != "subtitle2")
    for drop in (None, *steps):
        if drop == "subtitle2":
            # one line each, re-wrapped so that a cut subtitle ends with "…" (not mid-sentence)
            want.sub_lines, want.subtitles = 1, want.short_subtitles
        elif drop == "notes2":
            want.notes_rows = 1
        elif drop:
            want.wanted[drop] = False
        top, rows, bottom = _bands(want, sizes, pad)
        if H - top - bottom >= (MIN_VIEW_INSET if want.wanted["inset"] else MIN_VIEW) * H:
            break
    lay = Layout(W=W, H=H, n=len(plan.panels), pad=pad, sizes=sizes, text="hud" in show)
    view_y1 = lay.H - bottom
    for k in range(lay.n):
        x0 = lay.panel_x(k)
        lay.views.append((x0, top, x0 + lay.panel_width, view_y1))
        lay.headings.append(_heading_lines(texts.headings[k], want.subtitles[k], want.wanted, sizes, pad))
    lay.readout_y = view_y1
    lay.readout_lines = want.readout_lines if want.wanted["readouts"] else 0
    y = view_y1 + lay.readout_lines * sizes.line + (pad if rows else 0)
    for r in rows:
        r.y = y
        y += r.height
    lay.rows = rows
    lay.divider = (pad, view_y1 + lay.readout_lines * sizes.line)
    return lay


def _measure(plan, texts, metrics: TextMetrics, show, W: int, pad: int) -> _Wants:
    """The bands a frame would hold with room for all: the notes fit on one line if their
    widest sample (24 frames) does, else one line each."""
    n = len(plan.panels)
    hud_on = "hud" in show
    subtitles = [wrap(texts.subtitles[k], metrics, W // n - 2 * pad) for k in range(n)]
    short = [wrap(texts.subtitles[k], metrics, W // n - 2 * pad, lines=1) for k in range(n)]
    notes_n = len(texts.notes[0])
    F = plan.frames
    sample = sorted(set(np.linspace(0, F - 1, min(F, 24)).round().astype(int)))
    joined = max(metrics.width(NOTE_SEP.join(texts.notes[f])) for f in sample) if notes_n else 0.0
    plots = _fitting_plots(texts, metrics, show, W, pad)
    wanted = {"headings": hud_on, "subtitle": hud_on, "readouts": hud_on, "legend": hud_on and bool(texts.legend),
              "timebar": hud_on, "notes": hud_on and notes_n > 0, "title": hud_on and bool(texts.footer),
              "inset": bool(plots)}
    return _Wants(wanted=wanted, subtitles=subtitles, readout_lines=max(len(texts.readouts[k][0]) for k in range(n)),
                  notes_rows=1 if joined <= W - 2 * pad else notes_n, legend=texts.legend, plots=plots,
                  short_subtitles=short)


def _fitting_plots(texts, metrics: TextMetrics, show, W: int, pad: int) -> tuple[str, ...]:
    """The live plots ``show`` asks for that fit side by side across the frame, the rightmost
    dropped first: each needs its label column, its title (or ``PLOT_MIN_WIDTH`` body-text
    sizes) and a gap of two pads to the next."""
    plots = [plot for item, names in INSET_PLOTS.items() if item in show for plot in names]
    size = metrics.sizes.size

    def need(name: str) -> float:
        labels = max(metrics.width(PLOT_LABEL_SAMPLE), metrics.width(PLOT_TICK_SAMPLE.get(name, "")))
        return labels + pad + max(metrics.width(texts.plot_titles.get(name, "")), PLOT_MIN_WIDTH * size)

    while plots and sum(need(p) for p in plots) + 2 * pad * (len(plots) - 1) > W - 2 * pad:
        plots.pop()
    return tuple(plots)


def _bands(want: _Wants, sizes: TextSizes, pad: int) -> tuple[int, list[Row], int]:
    """(height above the views, the shared rows, height below the views) for what is wanted."""
    wanted = want.wanted
    top = pad
    if wanted["headings"]:
        top += sizes.heading_line
    if wanted["subtitle"]:
        top += sizes.line * max(len(s) for s in want.subtitles)
    top += pad if top > pad else 0
    bottom = pad
    bottom += sizes.line * want.readout_lines if wanted["readouts"] else 0
    rows = []
    if wanted["inset"]:
        rows.append(Row("inset", 3 * sizes.line + pad, payload=want.plots))
    if wanted["legend"]:
        rows.append(Row("legend", sizes.line + pad // 2, payload=want.legend))
    if wanted["timebar"]:
        rows.append(Row("timebar", sizes.line + pad // 2))
    if wanted["notes"]:
        rows.append(Row("notes", sizes.line * want.notes_rows, payload=want.notes_rows))
    if wanted["title"]:
        rows.append(Row("title", sizes.line))
    bottom += sum(r.height for r in rows) + (pad if rows else 0)
    return top, rows, bottom


def _heading_lines(heading, subtitle, wanted, sizes: TextSizes, pad: int) -> list:
    """A panel's heading (with its equation numbers) and subtitle lines: [(text, role, y, secondary)]."""
    items = []
    y = pad
    if wanted["headings"]:
        head, eq = heading
        items.append((head, "main", y, eq))
        y += sizes.heading_line
    if wanted["subtitle"]:
        for line in subtitle:
            items.append((line, "small", y, ""))
            y += sizes.line
    return items
