"""The documentation site: it builds with warnings as errors and its pages render in a real
browser (headless Chromium, no network).

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
DOCS_EXTRA = ("sphinx", "myst_parser", "pydata_sphinx_theme", "sphinx_copybutton")
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
    r = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                        "-d", str(tmp / "doctrees"), str(ROOT / "docs"), str(out)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"sphinx-build -W failed:\n{r.stderr[-4000:]}"
    return out


def readme_after(marker: str) -> str:
    """The first words of the README after ``marker``, where a page includes it."""
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


def test_front_page(site, tmp_path):
    page = site / "index.html"
    assert_not_blank(screenshot(page, tmp_path))
    _, text = page_text(page, tmp_path)
    assert readme_after("# spinviz") in text                  # the README's intro, included
    for title in ("Getting started", "Gallery", "Physics notes", "API reference"):
        assert title in text
    assert "on the right replaced by the free-motion values (2.3a), (2.3b)" in text     # the models table


def test_api_page_of_simulate(site, tmp_path):
    page = site / "generated" / "spinviz.simulate.html"
    assert_not_blank(screenshot(page, tmp_path))
    dom, text = page_text(page, tmp_path)
    # the signature, with the defaults as written in spinviz/driver.py
    sig = re.search(r'<dt class="sig[^"]*" id="spinviz.simulate">(.*?)</dt>', dom, flags=re.S).group(1)
    sig = re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", "", sig))).strip()
    assert sig.startswith("simulate(body: Body, model: str, omega0, *, t_end: float | None = None, "
                          "samples: int | None = None, t_eval=None, q0=None, euler_zxz0=None, method: str = 'auto',"), sig
    assert "kinematics: str = 'quaternion') → Trajectory" in sig, sig
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
    assert readme_after("how spinviz treats them:") in text   # the README's typo list, included


def test_gallery_embeds_the_turnable_page(site, tmp_path):
    """The gallery embeds the page of the default scene (an iframe of the copy in _static);
    that page, opened from the built site, draws both DAST crystals (orange) in Chromium."""
    from browser import WEBGL_FLAGS

    dom, text = page_text(site / "gallery.html", tmp_path)
    assert '<iframe class="turnable" src="_static/dast_cube_turnable.html"' in dom
    assert "Turn the crystal yourself" in text
    img = screenshot(site / "_static" / "dast_cube_turnable.html", tmp_path, fragment="frame=200", flags=WEBGL_FLAGS)
    view = img[175:560].astype(int)
    orange = (view[..., 0] > 150) & (view[..., 0] - view[..., 2] > 90) & (view[..., 1] > 60)
    assert orange[:, :640].sum() > 3000 and orange[:, 640:].sum() > 3000
