"""What a video shows and how simulation time maps to video time: ``RenderSpec``.

Every render input -- from a scene's ``[render]`` table, a command-line option or a Python
keyword -- is validated here and nowhere else: ``RenderSpec(...)`` and ``spec.with_(...)``
check every field, ``RenderSpec.from_mapping`` also checks TOML types and unknown keys, and
``check_output`` / ``check_horizon`` check what depends on the output format or the run.
Problems raise ``SpecError(key, reason)``; the scene layer adds the file name.

Pure Python: importing this module loads no rendering library.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

from ..errors import SpecError, brief

SHOW_ITEMS = ("body", "dipole", "omega", "L", "axes", "trail", "sphere", "hud", "hodograph", "inset", "power")
DEFAULT_SHOW = ("body", "dipole", "axes", "trail", "sphere", "hud")
ORIENTATION_ITEMS = ("body", "dipole", "omega", "L", "trail")
VIDEO_FORMATS = (".mp4", ".gif")

MIN_SIZE, MAX_SIZE = 16, 7680
MAX_FPS = 240
MAX_DURATION_S = 3600.0
MAX_FRAMES = 100_000            # ~55 min at 30 fps; the frame plan holds ~300 bytes per frame and panel (its picture ~1 kB)
MAX_GIF_BYTES = 1_000_000_000   # a GIF's frames are kept in memory (RGB, 3 bytes per pixel) until it is written
ZOOM_RANGE = (0.05, 20.0)       # outside it the body is a dot or fills the frame far beyond its edges
MAX_KNEE_RATIO = 1e15           # t_end / log_knee: float64 must still tell neighbouring frame times apart
MAX_TITLE = 160
CAPTIONS = ("outreach", "physics")


@dataclass(frozen=True)
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

    duration: float = 12.0
    fps: int = 30
    size: tuple[int, int] = (1280, 720)
    time_map: str = "linear"
    log_knee: float | None = None
    spin: str = "auto"
    spin_turns_per_second: float = 0.75
    show: tuple[str, ...] = DEFAULT_SHOW
    trail_seconds: float = 2.0
    azimuth_deg: float = -55.0
    elevation_deg: float = 22.0
    zoom: float = 1.0
    background: str = "white"
    title: str = ""
    poster: float = 1.0
    captions: str = "outreach"
    subtitles: tuple[str, ...] = ()

    def __post_init__(self):
        for f in fields(self):
            _CHECKS[f.name](self, f.name, getattr(self, f.name))
        if self.frames > MAX_FRAMES:
            raise SpecError("duration", f"{self.duration:g} s at {self.fps} fps is {self.frames} frames; "
                                        f"at most {MAX_FRAMES} are allowed")
        if self.spin_turns_per_second > self.fps / 4.0:
            raise SpecError("spin_turns_per_second", f"must be at most fps / 4 = {self.fps / 4.0:g} (a quarter turn per "
                                                     f"frame; faster spins alias), got {self.spin_turns_per_second:g}")

    # -- construction ---------------------------------------------------------------------
    @classmethod
    def from_mapping(cls, data, title: str = "") -> RenderSpec:
        """A spec from a parsed ``[render]`` table: TOML types checked, unknown keys refused.

        ``size`` and ``show`` come as lists; ``title`` defaults to ``title``."""
        if not isinstance(data, dict):
            raise SpecError("[render]", f"must be a table, got {type(data).__name__}")
        names = {f.name for f in fields(cls)}
        unknown = sorted(k for k in data if k not in names)
        if unknown:
            more = f" (also unknown: {', '.join(map(str, unknown[1:]))})" if len(unknown) > 1 else ""
            raise SpecError(str(unknown[0]), "unknown key" + more)
        kw = {"title": title}
        for key, value in data.items():
            kw[key] = _from_toml(key, value)
        return cls(**kw)

    def with_(self, **overrides) -> RenderSpec:
        """A copy with some fields replaced (validated like the original); None keeps a field."""
        return replace(self, **{k: v for k, v in overrides.items() if v is not None})

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
                                        f"got {self.log_knee:g}")

    def check_output(self, path: str, panels: int = 1) -> None:
        """The output format and the layout: .mp4 or .gif; MP4 (H.264, yuv420p) needs even
        sides; the width must split evenly into ``panels`` side-by-side panels."""
        import os

        ext = os.path.splitext(path)[1].lower()
        if ext not in VIDEO_FORMATS:
            raise SpecError("out", f"unknown video format {ext or '(none)'!r}; use .mp4 or .gif")
        w, h = self.size
        if ext == ".mp4" and (w % 2 or h % 2):
            raise SpecError("size", f"MP4 (H.264, yuv420p) needs an even width and height, got {w}x{h}")
        if w % panels:
            raise SpecError("size", f"{panels} panels side by side need a width divisible by {panels}, got {w}")
        if ext == ".gif" and 3 * self.frames * w * h > MAX_GIF_BYTES:
            raise SpecError("duration", f"a GIF of {self.frames} frames at {w}x{h} needs {3 * self.frames * w * h / 1e9:.1f} GB "
                                        f"of memory (limit {MAX_GIF_BYTES / 1e9:g} GB); make it shorter or smaller, or use .mp4")


def poster_for(out: str) -> str:
    """The PNG poster written beside a video: the same name with the extension .png."""
    import os

    return os.path.splitext(out)[0] + ".png"


# --- per-field validation ------------------------------------------------------------------
def _number(spec, key, v, lo=None, hi=None, lo_open=False, allow_none=False):
    if v is None and allow_none:
        return
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SpecError(key, f"must be a number, got {brief(v)}")
    if not math.isfinite(v):
        raise SpecError(key, f"must be finite, got {v}")
    if lo is not None and (v <= lo if lo_open else v < lo):
        raise SpecError(key, f"must be {'above' if lo_open else 'at least'} {lo:g}, got {v:g}")
    if hi is not None and v > hi:
        raise SpecError(key, f"must be at most {hi:g}, got {v:g}")


def _choice(options):
    def check(spec, key, v):
        if v not in options:
            raise SpecError(key, f"unknown value {brief(v)}; valid: {', '.join(options)}")
    return check


def _check_size(spec, key, v):
    ok = (isinstance(v, (tuple, list)) and len(v) == 2
          and all(isinstance(x, int) and not isinstance(x, bool) for x in v))
    if not ok or not all(MIN_SIZE <= x <= MAX_SIZE for x in v):
        raise SpecError(key, f"must be [width, height] in pixels ({MIN_SIZE}..{MAX_SIZE}), got {brief(v)}")
    if not isinstance(v, tuple):
        object.__setattr__(spec, key, tuple(v))


def _check_fps(spec, key, v):
    if isinstance(v, bool) or not isinstance(v, int):
        raise SpecError(key, f"must be an integer, got {brief(v)}")
    if not 1 <= v <= MAX_FPS:
        raise SpecError(key, f"must be between 1 and {MAX_FPS}, got {v}")


def _check_show(spec, key, v):
    if isinstance(v, str) or not isinstance(v, (tuple, list)) or not v or not all(isinstance(x, str) for x in v):
        raise SpecError(key, f"must be a non-empty list of names from: {', '.join(SHOW_ITEMS)}")
    for item in v:
        if item not in SHOW_ITEMS:
            raise SpecError(key, f"unknown item {item!r}; valid: {', '.join(SHOW_ITEMS)}")
    object.__setattr__(spec, key, tuple(dict.fromkeys(v)))


def _check_title(spec, key, v):
    if not isinstance(v, str):
        raise SpecError(key, f"must be a string, got {brief(v)}")
    if any(ord(c) < 0x20 or 0x7F <= ord(c) < 0xA0 for c in v):
        raise SpecError(key, "must be one line of printable text (no newlines or control characters)")
    if len(v) > MAX_TITLE:
        raise SpecError(key, f"must be at most {MAX_TITLE} characters, got {len(v)}")


def _check_subtitles(spec, key, v):
    if isinstance(v, str) or not isinstance(v, (tuple, list)) or len(v) > 2:
        raise SpecError(key, f"must be a list of one line per panel (at most 2), got {brief(v)}")
    for line in v:
        _check_title(spec, key, line)
    if not isinstance(v, tuple):
        object.__setattr__(spec, key, tuple(v))


_CHECKS = {
    "duration": lambda s, k, v: _number(s, k, v, lo=0.0, hi=MAX_DURATION_S, lo_open=True),
    "fps": _check_fps,
    "size": _check_size,
    "time_map": _choice(("linear", "log")),
    "log_knee": lambda s, k, v: _number(s, k, v, lo=0.0, lo_open=True, allow_none=True),
    "spin": _choice(("auto", "true", "slowed")),
    "spin_turns_per_second": lambda s, k, v: _number(s, k, v, lo=0.0, lo_open=True),
    "show": _check_show,
    "trail_seconds": lambda s, k, v: _number(s, k, v, lo=0.0, hi=MAX_DURATION_S),
    "azimuth_deg": lambda s, k, v: _number(s, k, v),
    "elevation_deg": lambda s, k, v: _number(s, k, v, lo=-89.0, hi=89.0),
    "zoom": lambda s, k, v: _number(s, k, v, lo=ZOOM_RANGE[0], hi=ZOOM_RANGE[1]),
    "background": _choice(("white", "black")),
    "title": _check_title,
    "poster": lambda s, k, v: _number(s, k, v, lo=0.0, hi=1.0),
    "captions": _choice(CAPTIONS),
    "subtitles": _check_subtitles,
}


def _from_toml(key: str, value):
    """TOML value -> field value: lists become tuples; integers stay integers."""
    if key in ("size", "show", "subtitles") and isinstance(value, list):
        return tuple(value)
    return value
