"""A frame plan as one self-contained web page: both models side by side, turnable and
zoomable with the mouse, a play/pause button and a time slider marked in the scene's units,
and the video's captions and honesty line.

The page is one file that loads nothing: three.js (vendored from the npm registry with its
MIT licence, ``web/``) and spinviz's viewer script are inline, allowed by their sha256
hashes under a Content-Security-Policy that permits nothing else (no remote load, no inline
handler, no eval); the model is the same glTF binary as ``--out X.glb``, carried as base64
and read from memory by three.js's GLTFLoader; the captions travel as JSON.  Everything that
comes from outside (titles, subtitles, captions) reaches the page as text: JSON in a data
block, set with textContent by the script (the <title> is HTML-escaped).

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
from importlib import resources

from ..presentation import style as model_style
from .captions import texts_of
from .gltf import model_offsets, view_gltf
from .style import ARROW_COLORS, AXIS_LENGTH, COLORS, VIEW_ANGLE, palette

__all__ = ["page", "csp_hash"]




def _asset(name: str) -> str:
    return resources.files(__package__).joinpath("web", name).read_text(encoding="utf-8")


def csp_hash(text: str) -> str:
    """The Content-Security-Policy source for an inline script or style: 'sha256-<base64>'."""
    return "'sha256-" + base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode("ascii") + "'"


def _css_rgb(rgb) -> str:
    return "rgb({}, {}, {})".format(*(int(round(255 * float(c))) for c in rgb))


def _hex(rgb255) -> str:
    return "#{:02x}{:02x}{:02x}".format(*rgb255)


def page_data(plan, kf) -> dict:
    """The JSON the viewer script reads: texts per frame (deduplicated notes), ticks, layout."""
    texts = texts_of(plan)
    table, index = [], []
    seen = {}
    for lines in texts.notes:
        key = tuple(lines)
        if key not in seen:
            seen[key] = len(table)
            table.append(list(lines))
        index.append(seen[key])
    pal = palette(plan.spec.background)
    return {
        "title": texts.footer, "scale": texts.scale,
        "headings": [list(h) for h in texts.headings], "subtitles": list(texts.subtitles),
        "model_colors": [_hex(model_style(p.model).color) for p in plan.panels],
        "legend": [{"key": k, "symbol": s, "name": nm, "color": _css_rgb(ARROW_COLORS[k])} for k, s, nm in texts.legend
                   if k in ARROW_COLORS],
        "ticks": [[float(p), str(label)] for p, label in texts.bar_ticks],
        "time": list(texts.time), "notes_table": table, "notes_index": index,
        "readouts": [[list(r) for r in panel] for panel in texts.readouts],
        "frames": plan.frames, "duration": plan.spec.duration, "fps": plan.spec.fps,
        "key_frames": [int(f) for f in kf.frame],
        "background": _hex(pal.bg), "view": view_gltf(plan.spec).tolist(), "yfov_deg": VIEW_ANGLE,
        "axes": "axes" in plan.spec.show, "axis_length": AXIS_LENGTH, "offsets": model_offsets(len(plan.panels)),
    }


def _json_block(data) -> str:
    """JSON safe inside a <script type="application/json"> element (no '</script>', no '<!--')."""
    return json.dumps(data, ensure_ascii=False).replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


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
    pal = palette(plan.spec.background)
    scene_colors = COLORS[plan.spec.background]
    css = (":root { " + f"--bg: {_hex(pal.bg)}; --fg: {_hex(pal.fg)}; --muted: {_hex(pal.muted)}; "
           f"--divider: {_hex(pal.divider)}; --axes: {_css_rgb(scene_colors['axes'])}; " + "}\n" + _asset("page.css"))
    three, viewer = _asset("three.min.js"), _asset("viewer.js")
    csp = (f"default-src 'none'; script-src {csp_hash(three)} {csp_hash(viewer)}; style-src {csp_hash(css)}; "
           "img-src 'none'; connect-src 'none'; font-src 'none'; base-uri 'none'; form-action 'none'")
    title = html.escape(texts_of(plan).footer if plan.spec.title == "" else plan.spec.title)
    panels = "\n".join(f'<div class="panel" id="panel-{k}"><h2 id="head-{k}"></h2><p class="sub" id="sub-{k}"></p>'
                       f'<p class="read" id="read-{k}"></p></div>' for k in range(len(plan.panels)))
    b64 = base64.b64encode(glb).decode("ascii")
    lines = [b64[i:i + 120] for i in range(0, len(b64), 120)]
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
<header><h1 id="title"></h1><p id="scale"></p></header>
<div id="stage">
{panels}
<div id="labels"></div>
</div>
<div id="controls"><button id="play" type="button">Play</button>
<div id="track"><input id="slider" type="range" min="0" max="1" step="1" value="0" aria-label="time"><div id="ticks"></div></div>
</div>
<div id="below">
<p id="time"></p>
<p id="notes"></p>
<div id="legend"></div>
<p id="status" role="status">Loading the model...</p>
</div>
<footer>Made with spinviz. The poses are the video's: at every frame within {_deg(kf.tolerance)} of what the video draws,
exact at the {kf.count} keyframes. Viewer: three.js (MIT licence), inside this page; nothing is loaded from the network.</footer>
<script type="application/json" id="spinviz-data">{_json_block(page_data(plan, kf))}</script>
<script type="application/octet-stream" id="spinviz-glb">
{chr(10).join(lines)}
</script>
<script>{three}</script>
<script>{viewer}</script>
</body>
</html>
"""


def _deg(rad: float) -> str:
    import math

    return f"{math.degrees(rad):.2g}°"
