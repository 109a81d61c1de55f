"""The documentation site: it builds with warnings as errors and its pages render in a real
browser (headless Chromium, no network); the gallery and the tutorial were executed by that
build, and every picture they show is a file the build made.

The site is built once per session into a temporary directory, or taken from
``SPINVIZ_DOCS_HTML`` when .ci/run has just built it with ``sphinx-build -W``.  Skipped only
where Chromium or the docs extra (``pip install -e ".[docs]"``) is missing, and never in CI.
"""

from __future__ import annotations

import html
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from browser import CHROMIUM, page_text, screenshot

ROOT = Path(__file__).resolve().parents[1]
DOCS_EXTRA = ("sphinx", "myst_nb", "sphinx_gallery", "jupyter_cache", "ipykernel", "pydata_sphinx_theme",
              "sphinx_copybutton")
EXAMPLES = sorted(p.stem for p in (ROOT / "examples").glob("plot_*.py"))
MISSING = [m for m in DOCS_EXTRA if importlib.util.find_spec(m) is None] + ([] if CHROMIUM else ["chromium"])

pytestmark = pytest.mark.slow
if MISSING:
    if os.environ.get("CI"):
        pytest.fail(f"CI must run the docs test, but {', '.join(MISSING)} is missing (see .ci/run)", pytrace=False)
    how = ["apt-get install chromium"] if not CHROMIUM else []
    how += ['pip install -e ".[docs]"'] if MISSING != ["chromium"] else []
    pytestmark = [pytestmark, pytest.mark.skip(reason=f"needs {', '.join(MISSING)} ({'; '.join(how)})")]


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    built = os.environ.get("SPINVIZ_DOCS_HTML")
    if built:
        out = Path(built)
        assert (out / "index.html").is_file(), f"SPINVIZ_DOCS_HTML={built} holds no built site"
        return out
    tmp = tmp_path_factory.mktemp("docs")
    out = tmp / "html"
    # every example rerun, even one an earlier build of docs/gallery/ ran already (the notebook
    # runs anyway: its cache lives in this new output directory)
    r = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                        "-D", "sphinx_gallery_conf.run_stale_examples=True",
                        "-d", str(tmp / "doctrees"), str(ROOT / "docs"), str(out)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"sphinx-build -W failed:\n{r.stderr[-4000:]}"
    return out


def readme_after(marker: str) -> str:
    """The first words of the README after ``marker``, where the front page includes it."""
    text = (ROOT / "README.md").read_text().split(marker, 1)[1]
    return " ".join(text.split()[:8])


def assert_not_blank(img: np.ndarray):
    assert img.shape == (900, 1280, 3)
    grey = img.mean(axis=2)
    background = np.median(grey)
    ink = np.abs(grey - background) > 60          # text, rules, pictures: clearly off the page colour
    assert background > 200                         # the light theme's white page
    assert 0.01 < ink.mean() < 0.6, ink.mean()      # something is drawn, and it is not a solid fill
    rows = np.flatnonzero(ink.any(axis=1))
    assert rows.min() < 150 and rows.max() > 600    # drawn from the header down the page, not one stray line
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 100    # anti-aliased text and images, not a flat error page


def images(page: Path, dom: str) -> list[Path]:
    """The files of the page's <img> elements (every one local: the site works offline)."""
    srcs = [html.unescape(s) for s in re.findall(r'<img\b[^>]*\bsrc="([^"]+)"', dom)]
    remote = [s for s in srcs if re.match(r"[a-z]+:", s) and not s.startswith("data:")]
    assert not remote, f"{page.name}: pictures from outside the site: {remote}"
    return [(page.parent / s).resolve() for s in srcs if not s.startswith("data:")]


def picture(path: Path) -> np.ndarray:
    """An image file of the site decoded (the first frame of a GIF), RGB."""
    from PIL import Image

    assert path.is_file(), path
    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"))


def assert_drawn(img: np.ndarray):
    """A picture with something in it: many colours, not one flat fill."""
    assert img.shape[0] >= 50 and img.shape[1] >= 50, img.shape
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 30
    assert img.std() > 10.0


def test_front_page(site, tmp_path):
    page = site / "index.html"
    assert_not_blank(screenshot(page, tmp_path))
    dom, text = page_text(page, tmp_path)
    assert readme_after("# spinviz") in text                  # the README's opening, included
    for title in ("Tutorial", "Getting started", "Commands", "Gallery", "Physics notes", "API reference"):
        assert title in text
    assert "on the right replaced by the free-motion values (2.3a), (2.3b)" in text     # the models table
    # the README's video, as the gallery rendered it in this build (not the committed GIF)
    assert [p.name for p in images(page, dom)] == ["sphx_glr_plot_video_001.gif"]
    assert "The 100 nm DAST cube of section 6.2 with its real parameters" in text       # its caption, included


