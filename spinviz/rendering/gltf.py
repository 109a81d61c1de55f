"""A frame plan as an animated glTF 2.0 model (.glb, or .gltf with its buffer embedded), for
Blender, three.js, ``<model-viewer>`` and the operating systems' 3-D viewers.

What the file holds (every length in units of the dipole arrow, which glTF reads as metres,
so a body is about a metre across):

* one node per model, placed and turned about the vertical by ``framing`` so that the file's
  camera sees each from the video's view direction, side by side as the video's panels; each
  with a child ``world`` node that turns spinviz's +z-up world frame into glTF's +y-up frame
  (a quarter turn about x); below it everything is in spinviz's world frame, as the video
  draws it;
* ``body``: the body's mesh (``meshes.body_part``, the video's colours) and, riding on it, the
  dipole arrow; its rotation channel holds the poses the video draws (``keyframes``);
* ``L`` and ``omega`` arrows: rotation channels turn +x along the vector, the shaft's scale
  and the head's translation channels give the arrow the video's length;
* the axes and the unit-sphere cage, when the scene shows them, as thin tubes (geometry a
  renderer draws, unlit in the video's line colours: ``KHR_materials_unlit``);
* the camera (the video's view, ``framing``) and, riding on it, the video's three lights
  (``KHR_lights_punctual``, directional);
* ``extras``: the clock (the MP4's: frame f at f / fps s, the animation's time of every
  keyframe exactly), the physical time and video frame of every keyframe, the stated and
  measured interpolation errors (slerp and component-wise), the spin mode and slowdown, the
  captions, the bodies' physical scale, and what Blender needs to play it whole.

Every node, mesh and material is named after its model ("reduced body", "truncated L arrow"),
so names stay unique; the two models' meshes share their geometry (one set of accessors).
Quaternions are (w, x, y, z) in spinviz and written in glTF's (x, y, z, w) order.  Colours are
the video's (sRGB) converted to glTF's linear base colours.  NumPy and pygltflib only (no
drawing library): a model is written without the render stack's VTK.
"""

from __future__ import annotations

import base64
import math

import numpy as np

from .. import rotations as R
from .. import units as U
from . import keyframes
from .captions import texts_of
from .framing import AMBIENT_STRENGTH, LUX_PER_W_M2, frame_models
from .meshes import Part, arrow_head, arrow_shaft, body_part
from .stage import _circle_points, rotation_x_to
from .style import ARROW_COLORS, ARROWS, AXIS_LENGTH, BODY_RADIUS, COLORS, body_color

__all__ = ["build", "to_bytes", "Z_UP_TO_Y_UP", "CAMERA_NAME", "model_prefixes", "BLENDER_SCRIPT_SUFFIX"]

LINE_RADIUS = 0.005        # the axes' and the cage's tubes: about a pixel of the video's 720-line frame
TUBE_SIDES = 4
CAGE_SEGMENTS = 72         # per circle of the cage (the video's lines have 144)
Z_UP_TO_Y_UP = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))     # (x, y, z, w): -90 deg about x, spinviz z -> glTF y
CAMERA_NAME = "camera (the video's view)"
BLENDER_SCRIPT_SUFFIX = "_blender.py"     # X.glb -> X_blender.py beside it (``blender.script``)
ARROW_WORDS = {"dipole": "dipole", "L": "L", "omega": "omega"}
FLOAT, UINT16, UINT32 = 5126, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


def linear_from_srgb(c) -> list[float]:
    """An sRGB colour (floats in [0, 1]) as glTF's linear base colour factor (IEC 61966-2-1)."""
    c = np.asarray(c, dtype=float)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).tolist()


