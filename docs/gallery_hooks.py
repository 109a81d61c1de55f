"""sphinx-gallery's hooks for the spinviz gallery (named in ``conf.py``'s ``sphinx_gallery_conf``
by their dotted names, so that the configuration stays picklable).

* ``ExampleOrder``: the gallery's order, the newcomer's: two models compared, then the 3-D
  pictures, then the analyses, then the results too long to compute in a build.
* ``snapshot`` (a ``reset_modules`` hook, run before each example) and ``written_pictures``
  (an image scraper, run after each code block): spinviz's plots, videos and diagrams are
  files (``compare.plot(c, "x.png")``, ``spinviz.render(sc, out="x.gif")``), written as a
  user writes them, into the working directory (sphinx-gallery runs an example in its own
  folder, ``examples/``).  Every PNG or GIF that appears there while an example runs is moved
  into the gallery's images and shown under the block that wrote it, in the order written (a
  picture left by running the example by hand is taken when the example writes it again); a
  file the example does not write is never touched.  A GIF stays a GIF, so a
  video plays on the page.  (matplotlib figures left open are caught by sphinx-gallery's own
  matplotlib scraper, listed first.)  A web page an example writes (``.html``: a turnable
  scene) is shown in a frame with a link to it on its own, and a glTF model (``.glb``) is
  offered for download, with the Blender script written beside it (``X_blender.py``); all
  go to ``docs/gallery/pages/``, which the site serves from its
  root (``html_extra_path``).  Any other file an example leaves in ``examples/`` stops the
  build, naming it: an example writes its other outputs (a store, a WAV) to a scratch folder,
  so that building the site leaves the checkout as it was.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from sphinx.errors import ExtensionError
from sphinx_gallery.scrapers import figure_rst

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
PAGES_DIR = Path(__file__).resolve().parent / "gallery" / "pages"       # conf.py's html_extra_path
PICTURES = (".png", ".gif")
PAGES = (".html",)
MODELS = (".glb",)
SCRIPTS = "_blender.py"          # what spinviz writes beside a model: X.glb -> X_blender.py

ORDER = [
    "plot_compare_models.py",
    "plot_render_frames.py",
    "plot_video.py",
    "plot_cellulose_rod.py",
    "plot_turnable.py",
    "plot_askew_top.py",
    "plot_observe.py",
    "plot_listen.py",
    "plot_atlas_figure.py",
    "plot_benchmarks.py",
]


class ExampleOrder:
    """``within_subsection_order``: the examples in ``ORDER``; one missing from it is an error
    (a new example must be placed, not appended by accident)."""

    def __init__(self, src_dir):
        self.src_dir = src_dir

    def __call__(self, filename: str) -> int:
        name = Path(filename).name
        if name not in ORDER:
            raise ValueError(f"examples/{name}: not placed in docs/gallery_hooks.py's ORDER")
        return ORDER.index(name)


_before: dict[str, int] = {}


def _listing() -> dict[str, int]:
    return {p.name: p.stat().st_mtime_ns for p in EXAMPLES.iterdir()}


def snapshot(gallery_conf, fname) -> None:
    """Before each example: what ``examples/`` already holds, and when each was written."""
    _before.clear()
    _before.update(_listing())


def written_pictures(block, block_vars, gallery_conf) -> str:
    """The PNG and GIF files the block wrote into ``examples/``, moved into the gallery's images
    (sphinx-gallery's next image names, the extension kept), as reST."""
    new_files = [EXAMPLES / name for name, mtime in _listing().items() if _before.get(name) != mtime]
    others = sorted(p.name for p in new_files if p.suffix.lower() not in PICTURES + PAGES + MODELS
                    and not p.name.endswith(SCRIPTS))
    example = Path(block_vars["src_file"]).stem
    if others:
        raise ExtensionError(f"{example}.py left {', '.join(others)} in examples/: write outputs other than "
                             f"pictures, pages and models to a scratch folder (tempfile.mkdtemp())")
    iterator = block_vars["image_path_iterator"]
    shown, names, rst = [], [], ""
    for _, name in sorted((p.stat().st_mtime_ns, p.name) for p in new_files):
        src = EXAMPLES / name
        suffix = src.suffix.lower()
        if suffix in PICTURES:
            dest = Path(next(iterator)).with_suffix(suffix)
            shutil.move(src, dest)
            shown.append(dest)
            names.append(name)
            continue
        if suffix in PAGES:
            served = f"sphx_glr_{example}_{src.stem}{suffix}"    # at the site's root, beside no page of it
        else:
            served = f"sphx_glr_{example}_files/{name}"         # a model and its script keep the names they know
        (PAGES_DIR / served).parent.mkdir(parents=True, exist_ok=True)
        shutil.move(src, PAGES_DIR / served)
        if suffix in PAGES:
            rst += (f"\n.. raw:: html\n\n    <iframe class=\"written-page\" src=\"../{served}\" title=\"{name}\" "
                    f"width=\"100%\" height=\"960\" loading=\"lazy\" allow=\"fullscreen\"></iframe>\n"
                    f"    <p><a href=\"../{served}\">{name} on its own</a> (full window)</p>\n\n")
        elif name.endswith(SCRIPTS):
            rst += f"\nIts Blender script: `{name} <../{served}>`__ (``blender --python {name}``).\n\n"
        else:
            rst += f"\nThe model: `{name} <../{served}>`__ ({(PAGES_DIR / served).stat().st_size / 1e3:.0f} kB).\n\n"
    # the alt text: the file names the example wrote (dast_cube_compare.png)
    pictures = figure_rst(shown, gallery_conf["src_dir"], fig_titles=", ".join(names)) if shown else ""
    return pictures + rst