def test_api_page_of_simulate(site, tmp_path):
    page = site / "generated" / "spinviz.simulate.html"
    assert_not_blank(screenshot(page, tmp_path))
    dom, text = page_text(page, tmp_path)
    # the signature, with the defaults as written in spinviz/driver.py
    sig = re.search(r'<dt class="sig[^"]*" id="spinviz.simulate">(.*?)</dt>', dom, flags=re.S).group(1)
    sig = re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", "", sig))).strip()
    assert sig.startswith("simulate(body: Body, model: str, omega0, *, t_end: float | None = None, "
                          "samples: int | None = None, t_eval=None, q0=None, euler_zxz0=None, method: str = 'auto',"), sig
    assert "kinematics: str = 'quaternion', environment=None) → Trajectory" in sig, sig
    # the docstring, its numpydoc sections as field lists: name (type) – meaning
    assert "Integrate the Euler equation of model with orientation; return a Trajectory." in text
    assert re.search(r"kinematics \(\{.quaternion., .euler_zxz., .none.\}\) – “quaternion” \(default\); "
                     r"“euler_zxz”, the Poisson equations \(6\.4\)", text)
    assert re.search(r"omega0 \(array_like, shape \(3,\)\) – Body-frame angular velocity at t = 0", text)


def test_physics_equations_render_offline(site, tmp_path):
    """MathJax is served from the site itself: every equation is typeset, none is an error."""
    dom, text = page_text(site / "physics.html", tmp_path)
    assert "https://" not in re.search(r'<script[^>]*mathjax[^>]*>', dom, flags=re.I).group(0)
    typeset = dom.count("<mjx-container")
    written = (ROOT / "docs" / "physics.md").read_text().count(r"\tag{")
    assert written >= 25 and typeset >= written, (typeset, written)
    assert "<mjx-merror" not in dom and "data-mjx-error" not in dom
    assert "The paper prints c² in (3.3)–(3.5); c³ is right" in text
    assert "(4.43)’s 7δ − 6 is 7δ − 4" in text                  # the typo list (MyST's typographic quote)
    assert "Does each model balance what it radiates?" in text


def test_experiment_page_shows_this_builds_pictures(site, tmp_path):
    """What a detector sees and hears: the gallery's pictures of this build, not committed ones."""
    page = site / "experiment.html"
    assert_not_blank(screenshot(page, tmp_path))
    dom, text = page_text(page, tmp_path)
    shown = images(page, dom)
    assert [p.name for p in shown if p.name.startswith("sphx_glr_")] == ["sphx_glr_plot_observe_001.png",
                                                                          "sphx_glr_plot_listen_001.png"]
    for p in shown:
        assert_drawn(picture(p))
    assert "How long to watch (spinviz decide)" in text and "The receiver ([observe])" in text


def test_commands_page(site, tmp_path):
    """Every command of the parser has its row, and the promises are there."""
    from spinviz.commands import COMMANDS

    page = site / "commands.html"
    assert_not_blank(screenshot(page, tmp_path))
    dom, text = page_text(page, tmp_path)
    for name in COMMANDS:
        assert f"spinviz {name}" in text, name
    for job in ("run", "verify", "bench", "evidence"):
        assert f"spinviz atlas {job}" in text, job
    assert "What every command promises" in text and "Ctrl-C, SIGTERM, SIGHUP" in text


def test_gallery_has_a_drawn_thumbnail_for_every_example(site, tmp_path):
    """Every example in examples/ ran in this build and drew something: its thumbnail is made
    from its first picture (sphinx-gallery's stand-ins, no_image.png and broken_example.png,
    scaled to the thumbnail size of docs/conf.py, mark one that drew none or failed)."""
    import sphinx_gallery
    from sphinx_gallery.utils import scale_image

    page = site / "gallery" / "index.html"
    assert_not_blank(screenshot(page, tmp_path))
    dom, text = page_text(page, tmp_path)
    thumbs = {re.match(r"sphx_glr_(.+)_thumb$", p.stem).group(1): p for p in images(page, dom)
              if p.stem.endswith("_thumb")}
    assert sorted(thumbs) == EXAMPLES
    stand_ins = []
    for name in ("no_image.png", "broken_example.png"):
        scale_image(Path(sphinx_gallery.__file__).parent / "_static" / name, tmp_path / name, 400, 280)
        stand_ins.append(picture(tmp_path / name))
    for name, p in thumbs.items():
        thumb = picture(p)
        assert not any(thumb.shape == s.shape and np.array_equal(thumb, s) for s in stand_ins), f"{name} drew no picture"
        assert_drawn(thumb)
    assert "Every picture on these pages was drawn while this site was built" in text