def xyzw(q) -> np.ndarray:
    """Scalar-first (w, x, y, z) quaternions, shape (..., 4), in glTF's (x, y, z, w) order."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


class _Writer:
    """The glTF document as a dict, and its one binary buffer."""

    def __init__(self):
        self.blob = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "spinviz"}, "scene": 0, "scenes": [], "nodes": [],
                    "meshes": [], "materials": [], "accessors": [], "bufferViews": [], "buffers": []}
        self._materials = {}
        self.extensions = set()

    def accessor(self, data, kind: str, target: int | None = None, minmax: bool = False) -> int:
        """An accessor for ``data`` (float32 unless integer), in a buffer view of its own."""
        data = np.ascontiguousarray(data)
        ctype = FLOAT if data.dtype.kind == "f" else (UINT16 if data.dtype == np.uint16 else UINT32)
        raw = data.astype(np.float32 if ctype == FLOAT else data.dtype).tobytes()
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.blob += raw
        self.doc["bufferViews"].append(view)
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": ctype,
               "count": int(data.shape[0]), "type": kind}
        if minmax:
            flat = data.astype(np.float32).reshape(data.shape[0], -1)
            acc["min"] = [float(x) for x in flat.min(axis=0)]
            acc["max"] = [float(x) for x in flat.max(axis=0)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name: str, rgb, unlit: bool = False) -> int:
        """The material ``name`` (one per name): matte, of the sRGB colour ``rgb``; ``unlit``
        draws the colour whatever the light (``KHR_materials_unlit``: the video's lines)."""
        if name not in self._materials:
            mat = {"name": name, "pbrMetallicRoughness": {
                "baseColorFactor": linear_from_srgb(rgb) + [1.0], "metallicFactor": 0.0,
                "roughnessFactor": 1.0 if unlit else 0.7}}
            if unlit:                       # the tubes are seen from inside where they cross
                mat["extensions"] = {"KHR_materials_unlit": {}}
                mat["doubleSided"] = True
                self.extensions.add("KHR_materials_unlit")
            self.doc["materials"].append(mat)
            self._materials[name] = len(self.doc["materials"]) - 1
        return self._materials[name]

    def geometry(self, part: Part, lit: bool = True) -> list:
        """The accessors of ``part``, one primitive per colour (triangles): [(attributes,
        indices, rgb)].  Meshes of both models reuse them; ``lit`` False leaves the normals out."""
        out = []
        tri_color = part.color[part.triangles[:, 0]]
        for rgb in np.unique(np.round(tri_color, 6), axis=0):
            tris = part.triangles[np.all(np.abs(tri_color - rgb) < 1e-6, axis=1)]
            used, inv = np.unique(tris.ravel(), return_inverse=True)
            attrs = {"POSITION": self.accessor(part.points[used], "VEC3", ARRAY_BUFFER, minmax=True)}
            if lit:
                nrm = part.normals[used] / np.linalg.norm(part.normals[used], axis=1, keepdims=True)
                attrs["NORMAL"] = self.accessor(nrm, "VEC3", ARRAY_BUFFER)
            idx = self.accessor(inv.astype(np.uint16 if used.size < 65536 else np.uint32), "SCALAR", ELEMENT_ARRAY_BUFFER)
            out.append((attrs, idx, tuple(float(c) for c in rgb)))
        return out

    def mesh(self, name: str, geometry: list, materials: list) -> int:
        """A mesh named ``name`` of ``geometry``'s primitives, each with its material index."""
        prims = [{"attributes": dict(attrs), "indices": idx, "material": m, "mode": 4}
                 for (attrs, idx, _), m in zip(geometry, materials)]
        self.doc["meshes"].append({"name": name, "primitives": prims})
        return len(self.doc["meshes"]) - 1

    def node(self, **fields) -> int:
        """A node (glTF fields; None values left out); returns its index."""
        self.doc["nodes"].append({k: v for k, v in fields.items() if v is not None})
        return len(self.doc["nodes"]) - 1


def _axes_part(color) -> Part:
    """The three axes as thin rods from the origin to ``AXIS_LENGTH`` along x, y, z."""
    parts = []
    for i in range(3):
        e = np.zeros(3)
        e[i] = AXIS_LENGTH
        parts.append(_tube(np.array([np.zeros(3), e]), color, closed=False))
    return Part.join(parts)


def _tube(curve, color, closed: bool) -> Part:
    """A thin tube of radius ``LINE_RADIUS`` and ``TUBE_SIDES`` sides along the polyline
    ``curve`` (n, 3) (closed: its last point joins its first), for an unlit material (its
    normals are the outward radial directions)."""
    c = np.asarray(curve, dtype=float)
    n = c.shape[0]
    if closed:
        tangent = np.roll(c, -1, axis=0) - np.roll(c, 1, axis=0)
        radial = c - c.mean(axis=0)
    else:
        tangent = np.repeat((c[-1] - c[0])[None, :], n, axis=0)
        ref = np.eye(3)[int(np.argmin(np.abs(tangent[0])))]
        radial = np.repeat(np.cross(tangent[0], ref)[None, :], n, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    radial -= np.sum(radial * tangent, axis=1, keepdims=True) * tangent
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    binormal = np.cross(tangent, radial)
    ang = 2.0 * math.pi * np.arange(TUBE_SIDES) / TUBE_SIDES
    ring = np.cos(ang)[None, :, None] * radial[:, None, :] + np.sin(ang)[None, :, None] * binormal[:, None, :]
    pts = (c[:, None, :] + LINE_RADIUS * ring).reshape(-1, 3)
    segs = n if closed else n - 1
    i = np.arange(segs)[:, None]
    j = np.arange(TUBE_SIDES)[None, :]
    a, b = i * TUBE_SIDES + j, i * TUBE_SIDES + (j + 1) % TUBE_SIDES
    a2, b2 = ((i + 1) % n) * TUBE_SIDES + j, ((i + 1) % n) * TUBE_SIDES + (j + 1) % TUBE_SIDES
    tris = np.concatenate([np.stack([a, b, b2], -1).reshape(-1, 3), np.stack([a, b2, a2], -1).reshape(-1, 3)])
    return Part(pts, ring.reshape(-1, 3), tris, np.tile(np.asarray(color, dtype=float), (pts.shape[0], 1)),
                np.zeros(pts.shape[0], bool))


def _cage_part(color) -> Part:
    """The unit-sphere cage (latitudes every 30 deg and meridians, ``CAGE_SEGMENTS`` segments
    each) as thin closed tubes."""
    step = 144 // CAGE_SEGMENTS
    return Part.join([_tube(c[:-1:step], color, closed=True) for c in _circle_points()])


def model_prefixes(plan) -> list[str]:
    """The name of each model in the file: its model ("reduced"), or with "left" / "right"
    when both panels show the same model -- so that every node, mesh and material name is
    unique."""
    models = [p.model for p in plan.panels]
    if len(set(models)) == len(models):
        return models
    return [f"{m} {side}" for m, side in zip(models, ("left", "right"))]


def physical_scale(plan) -> dict:
    """How the drawn body relates to the real one: its shape and dimensions (m), and the real
    metres per glTF metre (CGS scenes with a known shape), or that the size is arbitrary."""
    shape = plan.shape
    if shape is None:
        return {"shape": "unknown (a ball of radius 0.3 stands in)"}
    dims = np.asarray(shape.dims, dtype=float)
    if shape.kind == "rod":
        k = BODY_RADIUS / math.hypot(0.5 * dims[0], 0.5 * dims[1])
        names = ["length", "diameter"]
    else:
        k = BODY_RADIUS / (0.5 * float(np.linalg.norm(np.maximum(dims, 0.125 * dims.max()))))
        names = ["a", "b", "c"]
    out = {"shape": shape.kind, "label": shape.label, "drawn_bounding_radius_m": BODY_RADIUS,
           "note": "a thin rod is drawn at least 1/6 of its length thick and a flat box at least 1/8 as thick as "
                   "long, so that their spin shows; lengths otherwise to scale"}
    if plan.units == "cgs":
        out["dims_m"] = {n: float(d * U.M_PER_CM) for n, d in zip(names, dims)}
        out["real_m_per_gltf_m"] = float(U.M_PER_CM / k)
    else:
        out["dims"] = {n: float(d) for n, d in zip(names, dims)}
        out["note_units"] = "dimensionless scene: the dimensions are relative"
    return out


def build(plan, kf) -> tuple[dict, bytes]:
    """The glTF document (dict) and its binary buffer for ``plan`` animated by ``kf``.

    Parameters
    ----------
    plan : FramePlan
        What the video shows (spec, panels, shape, captions).
    kf : keyframes.Keyframes
        The keyframes (subset of the plan's frames) and their values.

    Returns
    -------
    (dict, bytes)
        The JSON document (its one buffer without a URI yet) and the buffer's bytes.
    """
    w = _Writer()
    geometry = _geometry(w, plan)
    texts = texts_of(plan)
    framing = frame_models(plan)
    times = w.accessor(kf.video_t.astype(np.float32), "SCALAR", minmax=True)
    samplers, channels = [], []

    def animate(node: int, path: str, values, kind: str):
        out = w.accessor(np.asarray(values, dtype=np.float32), kind)
        samplers.append({"input": times, "output": out, "interpolation": "LINEAR"})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})

    models = [_model(w, plan, k, keys, prefix, geometry, framing, texts, animate)
              for k, (keys, prefix) in enumerate(zip(kf.panels, model_prefixes(plan)))]
    camera = _camera(w, framing)
    w.doc["scenes"].append({"name": texts.footer, "nodes": models + [camera],
                            "extras": {"spinviz": _extras(plan, kf, texts, framing)}})
    w.doc["animations"] = [{"name": "spin", "samplers": samplers, "channels": channels,
                            "extras": {"video_frame": kf.frame.tolist(), "frame_position": kf.position.tolist(),
                                       "physical_time": kf.sim_t.tolist(),
                                       "physical_time_unit": "s" if plan.units == "cgs" else "tau0"}}]
    w.doc["buffers"].append({"byteLength": len(w.blob)})
    w.extensions.add("KHR_lights_punctual")
    w.doc["extensionsUsed"] = sorted(w.extensions)
    for key in ("materials", "meshes"):
        if not w.doc[key]:
            del w.doc[key]
    return w.doc, bytes(w.blob)


