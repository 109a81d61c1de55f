"""The turnable page (.html) for people: plain words, one sentence up front, a layout from a
360 px phone to a wide screen, a poster until the 3-D view is drawn, labels on the arrows,
full screen, a text alternative, the three.js MIT notice -- one file under a hash-only
Content-Security-Policy that loads nothing.

Fast tests read the markup and the texts (``pagetext`` on small frame plans made here);
headless Chromium (slow) opens the page from a file with no network at 360, 768 and 1280 px
and reads, through a probe script added to a copy of the page (and to its policy), where
each caption box and each canvas lies, whether the posters were up before any 3-D was drawn,
and what the page asked the network for (Chromium's net log).
"""

from __future__ import annotations

import html
import json
import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from spinviz import rotations as R
from spinviz.inputs.render import RenderSpec
from spinviz.rendering import keyframes, pagetext
from spinviz.rendering.frameplan import FramePlan, Panel, ShapeInfo

from media import ROOT, TITLE, check_csp, page_glb, sha

LICENCE = (ROOT / "spinviz" / "rendering" / "web" / "LICENSE-three.txt").read_text()


@pytest.fixture(scope="module")
def scene(askew):
    return askew.scene


@pytest.fixture(scope="module")
def plan(askew):
    return askew.plan


@pytest.fixture(scope="module")
def page(askew) -> Path:
    return askew.page


def fake_plan(models=("reduced", "truncated"), captions="outreach", F=5, units="cgs", body="DAST cube 100 nm") -> FramePlan:
    """A frame plan of a 100 nm cube turning at 7.1e9 turns/s, slowed 1.3e15 times, over
    19 days (F frames): only what the page's words read."""
    spec = RenderSpec(duration=F / 10, fps=10, captions=captions, show=("body", "dipole", "L", "axes", "sphere", "hud"))
    q = np.tile([1.0, 0.0, 0.0, 0.0], (F, 1))
    panels = [Panel(model=m, omega_mag=np.full(F, 2 * math.pi * 7.1e9), q=q, R_world_from_body=R.matrix_from_quat(q),
                    angle_dL_deg=np.full(F, 45.0)) for m in models]
    return FramePlan(spec=spec, video_t=np.linspace(0, spec.duration, F), sim_t=np.linspace(0, 19 * 86400.0, F),
                     panels=panels, units=units, body_name=body,
                     shape=ShapeInfo(kind="box", dims=(1e-5, 1e-5, 1e-5), label="cube (crystal faces)"),
                     d_body=np.array([0.0, 0.0, 1.0]), spin_mode="slowed", slowdown=np.full(F, 1.3e15),
                     time_scale=("Θ", 3.1 * 86400.0))


# --- the markup ----------------------------------------------------------------------------------
@pytest.mark.slow
def test_page_is_self_contained_under_its_csp(page, askew):
    """One file under 2 MB under a hash-only CSP (``check_csp``: no style attribute, no remote
    element either); the title is text (escaped), the data block cannot close its element; the
    model inside is the .glb ``render`` wrote for the same scene, byte for byte."""
    text = check_csp(page.read_text())
    assert "<b>" not in re.sub(r"<script\b[^>]*>.*?</script>", "", text, flags=re.S)
    assert "<title>Askew top &lt;b&gt;bold&lt;/b&gt; &amp; &quot;quoted&quot; &lt;/script&gt;</title>" in text
    assert '<h1 id="title">Askew top &lt;b&gt;bold&lt;/b&gt; &amp; &quot;quoted&quot; &lt;/script&gt;</h1>' in text
    data = re.search(r'<script type="application/json" id="spinviz-data">(.*?)</script>', text, flags=re.S).group(1)
    assert "<" not in data and json.loads(data)["frames"] == 180
    assert page_glb(text) == askew.glb.read_bytes()


@pytest.mark.slow
def test_page_carries_the_mit_notice_itself(page):
    """The three.js MIT licence, its copyright line and permission notice whole, is in the page
    (a downloaded page must carry it), not a pointer to a file."""
    text = html.unescape(re.sub(r"<script\b.*?</script>", "", page.read_text(), flags=re.S))
    squash = " ".join(LICENCE.split())
    assert squash in " ".join(text.split())
    assert "Copyright © 2010-2026 three.js authors" in text and "LICENSE-three.txt" not in text


