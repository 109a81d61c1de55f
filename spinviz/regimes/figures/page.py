"""The atlas as a self-contained web page: the delta-chi diagram of each model in
SVG, a cell's type shares and evidence on hover, its hodograph on click.

No library and no network: the page is one file with inline SVG, CSS and a few lines of
JavaScript.  Each cell is a ``<g>`` whose ``<title>`` the browser shows on hover; clicking it
(or opening the page with ``#open=MODEL:LEVEL:I:J``, level 0 the spec's grid) draws the stored series of the cell's first
member -- omega1 sqrt(tau) against omega2 sqrt(tau) and omega_perp sqrt(tau) against omega3
sqrt(tau), dots coloured by log tau -- in the side panel.  The series travel as base64 int16
at 1e-3 resolution: every other sample of the last ``2 SERIES_POINTS`` (the late decades,
where the types show).

Nothing from outside is ever markup.  The page is opened from links (its address's
``#open=`` is anyone's to write) and shows what a store holds (titles, model names, labels):
in the HTML every such value is escaped (``html.escape``, attributes quoted), the series
travel as JSON with every ``<`` escaped, and the script builds the side panel with
``createElement``/``createElementNS``, ``textContent`` and ``setAttribute`` only -- never
``innerHTML``.  A Content-Security-Policy in the page contains any future slip: no source but
the page's own script (allowed by its sha256: a static file has no fresh nonce) and its own
style sheet (by hash too); no inline event handler, ``style`` attribute, remote load, form,
frame or base.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
import math
import warnings

import numpy as np

from ...physics import asymptotics as FM
from ...physics import presets as P
from .cells import compose_levels
from .style import COLORS, LINE_STYLE, WORDS

W, H = 560, 470                # one panel's plot area, px
PAD_L, PAD_B, PAD_T = 52, 40, 12
SERIES_POINTS = 80


def _x(d: float) -> float:
    return PAD_L + (d + 1.0) / 2.0 * W


def _y(c: float) -> float:
    return PAD_T + (90.0 - c) / 90.0 * H


def _tip(model: str, c: dict, evidence: dict | None) -> str:
    n = sum(c["counts"].values())
    parts = [f"{model} model, \u03b4 = {c['delta']:+.3f}, \u03c7 = {c['chi_deg']:.2f}\u00b0"]
    for name, k in sorted(c["counts"].items(), key=lambda kv: -kv[1]):
        what = f"approaching {name[2:]}" if name.startswith("->") else name
        parts.append(f"{what}: {k}/{n} ({100 * k / n:.0f} %)")
    if c["coexist"]:
        parts.append("two types coexist among the starts")
    if evidence:
        parts.append(", ".join(f"{k} {v:.3g}" for k, v in evidence.items()))
    parts.append("click: hodograph of the first start")
    return "\n".join(parts)


def _text(value) -> str:
    """Any value as HTML text or a quoted attribute's value: escaped, never markup."""
    return html.escape(str(value), quote=True)


def _panel(model: str, cells: list[dict], evidence) -> str:
    name = _text(model)
    out = [f'<svg class="panel" viewBox="0 0 {PAD_L + W + 10} {PAD_T + H + PAD_B}" role="img" '
           f'aria-label="{name} model diagram">',
           f'<text x="{PAD_L + W / 2}" y="{PAD_T - 1}" class="ptitle">{name} model</text>']
    for c in cells:
        out.append(f'<g class="cell" data-id="{_text(c["id"])}"><title>{_text(_tip(model, c, evidence(c)))}</title>')
        x = c["x0"]
        y0, y1 = _y(c["y1"]), _y(c["y0"])
        for name, frac, hatched in c["bars"]:
            w = (c["x1"] - c["x0"]) * frac
            fill = f"url(#hatch-{_key(name)})" if hatched else COLORS[name]
            out.append(f'<rect x="{_x(x):.2f}" y="{y0:.2f}" width="{_x(x + w) - _x(x) + 0.4:.2f}" '
                       f'height="{y1 - y0 + 0.4:.2f}" fill="{fill}"/>')
            x += w
        if c["coexist"]:
            out.append(f'<circle cx="{_x(c["delta"]):.1f}" cy="{_y(c["chi_deg"]):.1f}" r="1.6" class="co"/>')
        out.append("</g>")
    out += _lines(model) + _axes()
    out.append("</svg>")
    return "\n".join(out)