def _model(w: _Writer, plan, k: int, keys, prefix: str, geometry: dict, framing, texts, animate) -> int:
    """Model k's node tree (placed and turned by ``framing``), its meshes and its animation
    channels (``animate(node, path, values, kind)``); returns the model node."""
    show = set(plan.spec.show)
    panel = plan.panels[k]
    meshes = _model_meshes(w, geometry, prefix, plan)
    children = []
    if keys.q is not None:
        body_children = []
        if "dipole" in show:
            body_children.append(_arrow(w, meshes, prefix, k, "dipole", R.quat_from_matrix(rotation_x_to(plan.d_body)),
                                        ARROWS["dipole"][3]))
        body = w.node(name=f"{prefix} body", mesh=meshes.get("body"), rotation=xyzw(keys.q[0]).tolist(),
                      children=body_children or None,
                      extras={"role": "body", "index": k, "physical_scale": physical_scale(plan)})
        animate(body, "rotation", xyzw(keys.q), "VEC4")
        children.append(body)
    for key, (q, length) in keys.arrows.items():
        node = _arrow(w, meshes, prefix, k, key, q[0], float(length[0]))
        head_len = ARROWS[key][1]
        animate(node, "rotation", xyzw(q), "VEC4")
        shaft, head = w.doc["nodes"][node]["children"]
        animate(shaft, "scale", np.c_[length - head_len, np.ones_like(length), np.ones_like(length)], "VEC3")
        animate(head, "translation", np.c_[length - head_len, np.zeros_like(length), np.zeros_like(length)], "VEC3")
        children.append(node)
    for key, label in (("axes", "axes"), ("cage", "unit sphere")):
        if key in meshes:
            children.append(w.node(name=f"{prefix} {label}", mesh=meshes[key]))
    world = w.node(name=f"{prefix} world (spinviz z up)", rotation=list(Z_UP_TO_Y_UP), children=children,
                   extras={"role": "world", "index": k})
    heading, equations = texts.headings[k]
    yaw = framing.yaws[k]
    return w.node(name=prefix, translation=[float(x) for x in framing.translations[k]],
                  rotation=[0.0, math.sin(0.5 * yaw), 0.0, math.cos(0.5 * yaw)], children=[world],
                  extras={"role": "model", "index": k, "model": panel.model, "heading": heading,
                          "equations": equations, "subtitle": texts.subtitles[k], "yaw_deg": math.degrees(yaw)})


