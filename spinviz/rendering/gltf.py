"""A frame plan as an animated glTF 2.0 model (.glb, or .gltf with its buffer embedded), for
Blender, three.js, ``<model-viewer>`` and the operating systems' 3-D viewers.

What the file holds (every length in units of the dipole arrow, which glTF reads as metres,
so a body is about a metre across):

* one node per model, side by side along glTF's +x (``SPACING`` apart), each with a child
  ``world`` node that turns spinviz's +z-up world frame into glTF's +y-up frame (a quarter
  turn about x); below it everything is in spinviz's world frame, as the video draws it;
* ``body``: the body's mesh (``meshes.body_part``, the video's colours) and, riding on it, the
  dipole arrow; its rotation channel holds the poses the video draws (``keyframes``);
* ``L`` and ``omega`` arrows: rotation channels turn +x along the vector, the shaft's scale
  and the head's translation channels give the arrow the video's length;
* the axes (thin rods) and the unit-sphere cage (lines) when the scene shows them; a
  camera at the video's view direction;
* ``extras``: the time map (the animation's clock is the video's: seconds of video), the
  physical time and video frame of every keyframe, the stated and measured interpolation
  errors, the spin mode and slowdown, the captions, and the bodies' physical scale.

Quaternions are (w, x, y, z) in spinviz and written in glTF's (x, y, z, w) order.  Colours are
the video's (sRGB) converted to glTF's linear base colours.  NumPy and pygltflib only (no
drawing library): a model is written without the render stack's VTK.
"""

from __future__ import annotations

import base64
import math

import numpy as np

from .. import units as U
from . import keyframes
from .captions import texts_of
from .meshes import Part, arrow_head, arrow_shaft, body_part, cylinder_z
from .stage import _circle_points, rotation_x_to
from .style import ARROW_COLORS, ARROWS, AXIS_LENGTH, BODY_RADIUS, COLORS, VIEW_ANGLE, body_color

__all__ = ["build", "to_bytes", "SPACING", "Z_UP_TO_Y_UP"]

SPACING = 3.2              # between the models' centres, glTF metres (dipole-arrow units)
AXIS_RADIUS = 0.008
Z_UP_TO_Y_UP = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))     # (x, y, z, w): -90 deg about x, spinviz z -> glTF y
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

    def material(self, rgb, name: str) -> int:
        """A matte material of the sRGB colour ``rgb`` (one per colour)."""
        key = tuple(round(float(c), 6) for c in rgb)
        if key not in self._materials:
            self.doc["materials"].append({"name": name, "pbrMetallicRoughness": {
                "baseColorFactor": linear_from_srgb(key) + [1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7}})
            self._materials[key] = len(self.doc["materials"]) - 1
        return self._materials[key]

    def mesh(self, part: Part, name: str) -> int:
        """A mesh of ``part``: one primitive per colour (triangles)."""
        prims = []
        tri_color = part.color[part.triangles[:, 0]]
        for rgb in np.unique(np.round(tri_color, 6), axis=0):
            tris = part.triangles[np.all(np.abs(tri_color - rgb) < 1e-6, axis=1)]
            used, inv = np.unique(tris.ravel(), return_inverse=True)
            pts = part.points[used]
            nrm = part.normals[used] / np.linalg.norm(part.normals[used], axis=1, keepdims=True)
            prims.append({"attributes": {"POSITION": self.accessor(pts, "VEC3", ARRAY_BUFFER, minmax=True),
                                         "NORMAL": self.accessor(nrm, "VEC3", ARRAY_BUFFER)},
                          "indices": self.accessor(inv.astype(np.uint16 if used.size < 65536 else np.uint32), "SCALAR",
                                                   ELEMENT_ARRAY_BUFFER),
                          "material": self.material(rgb, f"{name} colour"), "mode": 4})
        self.doc["meshes"].append({"name": name, "primitives": prims})
        return len(self.doc["meshes"]) - 1

    def lines(self, curves, rgb, name: str) -> int:
        """A mesh of polylines [(n, 3)] as one LINES primitive of one colour."""
        pts, idx, start = [], [], 0
        for c in curves:
            pts.append(c)
            k = np.arange(start, start + len(c) - 1)
            idx.append(np.c_[k, k + 1].ravel())
            start += len(c)
        pts = np.vstack(pts)
        prim = {"attributes": {"POSITION": self.accessor(pts, "VEC3", ARRAY_BUFFER, minmax=True)},
                "indices": self.accessor(np.concatenate(idx).astype(np.uint16 if len(pts) < 65536 else np.uint32),
                                         "SCALAR", ELEMENT_ARRAY_BUFFER),
                "material": self.material(rgb, f"{name} colour"), "mode": 1}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def node(self, **fields) -> int:
        """A node (glTF fields; None values left out); returns its index."""
        self.doc["nodes"].append({k: v for k, v in fields.items() if v is not None})
        return len(self.doc["nodes"]) - 1


def _rotate(part: Part, m) -> Part:
    return Part(part.points @ m.T, part.normals @ m.T, part.triangles, part.color, part.lit)


def _axes_part(color) -> Part:
    """The three axes as thin rods from the origin to ``AXIS_LENGTH`` along x, y, z."""
    rod = cylinder_z(AXIS_RADIUS, 0.5 * AXIS_LENGTH, 8, np.asarray(color))
    rod = Part(rod.points + [0.0, 0.0, 0.5 * AXIS_LENGTH], rod.normals, rod.triangles, rod.color, rod.lit)
    to_x = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])    # z -> x
    to_y = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])    # z -> y
    return Part.join([_rotate(rod, to_x), _rotate(rod, to_y), rod])