@pytest.mark.slow
def test_each_view_has_its_poster_and_the_text_alternative(page, plan):
    """Each view holds its poster in the markup (an inline SVG of the opening frame, labelled by
    the text alternative), so it is drawn before any script has run; the text alternative
    says what the view shows."""
    text = page.read_text()
    for k in range(2):
        view = re.search(rf'<div class="view" id="view-{k}">(.*?)</div></div>', text, flags=re.S).group(1)
        assert view.startswith(f'<svg class="poster" id="poster-{k}" role="img" aria-labelledby="alt"')
        assert view.count("<polygon") > 30 and view.count("<polyline") > 10
    alt = re.search(r'<p id="alt">(.*?)</p>', text).group(1)
    assert "red arrow labelled d" in alt and "green arrow labelled L" in alt and "blue arrow labelled Ω" in alt
    assert "Reduced equation" in alt and "Truncated equation" in alt
    assert '<button id="full" type="button" hidden>Full screen</button>' in text


def test_outreach_words_are_plain():
    """On an outreach scene: one sentence up front naming the crystal, the radiation and what
    differs; headings without equation numbers; time and slider in days; the slowdown and the
    numbers in words.  A physics scene keeps the video's captions."""
    t = pagetext.page_texts(fake_plan())
    assert t.lead == ("Two copies of the same crystal (DAST cube 100 nm), set spinning the same way, are slowed by the "
                      "radio waves they give off; they differ only in the theory of that braking: the reduced equation "
                      "or the truncated equation, each shown under its name.")
    assert t.headings == [["Reduced equation", ""], ["Truncated equation", ""]]
    assert [label for _, label in t.ticks] == ["5 days", "10 days", "15 days"]
    assert t.scale == "The slider spans 19 days of the crystal's life."
    assert t.time[0] == "at the start" and t.time[-1] == "after 19 days"
    assert t.notes[0] == ["The real crystal spins 1.3 million billion times faster than shown: slowed down so you can "
                          "see it turn."]
    assert t.readouts[0][2] == ["turns 7.1 billion times a second", "dipole at 45° to the spin axis"]
    everything = json.dumps([t.lead, t.headings, t.ticks, t.time, t.notes, t.readouts, t.scale], ensure_ascii=False)
    assert not re.search(r"\(\d\.\d+\)|Θ|∠|10[⁰¹²³⁴⁵⁶⁷⁸⁹]", everything)
    physics = pagetext.page_texts(fake_plan(captions="physics"))
    assert physics.headings == [["reduced", "(2.2)+(2.3)"], ["truncated", "(2.5)"]]
    assert "Θ" in physics.scale and "∠(d, L) = 45°" in physics.readouts[0][0]


def test_one_model_is_one_crystal():
    """A one-model scene speaks of one crystal: the lead, what the controls do, the text
    alternative; no 'both'."""
    t = pagetext.page_texts(fake_plan(models=("reduced",)))
    assert t.one and t.lead == ("A crystal (DAST cube 100 nm), set spinning, is slowed by the radio waves it gives off, "
                                "as the reduced equation describes that braking.")
    assert t.how.startswith("Drag to turn the crystal,")
    assert "both" not in json.dumps([t.lead, t.how, t.alt, t.no_webgl, t.notes])
    assert pagetext.page_texts(fake_plan()).how.startswith("Drag to turn both crystals,")
    same = pagetext.page_texts(fake_plan(models=("reduced", "reduced"), units="dimensionless", body="symmetric top"))
    assert same.lead.startswith("Two runs of the same spinning top under the reduced equation")


