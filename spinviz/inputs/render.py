"""What a video shows and how simulation time maps to video time: ``RenderSpec``.

Every render input -- a scene's ``[render]`` table, a command-line option, a Python keyword
of ``render``, ``render_frame``, ``Renderer`` -- is this one class: ``RenderSpec(...)``,
``spec.with_(...)`` and ``dataclasses.replace`` validate every field (``SpecError(key,
reason)`` naming the field, which is also the TOML key and the keyword); ``check_output`` /
``check_horizon`` check what depends on the output format or the run.  It lives below both
the scenes and the rendering package (which imports it from here), so that a
scene validates its ``[render]`` table without importing rendering.

To add a setting: one annotated field below (type, range, default, docstring line); the
TOML key, the keyword and ``with_`` follow.  A value that depends on other fields is checked
in ``_together``.
"""

from __future__ import annotations

import dataclasses
import math
import os
from typing import Annotated, Literal

from pydantic import AfterValidator, Field, PlainValidator, model_validator

from ..errors import SpecError, brief
from ..executors.processes import usable_cores
from .base import Flag, Int, Line, NonNegative, Path, Positive, Real, one_line, request, shown, wrong_type

SHOW_ITEMS = ("body", "dipole", "omega", "L", "axes", "trail", "sphere", "hud", "hodograph", "inset", "power")
DEFAULT_SHOW = ("body", "dipole", "axes", "trail", "sphere", "hud")
ORIENTATION_ITEMS = ("body", "dipole", "omega", "L", "trail")
VIDEO_FORMATS = (".mp4", ".gif")
MODEL_FORMATS = (".glb", ".gltf", ".html")      # the animated glTF model, and the page that shows it
MODEL_ITEMS = ("body", "dipole", "omega", "L")   # what a model or page is made of: at least one must be shown
MAX_PAGE_FRAMES = 20_000        # a page carries the captions of every frame (~0.2 kB each)

MIN_SIZE, MAX_SIZE = 16, 7680
MAX_FPS = 240
MAX_DURATION_S = 3600.0
MAX_FRAMES = 100_000            # ~55 min at 30 fps; the frame plan holds ~300 bytes per frame and panel (its picture ~1 kB)
MAX_GIF_BYTES = 1_000_000_000   # a GIF's frames are kept in memory (RGB, 3 bytes per pixel) until it is written
ZOOM_RANGE = (0.05, 20.0)       # outside it the body is a dot or fills the frame far beyond its edges
MAX_KNEE_RATIO = 1e15           # t_end / log_knee: float64 must still tell neighbouring frame times apart
MAX_TITLE = 160


def _size(v):
    if isinstance(v, list):
        v = tuple(v)
    ok = (isinstance(v, tuple) and len(v) == 2
          and all(isinstance(x, int) and not isinstance(x, bool) for x in v))
    if not ok:
        raise wrong_type(f"must be [width, height] in pixels ({MIN_SIZE}..{MAX_SIZE}), got {brief(v)}")
    if not all(MIN_SIZE <= x <= MAX_SIZE for x in v):
        raise ValueError(f"must be [width, height] in pixels ({MIN_SIZE}..{MAX_SIZE}), got {brief(v)}")
    return (int(v[0]), int(v[1]))


def _show(v):
    if isinstance(v, str) or not isinstance(v, (tuple, list)) or not v or not all(isinstance(x, str) for x in v):
        raise wrong_type(f"must be a non-empty list of names from: {', '.join(SHOW_ITEMS)}")
    for item in v:
        if item not in SHOW_ITEMS:
            raise ValueError(f"unknown item {brief(item)}; valid: {', '.join(SHOW_ITEMS)}")
    return tuple(dict.fromkeys(v))


def _title(v):
    if len(v) > MAX_TITLE:
        raise ValueError(f"must be at most {MAX_TITLE} characters, got {len(v)}")
    return v


def _subtitles(v):
    if isinstance(v, str) or not isinstance(v, (tuple, list)):
        raise wrong_type(f"must be a list of one line per panel (at most 2), got {brief(v)}")
    if len(v) > 2:
        raise ValueError(f"must be a list of one line per panel (at most 2), got {brief(v)}")
    for line in v:                          # each the same as a title
        _title(one_line(line))
    return tuple(v)


Title = Annotated[Line, AfterValidator(_title)]