def _lines(model: str) -> list[str]:
    out = []
    for line in FM.boundaries(model, n=401):
        key = next(k for k in sorted(LINE_STYLE, key=len, reverse=True) if line["name"].startswith(k))
        color, ls, at = LINE_STYLE[key]
        color = {"k": "#000000"}.get(color, color)               # matplotlib's shorthand is no SVG colour
        d, c = line["delta"], np.degrees(line["chi"])
        ok = np.isfinite(c) & (c >= 0) & (c <= 90)
        pts = " ".join(f"{_x(a):.1f},{_y(b):.1f}" for a, b in zip(d[ok], c[ok]))
        dash = {"--": "6,3", ":": "2,3", "-.": "7,3,2,3"}.get(ls, "")
        out.append(f'<polyline points="{pts}" fill="none" stroke="{color}" stroke-width="1.6" '
                   f'stroke-dasharray="{dash}" pointer-events="none"/>')
        inside = ok & (c > 2) & (c < 88)
        if inside.any():
            k = int(np.argmin(np.where(inside, np.abs(d - at), np.inf)))
            out.append(f'<text x="{_x(d[k]):.1f}" y="{_y(c[k]) - 3:.1f}" class="lbl" fill="{color}">'
                       f'{html.escape(line["label"])}</text>')
    for fam in P.dast_families():
        y = _y(math.degrees(fam["chi"][0]))
        out.append(f'<line x1="{_x(-1)}" x2="{_x(1)}" y1="{y:.1f}" y2="{y:.1f}" stroke="#404040" stroke-width="1" '
                   f'stroke-dasharray="{"" if fam["style"] == "-" else "7,3,2,3"}" pointer-events="none"/>'
                   f'<text x="{_x(-0.98):.1f}" y="{y - 3:.1f}" class="lbl" fill="#303030">{html.escape(fam["short"])}</text>')
    return out


def _axes() -> list[str]:
    out = [f'<rect x="{PAD_L}" y="{PAD_T}" width="{W}" height="{H}" fill="none" stroke="#333"/>']
    for d in np.linspace(-1, 1, 9):
        out.append(f'<text x="{_x(d):.1f}" y="{PAD_T + H + 14}" class="tick">{d:g}</text>')
    for c in range(0, 91, 15):
        out.append(f'<text x="{PAD_L - 6}" y="{_y(c) + 4:.1f}" class="tick" text-anchor="end">{c}</text>')
    out.append(f'<text x="{PAD_L + W / 2}" y="{PAD_T + H + 32}" class="axis">\u03b4 = 1 \u2212 I\u2083/I\u2081</text>')
    out.append(f'<text x="14" y="{PAD_T + H / 2}" class="axis" transform="rotate(-90 14 {PAD_T + H / 2})">'
               f'\u03c7 (deg)</text>')
    return out


def _pack(series: dict) -> dict:
    """cell id -> {"label", "tau0", "tau1", "b64"}: the last SERIES_POINTS samples of omega
    sqrt(tau) as int16 at 1e-3 (clipped to +-32)."""
    out = {}
    for cid, s in series.items():
        tau = np.asarray(s["tau"], dtype=float)
        w = np.asarray(s["omega"], dtype=float)
        ok = (tau > 0) & np.all(np.isfinite(w), axis=1)
        tau, w = tau[ok][-2 * SERIES_POINTS::2], w[ok][-2 * SERIES_POINTS::2]
        if len(tau) < 2:
            continue
        x = np.clip(np.round(w * np.sqrt(tau)[:, None] * 1e3), -32000, 32000).astype("<i2")
        out[cid] = {"label": s.get("label", ""), "where": s.get("where", cid),
                    "lt0": float(np.log10(tau[0])), "lt1": float(np.log10(tau[-1])),
                    "b64": base64.b64encode(x.tobytes()).decode()}
    return out