def _geometry(w: _Writer, plan) -> dict:
    """The geometry ``plan`` shows, written once (both models' meshes use it): part -> the
    ``_Writer.geometry`` primitives and each one's role ("body", "body dark half", ...)."""
    show = set(plan.spec.show)
    colors = COLORS[plan.spec.background]
    body_from_shape = np.asarray(plan.shape.R_body_from_shape if plan.shape else np.eye(3), dtype=float)
    out = {}
    if "body" in show:
        base = body_color(plan.body_name)
        second = "body dark half" if plan.shape is not None and plan.shape.kind == "rod" else "body edges"
        geo = w.geometry(body_part(plan.shape, base, body_from_shape))
        out["body"] = (geo, ["body" if np.allclose(rgb, base, atol=1e-6) else second for *_, rgb in geo], False)
    for key in ("dipole", "L", "omega"):
        if key in show:
            shaft, head_len, head_r, _ = ARROWS[key]
            color = np.asarray(ARROW_COLORS[key])
            role = f"{ARROW_WORDS[key]} arrow"
            out[key + "_shaft"] = (w.geometry(arrow_shaft(shaft, color)), [role], False)
            out[key + "_head"] = (w.geometry(arrow_head(head_len, head_r, color)), [role], False)
    if "axes" in show:
        out["axes"] = (w.geometry(_axes_part(colors["axes"]), lit=False), ["axes"], True)
    if "sphere" in show:
        out["cage"] = (w.geometry(_cage_part(colors["sphere"]), lit=False), ["unit sphere"], True)
    return out