def example_page(site: Path, name: str, tmp_path: Path) -> tuple[str, list[Path]]:
    """An example's page: its text, and its pictures (those the build made for it)."""
    page = site / "gallery" / f"{name}.html"
    dom, text = page_text(page, tmp_path)
    made = [p for p in images(page, dom) if p.stem.startswith(f"sphx_glr_{name}_")]
    assert made, f"{name}: no picture"
    for p in made:
        assert_drawn(picture(p))
    return text, made


def test_gallery_pages_show_what_their_code_made(site, tmp_path):
    """Each page shows its pictures and its printed output; a few pictures are checked for what
    the code asked of them."""
    from PIL import Image

    shown, texts = {}, {}
    for name in EXAMPLES:
        texts[name], shown[name] = example_page(site, name, tmp_path)
        assert "Download Python source code" in texts[name]
        assert "Traceback" not in texts[name]
    # render_frame's arrays are shown pixel for pixel: 640 x 360, the size the code asked for
    assert [picture(p).shape for p in shown["plot_render_frames"]] == [(360, 640, 3)] * 3
    # no two examples show the same picture
    seen: dict = {}
    for name, files in shown.items():
        for p in files:
            key = picture(p).tobytes()
            assert key not in seen or seen[key] == name, f"{name} shows the same picture as {seen[key]}"
            seen[key] = name
    # the video is a GIF that plays: 80 frames (8 s at 10 fps), and the picture moves
    gif = next(p for p in shown["plot_video"] if p.suffix == ".gif")
    with Image.open(gif) as im:
        assert im.n_frames == 80 and im.size == (640, 360)
        first = np.asarray(im.convert("RGB"))
        im.seek(im.n_frames - 1)
        last = np.asarray(im.convert("RGB"))
    assert (np.abs(first.astype(int) - last.astype(int)).sum(axis=2) > 60).mean() > 0.01
    # the figure atlas drawn from the committed extract by spinviz's own functions: the
    # two-panel diagram (7.2 x 7.6 in per panel at 110 dpi) and the hodographs
    assert [picture(p).shape for p in shown["plot_atlas_figure"]][0] == (836, 1584, 3)
    saved = np.load(ROOT / "examples" / "data" / "atlas_figure_labels.npz")
    for k in range(int(saved["levels"])):                       # each level as the extract holds it
        regime = saved[f"regime_{k}"]
        n = regime.shape[1]
        assert f"level {k}: {n} x {n} cells, {int((regime != 0).sum())} runs" in texts["plot_atlas_figure"]
    # the printed output of the comparison's code
    assert "first time the models differ by" in texts["plot_compare_models"]
    assert "residual rotation about the dipole" in texts["plot_compare_models"]


def test_tutorial_ran_in_this_build(site, tmp_path):
    """The tutorial's cells ran when the site was built: their outputs, the pictures they drew
    (a matplotlib figure, a rendered frame at the size asked for, the atlas's diagram), and no
    error."""
    import spinviz

    page = site / "tutorial.html"
    assert_not_blank(screenshot(page, tmp_path))
    dom, text = page_text(page, tmp_path)
    # a cell and its output, each with its copy button
    assert f"print(spinviz.__version__) Copy to clipboard {spinviz.__version__} Copy to clipboard" in text
    assert "difference of angle(d, L)" in text                             # the comparison's table
    assert re.search(r"72 runs \(0 already there, 72 computed now\)", text)   # the atlas: 3 x 3 x 4 x 2
    assert re.search(r"delta = \+0\.67, chi = 75\.0 deg:", text)              # its labels, cell by cell
    assert "Traceback" not in text and 'class="output traceback' not in dom and 'class="output stderr' not in dom
    shapes = [picture(p).shape for p in images(page, dom)]
    assert len(shapes) == 3
    assert (450, 800, 3) in shapes                                         # spinviz.render_frame(sc, size=(800, 450))
    for p in images(page, dom):
        assert_drawn(picture(p))


def test_gallery_embeds_the_turnable_page(site, tmp_path):
    """The gallery's page example embeds the page of the default scene that it wrote in this
    build (an iframe); that page, opened from the built site, draws both DAST crystals
    (orange) in Chromium."""
    from browser import WEBGL_FLAGS

    page = site / "gallery" / "plot_turnable.html"
    dom, text = page_text(page, tmp_path)
    src = html.unescape(re.search(r'<iframe class="written-page" src="([^"]+)"', dom).group(1))
    assert src == "../sphx_glr_plot_turnable_dast_cube_turnable.html"       # served from the site's root
    assert "Turn the crystal yourself" in text
    img = screenshot((page.parent / src).resolve(), tmp_path, fragment="frame=200", flags=WEBGL_FLAGS)
    view = img[175:560].astype(int)
    orange = (view[..., 0] > 150) & (view[..., 0] - view[..., 2] > 90) & (view[..., 1] > 60)
    assert orange[:, :640].sum() > 3000 and orange[:, 640:].sum() > 3000