@request
class RenderSpec:
    """What a video shows and how simulation time maps to video time (the ``[render]`` table).

    duration : s of video; fps; size : (width, height) px.
    time_map : "linear" or "log" -- video time s in [0, 1] maps to t = t_end s, or to
        t = knee ((1 + t_end/knee)^s - 1) (logarithmic once t >> knee).
    log_knee : knee of the log map, in the scene's time unit (default t_end / 1000).
    spin : "auto", "true" (the simulated orientation at each frame) or "slowed" (symmetric
        tops: slow geometry exact, spin and precession phases re-timed so that the shown
        spin rate is ``spin_turns_per_second`` x |Omega_L(t)| / |Omega_L(0)|; labelled).
    show : the actors to build (others are not built, and what they need is not computed);
        "inset" adds live plots of angle(d, L) and |Omega| of both models; "power" a live plot
        of the radiated power P(t) of each model (log scale; W, or I1/tau0^3 dimensionless).
    trail_seconds : length of the dipole trail, video seconds.
    azimuth_deg, elevation_deg, zoom : the camera (view direction from the origin).
    background : "white" or "black".  title : shown under the panels when there is room.
    poster : where in the video (0..1) the PNG poster frame is taken.
    captions : "outreach" (plain words, numbers for people) or "physics" (symbols,
        equation numbers, scientific notation).
    subtitles : one plain-words line per panel saying what its model does in this scene
        (default: what each model predicts in general).
    """

    duration: Annotated[Positive, Field(le=MAX_DURATION_S)] = 12.0
    fps: Annotated[Int, Field(ge=1, le=MAX_FPS)] = 30
    size: Annotated[tuple[int, int], PlainValidator(_size)] = (1280, 720)
    time_map: Literal["linear", "log"] = "linear"
    log_knee: Positive | None = None
    spin: Literal["auto", "true", "slowed"] = "auto"
    spin_turns_per_second: Positive = 0.75
    show: Annotated[tuple[str, ...], PlainValidator(_show)] = DEFAULT_SHOW
    trail_seconds: Annotated[NonNegative, Field(le=MAX_DURATION_S)] = 2.0
    azimuth_deg: Real = -55.0
    elevation_deg: Annotated[Real, Field(ge=-89.0, le=89.0)] = 22.0
    zoom: Annotated[Real, Field(ge=ZOOM_RANGE[0], le=ZOOM_RANGE[1])] = 1.0
    background: Literal["white", "black"] = "white"
    title: Title = ""
    poster: Annotated[Real, Field(ge=0.0, le=1.0)] = 1.0
    captions: Literal["outreach", "physics"] = "outreach"
    subtitles: Annotated[tuple[str, ...], PlainValidator(_subtitles)] = ()

    @model_validator(mode="after")
    def _together(self):
        if self.frames > MAX_FRAMES:
            raise SpecError("duration", f"{self.duration:g} s at {self.fps} fps is {self.frames} frames; "
                                        f"at most {MAX_FRAMES} are allowed")
        if self.spin_turns_per_second > self.fps / 4.0:
            cap = self.fps / 4.0
            raise SpecError("spin_turns_per_second", f"must be at most fps / 4 = {cap:g} (a quarter turn per "
                                                     f"frame; faster spins alias), got {shown(self.spin_turns_per_second, cap)}")
        return self

    def with_(self, **overrides) -> RenderSpec:
        """A copy with some fields replaced (validated like the original); None keeps a field."""
        return dataclasses.replace(self, **{k: v for k, v in overrides.items() if v is not None})

    # -- derived --------------------------------------------------------------------------
    @property
    def needs_orientation(self) -> bool:
        """False when nothing shown depends on the orientation (e.g. a hodograph-only scene):
        then no orientation is integrated at all."""
        return any(item in self.show for item in ORIENTATION_ITEMS)

    @property
    def frames(self) -> int:
        """F = round(duration x fps), at least 2."""
        return max(2, int(round(self.duration * self.fps)))

    def knee(self, t_end: float) -> float:
        """The knee of the log time map: ``log_knee``, or t_end / 1000 by default."""
        return self.log_knee or t_end / 1000.0

    def video_fraction(self, t: float, t_end: float) -> float:
        """The fraction of the video (0..1) at which simulation time ``t`` is shown: the
        inverse of the time map (t and t_end in the scene's time unit)."""
        if self.time_map == "linear":
            return t / t_end
        k = self.knee(t_end)
        return math.log1p(t / k) / math.log1p(t_end / k)

    # -- checks that need more than the spec ----------------------------------------------
    def check_horizon(self, t_end: float) -> None:
        """The log knee must lie inside the run, and not so far below t_end that float64
        cannot separate the frame times."""
        if self.log_knee is not None and not self.log_knee < t_end:
            raise SpecError("log_knee", f"must be below t_end = {t_end:g}")
        if self.log_knee is not None and t_end / self.log_knee > MAX_KNEE_RATIO:
            raise SpecError("log_knee", f"must be at least t_end / {MAX_KNEE_RATIO:g} = {t_end / MAX_KNEE_RATIO:.3g}, "
                                        f"got {shown(self.log_knee, t_end / MAX_KNEE_RATIO)}")

    def check_output(self, path: str, panels: int = 1) -> None:
        """The output format and the layout: .mp4 or .gif; MP4 (H.264, yuv420p) needs even
        sides; the width must split evenly into ``panels`` side-by-side panels.  A model or
        page (.glb, .gltf, .html) needs a body or an arrow among ``show``."""
        ext = os.path.splitext(os.fspath(path))[1].lower()
        if ext in MODEL_FORMATS:
            self._check_model(ext)
            return
        if ext not in VIDEO_FORMATS:
            raise SpecError("out", f"unknown output format {brief(ext) if ext else '(none)'}; "
                                   f"use .mp4 or .gif (video), .glb or .gltf (animated 3-D model) or .html (web page)")
        w, h = self.size
        if ext == ".mp4" and (w % 2 or h % 2):
            raise SpecError("size", f"MP4 (H.264, yuv420p) needs an even width and height, got {w}x{h}")
        if w % panels:
            raise SpecError("size", f"{panels} panels side by side need a width divisible by {panels}, got {w}")
        if ext == ".gif" and 3 * self.frames * w * h > MAX_GIF_BYTES:
            raise SpecError("duration", f"a GIF of {self.frames} frames at {w}x{h} needs {3 * self.frames * w * h / 1e9:.1f} GB "
                                        f"of memory (limit {MAX_GIF_BYTES / 1e9:g} GB); make it shorter or smaller, or use .mp4")

    def _check_model(self, ext: str) -> None:
        if not any(item in self.show for item in MODEL_ITEMS):
            raise SpecError("show", f"a {ext} shows the body and its arrows; this scene shows none of "
                                    f"{', '.join(MODEL_ITEMS)} (show = {list(self.show)})")
        if ext == ".html" and self.frames > MAX_PAGE_FRAMES:
            raise SpecError("duration", f"{self.duration:g} s at {self.fps} fps is {self.frames} frames; a page holds "
                                        f"the captions of every frame, at most {MAX_PAGE_FRAMES}")


