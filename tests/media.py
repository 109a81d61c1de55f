"""What the tests of the glTF model, the page, Blender and the notebook view share: a small
scene, the page's Content-Security-Policy check, and a reader of glTF files written apart
from spinviz's writer (node transforms composed from the file's own TRS, accessors read
from the buffer, quaternions interpolated as the viewers do)."""

from __future__ import annotations

import base64
import hashlib
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from spinviz import rotations as R

from tomlgen import value

ROOT = Path(__file__).resolve().parents[1]
VALIDATOR_DIR = ROOT / ".ci" / "node"
TITLE = 'Askew top <b>bold</b> & "quoted" </script>'


def write_scene(path: Path, title: str = TITLE, models=("reduced", "truncated"), **render) -> Path:
    """A dimensionless askew top, both models, shown in true spin (about 14 deg a frame)."""
    r = {"duration": 6.0, "fps": 30, "size": [640, 360], "spin": "true", "title": title,
         "show": ["body", "dipole", "omega", "L", "axes", "sphere", "hud"], **render}
    path.write_text(
        "[body]\ndelta = 0.3\nchi = 0.7\n"
        "[initial]\nomega = [0.0, 0.05, 0.3]\neuler_zxz = [0.0, 1.5707963267948966, 0.0]\n"
        f"[simulation]\nmodels = {json.dumps(list(models))}\nt_end = 300.0\nsamples = 400\n"
        "[render]\n" + "".join(f"{k} = {value(v) if not isinstance(v, list) else json.dumps(v)}\n" for k, v in r.items()))
    return path


def sha(text: str) -> str:
    return "'sha256-" + base64.b64encode(hashlib.sha256(text.encode()).digest()).decode() + "'"


def check_csp(text: str, size_limit: int = 2_000_000) -> str:
    """``text`` (a page) after checking: under 2 MB, every executable script inline and allowed
    by its sha256 in the Content-Security-Policy, which allows nothing else (no remote load,
    no inline handler, no style attribute), the style by its hash."""
    assert len(text.encode()) < size_limit
    csp = re.search(r'<meta http-equiv="Content-Security-Policy" content="([^"]+)">', text).group(1)
    assert "default-src 'none'" in csp and "unsafe" not in csp and "http" not in csp and "data:" not in csp
    scripts = re.findall(r"<script>(.*?)</script>", text, flags=re.S)
    assert len(scripts) == 2
    allowed = re.search(r"script-src ([^;]+)", csp).group(1).split()
    assert sorted(allowed) == sorted(sha(s) for s in scripts)
    style = re.search(r"<style>(.*?)</style>", text, flags=re.S).group(1)
    assert re.search(r"style-src ([^;]+)", csp).group(1).split() == [sha(style)]
    made = Markup()
    made.feed(text)
    assert made.handlers == [] and made.styled == []              # the policy would refuse a style attribute
    assert made.tags.isdisjoint({"img", "iframe", "object", "embed", "link", "base", "frame", "audio", "video"})
    return text


class Markup(HTMLParser):
    """The elements of a document, its inline event handlers (attributes on...) and its style
    attributes -- what is markup, not text."""

    def __init__(self):
        super().__init__()
        self.tags, self.handlers, self.styled = set(), [], []

    def handle_starttag(self, tag, attrs):
        self.tags.add(tag)
        self.handlers += [(tag, name) for name, _ in attrs if name.lower().startswith("on")]
        self.styled += [tag for name, _ in attrs if name.lower() == "style"]


def page_glb(text: str) -> bytes:
    """The model a page carries."""
    b64 = re.search(r'<script type="application/octet-stream" id="spinviz-glb">(.*?)</script>', text, flags=re.S).group(1)
    return base64.b64decode("".join(b64.split()))


# --- reading a glTF file -------------------------------------------------------------------------
def load(path):
    import pygltflib

    g = pygltflib.GLTF2().load(str(path))
    return g, g.binary_blob()


def accessor(g, blob: bytes, i: int) -> np.ndarray:
    a = g.accessors[i]
    v = g.bufferViews[a.bufferView]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[a.type]
    dtype = {5126: "<f4", 5123: "<u2", 5125: "<u4"}[a.componentType]
    data = np.frombuffer(blob, dtype=dtype, count=a.count * width, offset=v.byteOffset + (a.byteOffset or 0))
    return data.reshape(a.count, width) if width > 1 else data


def wxyz(q_xyzw) -> np.ndarray:
    q = np.asarray(q_xyzw, dtype=float)
    return np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def trs(node) -> np.ndarray:
    """A node's local 4x4 matrix from its translation, rotation and scale."""
    m = np.eye(4)
    if node.rotation is not None:
        m[:3, :3] = R.matrix_from_quat(wxyz(node.rotation))
    if node.scale is not None:
        m[:3, :3] = m[:3, :3] * np.asarray(node.scale)[None, :]
    if node.translation is not None:
        m[:3, 3] = node.translation
    return m


def world_matrices(g) -> dict[int, np.ndarray]:
    """Every node's world matrix (the file's static pose: no animation applied)."""
    out = {}

    def walk(i, parent):
        out[i] = parent @ trs(g.nodes[i])
        for c in g.nodes[i].children or []:
            walk(c, out[i])

    for i in g.scenes[g.scene].nodes:
        walk(i, np.eye(4))
    return out


def channel(g, blob, node_name: str, path: str):
    """(times, values) of the animation channel ``path`` of the node ``node_name``."""
    idx = next(i for i, n in enumerate(g.nodes) if n.name == node_name)
    anim = g.animations[0]
    ch = next(c for c in anim.channels if c.target.node == idx and c.target.path == path)
    s = anim.samplers[ch.sampler]
    assert s.interpolation == "LINEAR"
    return accessor(g, blob, s.input), accessor(g, blob, s.output)


def componentwise(t_keys, q_keys, t) -> np.ndarray:
    """What Blender's F-curves draw: each of the four numbers interpolated linearly, then normalized."""
    q = np.stack([np.interp(t, t_keys, q_keys[:, i]) for i in range(4)], axis=-1)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def validate(path: Path) -> dict:
    node = shutil.which("node")
    if node is None or not (VALIDATOR_DIR / "node_modules" / "gltf-validator").is_dir():
        pytest.fail("the Khronos glTF validator is missing: npm install --prefix .ci/node gltf-validator@2.0.0-dev.3.10 "
                    "(.ci/run does this)", pytrace=False)
    r = subprocess.run([node, str(ROOT / "tests" / "gltf_validate.js"), str(VALIDATOR_DIR), str(path)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)
