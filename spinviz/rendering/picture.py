"""The complete plan of a video at its size: ``Picture`` = frame plan + layout + camera +
stage + overlay.  The drawing layer turns it into pixels and decides nothing.

Planning runs in two steps.  ``timeline.plan_frames`` (in the process that simulated)
samples the trajectories at the frame times: a ``FramePlan``, independent of the frame size.
``plan_picture`` then lays that plan out on its frame: bands and type sizes (``layout``),
the camera fitted to every frame's content and the 3-D views narrowed to it (``stage``),
the axis labels, and the text and marks over the frame (``overlay``).  Everything here is
plain data and pure NumPy; a ``Picture`` pickles to the render workers as one message.
"""

from __future__ import annotations

from dataclasses import dataclass

from .camera import Camera
from .frameplan import FramePlan
from .layout import Layout, TextMetrics, make_layout
from .overlay import Overlay, make_overlay
from .stage import Stage, fit_camera, make_stage


@dataclass
class Picture:
    """What every frame of a video shows and where, at the size of ``plan.spec``.

    plan : the frame plan (frame times, per-panel vectors); layout : the bands, the 3-D views
    and the type sizes (output pixels); camera : shared by all panels, fixed for the video;
    stage : the 3-D content and its poses per frame; overlay : text and 2-D marks.
    """

    plan: FramePlan
    layout: Layout
    camera: Camera
    stage: Stage
    overlay: Overlay

    @property
    def frames(self) -> int:
        return self.plan.frames

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of a frame, px."""
        return self.plan.spec.size

    def project(self, panel: int, points):
        """Output pixels (N, 2) as (column, row) of world points (N, 3) seen in ``panel``."""
        return self.camera.to_pixels(points, self.layout.views[panel])


def plan_picture(plan: FramePlan, metrics: TextMetrics) -> Picture:
    """Lay ``plan`` out on its frame.  ``metrics``: the fonts' sizes and text widths (the
    drawing layer's ``fonts.Fonts``, built for ``layout.TextSizes.for_height(H)``)."""
    camera, layout = fit_camera(plan, make_layout(plan, metrics))
    stage = make_stage(plan, layout, camera)
    return Picture(plan=plan, layout=layout, camera=camera, stage=stage,
                   overlay=make_overlay(plan, layout, metrics, stage.labels))
