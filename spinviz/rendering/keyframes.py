"""Keyframes for a glTF animation: which of a video's frames a viewer needs so that its own
interpolation redraws the video.

Pure NumPy (a planning module: no drawing library).  The animation's clock is the MP4's: video
frame f is shown at f / fps seconds (``frame_clock``), so a viewer set to the video's frame
rate (Blender at ``fps``) lands on the video's frames at whole frame numbers.  Between two
keyframes a viewer draws a rotation in one of two ways: slerp at a constant rate (the
sampler's LINEAR interpolation as the glTF specification defines it, and three.js), or the
four numbers interpolated one by one and normalized (Blender's quaternion F-curves);
lengths and offsets linearly.  The keyframes are a subset of the video's own frames
(``FramePlan``): at a keyframe the file holds exactly the pose the video draws there, and the
subset is chosen, greedily from the first frame, so that at every frame in between *both*
interpolations -- body orientation, the direction of every moving arrow -- lie within
``tolerance`` (rad) of the pose the video draws at that frame, and every arrow's length
within ``LENGTH_TOLERANCE``.  Consecutive keyframes are sign-aligned (q . q' >= 0) and less
than ``MAX_STEP`` (50 deg) apart, so that the component-wise path is the same short arc as
slerp's; where two neighbouring video frames are further apart (an aliased spin), slerp
midpoints are added -- poses on the path every viewer draws anyway, flagged as not drawn by
the video.

Quaternions here are scalar-first (w, x, y, z), body -> world for the body, and for an arrow
the rotation taking +x along it; the glTF writer reorders them to (x, y, z, w).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import rotations as R
from .stage import ARROW_VECTORS, arrow_length

TOLERANCE_DEG = 0.25            # default: the viewer's pose within this angle of the video's at every frame
LENGTH_TOLERANCE = 0.003        # arrow lengths, in units of the dipole arrow (1 = the glTF metre)
MAX_STEP = math.radians(50.0)   # rotation between consecutive keyframes stays below this (rad): under a quarter turn,
                                # so component-wise interpolation follows slerp's short arc
MOVING_ARROWS = ("L", "omega")  # turned in the world frame; the dipole arrow rides on the body
INTERPOLATIONS = ("slerp", "componentwise")


def frame_clock(plan) -> np.ndarray:
    """(F,) seconds at which the MP4 shows each frame: f / fps (the glTF animation's clock)."""
    return np.arange(plan.frames, dtype=float) / float(plan.spec.fps)


@dataclass
class PanelKeys:
    """One model's animated values at the K keyframes.

    q : (K, 4) body -> world, (w, x, y, z), sign-aligned; arrows : key ("L", "omega") ->
    (q (K, 4) the rotation taking +x along the arrow, (K,) its drawn length, dipole-arrow units).
    """

    model: str
    q: np.ndarray | None
    arrows: dict = field(default_factory=dict)


@dataclass
class Keyframes:
    """The animation of a frame plan.

    frame : (K,) the video frame each keyframe shows, or -1 for a slerp midpoint added between
    two frames more than ``MAX_STEP`` apart; position : (K,) the frame number on the video's
    clock (a midpoint's is fractional); video_t : (K,) seconds on the MP4's clock, position /
    fps (the animation's clock); fps : the video's frame rate; sim_t : (K,) simulation time,
    scene unit (a midpoint's by the time map); panels : one ``PanelKeys`` per model;
    tolerance : the stated bound (rad); max_error : the largest angle between the slerped pose
    and the video's, over every frame (rad); max_error_componentwise : the same for the
    component-wise interpolation (Blender's); max_length_error : the same for the arrows'
    lengths (dipole-arrow units); max_step : the largest rotation between consecutive
    keyframes (rad).
    """

    frame: np.ndarray
    position: np.ndarray
    video_t: np.ndarray
    fps: int
    sim_t: np.ndarray
    panels: list
    tolerance: float
    max_error: float = 0.0
    max_error_componentwise: float = 0.0
    max_length_error: float = 0.0
    max_step: float = 0.0

    @property
    def count(self) -> int:
        """K, the number of keyframes."""
        return int(self.frame.size)


def arrow_track(v_world: np.ndarray, key: str) -> tuple[np.ndarray, np.ndarray]:
    """(q (F, 4), length (F,)) of an arrow along ``v_world`` (F, 3) at every frame: q takes +x
    along v, carried from frame to frame by the smallest rotation between consecutive
    directions (so the arrow's roll about itself, which no one sees, stays continuous and
    slerp between nearby frames sweeps the direction along the great circle); length as the
    video draws it (``stage.arrow_length``).  A zero vector keeps the previous direction."""
    v = np.asarray(v_world, dtype=float)
    n = np.linalg.norm(v, axis=1)
    lengths = np.array([arrow_length(key, float(x)) for x in n])
    q = np.empty((v.shape[0], 4))
    prev_u, prev_q = np.array([1.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0, 0.0])
    for f in range(v.shape[0]):
        if n[f] > 0.0:
            u = v[f] / n[f]
            prev_q = R.normalize(R.multiply(R.quat_between(prev_u, u), prev_q))
            prev_u = u
        q[f] = prev_q
    return R.unflip(q), lengths


def _tracks(plan) -> list[dict]:
    """Per panel {"body": q (F, 4) sign-aligned or absent, arrow key: (q, length)}."""
    out = []
    for panel in plan.panels:
        tr = {}
        if panel.q is not None:
            tr["body"] = R.unflip(panel.q)
        for key in MOVING_ARROWS:
            v = getattr(panel, ARROW_VECTORS[key])
            if v is not None and key in plan.spec.show:
                tr[key] = arrow_track(v, key)
        out.append(tr)
    return out


def _slerp(qa, qb, tau):
    """slerp from qa to qb (each (4,), or (n, 4) row by row; sign-aligned) at fractions tau (n,)
    -> (n, 4)."""
    qa, qb = np.broadcast_arrays(np.atleast_2d(qa), np.atleast_2d(qb))
    tau = np.asarray(tau, dtype=float)
    rel = R.multiply(R.conjugate(qa), qb)
    half = np.arctan2(np.linalg.norm(rel[:, 1:], axis=1), rel[:, 0])
    nv = np.linalg.norm(rel[:, 1:], axis=1, keepdims=True)
    axis = np.divide(rel[:, 1:], nv, out=np.zeros_like(rel[:, 1:]), where=nv > 0.0)
    return R.multiply(qa, R.exp_rotvec(2.0 * (tau * half)[:, None] * axis))


def _componentwise(qa, qb, tau):
    """The four numbers interpolated one by one from qa to qb (each (4,) or (n, 4);
    sign-aligned) at fractions tau (n,), then normalized (Blender's quaternion F-curves) ->
    (n, 4)."""
    tau = np.asarray(tau, dtype=float)[:, None]
    return R.normalize((1.0 - tau) * np.atleast_2d(qa) + tau * np.atleast_2d(qb))


_BETWEEN = {"slerp": _slerp, "componentwise": _componentwise}


def _span_errors(tracks, i: int, j: int) -> tuple[float, float]:
    """(largest angle, largest length error) at frames i+1 .. j-1 when a viewer interpolates
    from frame i to frame j, by slerp or component by component (the worse of the two): body
    misorientation, arrow direction."""
    if j - i < 2:
        return 0.0, 0.0
    tau = np.arange(1, j - i) / float(j - i)
    ang, dlen = 0.0, 0.0
    x = np.array([1.0, 0.0, 0.0])
    for tr in tracks:
        for key, val in tr.items():
            q = val if key == "body" else val[0]
            for between in _BETWEEN.values():
                s = between(q[i], q[j], tau)
                if key == "body":
                    ang = max(ang, float(np.max(R.misorientation(s, q[i + 1:j]))))
                else:
                    ang = max(ang, float(np.max(R.angle_between(R.world_from_body(s, x),
                                                                R.world_from_body(q[i + 1:j], x)))))
            if key != "body":
                ln = val[1]
                lin = ln[i] + tau * (ln[j] - ln[i])
                dlen = max(dlen, float(np.max(np.abs(lin - ln[i + 1:j]))))
    return ang, dlen


def _step(tracks, i: int, j: int) -> float:
    """The largest rotation (rad) of any animated quaternion from frame i to frame j."""
    worst = 0.0
    for tr in tracks:
        for key, val in tr.items():
            q = val if key == "body" else val[0]
            worst = max(worst, float(R.misorientation(q[i], q[j])))
    return worst


def choose(plan, tolerance_deg: float = TOLERANCE_DEG) -> Keyframes:
    """The keyframes of ``plan`` (a ``FramePlan`` that shows the orientation).

    Greedy: from the last keyframe, the next is the furthest frame such that interpolating
    to it -- by slerp and component by component -- keeps every frame in between within
    ``tolerance_deg`` (body and arrow directions) and ``LENGTH_TOLERANCE`` (arrow lengths)
    of the video, and turns nothing by ``MAX_STEP`` or more.  The first and last frames are
    always keyframes.

    Returns
    -------
    Keyframes
        Frame indices, times on the MP4's clock (f / fps), simulation times, per-panel values
        (sign-aligned) and the measured largest errors over every frame of the plan.
    """
    tol = math.radians(tolerance_deg)
    tracks = _tracks(plan)
    F = plan.frames
    keep = [0]
    i = 0
    while i < F - 1:
        j = i + 1
        while j + 1 < F:
            if _step(tracks, i, j + 1) >= MAX_STEP:
                break
            ang, dlen = _span_errors(tracks, i, j + 1)
            if ang > tol or dlen > LENGTH_TOLERANCE:
                break
            j += 1
        keep.append(j)
        i = j
    frames = np.array(keep)
    return _assemble(plan, tracks, frames, tol)


def _assemble(plan, tracks, frames, tol) -> Keyframes:
    """The chosen frames' values, slerp midpoints where neighbours turn by ``MAX_STEP`` or
    more, and the measured errors."""
    vt, st = np.asarray(plan.video_t, dtype=float), np.asarray(plan.sim_t, dtype=float)
    # split any step that is too large (neighbouring frames alone: an aliased spin) into equal parts
    rows = []                       # (frame or -1, frame position, {track: (i, j, tau)})
    for a, b in zip(frames[:-1], frames[1:]):
        parts = max(1, math.ceil(_step(tracks, a, b) / (0.9 * MAX_STEP))) if b - a == 1 else 1
        rows.append((int(a), float(a), (a, b, 0.0)))
        for p in range(1, parts):
            rows.append((-1, a + (b - a) * p / parts, (a, b, p / parts)))
    rows.append((int(frames[-1]), float(frames[-1]), (frames[-1], frames[-1], 0.0)))
    frame = np.array([r[0] for r in rows])
    position = np.array([r[1] for r in rows])
    # a midpoint's simulation time: the time map at its place between its frames' map parameters
    sim_t = np.array([st[f] if f >= 0 else _sim_at(plan, vt[a] + (vt[b] - vt[a]) * tau)
                      for f, _, (a, b, tau) in rows])
    panels = []
    for panel, tr in zip(plan.panels, tracks):
        keys = PanelKeys(model=panel.model, q=None)
        for key, val in tr.items():
            q_all = val if key == "body" else val[0]
            q = np.array([q_all[a] if tau == 0.0 else _slerp(q_all[a], q_all[b], [tau])[0] for _, _, (a, b, tau) in rows])
            q = R.unflip(q)
            if key == "body":
                keys.q = q
            else:
                ln = val[1]
                keys.arrows[key] = (q, np.array([ln[a] + tau * (ln[b] - ln[a]) for _, _, (a, b, tau) in rows]))
        panels.append(keys)
    fps = int(plan.spec.fps)
    kf = Keyframes(frame=frame, position=position, video_t=position / float(fps), fps=fps, sim_t=sim_t, panels=panels,
                   tolerance=tol)
    kf.max_error, kf.max_length_error = measure(kf, plan, "slerp", tracks)
    kf.max_error_componentwise, _ = measure(kf, plan, "componentwise", tracks)
    kf.max_step = max((float(np.max(R.misorientation(q[:-1], q[1:]))) for q in _all_quats(kf) if len(q) > 1),
                      default=0.0)
    return kf


def _sim_at(plan, v: float) -> float:
    """Simulation time at the time map's parameter ``v`` (0 .. duration) by the plan's time map."""
    spec = plan.spec
    s = v / spec.duration
    t_end = plan.t_end
    if spec.time_map == "linear":
        return t_end * s
    k = spec.knee(t_end)
    return k * math.expm1(s * math.log1p(t_end / k))


def _all_quats(kf: Keyframes):
    for p in kf.panels:
        if p.q is not None:
            yield p.q
        for q, _ in p.arrows.values():
            yield q


def interpolate(kf: Keyframes, video_t, how: str = "slerp") -> list[dict]:
    """What a glTF viewer draws at times ``video_t`` (M,) of the animation's clock (seconds,
    frame f at f / fps) from the keyframes: per panel {"body": q (M, 4), arrow key: (q (M, 4),
    length (M,))} -- rotations by slerp (three.js's and the sample viewer's LINEAR) or, with
    ``how="componentwise"``, component by component and normalized (Blender's F-curves);
    lengths linearly."""
    t = np.atleast_1d(np.asarray(video_t, dtype=float))
    kt = kf.video_t
    i = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, max(kt.size - 2, 0))
    j = np.minimum(i + 1, kt.size - 1)
    span = kt[j] - kt[i]
    tau = np.clip(np.divide(t - kt[i], span, out=np.zeros_like(t), where=span > 0), 0.0, 1.0)
    between = _BETWEEN[how]

    def rows(q):
        return between(q[i], q[j], tau)

    out = []
    for p in kf.panels:
        d = {}
        if p.q is not None:
            d["body"] = rows(p.q)
        for key, (q, ln) in p.arrows.items():
            d[key] = (rows(q), ln[i] + tau * (ln[j] - ln[i]))
        out.append(d)
    return out


def measure(kf: Keyframes, plan, how: str = "slerp", tracks=None) -> tuple[float, float]:
    """(largest angle (rad), largest arrow-length error) between what a viewer interpolates
    from ``kf`` (``how``: "slerp" or "componentwise") and what ``plan`` draws, over every
    frame of the plan, each at its time on the MP4's clock (``tracks``: ``_tracks(plan)``,
    if already made)."""
    shown = interpolate(kf, frame_clock(plan), how)
    tracks = _tracks(plan) if tracks is None else tracks
    ang, dlen = 0.0, 0.0
    x = np.array([1.0, 0.0, 0.0])
    for got, want in zip(shown, tracks):
        for key, val in want.items():
            if key == "body":
                ang = max(ang, float(np.max(R.misorientation(got["body"], val))))
            else:
                q, ln = got[key]
                ang = max(ang, float(np.max(R.angle_between(R.world_from_body(q, x), R.world_from_body(val[0], x)))))
                dlen = max(dlen, float(np.max(np.abs(ln - val[1]))))
    return ang, dlen