SCRIPT = r"""
'use strict';
const NS = 'http://www.w3.org/2000/svg';
const S = JSON.parse(document.getElementById('series').textContent);
function svg(tag, attrs, text) {
  const e = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (text !== undefined) e.textContent = text;
  return e;
}
function para(tag, text) { const e = document.createElement(tag); e.textContent = text; return e; }
function hodo(id) {
  const box = document.getElementById('hodo');
  const s = Object.prototype.hasOwnProperty.call(S, id) ? S[id] : null;
  document.querySelectorAll('.cell').forEach(g => g.classList.toggle('sel', g.dataset.id === id));
  box.replaceChildren();
  if (!s) { box.append(para('p', `${id.slice(0, 200)}: no stored series for this cell`)); return; }
  const raw = atob(s.b64), n = raw.length / 6, v = new DataView(new ArrayBuffer(raw.length));
  for (let i = 0; i < raw.length; i++) v.setUint8(i, raw.charCodeAt(i));
  const p = []; for (let k = 0; k < n; k++) p.push([0,1,2].map(a => v.getInt16(6*k + 2*a, true) / 1000));
  const big = (q) => Math.max(Math.abs(q[0]), Math.abs(q[1]), Math.hypot(q[0], q[1]), Math.abs(q[2]));
  const lim = Math.max(0.05, ...p.map(big)) * 1.1;
  const sc = (x) => 110 + 100 * x / lim, col = (k) => `hsl(${260 - 200 * k / Math.max(1, n - 1)},70%,45%)`;
  const fig = (title, xy) => {
    const f = svg('svg', {viewBox: '0 0 220 240', class: 'h'});
    f.append(svg('text', {x: 110, y: 232, class: 'tick'}, title),
             svg('line', {x1: 10, x2: 210, y1: 110, y2: 110, stroke: '#bbb'}),
             svg('line', {x1: 110, x2: 110, y1: 10, y2: 210, stroke: '#bbb'}));
    p.forEach((q, k) => { const [x, y] = xy(q); f.append(svg('circle', {cx: sc(x), cy: sc(-y), r: 2, fill: col(k)})); });
    return f;
  };
  box.append(para('h3', `${s.where}: first start, label ${s.label}`),
    fig('\u03c9\u2081\u221a\u03c4 \u2192, \u03c9\u2082\u221a\u03c4 \u2191', q => [q[0], q[1]]),
    fig('\u03c9\u22a5\u221a\u03c4 \u2192, \u03c9\u2083\u221a\u03c4 \u2191', q => [Math.hypot(q[0], q[1]), q[2]]),
    para('p', `log\u2081\u2080 \u03c4 from ${s.lt0.toFixed(1)} (violet) to ${s.lt1.toFixed(1)} (green); ` +
              `axes to \u00b1${lim.toFixed(2)}`));
}
document.querySelectorAll('.cell').forEach(g => g.addEventListener('click', () => hodo(g.dataset.id)));
const m = location.hash.match(/open=([^&]+)/);
if (m) { let id = m[1]; try { id = decodeURIComponent(id); } catch (e) { /* not %-encoded: as written */ } hodo(id); }
"""

STYLE = """
body{font-family:sans-serif;margin:12px;color:#222} h1{font-size:18px} .row{display:flex;flex-wrap:wrap;gap:8px}
.panel{width:620px;height:auto} .ptitle{font-size:14px;text-anchor:middle} .tick{font-size:10px;text-anchor:middle}
.axis{font-size:12px;text-anchor:middle} .lbl{font-size:10px;paint-order:stroke;stroke:#fff;stroke-width:3px}
.cell rect{shape-rendering:crispEdges}
.cell:hover rect{opacity:.75} .cell.sel rect{stroke:#000;stroke-width:1} .co{fill:#000;stroke:#fff;stroke-width:.5}
#hodo{min-width:460px} .h{width:220px} .legend span{display:inline-block;margin:2px 10px 2px 0;font-size:12px}
.legend i{display:inline-block;width:14px;height:10px;margin-right:4px;border:1px solid #888;vertical-align:middle}
.defs{position:absolute} .sw-hatched{background:repeating-linear-gradient(45deg,#888 0 2px,#fff 2px 4px)}
"""


def _key(label: str) -> str:
    """A type's label as an id or class name ("3.9" -> "3_9")."""
    return label.replace(".", "_")


def _sha256(text: str) -> str:
    return "'sha256-" + base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode("ascii") + "'"


def policy(script: str, style: str) -> str:
    """The page's Content-Security-Policy: nothing loads or runs but its own script and style
    sheet (each allowed by its sha256), so an inline event handler, a ``style`` attribute, a
    remote image or script, a form, a frame or a ``<base>`` would all be refused."""
    return (f"default-src 'none'; script-src {_sha256(script)}; style-src {_sha256(style)}; base-uri 'none'; "
            f"form-action 'none'")


