"""The complete plan of a video at its size: ``Picture`` = frame plan + layout + camera +
stage + overlay.  The drawing layer turns it into pixels and decides nothing.

Planning runs in two steps.  ``timeline.plan_frames`` (in the process that simulated)
samples the trajectories at the frame times: a ``FramePlan``, independent of the frame size.
``plan_picture`` then lays that plan out on its frame, in one pass down: all its words
(``captions``), its colours (``style``), the bands and type sizes (``layout``), the 3-D
content with every frame's poses, the camera fitted to all of it and the axis labels
(``stage``), and the text and marks over the frame, every frame's included (``overlay``).
Everything here is plain data and pure NumPy; a ``Picture`` pickles to the render workers
as one message, and drawing a frame only reads it.
"""

from __future__ import annotations

from dataclasses import dataclass

from .camera import Camera
from .captions import texts_of
from .frameplan import FramePlan
from .layout import Layout, TextMetrics, make_layout
from .overlay import Overlay, make_overlay
from .stage import Stage, plan_stage
from .style import Theme, theme


@dataclass
class Picture:
    """What every frame of a video shows and where, at the size of ``plan.spec``.

    plan : the frame plan (frame times, per-panel vectors); theme : the colours; layout : the
    bands, the 3-D views and the type sizes (output pixels); camera : shared by all panels,
    fixed for the video; stage : the 3-D content and its poses per frame; overlay : text and
    2-D marks, per frame where they change.
    """

    plan: FramePlan
    theme: Theme
    layout: Layout
    camera: Camera
    stage: Stage
    overlay: Overlay

    @property
    def frames(self) -> int:
        """F, the number of frames."""
        return self.plan.frames

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of a frame, px."""
        return self.plan.spec.size

    def project(self, panel: int, points):
        """Output pixels (N, 2) as (column, row) of world points (N, 3) seen in ``panel``."""
        return self.camera.to_pixels(points, self.layout.views[panel])


def plan_picture(plan: FramePlan, metrics: TextMetrics) -> Picture:
    """Lay ``plan`` out on its frame, in one pass down.

    Parameters
    ----------
    plan : FramePlan
        What each frame shows; its spec gives the frame size (W, H) px.
    metrics : layout.TextMetrics
        Type sizes and text widths, px: the drawing layer's ``fonts.Fonts`` built for
        ``layout.TextSizes.for_height(H)``, or any stand-in (tests).

    Returns
    -------
    Picture
        Plain data: every frame's words, layout, camera, poses and marks.
    """
    texts = texts_of(plan)
    colors = theme(plan.spec.background, plan.body_name)
    stage, camera, layout = plan_stage(plan, make_layout(plan, texts, metrics), colors)
    overlay = make_overlay(plan, layout, texts, colors, metrics, stage.labels)
    return Picture(plan=plan, theme=colors, layout=layout, camera=camera, stage=stage, overlay=overlay)
