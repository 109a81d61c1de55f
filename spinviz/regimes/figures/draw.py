"""``--plot PATH``: the pictures of an atlas store -- the diagram (every refinement level), the
hodographs and the interactive page -- their paths checked before any work and landed
together (atomically) after it."""

from __future__ import annotations

import os

from ...atomic import Outputs, check_outputs
from ...errors import UsageError


def hodograph_path(path: str) -> str:
    """The hodographs drawn beside the diagram ``path``: ``<stem>_hodographs<ext>``."""
    stem, ext = os.path.splitext(path)
    return f"{stem}_hodographs{ext}"


def page_path(path: str) -> str:
    """The interactive page drawn beside the diagram ``path``: ``<stem>.html``."""
    return f"{os.path.splitext(path)[0]}.html"


def check_plot_paths(path: str, out: str, spec=None) -> list[str]:
    """The three output paths of ``--plot PATH`` -- the diagram, the hodographs and the
    page -- checked before any work."""
    if os.path.splitext(path)[1].lower() != ".png":
        raise UsageError(f"--plot: {path}: the pictures are PNG; give a path ending in .png")
    paths = [path, hodograph_path(path), page_path(path)]
    for p in paths:
        if os.path.abspath(p).startswith(os.path.abspath(out) + os.sep) or os.path.abspath(p) == os.path.abspath(out):
            raise UsageError(f"--plot: {p}: inside the store {out}")
    inputs = [spec.path] if spec is not None and os.path.exists(spec.path) else []
    check_outputs(paths, inputs)
    return paths


def open_levels(store_path: str) -> list:
    """The atlas at ``store_path`` and its refinement levels (``store.stored_levels``), each
    opened with ``store.open_atlas``: the coarse grid first."""
    from ..store.dataset import open_atlas, stored_levels

    return [open_atlas(p) for p in stored_levels(store_path)]


def draw(store_path: str, paths: list[str]) -> list[str]:
    """The pictures of the store -- diagram (every refinement level), hodographs and, when a
    third path is given, the interactive page -- landed together (atomically)."""
    from .diagram import diagram
    from .hodographs import hodographs
    from .page import page_of

    levels = open_levels(store_path)
    with Outputs(paths) as tmps:
        diagram(levels, tmps[0])
        hodographs(levels[0], tmps[1])
        if len(paths) > 2:
            with open(tmps[2], "w", encoding="utf-8") as f:
                f.write(page_of(levels))
    return list(paths)


