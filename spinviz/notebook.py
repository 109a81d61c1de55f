"""The turnable view inline in a notebook: ``spinviz.show(source)``.

``show`` makes the page ``render(source, out="X.html")`` writes -- the same HTML, under the
same Content-Security-Policy, nothing loaded from the network -- and returns a ``Turnable``,
which Jupyter (JupyterLab, Notebook, VS Code, myst-nb's pages) displays inline through its
``_repr_html_``: an ``<iframe>`` whose ``srcdoc`` is the page, sandboxed to run its own
scripts only.  The page keeps its own policy inside the frame, and nothing of it mixes with
the notebook's document.  Nothing is drawn until asked: a ``Trajectory`` or a ``Scene`` shows
its usual text in a notebook, since a turnable view costs a simulation (a scene) and about
a megabyte of page kept in the notebook.
"""

from __future__ import annotations

import html
import os

from .atomic import atomic_path

__all__ = ["show", "Turnable"]

HEIGHT = {1: 760, 2: 900}       # px of the inline frame: the page's heading, views, controls and captions


class Turnable:
    """A turnable view of a source, shown inline by Jupyter.

    Attributes: ``html`` (the page, one self-contained document), ``keyframes`` and
    ``frames`` (of its model), ``height`` (px of the inline frame).
    """

    def __init__(self, page: str, keyframes: int, frames: int, height: int):
        self.html = page
        self.keyframes = keyframes
        self.frames = frames
        self.height = height

    def _repr_html_(self) -> str:
        """The page in a sandboxed iframe (``srcdoc``): it runs its own scripts and nothing else."""
        return (f'<iframe srcdoc="{html.escape(self.html, quote=True)}" sandbox="allow-scripts" '
                f'allow="fullscreen" allowfullscreen width="100%" height="{self.height}" frameborder="0" '
                f'title="spinviz: turnable view"></iframe>')

    def save(self, path) -> str:
        """Write the page to ``path`` (.html, atomically); returns the path."""
        path = os.fspath(path)
        with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(self.html)
        return path

    def __repr__(self) -> str:
        return f"<spinviz turnable view: {self.keyframes} keyframes of {self.frames} frames, {len(self.html) / 1e3:.0f} kB>"


def show(source, *, height: int | None = None, **overrides) -> Turnable:
    """The turnable view of ``source``, for a notebook: the page ``render(source,
    out="X.html")`` writes, displayed inline.

    Parameters
    ----------
    source : Scene, path, Trajectory or list of one or two Trajectories
        A scene (``Scene`` or the path of its TOML) is simulated at the frame times;
        trajectories are shown as they are (one model each).
    height : int, optional
        Height of the inline frame, px (default 900 for two models, 760 for one).
    **overrides
        ``RenderSpec`` fields (duration, fps, show, captions, ...) replacing the scene's
        ``[render]`` table.

    Returns
    -------
    Turnable
        Shown inline by Jupyter; ``.html`` is the page, ``.save(path)`` writes it.
    """
    import importlib.util

    from . import pipeline
    from .inputs.render import RenderArguments

    height = RenderArguments(height=height).height
    if importlib.util.find_spec("pygltflib") is None:
        raise pipeline.MissingRenderStack("a turnable view needs the optional package 'pygltflib': "
                                          "pip install 'spinviz[render]'")
    from .rendering.export import page_html

    scene, trajs, spec = pipeline.resolve_spec(source, **overrides)
    spec.check_output("view.html", len(scene.models) if scene is not None else len(trajs))
    frame_plan = pipeline._plan(scene, trajs, spec)
    page, kf = page_html(frame_plan)
    n = len(frame_plan.panels)
    return Turnable(page, kf.count, frame_plan.frames, height or HEIGHT[n])
