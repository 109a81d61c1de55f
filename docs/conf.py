"""Sphinx configuration of the spinviz documentation.

Build (no network needed): ``sphinx-build -W --keep-going -b html docs docs/_build/html``.

The content pages are Markdown (MyST).  Pages whose numbers other commands regenerate
(``docs/accuracy.md`` by ``spinviz report``, ``docs/atlas.md``) are pages of this site as
they are, and the README's sections are *included*, never copied, so the site shows what
the repository says today.  The API reference is generated from the docstrings by
autosummary/autodoc.  The gallery (``examples/*.py``, by sphinx-gallery) and the tutorial
(``docs/tutorial.md``, a MyST notebook, by myst-nb) are executed by every build, and the
pages that show the README's pictures show the gallery's instead: what the site shows is
what the code draws today.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))          # the checkout's spinviz, installed or not
sys.path.insert(0, str(DOCS))          # gallery_hooks, named in sphinx_gallery_conf

# Importing for autodoc must never need a display: pyvista is imported (not plotted) by
# the rendering modules; keep it and VTK off-screen should anything ask for a window.
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
os.environ.setdefault("MPLBACKEND", "Agg")

import spinviz  # noqa: E402

project = "spinviz"
author = "spinviz developers"
copyright = "spinviz developers (MIT licence)"
version = release = spinviz.__version__

extensions = [
    # MyST Markdown pages, and notebooks written in MyST Markdown executed at build time
    # (myst-nb includes myst-parser, so it replaces it in this list)
    "myst_nb",
    # the gallery: examples/*.py run at build time, their pictures scraped (below)
    "sphinx_gallery.gen_gallery",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    # numpydoc sections (Parameters / Returns / Raises, with a line of dashes) become field
    # lists; docstrings without sections keep the "name : meaning" lines handled below.
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx_copybutton",
    # MathJax 3 shipped inside a PyPI package and copied into _static: the physics page's
    # equations render with no network, at build time or when the page is read.
    "sphinx-mathjax-offline",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb"}      # MyST Markdown, notebooks or not
root_doc = "index"
exclude_patterns = [
    "_build",
    "Thumbs.db",
    ".DS_Store",
    # sphinx-gallery writes each example beside its page as a script and a notebook to
    # download; they are not pages of the site (myst-nb would otherwise read the notebooks)
    "gallery/*.ipynb",
    "gallery/*.py",
    "gallery/*.zip",
    "gallery/*.json",
]
templates_path = ["_templates"]

# --- MyST -------------------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3        # README links such as (#regime-atlas) resolve
suppress_warnings = [
    # A README section is included from below its own "##" heading (the page's "#" title
    # replaces it), so its "###" subsections follow the "#" directly.
    "myst.header",
]

# --- Executed pages: the gallery and the tutorial ------------------------------------------
# Every picture these pages show is drawn while the site is built, by code shown on the page;
# an exception in an example or a notebook cell fails the build.  Computations too long for a
# build (the figure atlas, the accuracy report) are read from small committed results.

# The gallery (sphinx-gallery, as pyvista builds its own): examples/*.py, each opening with a
# docstring that becomes its page's text, run in examples/ and written to docs/gallery/.
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",                   # every example is run
    "ignore_pattern": r"/data/",                     # the committed results and the script that made them
    "within_subsection_order": "gallery_hooks.ExampleOrder",
    # open matplotlib figures (e.g. imshow of spinviz.render_frame's RGB array), then the
    # PNG and GIF files spinviz's own plot and render calls write (gallery_hooks)
    "image_scrapers": ("matplotlib", "gallery_hooks.written_pictures"),
    "reset_modules": ("matplotlib", "gallery_hooks.snapshot"),
    "abort_on_example_error": True,                  # the first failing example stops the build
    "remove_config_comments": True,
    "capture_repr": ("__repr__",),                   # a block's last value is shown as print() would
    "show_memory": False,
    "show_signature": False,
    "download_all_examples": False,                  # each page offers its own .py and .ipynb
    "thumbnail_size": (400, 280),
    "min_reported_time": 1,
}

# The tutorial (myst-nb, as heyoka.py executes its notebooks): MyST Markdown notebooks run by
# a Jupyter kernel at build time; jupyter-cache keeps the outputs of an unchanged notebook, so
# a rebuild reruns only what changed ("cache"; a clean build runs everything).
nb_execution_mode = "cache"
nb_execution_raise_on_error = True                   # a cell's exception fails the build
nb_execution_timeout = 600                           # seconds per cell (the tutorial's atlas takes ~8 s)
nb_execution_show_tb = True                          # a failure's traceback in the build log
nb_merge_streams = True                              # a cell's stdout as one block, not one per print

# --- API reference ------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": True, "member-order": "bysource"}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True      # the signature shows ``method='auto'``, not a repr
add_module_names = False
napoleon_google_docstring = False     # only numpydoc sections: a line ending in ":" stays prose
napoleon_numpy_docstring = True
napoleon_use_rtype = False            # "Returns: (type) -- meaning" on one line, as the docstrings read
napoleon_use_ivar = True              # "Attributes" as a field list: no second target beside autodoc's members
# Heavy optional stacks are installed for the docs build (the "docs" extra pulls the render
# and ensemble extras), so nothing is mocked: what the reference shows is what imports.

# Many of the project's docstrings list parameters as lines ``name : meaning``
# (shape, units and frame on the line) outside any numpydoc section; shown as reST they would
# run together into one paragraph.  This turns such a paragraph into a definition list.  (The
# public entry points use numpydoc sections, which napoleon renders; once every docstring
# does, this hook can go.  Napoleon runs first and its output never matches ``_PARAM``.)
_PARAM = re.compile(r"^(?P<names>[A-Za-z_*][\w*]*(?:\s*,\s*[A-Za-z_*][\w*]*)*)\s+:\s+(?P<text>\S.*)$")


def _parameter_lists(app, what, name, obj, options, lines):
    out: list[str] = []
    i = 0
    while i < len(lines):
        j = i
        while j < len(lines) and lines[j].strip():
            j += 1
        block = lines[i:j]
        if block and _PARAM.match(block[0]):         # indented blocks (literal, quoted) never match
            for line in block:
                m = _PARAM.match(line)
                if m:
                    names = ", ".join(f"``{n.strip()}``" for n in m["names"].split(","))
                    out += [names, f"    {m['text']}"]
                else:
                    out.append(f"    {line.strip()}")
        else:
            out += block
        if j < len(lines):
            out.append(lines[j])
        i = j + 1
    lines[:] = out


# |x| is the docstrings' notation for a magnitude (|omega(0)|, |Omega|), never a reST
# substitution: escape the bars outside inline literals and literal blocks.
_LITERAL = re.compile(r"(``.*?``)")


def _magnitude_bars(app, what, name, obj, options, lines):
    literal_indent = None                      # indentation of the "::" paragraph, inside a literal block
    for k, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if not line.strip() or indent > literal_indent:
                continue
            literal_indent = None
        if line.lstrip().startswith(">>>"):
            continue
        parts = _LITERAL.split(line)
        lines[k] = "".join(p if i % 2 else p.replace("|", "\\|") for i, p in enumerate(parts))
        if line.rstrip().endswith("::"):
            literal_indent = indent


def _skip_exported(app, what, name, obj, skip, options):
    """A public name (``spinviz.simulate``, ``spinviz.Trajectory``, ...) is documented once, on
    its own page of the API reference, not again on its defining module's page."""
    if what == "module" and any(obj is getattr(spinviz, n) for n in _PUBLIC):
        return True
    return None


_PUBLIC = [n for n in spinviz.__all__ if not n.startswith("_") and n != "PRESETS"]


def setup(app):
    app.connect("autodoc-process-docstring", _parameter_lists)
    app.connect("autodoc-process-docstring", _magnitude_bars)
    app.connect("autodoc-skip-member", _skip_exported)


# --- HTML -----------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"spinviz {release}"
html_static_path = ["_static"]
# the web pages and models the gallery's examples write (gallery_hooks), served from the root
(DOCS / "gallery" / "pages").mkdir(parents=True, exist_ok=True)
html_extra_path = ["gallery/pages"]
html_css_files = ["spinviz.css"]
html_theme_options = {
    "navigation_with_keys": False,
    "header_links_before_dropdown": 7,
    "navbar_align": "left",
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
# The section navigation only where there is a section to navigate: the API reference.
html_sidebars = {page: [] for page in
                 ("index", "tutorial", "getting_started", "scenes", "gallery/**", "physics", "integrators", "accuracy",
                  "atlas", "experiment", "design")}
html_show_sourcelink = False
html_copy_source = False