def page(levels, series: dict | None = None, evidence=None, title: str | None = None) -> str:
    """The page of one atlas: ``levels`` an ``open_atlas`` Dataset or the list of its
    refinement levels (``plot.open_levels``).  series : cell id ("model:level:i:j") ->
    {"tau", "omega" (N, 3), "label"}; evidence(model, cell) -> a small dict shown on hover."""
    levels = levels if isinstance(levels, (list, tuple)) else [levels]
    ds = levels[0]
    models = [str(m) for m in ds["model"].values]
    cells = {m: compose_levels(levels, m) for m in models}
    panels = [_panel(m, cells[m], (lambda c, m=m: evidence(m, c)) if evidence else (lambda c: None)) for m in models]
    drawn = {c["id"] for m in models for c in cells[m]}          # a cell a finer level covers is not drawn
    series = {cid: s for cid, s in (series or {}).items() if cid in drawn}
    hatches = "".join(
        f'<pattern id="hatch-{_key(k)}" patternUnits="userSpaceOnUse" width="4" height="4" '
        f'patternTransform="rotate(45)"><rect width="4" height="4" fill="{c}"/><line x1="0" y1="0" x2="0" y2="4" '
        f'stroke="#fff" stroke-width="1.4"/></pattern>' for k, c in COLORS.items())
    found = {name for m in models for c in cells[m] for name, _, _ in c["bars"]}
    legend = "".join(f'<span><i class="sw-{_key(k)}"></i>{_text(w)}</span>' for k, w in WORDS.items() if k in found)
    legend += ('<span><i class="sw-hatched"></i>'
               'hatched: still approaching that type (a slow hand-over)</span><span>\u25cf two types coexist</span>'
               '<span>black lines: the paper\'s boundaries; blue/red: spinviz\'s (each labelled)</span>')
    style = STYLE + "".join(f".sw-{_key(k)}{{background:{c}}}" for k, c in COLORS.items()) + "\n"
    if len(levels) > 1:
        legend += (f'<span>smaller cells: {len(levels) - 1} refinement level(s) where the types change, down to '
                   f'{levels[-1].sizes["delta"]} \u00d7 {levels[-1].sizes["chi"]} cells</span>')
    head = _text(title or ds.attrs.get("title", "regime atlas"))
    # JSON inside <script type="application/json">: every "<" escaped, so no "</script>" or
    # "<!--" in a title, label or id can end or change the block
    data = json.dumps(_pack(series or {}), separators=(",", ":")).replace("<", "\\u003c")
    csp = _text(policy(SCRIPT, style))
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            f'<meta http-equiv="Content-Security-Policy" content="{csp}"><title>{head}</title><style>{style}</style>'
            f'</head><body><h1>{head}</h1><svg width="0" height="0" class="defs"><defs>{hatches}</defs></svg>'
            f'<div class="row">{"".join(panels)}<div id="hodo"><p>Hover a cell for its types and evidence; click it for '
            f'the hodograph of its first start.</p></div></div><div class="legend">{legend}</div>'
            f'<script type="application/json" id="series">{data}</script><script>{SCRIPT}</script></body></html>')


EVIDENCE = ("slope_perp", "slope_3")     # shown on hover: the exponents of |omega_perp| and |omega_3| in tau


def page_of(levels: list) -> str:
    """The page of an atlas read from its store: every level's cells, the stored series of
    each cell's first start (``[output].series``), and on hover the median confidence and
    fitted exponents of the cell's runs."""
    series, medians = {}, {}
    for k, ds in enumerate(levels):
        has_series = "series" in ds and ds.sizes.get("start", 0) > 0
        tau = ds["tau"].values if has_series else None
        for model in [str(m) for m in ds["model"].values]:
            sub = ds.sel(model=model)
            lab = sub["label"].values
            done = (lab != "missing").all(axis=-1)
            conf = np.where(done[..., None], sub["confidence"].values, np.nan)
            ev = sub["evidence"].sel(quantity=list(EVIDENCE)).values
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)        # all-NaN cells: no median
                med_c, med_e = np.nanmedian(conf, axis=-1), np.nanmedian(ev, axis=-2)
            w = sub["series"].isel(start=0).values.astype(float) if has_series else None
            t_hand = sub["tau_handover"].values[..., 0] if "tau_handover" in sub else None
            for i, j in zip(*np.nonzero(done)):
                cid = f"{model}:{k}:{i}:{j}"
                medians[cid] = {"confidence": med_c[i, j], **{q: med_e[i, j, n] for n, q in enumerate(EVIDENCE)}}
                if w is not None and np.isfinite(w[i, j]).any():
                    where = (f"{model} model, \u03b4 = {float(ds['delta'][i]):+.3f}, "
                             f"\u03c7 = {math.degrees(float(ds['chi'][j])):.2f}\u00b0")
                    t_h = float(t_hand[i, j]) if t_hand is not None else math.nan
                    after = (f" (averaged flow from \u03c4 = {t_h:.0e}: the amplitudes the run's, the phase the "
                             f"averaged one)") if math.isfinite(t_h) else ""
                    series[cid] = {"tau": tau, "omega": w[i, j], "label": str(lab[i, j, 0]) + after, "where": where}
    return page(levels, series, lambda model, c: {q: v for q, v in medians.get(c["id"], {}).items()
                                                   if np.isfinite(v)})
