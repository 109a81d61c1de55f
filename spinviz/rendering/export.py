"""A frame plan as a glTF model (.glb, .gltf) or a self-contained web page (.html), written
atomically: ``export(plan, out)``.

No drawing library: keyframes (``keyframes``), the glTF document (``gltf``, written with
pygltflib) and the page (``webpage``) are NumPy and text.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

from ..atomic import atomic_path
from ..errors import printable
from ..inputs.render import MODEL_FORMATS
from . import gltf, keyframes, webpage

__all__ = ["export", "ExportResult", "MODEL_FORMATS"]


@dataclass
class ExportResult:
    """What ``export`` wrote: path, format ("glb", "gltf", "html"), bytes, the video's frames,
    the keyframes, the stated tolerance and the largest measured error (deg), seconds, notes."""

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

    def describe(self) -> str:
        """One line for the command line, the path escaped (``errors.printable``) as every echoed name is."""
        kind = {"glb": "glTF model (binary)", "gltf": "glTF model", "html": "web page"}[self.format]
        return (f"{printable(self.path, 300)}: {kind}, {self.bytes / 1e3:.0f} kB, {self.keyframes} keyframes of "
                f"{self.frames} frames "
                f"(within {self.tolerance_deg:g} deg of every frame; largest {self.max_error_deg:.3g} deg), "
                f"written in {self.seconds:.1f} s")


def export(plan, out: str, tolerance_deg: float = keyframes.TOLERANCE_DEG) -> ExportResult:
    """Write ``plan`` as the model or page ``out`` names by its extension.

    Parameters
    ----------
    plan : FramePlan
        What the video shows; it must show the orientation (a body or an arrow).
    out : str
        A .glb, .gltf or .html path, written atomically.
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
    if ext == ".gltf":
        data = gltf.to_bytes(doc, blob, binary=False)
    else:
        data = gltf.to_bytes(doc, blob)
        if ext == ".html":
            data = webpage.page(plan, kf, data).encode("utf-8")
    with atomic_path(out) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return ExportResult(path=os.fspath(out), format=ext[1:], bytes=len(data), frames=plan.frames, keyframes=kf.count,
                        tolerance_deg=tolerance_deg, max_error_deg=math.degrees(kf.max_error),
                        seconds=time.perf_counter() - t0, notes=list(plan.notes))