# --- in Chromium ---------------------------------------------------------------------------------
PROBE = r"""(function () {
  const box = (el) => { const r = el.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
  const q = (s) => Array.from(document.querySelectorAll(s));
  const posters = q('svg.poster');
  const out = { before: { canvases: q('canvas').length, posters: posters.map(box), views: q('.view').map(box),
                          visible: posters.map((p) => getComputedStyle(p).visibility) } };
  function done() {
    if (!document.body.classList.contains('ready') && !document.body.classList.contains('nogl')) { setTimeout(done, 50); return; }
    const captions = {};
    ['#title', '#lead', '#controls', '#time', '#notes', '#legend', '#scale', '#status', 'footer'].forEach((s) => {
      captions[s] = box(document.querySelector(s)); });
    q('.panel h2, .panel .sub, .panel .read').forEach((e) => { captions['#' + e.id] = box(e); });
    out.after = { canvases: q('canvas').map(box), views: q('.view').map(box), labels: q('.lab').map(box),
                  visible: posters.map((p) => getComputedStyle(p).visibility), width: window.innerWidth,
                  scrollWidth: document.documentElement.scrollWidth, captions: captions };
    window.parent.postMessage(JSON.stringify(out), '*');
  }
  window.addEventListener('load', () => setTimeout(done, 0));
})();"""


def probed(page: Path, tmp_path: Path) -> Path:
    """A copy of ``page`` in ``tmp_path`` with the probe script before three.js, allowed by its
    hash; the probe posts what it saw to the window that frames the page."""
    text = page.read_text()
    text = text.replace("script-src ", f"script-src {sha(PROBE)} ", 1)
    text = text.replace("<script>", f"<script>{PROBE}</script>\n<script>", 1)
    out = tmp_path / f"probed-{page.name}"
    out.write_text(text)
    return out


def overlap(a, b) -> bool:
    return min(a[2], b[2]) - max(a[0], b[0]) > 0.5 and min(a[3], b[3]) - max(a[1], b[1]) > 0.5


def chromium_or_fail():
    from browser import CHROMIUM

    if CHROMIUM is None:
        pytest.fail("the page tests need chromium (apt-get install chromium; .ci/run does this)", pytrace=False)


@pytest.mark.slow
@pytest.mark.parametrize("width", [360, 768, 1280])
def test_layout_from_a_phone_to_a_wide_screen(page, tmp_path, width):
    """At 360, 768 and 1280 px: both views drawn (a canvas each, inside its view), no caption
    box over either canvas, nothing wider than the window; one view under the other on a
    phone, side by side from 768 px; the posters were up, where the views are, before any
    canvas existed, and are hidden once the views are drawn; no request left the file and
    nothing was refused by the policy."""
    from browser import WEBGL_FLAGS, chromium, framed, page_requests

    chromium_or_fail()
    net = tmp_path / "net.json"
    r = chromium(framed(probed(page, tmp_path), tmp_path, width), tmp_path, *WEBGL_FLAGS, "--window-size=1300,1000",
                 "--dump-dom", "--enable-logging=stderr", "--v=0", f"--log-net-log={net}")
    assert "Content Security Policy" not in r.stderr and "Uncaught" not in r.stderr, r.stderr[-2000:]
    assert page_requests(net) == []
    probe = json.loads(html.unescape(re.search(r'<pre id="out">(.*?)</pre>', r.stdout, flags=re.S).group(1)))
    before, after = probe["before"], probe["after"]
    assert before["canvases"] == 0 and before["visible"] == ["visible", "visible"]
    assert before["posters"] == before["views"] and all(v[2] - v[0] > 250 for v in before["views"])
    assert after["visible"] == ["hidden", "hidden"] and after["width"] == width and after["scrollWidth"] <= width
    canvases, views = after["canvases"], after["views"]
    assert len(canvases) == 2 and canvases == views
    for c in canvases:
        assert c[0] >= 0 and c[2] <= width and (c[2] - c[0]) * (c[3] - c[1]) > 250 * 180
        for name, box in after["captions"].items():
            assert not overlap(c, box), (width, name, box, c)
    a, b = canvases
    if width < 700:
        assert b[1] >= a[3]                                   # one under the other
    else:
        assert b[0] >= a[2] and abs(a[1] - b[1]) < 1          # side by side, in line
    assert len(after["labels"]) == 2 * (3 + 3)                # d, L, Omega and x, y, z in each view


