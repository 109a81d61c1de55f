"""Where the glTF model puts its models, its camera and its lights: the video's two panels as
one camera's picture.

Pure NumPy (a planning module: no drawing library).  The video draws each model in a panel of
its own, seen from ``azimuth_deg``, ``elevation_deg`` at the distance ``camera.fit`` chooses
for a panel (W/n wide, H high).  One perspective camera sees n models side by side only if
each stands in its own direction from it, so here every model stands at that same distance
from the camera, at the video's elevation below it and turned aside by alpha_k (its centre at
the middle of its n-th of the frame); its node is turned about the vertical by the angle that
makes the camera see it exactly from the video's view direction.  The camera looks straight
ahead, pitched so that the content of both models is centred top to bottom, and its field of
view is the narrowest that holds every point any frame draws (the same points the video's
camera is fitted to) within ``MARGIN``.  Both models therefore appear the same size, at the
same height, each from the video's direction and at the video's perspective (the same
distance); what differs from two panels is only that a pitched pinhole camera leans the
verticals of a model off the frame's centre by a few degrees.

The lights are the video's (``camera.Camera.lights``: a key from the upper left, a fill from
the right, a head light), fixed to the camera as in the video: directional lights in the
camera's frame, their strengths in glTF's unit, lux.  Blender's importer reads lux / 683 as a
sun's W/m^2, and a sun of S W/m^2 lights a matte surface of albedo a facing it to a * S / pi
(measured here: albedo 0.5, S = 1 gives 0.165, 0.159 + the specular part); the video lights a
face to (its colour) x (the Lambert weight), so a light's intensity is weight x pi x 683 lux.

glTF frame: +y up, the camera looks along its -z.  spinviz's world (z up) maps to it by
(x, y, z) -> (x, z, -y) (each model's ``world`` node) after the model node's turn.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import rotations as R
from .camera import Camera
from .stage import content_points
from .style import AMBIENT, VIEW_ANGLE

__all__ = ["Framing", "frame_models", "gltf_from_spinviz", "LUX_PER_W_M2", "SUN_STRENGTH"]

MARGIN = 0.06                   # free border of the frame, in units of its half-width and half-height
LUX_PER_W_M2 = 683.0            # glTF lux per Blender W/m^2 (the importer's and exporter's "Standard" conversion)
# the video's lights (camera.Camera.lights) in the camera's frame (x right, y up, z towards the viewer):
# name, direction towards the light, the video's Lambert weight (camera.Camera.lights)
SUN_STRENGTH = (("key light", (-0.55, 0.75, 0.45), 0.55), ("fill light", (0.85, -0.15, 0.35), 0.22),
                ("head light", (0.0, 0.0, 1.0), 0.25))
AMBIENT_STRENGTH = AMBIENT      # the video's ambient term: glTF has no ambient light; Blender's world gives it


def gltf_from_spinviz(v) -> np.ndarray:
    """spinviz world vectors (..., 3), z up, in glTF's +y-up frame: (x, y, z) -> (x, z, -y)."""
    v = np.asarray(v, dtype=float)
    return np.stack([v[..., 0], v[..., 2], -v[..., 1]], axis=-1)


def _yaw(beta: float) -> np.ndarray:
    """(w, x, y, z) of a turn by ``beta`` rad about glTF's +y."""
    return np.array([math.cos(0.5 * beta), 0.0, math.sin(0.5 * beta), 0.0])


@dataclass
class Framing:
    """The layout of the glTF file's scene (glTF frame, lengths in dipole-arrow units).

    translations : per model (3,), its node's place; yaws : per model, its node's turn about
    +y (rad); camera_translation : (3,); camera_rotation : (4,) (w, x, y, z), the camera's
    pitch; yfov : vertical field of view (rad); aspect : width / height (the video's);
    distance : from the camera to each model's origin (the video's panel camera's); pitch :
    rad below the horizon; lights : [(name, rotation (w, x, y, z) in the camera's frame,
    intensity in lux)]; max_ndc : (2,) the largest |x|, |y| of any drawn point in the frame,
    normalized device coordinates (within 1 - MARGIN).
    """

    translations: list
    yaws: list
    camera_translation: np.ndarray
    camera_rotation: np.ndarray
    yfov: float
    aspect: float
    distance: float
    pitch: float
    lights: list
    max_ndc: np.ndarray

    def project(self, k: int, p_spinviz) -> np.ndarray:
        """Normalized device coordinates (N, 2) in the camera's picture of points (N, 3) of
        model k's spinviz world frame (x right, y up; the frame is [-1, 1] on both)."""
        p = R.world_from_body(_yaw(self.yaws[k]), gltf_from_spinviz(np.atleast_2d(p_spinviz)))
        p = p + np.asarray(self.translations[k]) - self.camera_translation
        right = R.world_from_body(self.camera_rotation, [1.0, 0.0, 0.0])
        up = R.world_from_body(self.camera_rotation, [0.0, 1.0, 0.0])
        back = R.world_from_body(self.camera_rotation, [0.0, 0.0, 1.0])
        depth = -(p @ back)
        t = math.tan(0.5 * self.yfov)
        return np.c_[(p @ right) / (depth * t * self.aspect), (p @ up) / (depth * t)]

    def view_direction(self, k: int) -> np.ndarray:
        """(3,) unit, glTF frame: from model k's origin towards the camera."""
        d = self.camera_translation - np.asarray(self.translations[k])
        return d / np.linalg.norm(d)


