"""A frame plan as one self-contained web page for people: what the crystals are in one
sentence, each model turnable under its heading (side by side on a wide screen, one above
the other on a phone), a play/pause button and a time slider in people's units, full screen,
labels on the arrows, and the captions in plain words (``pagetext``; the physics captions
where the scene asks for them).

The page is one file that loads nothing: three.js (vendored from the npm registry, its MIT
licence printed in the page) and spinviz's viewer script are inline, allowed by their sha256
hashes under a Content-Security-Policy that permits nothing else (no remote load, no inline
handler, no eval, no style attribute); the model is the same glTF binary as ``--out X.glb``,
carried as base64 and read from memory by three.js's GLTFLoader.  Until the 3-D view is
ready -- and in a browser without WebGL -- each view shows its poster, the opening frame as
inline SVG (``poster``), at the place the 3-D view then draws it.  Every text from outside
(titles, subtitles, captions) reaches the page as text: escaped in the markup, JSON in a
data block, set with textContent by the script.

The page exposes the pose it shows: ``window.pose(k)`` returns model k's body orientation,
scalar first (w, x, y, z), body -> spinviz world, and each panel element carries it in its
``data-pose`` attribute.  ``#frame=N`` in the address opens it at the video's frame N (as if
the slider had been set there); ``#frame=N&view=AZ,EL`` also turns the view to that azimuth
and elevation (degrees, as the scene's ``azimuth_deg``, ``elevation_deg``): a link to a
chosen moment and viewpoint.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
import math
from importlib import resources

from ..presentation import style as model_style
from .pagetext import ARROW_LABELS, page_texts
from .poster import page_camera, svg, view_direction
from .style import ARROW_COLORS, AXIS_LENGTH, COLORS, palette

__all__ = ["page", "csp_hash", "THREE_LICENCE"]

THREE_LICENCE = "LICENSE-three.txt"


def _asset(name: str) -> str:
    return resources.files(__package__).joinpath("web", name).read_text(encoding="utf-8")


def csp_hash(text: str) -> str:
    """The Content-Security-Policy source for an inline script or style: 'sha256-<base64>'."""
    return "'sha256-" + base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode("ascii") + "'"


def _css_rgb(rgb) -> str:
    return "rgb({}, {}, {})".format(*(int(round(255 * float(c))) for c in rgb))


def _hex(rgb255) -> str:
    return "#{:02x}{:02x}{:02x}".format(*rgb255)


def page_data(plan, kf, texts, camera) -> dict:
    """The JSON the viewer script reads: texts per frame (deduplicated notes), the clock, the
    view camera (distance, image-plane half-extent R) and the labels."""
    table, index = [], []
    seen = {}
    for lines in texts.notes:
        key = tuple(lines)
        if key not in seen:
            seen[key] = len(table)
            table.append(list(lines))
        index.append(seen[key])
    pal = palette(plan.spec.background)
    v = view_direction(plan.spec)
    return {
        "time": list(texts.time), "notes_table": table, "notes_index": index,
        "readouts": [[list(r) for r in panel] for panel in texts.readouts],
        "frames": plan.frames, "fps": plan.spec.fps, "key_frames": [int(f) for f in kf.frame],
        "background": _hex(pal.bg), "view": [float(v[0]), float(v[2]), float(-v[1])],
        "distance": camera[0], "extent": camera[1], "panels": len(plan.panels),
        "axes": "axes" in plan.spec.show, "axis_length": AXIS_LENGTH,
        "labels": {k: ARROW_LABELS[k] for k in ("dipole", "L", "omega") if k in plan.spec.show},
        "how": texts.how, "no_webgl": texts.no_webgl,
    }


def _json_block(data) -> str:
    """JSON safe inside a <script type="application/json"> element (no '</script>', no '<!--')."""
    return json.dumps(data, ensure_ascii=False).replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def _css(plan, texts) -> str:
    """The page's style sheet: its colours, the slider's marks and the legend's chips, then
    ``web/page.css`` (one block, allowed by its hash: no style attribute is needed)."""
    pal = palette(plan.spec.background)
    scene_colors = COLORS[plan.spec.background]
    rules = [":root { " + f"--bg: {_hex(pal.bg)}; --fg: {_hex(pal.fg)}; --muted: {_hex(pal.muted)}; "
             f"--divider: {_hex(pal.divider)}; --axes: {_css_rgb(scene_colors['axes'])}; " + "}"]
    for k, p in enumerate(plan.panels):
        rules.append(f"#head-{k} {{ color: {_hex(model_style(p.model).color)}; }}")
    for key, rgb in ARROW_COLORS.items():
        rules.append(f".c-{key} {{ background: {_css_rgb(rgb)}; }} .lab-{key} {{ color: {_css_rgb(rgb)}; }}")
    for i, (pos, _) in enumerate(texts.ticks):
        rules.append(f"#tick-{i} {{ left: {100 * pos:.3f}%; }}")
    return "\n".join(rules) + "\n" + _asset("page.css")


def _lines(lines) -> str:
    return html.escape("\n".join(lines))


def _panels(plan, texts, camera) -> str:
    """Each model's section: heading, subtitle, its 3-D view (the poster until the script
    draws) and its numbers at the first frame."""
    e = html.escape
    return "\n".join(
        f'<section class="panel" id="panel-{k}" aria-labelledby="head-{k}">'
        f'<h2 id="head-{k}">{e(h[0])}{f" <span class=eq>{e(h[1])}</span>" if h[1] else ""}</h2>'
        f'<p class="sub" id="sub-{k}">{e(texts.subtitles[k])}</p>'
        f'<div class="view" id="view-{k}">{svg(plan, k, *camera)}<div class="labels" id="labels-{k}" aria-hidden="true">'
        f'</div></div><p class="read" id="read-{k}">{_lines(texts.readouts[k][0])}</p></section>'
        for k, h in enumerate(texts.headings))


def page(plan, kf, glb: bytes) -> str:
    """The page's HTML.

    Parameters
    ----------
    plan : FramePlan
        Captions, ticks, colours, the camera's direction.
    kf : keyframes.Keyframes
        The keyframes of ``glb`` (the slider's frames map onto them).
    glb : bytes
        The binary glTF (``gltf.to_bytes``) the page shows.

    Returns
    -------
    str
        One HTML document, nothing external.
    """
    texts = page_texts(plan)
    camera = page_camera(plan)
    css = _css(plan, texts)
    three, viewer = _asset("three.min.js"), _asset("viewer.js")
    csp = (f"default-src 'none'; script-src {csp_hash(three)} {csp_hash(viewer)}; style-src {csp_hash(css)}; "
           "img-src 'none'; connect-src 'none'; font-src 'none'; base-uri 'none'; form-action 'none'")
    e = html.escape
    title = e(texts.title if plan.spec.title == "" else plan.spec.title)
    panels = _panels(plan, texts, camera)
    ticks = "".join(f'<span class="tick{_tick_class(i, pos, len(texts.ticks))}" id="tick-{i}">{e(label)}</span>'
                    for i, (pos, label) in enumerate(texts.ticks))
    legend = "".join(f'<span class="item"><span class="chip c-{key}"></span>{e(sym)}: {e(words)}</span>'
                     if key in ARROW_COLORS else f'<span class="item">{e(sym)}: {e(words)}</span>'
                     for key, sym, words in texts.legend)
    b64 = base64.b64encode(glb).decode("ascii")
    lines = [b64[i:i + 120] for i in range(0, len(b64), 120)]
    licence = e(_asset(THREE_LICENCE).strip())
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="{csp}">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>{css}</style>
</head>
<body>
<div id="app">
<header><h1 id="title">{e(texts.title)}</h1><p id="lead">{e(texts.lead)}</p></header>
<div id="stage" class="n{len(plan.panels)}">
{panels}
</div>
<div id="controls"><button id="play" type="button">Play</button>
<div id="track"><input id="slider" type="range" min="0" max="{plan.frames - 1}" step="1" value="0" \
aria-label="time in the video"><div id="ticks">{ticks}</div></div>
<button id="full" type="button" hidden>Full screen</button></div>
<div id="below">
<p id="time">{e(texts.time[0])}</p>
<p id="notes">{e(" ".join(texts.notes[0]))}</p>
<div id="legend">{legend}</div>
<p id="scale">{e(texts.scale)}</p>
<p id="status" role="status">Loading the 3-D view...</p>
<noscript><p>Scripts are off in this browser: the pictures show the start only.</p></noscript>
<p id="alt">{e(texts.alt)}</p>
</div>
</div>
<footer><p>Made with spinviz. The poses are the video's: at every frame within {_deg(kf.tolerance)} of what the video
draws, exact at the {kf.count} keyframes. Nothing is loaded from the network: the 3-D viewer, three.js, is inside this
page, under the MIT licence below.</p>
<details><summary>Licence of three.js</summary><pre id="licence">{licence}</pre></details></footer>
<script type="application/json" id="spinviz-data">{_json_block(page_data(plan, kf, texts, camera))}</script>
<script type="application/octet-stream" id="spinviz-glb">
{chr(10).join(lines)}
</script>
<script>{three}</script>
<script>{viewer}</script>
</body>
</html>
"""


def _tick_class(i: int, pos: float, count: int) -> str:
    """A mark's classes: "minor" (every other one, hidden on a phone) and "end" (right-aligned
    near the slider's end, so that its label stays on the page)."""
    out = " minor" if count > 3 and i % 2 == 0 and pos < 0.95 else ""
    return out + (" end" if pos > 0.9 else "")


def _deg(rad: float) -> str:
    return f"{math.degrees(rad):.2g}°"