# --- the arguments of render, render_frame, Renderer and plan -------------------------------------
def _workers(v):
    cores = usable_cores()
    if v > cores:
        raise ValueError(f"must be at most {cores}, the cores this process may use (more render processes than cores "
                         f"only share them), got {v}")
    return v


@request
class RenderArguments:
    """The arguments of ``render``, ``render_frame``, ``Renderer`` and ``plan`` that are not
    ``RenderSpec`` fields (those are checked by ``RenderSpec``): times in the scene's unit.

    t : the physical time a picture shows, in [0, the run's end] (checked against it later);
    t_end : where a video (a frame plan) ends; frames : F of a plan; frame : an index of one;
    out : the video's path; workers : render processes; progress : a bar on stderr;
    height : px of a notebook's inline turnable view (``spinviz.show``).
    """

    t: Annotated[Real, Field(ge=0.0)] | None = None
    t_end: Positive | None = None
    frames: Annotated[Int, Field(ge=2, le=MAX_FRAMES)] | None = None
    frame: Int | None = None
    out: Path = None
    workers: Annotated[Int, Field(ge=1), AfterValidator(_workers)] | None = None
    progress: Flag = False
    height: Annotated[Int, Field(ge=200, le=4000)] | None = None


def poster_for(out: str) -> str:
    """The PNG poster written beside a video: the same name with the extension .png."""
    return os.path.splitext(os.fspath(out))[0] + ".png"


def default_output(scene, directory: str = "renders") -> str:
    """Where a scene's video goes by default: ``renders/<scene file's stem>.mp4``.  ``scene``: a
    ``Scene`` (anything with a ``path``) or the path of its file; trajectories have no default
    (``SpecError`` naming ``out``).  Beside ``RenderSpec.check_output``, which checks it."""
    path = scene if isinstance(scene, (str, os.PathLike)) else getattr(scene, "path", None)
    if not isinstance(path, (str, os.PathLike)):
        raise SpecError("out", "missing value: trajectories have no default video path; give a .mp4 or .gif path")
    stem = os.path.splitext(os.path.basename(os.fspath(path)))[0]
    return os.path.join(directory, f"{stem}.mp4")
