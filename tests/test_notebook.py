"""The turnable view inline in a notebook: ``spinviz.show(source)``.

What Jupyter displays (``_repr_html_``) is one sandboxed iframe whose ``srcdoc`` is the page
``render(source, out="X.html")`` writes, byte for byte (slow: two pages) -- so it passes the
page's own CSP check -- for a trajectory, a pair of them or a scene; in Chromium (slow) the
framed page draws both crystals.
"""

from __future__ import annotations

import html
import json
import re

import pytest

import spinviz
from spinviz.errors import SpecError, SpecTypeError

from media import check_csp, sha, write_scene

LOOK = {"duration": 1.0, "fps": 10, "show": ("body", "dipole", "L", "axes", "sphere", "hud")}


@pytest.fixture(scope="module")
def runs():
    body = spinviz.symmetric_top(0.3, 0.7)
    return [spinviz.simulate(body, m, (0.0, 0.05, 0.3), t_end=40.0, samples=200) for m in ("reduced", "truncated")]


def srcdoc(shown: str) -> str:
    """The page inside the one iframe that ``shown`` (a ``_repr_html_``) is."""
    m = re.fullmatch(r'<iframe srcdoc="([^"]*)" sandbox="allow-scripts" allow="fullscreen" allowfullscreen '
                     r'width="100%" height="(\d+)" frameborder="0" title="spinviz: turnable view"></iframe>', shown, flags=re.S)
    assert m is not None, shown[:200]
    return html.unescape(m.group(1))


def test_a_pair_of_trajectories_shows_as_a_self_contained_page_inline(runs, tmp_path):
    """The display is one sandboxed iframe (its scripts only, full screen allowed) whose page,
    two panels, passes the page's CSP check; ``save`` writes that page."""
    view = spinviz.show(runs, **LOOK)
    page = srcdoc(view._repr_html_())
    assert page == view.html
    check_csp(page)
    assert page.count('class="panel"') == 2 and view.frames == 10 and 2 <= view.keyframes <= 10
    assert view.save(tmp_path / "saved.html") == str(tmp_path / "saved.html")
    assert (tmp_path / "saved.html").read_text() == page


@pytest.mark.slow
def test_the_inline_page_is_the_one_render_writes(runs, tmp_path):
    """Byte for byte the page ``render(source, out="X.html")`` writes with the same settings,
    for a pair of trajectories and for one (whose page speaks of one crystal); a scene (a path)
    is simulated and shown, and a hostile title stays text inside the frame's markup."""
    for source in (runs, runs[0]):
        out = tmp_path / "x.html"
        spinviz.render(source, out=str(out), **LOOK)
        assert srcdoc(spinviz.show(source, **LOOK)._repr_html_()) == out.read_text()
    assert "Drag to turn the crystal" in out.read_text() and out.read_text().count('class="panel"') == 1
    scene = write_scene(tmp_path / "t.toml", title='x" onload="alert(1)', duration=1.0, fps=10)
    shown = spinviz.show(str(scene), height=500)._repr_html_()
    assert 'height="500"' in shown and shown.count('"') == 14          # no quote of the title escapes the attribute
    check_csp(srcdoc(shown))


def test_bad_arguments_get_one_clear_error(runs):
    with pytest.raises(SpecError, match="^height: must lie in"):
        spinviz.show(runs, height=10)
    with pytest.raises(SpecTypeError, match="^source: must be"):
        spinviz.show(42)
    with pytest.raises(SpecError, match="^show: a .html shows the body and its arrows"):
        spinviz.show(runs, duration=1.0, fps=10, show=("hud",))


@pytest.mark.slow
def test_the_inline_view_draws_in_chromium(runs, tmp_path):
    """A notebook's output cell, as a file: inside its sandboxed frame the page draws both views
    (a probe added to the page, and to its policy, reports two canvases the size of their views
    once the page is ready) and shows both crystals (the tan box in each half of the frame)."""
    from browser import CHROMIUM, WEBGL_FLAGS, chromium, screenshot
    from test_page import PROBE

    from spinviz.notebook import Turnable

    if CHROMIUM is None:
        pytest.fail("the notebook view's test needs chromium (apt-get install chromium; .ci/run does this)", pytrace=False)
    view = spinviz.show(runs, **LOOK)
    page = view.html.replace("script-src ", f"script-src {sha(PROBE)} ", 1)
    page = page.replace("<script>", f"<script>{PROBE}</script>\n<script>", 1)
    cell = tmp_path / "cell.html"
    cell.write_text("<!DOCTYPE html><html><body style='margin:0'>" + Turnable(page, 0, 0, 900)._repr_html_()
                    + '<pre id="out"></pre><script>window.addEventListener("message", (e) => { '
                      'document.getElementById("out").textContent = String(e.data); });</script></body></html>')
    # a frame of another origin (a sandboxed one has none) runs in a process of its own, whose clock headless
    # Chromium's virtual time does not drive: one process here
    flags = (*WEBGL_FLAGS, "--disable-site-isolation-trials", "--disable-features=IsolateOrigins,site-per-process")
    dom = chromium(cell, tmp_path, *flags, "--window-size=1280,1000", "--dump-dom").stdout
    after = json.loads(html.unescape(re.search(r'<pre id="out">(.*?)</pre>', dom, flags=re.S).group(1)))["after"]
    assert len(after["canvases"]) == 2 and after["canvases"] == after["views"] and after["visible"] == ["hidden", "hidden"]
    img = screenshot(cell, tmp_path, size=(1280, 900), flags=flags)
    tan = (img.astype(int).mean(axis=2) < 200) & (img[..., 0].astype(int) - img[..., 2] > 15)
    assert tan[:, :640].sum() > 2000 and tan[:, 640:].sum() > 2000