def _quat_from_matrix(m) -> np.ndarray:
    """(w, x, y, z) of a rotation matrix (3, 3) (Shepperd's method, one matrix)."""
    m = np.asarray(m, dtype=float)
    tr = np.trace(m)
    cands = [1.0 + tr, 1.0 + 2 * m[0, 0] - tr, 1.0 + 2 * m[1, 1] - tr, 1.0 + 2 * m[2, 2] - tr]
    k = int(np.argmax(cands))
    s = 2.0 * math.sqrt(cands[k])
    if k == 0:
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif k == 1:
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif k == 2:
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    return q / np.linalg.norm(q) * (1.0 if q[0] >= 0 else -1.0)


def view_gltf(spec) -> np.ndarray:
    """The video's view direction (towards the camera, ``azimuth_deg``, ``elevation_deg``) in
    glTF's frame: spinviz (x, y, z) -> glTF (x, z, -y)."""
    az, el = math.radians(spec.azimuth_deg), math.radians(spec.elevation_deg)
    v = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    return np.array([v[0], v[2], -v[1]])


def model_offsets(n: int) -> list[float]:
    """glTF x of each of ``n`` models' centres, side by side about 0."""
    return [(k - 0.5 * (n - 1)) * SPACING for k in range(n)]


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
    spec, show = plan.spec, set(plan.spec.show)
    w = _Writer()
    meshes = _meshes(w, plan)
    texts = texts_of(plan)
    times = w.accessor(kf.video_t.astype(np.float32), "SCALAR", minmax=True)
    samplers, channels = [], []

    def animate(node: int, path: str, values, kind: str):
        out = w.accessor(np.asarray(values, dtype=np.float32), kind)
        samplers.append({"input": times, "output": out, "interpolation": "LINEAR"})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})

    models = []
    for k, (panel, keys, x) in enumerate(zip(plan.panels, kf.panels, model_offsets(len(plan.panels)))):
        children = []
        if keys.q is not None:
            body_children = []
            if "dipole" in show:
                body_children.append(_arrow(w, meshes, "dipole", rotation_x_to(plan.d_body), ARROWS["dipole"][3]))
            body = w.node(name=f"{panel.model} body", mesh=meshes.get("body"), rotation=xyzw(keys.q[0]).tolist(),
                          children=body_children or None,
                          extras={"role": "body", "index": k, "physical_scale": physical_scale(plan)})
            animate(body, "rotation", xyzw(keys.q), "VEC4")
            children.append(body)
        for key, (q, length) in keys.arrows.items():
            node = _arrow(w, meshes, key, None, float(length[0]), q0=q[0], name=f"{panel.model} {key}")
            head_len = ARROWS[key][1]
            animate(node, "rotation", xyzw(q), "VEC4")
            shaft, head = w.doc["nodes"][node]["children"]
            animate(shaft, "scale", np.c_[length - head_len, np.ones_like(length), np.ones_like(length)], "VEC3")
            animate(head, "translation", np.c_[length - head_len, np.zeros_like(length), np.zeros_like(length)], "VEC3")
            children.append(node)
        for key in ("axes", "cage"):
            if key in meshes:
                children.append(w.node(name=f"{panel.model} {key}", mesh=meshes[key]))
        world = w.node(name=f"{panel.model} world (spinviz z up)", rotation=list(Z_UP_TO_Y_UP), children=children)
        heading, equations = texts.headings[k]
        models.append(w.node(name=panel.model, translation=[x, 0.0, 0.0], children=[world],
                             extras={"role": "model", "index": k, "model": panel.model, "heading": heading,
                                     "equations": equations, "subtitle": texts.subtitles[k]}))
    camera = _camera(w, spec, len(plan.panels))
    w.doc["scenes"].append({"name": texts.footer, "nodes": models + [camera], "extras": {"spinviz": _extras(plan, kf, texts)}})
    w.doc["animations"] = [{"name": "spin", "samplers": samplers, "channels": channels,
                            "extras": {"video_frame": kf.frame.tolist(), "physical_time": kf.sim_t.tolist(),
                                       "physical_time_unit": "s" if plan.units == "cgs" else "tau0"}}]
    w.doc["buffers"].append({"byteLength": len(w.blob)})
    for key in ("materials", "meshes"):
        if not w.doc[key]:
            del w.doc[key]
    return w.doc, bytes(w.blob)


