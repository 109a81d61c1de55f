"""A frame plan as a glTF model (.glb, .gltf) with the Blender script beside it, or a
self-contained web page (.html), written atomically: ``export(plan, out)``.

No drawing library: keyframes (``keyframes``), the glTF document (``gltf``, written with
pygltflib), the Blender script (``blender``) and the page (``webpage``) are NumPy and text.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

from ..atomic import Outputs
from ..errors import printable
from ..inputs.render import MODEL_FORMATS
from . import blender, gltf, keyframes, webpage

__all__ = ["export", "page_html", "ExportResult", "MODEL_FORMATS"]


@dataclass
class ExportResult:
    """What ``export`` wrote: path, format ("glb", "gltf", "html"), bytes, the video's frames,
    the keyframes, the stated tolerance and the largest measured error (deg, slerp and
    component-wise), seconds, notes, and the Blender script written beside a model (or None)."""

    path: str
    format: str
    bytes: int
    frames: int
    keyframes: int
    tolerance_deg: float
    max_error_deg: float
    seconds: float
    notes: list = field(default_factory=list)
    poster: str | None = None
    max_error_componentwise_deg: float = 0.0
    script: str | None = None
    fps: int = 0

    def describe(self) -> str:
        """One line for the command line, the path escaped (``errors.printable``) as every echoed name is."""
        kind = {"glb": "glTF model (binary)", "gltf": "glTF model", "html": "web page"}[self.format]
        worst = max(self.max_error_deg, self.max_error_componentwise_deg)
        line = (f"{printable(self.path, 300)}: {kind}, {self.bytes / 1e3:.0f} kB, {self.keyframes} keyframes of "
                f"{self.frames} frames (within {self.tolerance_deg:g} deg of every frame; largest {worst:.3g} deg), "
                f"written in {self.seconds:.1f} s")
        if self.script:
            line += (f"; {printable(self.script, 300)} opens it in Blender at {self.fps} fps, frames 0-{self.frames - 1}, "
                     f"through its camera")
        return line


def page_html(plan, tolerance_deg: float = keyframes.TOLERANCE_DEG):
    """(the page's HTML, its keyframes) of ``plan``: what ``export`` writes to X.html."""
    kf = keyframes.choose(plan, tolerance_deg)
    doc, blob = gltf.build(plan, kf)
    return webpage.page(plan, kf, gltf.to_bytes(doc, blob)), kf


def export(plan, out: str, tolerance_deg: float = keyframes.TOLERANCE_DEG) -> ExportResult:
    """Write ``plan`` as the model or page ``out`` names by its extension.

    Parameters
    ----------
    plan : FramePlan
        What the video shows; it must show the orientation (a body or an arrow).
    out : str
        A .glb, .gltf or .html path, written atomically; beside a .glb or .gltf ``X``, the
        Blender script ``X_blender.py`` (``blender.script``), the two together or neither.
    tolerance_deg : float
        The viewers' interpolation stays within this angle of every frame's pose.

    Returns
    -------
    ExportResult
    """
    t0 = time.perf_counter()
    ext = os.path.splitext(os.fspath(out))[1].lower()
    if ext not in MODEL_FORMATS:
        raise ValueError(f"not a model or page format: {ext!r}")
    kf = keyframes.choose(plan, tolerance_deg)
    doc, blob = gltf.build(plan, kf)
    files = {}
    if ext == ".gltf":
        files[out] = gltf.to_bytes(doc, blob, binary=False)
    else:
        files[out] = gltf.to_bytes(doc, blob)
        if ext == ".html":
            files[out] = webpage.page(plan, kf, files[out]).encode("utf-8")
    script = None
    if ext != ".html":
        script = blender.script_path(out)
        files[script] = blender.script(plan, out).encode("utf-8")
    with Outputs(list(files)) as tmps:
        for tmp, data in zip(tmps, files.values()):
            with open(tmp, "wb") as fh:
                fh.write(data)
    return ExportResult(path=os.fspath(out), format=ext[1:], bytes=len(files[out]), frames=plan.frames,
                        keyframes=kf.count, tolerance_deg=tolerance_deg, max_error_deg=math.degrees(kf.max_error),
                        max_error_componentwise_deg=math.degrees(kf.max_error_componentwise),
                        seconds=time.perf_counter() - t0, notes=list(plan.notes), script=script, fps=int(plan.spec.fps))