def _view(spec) -> np.ndarray:
    az, el = math.radians(spec.azimuth_deg), math.radians(spec.elevation_deg)
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


def frame_models(plan) -> Framing:
    """The camera, the models' places and the lights of ``plan``'s glTF scene.

    Parameters
    ----------
    plan : FramePlan
        Its spec gives the view (``azimuth_deg``, ``elevation_deg``, ``zoom``) and the frame
        (``size``); its content (``stage.content_points``) what must stay in the picture.

    Returns
    -------
    Framing
    """
    spec = plan.spec
    n = len(plan.panels)
    view = _view(spec)
    el = math.radians(spec.elevation_deg)
    W, H = spec.size
    aspect = W / H
    pts = np.unique(np.round(content_points(plan), 4), axis=0)
    # the video's panel camera: its distance sets the perspective
    D = Camera(view, aspect / n, pts, (MARGIN, MARGIN), spec.zoom).distance
    g_view = gltf_from_spinviz(view)
    centres = [(k + 0.5) / n * 2.0 - 1.0 for k in range(n)]          # each model's middle of its n-th, NDC x
    t = math.tan(math.radians(0.5 * VIEW_ANGLE))
    for _ in range(40):
        alphas = [math.atan(c * t * aspect) for c in centres]
        places = [D * np.array([math.sin(a) * math.cos(el), -math.sin(el), -math.cos(a) * math.cos(el)]) for a in alphas]
        yaws = [math.atan2(-p[0], -p[2]) - math.atan2(g_view[0], g_view[2]) for p in places]
        world = [R.world_from_body(_yaw(b), gltf_from_spinviz(pts)) + p for b, p in zip(yaws, places)]
        allp = np.vstack(world)
        pitch = _centred_pitch(allp)
        ndc = _ndc(allp, pitch, t, aspect)
        worst = np.max(np.abs(ndc), axis=0) / (1.0 - MARGIN)
        need = float(np.max(worst))
        if abs(need - 1.0) < 1e-5:
            break
        t *= need
    mid = np.mean(places, axis=0)
    cam_rot = np.array([math.cos(-0.5 * pitch), math.sin(-0.5 * pitch), 0.0, 0.0])
    lights = [(name, R.quat_between((0.0, 0.0, 1.0), np.asarray(d) / np.linalg.norm(d)), weight * math.pi * LUX_PER_W_M2)
              for name, d, weight in SUN_STRENGTH]
    return Framing(translations=[p - mid for p in places], yaws=yaws, camera_translation=-mid, camera_rotation=cam_rot,
                   yfov=2.0 * math.atan(t), aspect=aspect, distance=float(D), pitch=pitch, lights=lights,
                   max_ndc=np.max(np.abs(ndc), axis=0))


def _ndc(p, pitch: float, t: float, aspect: float) -> np.ndarray:
    """NDC (N, 2) of points p (N, 3) relative to a camera at the origin looking along -z,
    pitched down by ``pitch``, with tan(yfov / 2) = t."""
    c, s = math.cos(pitch), math.sin(pitch)
    depth = -p[:, 1] * s - p[:, 2] * c                     # along the forward axis (0, -sin, -cos)
    up = p[:, 1] * c - p[:, 2] * s                         # along (0, cos, -sin)
    return np.c_[p[:, 0] / (depth * t * aspect), up / (depth * t)]


def _centred_pitch(p) -> float:
    """The pitch (rad, down) that centres points p (N, 3) top to bottom: their highest and
    lowest NDC y equal and opposite (bisection; the content lies below the horizon)."""
    lo, hi = -0.5 * math.pi + 0.01, 0.5 * math.pi - 0.01

    def off(pitch):
        y = _ndc(p, pitch, 1.0, 1.0)[:, 1]
        return float(y.max() + y.min())

    for _ in range(48):              # to ~1e-14 rad
        mid = 0.5 * (lo + hi)
        if off(mid) > 0.0:          # content above the centre: the camera looks too far down
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)