@pytest.mark.slow
def test_page_in_chromium_turns_to_the_videos_pose(page, plan, tmp_path):
    """Opened at #frame=N (the slider set to frame N) it shows, for both models, the video's pose
    at frame N to 1e-6 rad (a keyframe) or within the stated bound (a frame between); the
    crystals are drawn where the posters showed them (the tan box's pixels in the WebGL
    picture and in the poster, script taken out, mostly the same); without WebGL the posters
    stay and the page says why."""
    from browser import WEBGL_FLAGS, chromium, screenshot

    chromium_or_fail()
    kf = keyframes.choose(plan)
    key = int(kf.frame[len(kf.frame) // 2])
    between = int(next(f for f in range(1, plan.frames) if f not in set(kf.frame.tolist())))
    for f, bound in ((key, 1e-6), (between, math.radians(keyframes.TOLERANCE_DEG) + 1e-6)):
        r = chromium(page, tmp_path, *WEBGL_FLAGS, "--enable-logging=stderr", "--v=0", "--dump-dom", fragment=f"frame={f}")
        assert "Content Security Policy" not in r.stderr and "Uncaught" not in r.stderr, r.stderr[-2000:]
        assert f'data-frame="{f}"' in r.stdout and 'class="ready"' in r.stdout
        for k, panel in enumerate(plan.panels):
            shown = json.loads(re.search(rf'id="panel-{k}"[^>]* data-pose="([^"]+)"', r.stdout).group(1))
            err = R.misorientation(R.normalize(np.array(shown)), panel.q[f])
            assert err < bound and (bound < 1e-5 or err > 1e-6)
    drawn = screenshot(page, tmp_path, fragment="frame=0", flags=WEBGL_FLAGS).astype(int)
    still = tmp_path / "still.html"
    still.write_text(re.sub(r"<script>.*?</script>", "", page.read_text(), flags=re.S))
    poster = screenshot(still, tmp_path).astype(int)

    def tan(img):
        return (img.mean(axis=2) < 200) & (img[..., 0] - img[..., 2] > 15)

    a, b = tan(drawn), tan(poster)
    assert a[:, :640].sum() > 3000 and a[:, 640:].sum() > 3000
    assert (a & b).sum() > 0.8 * max(a.sum(), b.sum())
    dom = chromium(page, tmp_path, "--disable-webgl", "--disable-3d-apis", "--dump-dom", fragment="frame=3").stdout
    assert "cannot draw 3-D (no WebGL)" in dom and 'data-frame="3"' in dom and 'class="nogl"' in dom


@pytest.mark.slow
def test_the_request_check_can_fail(tmp_path):
    """The net-log check sees a page's request: a page that loads an image from a host is caught."""
    from browser import chromium, page_requests

    chromium_or_fail()
    leak = tmp_path / "leak.html"
    leak.write_text('<!DOCTYPE html><html><body><img src="http://example.invalid/x.png"></body></html>')
    net = tmp_path / "net.json"
    chromium(leak, tmp_path, "--dump-dom", f"--log-net-log={net}")
    assert page_requests(net) == ["http://example.invalid/x.png"]


@pytest.mark.slow                      # the validator: installed by .ci/run before its slow pass
def test_committed_page_carries_the_committed_model():
    """The committed page beside renders/dast_cube.glb (under 2 MB, its CSP right) carries that
    very model: both written by this code from scenes/default.toml.  (The documentation
    site's page is written by its gallery.)"""
    text = check_csp((ROOT / "renders" / "dast_cube_turnable.html").read_text())
    assert page_glb(text) == (ROOT / "renders" / "dast_cube.glb").read_bytes()


@pytest.mark.slow
def test_title_is_text(plan):
    """A scene's title goes into the page's heading as text, and so do its subtitles."""
    from dataclasses import replace

    from spinviz.rendering import webpage

    p = replace(plan, spec=plan.spec.with_(subtitles=("<i>one</i>", "two & <svg onload=x>")))
    kf = SimpleNamespace(frame=np.array([0, p.frames - 1]), count=2, tolerance=0.004)
    text = webpage.page(p, kf, b"glTF")
    assert "&lt;i&gt;one&lt;/i&gt;" in text and "two &amp; &lt;svg onload=x&gt;" in text
    assert TITLE not in text