_MESH_NAMES = {"body": "body", "axes": "axes", "cage": "unit sphere"}


def _model_meshes(w: _Writer, geometry: dict, prefix: str, plan) -> dict:
    """One model's meshes and materials, named "<prefix> <part>", on the shared geometry:
    part -> mesh index."""
    out = {}
    for part, (geo, roles, unlit) in geometry.items():
        mats = [w.material(f"{prefix} {role}", rgb, unlit) for (*_, rgb), role in zip(geo, roles)]
        if part in _MESH_NAMES:
            name = _MESH_NAMES[part]
        else:
            key, piece = part.rsplit("_", 1)
            name = f"{ARROW_WORDS[key]} arrow {piece}"
        out[part] = w.mesh(f"{prefix} {name}", geo, mats)
    return out


def _arrow(w: _Writer, meshes, prefix: str, k: int, key: str, q, length: float) -> int:
    """An arrow node "<prefix> <key> arrow": its rotation ``q`` (w, x, y, z), a shaft child
    scaled to ``length`` minus the head and a head child moved to its end."""
    head_len = ARROWS[key][1]
    word = ARROW_WORDS[key]
    shaft = w.node(name=f"{prefix} {word} shaft", mesh=meshes[key + "_shaft"], scale=[length - head_len, 1.0, 1.0])
    head = w.node(name=f"{prefix} {word} head", mesh=meshes[key + "_head"], translation=[length - head_len, 0.0, 0.0])
    return w.node(name=f"{prefix} {word} arrow", rotation=xyzw(q).tolist(), children=[shaft, head],
                  extras={"role": "arrow", "key": key, "index": k, "head_length": head_len})


def _camera(w: _Writer, framing) -> int:
    """The camera (``framing``: the video's view of every model) and, riding on it, the
    video's lights (``KHR_lights_punctual``, directional, in lux)."""
    w.doc.setdefault("cameras", []).append({"name": CAMERA_NAME, "type": "perspective",
                                            "perspective": {"yfov": framing.yfov, "aspectRatio": framing.aspect,
                                                            "znear": 0.05, "zfar": 20.0 * framing.distance}})
    lights = w.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
    children = []
    for name, q, lux in framing.lights:
        lights.append({"name": name, "type": "directional", "color": [1.0, 1.0, 1.0], "intensity": lux})
        children.append(w.node(name=name, rotation=xyzw(q).tolist(),
                               extensions={"KHR_lights_punctual": {"light": len(lights) - 1}}))
    return w.node(name=CAMERA_NAME, camera=len(w.doc["cameras"]) - 1,
                  translation=[float(x) for x in framing.camera_translation],
                  rotation=xyzw(framing.camera_rotation).tolist(), children=children)


def physical_map(spec, frames: int) -> str:
    """The physical time of video frame f, as the extras state it (t_end, knee: the clock's)."""
    if spec.time_map == "linear":
        return f"t = t_end * f / {frames - 1}"
    return f"t = knee * ((1 + t_end / knee) ** (f / {frames - 1}) - 1)"