def _meshes(w: _Writer, plan) -> dict:
    """The meshes ``plan`` shows, each once (both models use them): name -> mesh index."""
    show = set(plan.spec.show)
    colors = COLORS[plan.spec.background]
    body_from_shape = np.asarray(plan.shape.R_body_from_shape if plan.shape else np.eye(3), dtype=float)
    meshes = {}
    if "body" in show:
        meshes["body"] = w.mesh(body_part(plan.shape, body_color(plan.body_name), body_from_shape), "body")
    for key in ("dipole", "L", "omega"):
        if key in show:
            shaft, head_len, head_r, _ = ARROWS[key]
            color = np.asarray(ARROW_COLORS[key])
            meshes[key + "_shaft"] = w.mesh(arrow_shaft(shaft, color), f"{key} arrow shaft")
            meshes[key + "_head"] = w.mesh(arrow_head(head_len, head_r, color), f"{key} arrow head")
    if "axes" in show:
        meshes["axes"] = w.mesh(_axes_part(colors["axes"]), "axes")
    if "sphere" in show:
        meshes["cage"] = w.lines(list(_circle_points()), colors["sphere"], "unit sphere")
    return meshes


def _arrow(w: _Writer, meshes, key: str, rot3, length: float, q0=None, name: str | None = None) -> int:
    """An arrow node: its rotation (a matrix ``rot3`` or the quaternion ``q0``, (w, x, y, z)),
    a shaft child scaled to ``length`` minus the head and a head child moved to its end."""
    head_len = ARROWS[key][1]
    shaft = w.node(name=f"{name or key} shaft", mesh=meshes[key + "_shaft"], scale=[length - head_len, 1.0, 1.0])
    head = w.node(name=f"{name or key} head", mesh=meshes[key + "_head"], translation=[length - head_len, 0.0, 0.0])
    q = q0 if q0 is not None else _quat_from_matrix(rot3)
    return w.node(name=name or f"{key} arrow", rotation=xyzw(q).tolist(), children=[shaft, head])


def _camera(w: _Writer, spec, n: int) -> int:
    """A perspective camera looking at the models from the video's view direction."""
    aspect = spec.size[0] / spec.size[1]
    yfov = math.radians(VIEW_ANGLE)
    half_w = 0.5 * (n - 1) * SPACING + 1.7
    dist = max(half_w / (math.tan(0.5 * yfov) * aspect), 1.7 / math.tan(0.5 * yfov)) * 1.05
    back = view_gltf(spec)
    yaw, pitch = math.atan2(back[0], back[2]), -math.asin(back[1])
    q = _mul((math.cos(0.5 * yaw), 0.0, math.sin(0.5 * yaw), 0.0), (math.cos(0.5 * pitch), math.sin(0.5 * pitch), 0.0, 0.0))
    w.doc.setdefault("cameras", []).append({"name": "the video's view", "type": "perspective",
                                            "perspective": {"yfov": yfov, "aspectRatio": aspect, "znear": 0.05,
                                                            "zfar": 100.0}})
    return w.node(name="camera (the video's view)", camera=len(w.doc["cameras"]) - 1,
                  translation=(back * dist).tolist(), rotation=xyzw(q).tolist())


def _mul(a, b):
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return np.array([a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3, a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
                     a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1, a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0])


def _extras(plan, kf, texts) -> dict:
    """What the file says about itself: clock, time map, spin, errors, captions."""
    spec = plan.spec
    ts = plan.time_scale
    out = {
        "about": "spinviz: rotation of a dipolar nanocrystal under the radiation-reaction torque",
        "quaternions": "glTF (x, y, z, w); the body's rotation maps body-frame vectors to spinviz's world frame",
        "frame": "each model's 'world' node turns spinviz's +z-up world frame into glTF's +y-up frame",
        "lengths": "units of the dipole arrow (its tip on the unit sphere), read as metres",
        "clock": {"seconds": "video seconds, the same clock as the MP4", "duration_s": spec.duration, "fps": spec.fps,
                  "video_frames": plan.frames, "time_map": spec.time_map,
                  "physical_time_end": plan.t_end, "physical_time_unit": "s" if plan.units == "cgs" else "tau0",
                  "map": ("t = t_end * v / duration" if spec.time_map == "linear"
                          else "t = knee * ((1 + t_end / knee) ** (v / duration) - 1)")},
        "keyframes": {"count": kf.count, "tolerance_deg": math.degrees(kf.tolerance),
                      "max_error_deg": math.degrees(kf.max_error), "max_length_error_m": kf.max_length_error,
                      "max_step_deg": math.degrees(kf.max_step),
                      "max_step_limit_deg": math.degrees(keyframes.MAX_STEP),
                      "what": "a subset of the video's frames: at each the exact pose the video draws; the viewer's "
                              "LINEAR interpolation stays within tolerance_deg of every frame in between"},
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