def _extras(plan, kf, texts, framing) -> dict:
    """What the file says about itself: clock, time map, spin, errors, captions, camera, lights,
    and how Blender plays it whole."""
    spec = plan.spec
    ts = plan.time_scale
    F = plan.frames
    out = {
        "about": "spinviz: rotation of a dipolar nanocrystal under the radiation-reaction torque",
        "quaternions": "glTF (x, y, z, w); the body's rotation maps body-frame vectors to spinviz's world frame",
        "frame": "each model's 'world' node turns spinviz's +z-up world frame into glTF's +y-up frame; the model node "
                 "above it places the model and turns it about the vertical so that the camera sees it from the "
                 "video's direction",
        "lengths": "units of the dipole arrow (its tip on the unit sphere), read as metres",
        "clock": {"seconds": "the MP4's clock: video frame f is shown at f / fps seconds, and a keyframe of frame f "
                             "is at exactly that time (float32)",
                  "fps": spec.fps, "video_frames": F, "last_frame_s": (F - 1) / spec.fps,
                  "time_map": spec.time_map, "physical_time_end": plan.t_end,
                  "physical_time_unit": "s" if plan.units == "cgs" else "tau0", "map": physical_map(spec, F)},
        "keyframes": {"count": kf.count, "tolerance_deg": math.degrees(kf.tolerance),
                      "max_error_deg": math.degrees(kf.max_error),
                      "max_error_componentwise_deg": math.degrees(kf.max_error_componentwise),
                      "max_length_error_m": kf.max_length_error,
                      "max_step_deg": math.degrees(kf.max_step),
                      "max_step_limit_deg": math.degrees(keyframes.MAX_STEP),
                      "what": "a subset of the video's frames: at each the exact pose the video draws; between them a "
                              "viewer's slerp (LINEAR) and a component-wise interpolation (Blender's F-curves) both "
                              "stay within tolerance_deg of every frame"},
        "camera": {"name": CAMERA_NAME, "yfov_deg": math.degrees(framing.yfov), "aspect": framing.aspect,
                   "distance_m": framing.distance, "pitch_deg": math.degrees(framing.pitch),
                   "view": "each model seen from the video's azimuth_deg and elevation_deg at the video's panel "
                           "distance, side by side as the video's panels",
                   "azimuth_deg": spec.azimuth_deg, "elevation_deg": spec.elevation_deg},
        "lights": {"what": "the video's key, fill and head lights, directional, riding on the camera; intensities in "
                           "lux (Blender's default import reads lux / 683 as a sun's W/m^2); a viewer without exposure "
                           "control (three.js) wants them divided by 683",
                   "ambient": AMBIENT_STRENGTH, "lux_per_w_m2": LUX_PER_W_M2},
        "blender": {"fps": spec.fps, "frame_start": 0, "frame_end": F - 1, "camera": CAMERA_NAME,
                    "resolution": list(spec.size),
                    "by_hand": f"set the scene's frame rate to {spec.fps} fps before File > Import > glTF 2.0 (the "
                               f"importer places a key at its time x the scene's rate), the frame range to 0-{F - 1}, "
                               f"and make '{CAMERA_NAME}' the scene's camera",
                    "script": "spinviz writes NAME" + BLENDER_SCRIPT_SUFFIX + " beside NAME.glb: it does all this"},
        "spin_mode": plan.spin_mode, "notes": list(plan.notes), "title": texts.footer,
        "time_scale": {"symbol": ts[0], "value": ts[1]} if ts else None, "scale_text": texts.scale,
        "units": plan.units, "body": plan.body_name,
    }
    if spec.time_map == "log":
        out["clock"]["knee"] = spec.knee(plan.t_end)
    if plan.slowdown is not None:
        out["slowdown_at_keyframes"] = [float(plan.slowdown[f]) if f >= 0 else None for f in kf.frame]
    return out


def to_bytes(doc: dict, blob: bytes, binary: bool = True) -> bytes:
    """The file's bytes: GLB (binary: JSON chunk and BIN chunk) or a .gltf whose buffer is
    embedded as a base64 data URI (one self-contained text file).  Written with pygltflib."""
    import pygltflib

    doc = dict(doc)
    doc["buffers"] = [dict(doc["buffers"][0])]
    if binary:
        g = pygltflib.GLTF2.from_dict(doc)
        g.set_binary_blob(blob)
        return b"".join(g.save_to_bytes())
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    g = pygltflib.GLTF2.from_dict(doc)
    return g.gltf_to_json().encode("utf-8")
