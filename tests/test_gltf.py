"""The animated glTF model (.glb, .gltf) and the page that shows it (.html).

Faithful to the video: the keyframes are the video's own frames, at which the file holds the
pose the video draws (render_frame's, to 1e-6 rad after float32); between them the viewers'
slerp stays within the stated angle of every frame.  The .glb passes the Khronos validator
(npm gltf-validator, installed by .ci/run); the page, opened by headless Chromium from a
file with no network, draws both crystals and, with its slider set, shows the run's pose.
"""

from __future__ import annotations

import base64
import hashlib
import json
import math
import os
import re
import shutil
import subprocess
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import spinviz
from spinviz import pipeline
from spinviz import rotations as R
from spinviz.commands import main
from spinviz.rendering import gltf, keyframes
from spinviz.rendering.stage import arrow_length
from spinviz.rendering.style import ARROWS

from tomlgen import value

ROOT = Path(__file__).resolve().parents[1]
VALIDATOR_DIR = ROOT / ".ci" / "node"
TITLE = 'Askew top <b>bold</b> & "quoted" </script>'


def write_scene(path: Path, title: str = TITLE, **render) -> Path:
    """A dimensionless askew top, both models, shown in true spin (about 14 deg a frame)."""
    r = {"duration": 6.0, "fps": 30, "size": [640, 360], "spin": "true", "title": title,
         "show": ["body", "dipole", "omega", "L", "axes", "sphere", "hud"], **render}
    path.write_text(
        "[body]\ndelta = 0.3\nchi = 0.7\n"
        "[initial]\nomega = [0.0, 0.05, 0.3]\neuler_zxz = [0.0, 1.5707963267948966, 0.0]\n"
        "[simulation]\nmodels = [\"reduced\", \"truncated\"]\nt_end = 300.0\nsamples = 400\n"
        "[render]\n" + "".join(f"{k} = {value(v) if not isinstance(v, list) else json.dumps(v)}\n" for k, v in r.items()))
    return path


@pytest.fixture(scope="module")
def scene(tmp_path_factory) -> Path:
    return write_scene(tmp_path_factory.mktemp("gltf") / "askew_true.toml")


@pytest.fixture(scope="module")
def plan(scene):
    return pipeline.plan(str(scene))


@pytest.fixture(scope="module")
def glb(scene, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("glb") / "askew.glb"
    res = spinviz.render(str(scene), out=str(out))
    assert res.path == str(out) and res.format == "glb" and res.bytes == out.stat().st_size
    return out


# --- keyframes ------------------------------------------------------------------------------
@pytest.mark.slow
def test_keyframes_are_video_frames_within_the_stated_angle(plan):
    """Every keyframe is one of the video's frames holding exactly its pose; slerp between them
    (rotations.slerp_series, an implementation apart from the chooser's) stays within the
    tolerance at every frame, for the body and the L and Omega arrows; consecutive keyframes
    are sign-aligned and under a quarter turn apart; fewer keyframes than frames, more for a
    tighter tolerance."""
    assert plan.spin_mode == "true" and plan.frames == 180
    kf = keyframes.choose(plan)
    f = kf.frame
    assert f[0] == 0 and f[-1] == plan.frames - 1 and np.all(np.diff(f) > 0)
    assert 10 < kf.count < plan.frames
    tol = math.radians(keyframes.TOLERANCE_DEG)
    x = np.array([1.0, 0.0, 0.0])
    for panel, keys in zip(plan.panels, kf.panels):
        assert np.max(R.misorientation(keys.q, panel.q[f])) < 1e-12
        between = R.slerp_series(kf.video_t, keys.q, plan.video_t)
        err = R.misorientation(between, panel.q)
        assert np.max(err) <= tol + 1e-12 and np.max(err) > 0.3 * tol         # used, not wasted
        for q in (keys.q, *(a[0] for a in keys.arrows.values())):
            assert np.all(np.sum(q[1:] * q[:-1], axis=1) >= 0.0)
            assert np.max(R.misorientation(q[1:], q[:-1])) < keyframes.MAX_STEP < 0.5 * math.pi
        for key, vec in (("L", panel.L_world), ("omega", panel.omega_world)):
            qa, ln = keys.arrows[key]
            assert np.max(R.angle_between(R.world_from_body(qa, x), vec[f])) < 1e-12
            direction = R.world_from_body(R.slerp_series(kf.video_t, qa, plan.video_t), x)
            assert np.max(R.angle_between(direction, vec)) <= tol + 1e-12
            lengths = np.array([arrow_length(key, float(v)) for v in np.linalg.norm(vec, axis=1)])
            assert np.max(np.abs(np.interp(plan.video_t, kf.video_t, ln) - lengths)) <= keyframes.LENGTH_TOLERANCE + 1e-12
    assert keyframes.choose(plan, 0.05).count > kf.count


def _spinning_plan(deg_per_frame: float, frames: int = 7):
    """A bare plan: one body turning about z at a fixed angle per frame (no arrows)."""
    ang = np.radians(deg_per_frame) * np.arange(frames)
    q = np.c_[np.cos(ang / 2), np.zeros(frames), np.zeros(frames), np.sin(ang / 2)]
    spec = SimpleNamespace(show=("body",), duration=1.0, time_map="linear")
    panel = SimpleNamespace(model="free", q=q, L_world=None, omega_world=None)
    vt = np.linspace(0.0, 1.0, frames)
    return SimpleNamespace(panels=[panel], video_t=vt, sim_t=10.0 * vt, spec=spec, t_end=10.0, frames=frames)


def test_frames_a_half_turn_apart_get_slerp_midpoints():
    """An aliased spin of 120 deg a frame: midpoints (frame -1, on the slerp path between the
    two frames, their time on the time map) keep every step under MAX_STEP (40 deg steps); the
    frames themselves stay exact."""
    p = _spinning_plan(120.0)
    kf = keyframes.choose(p)
    q = kf.panels[0].q
    assert np.max(R.misorientation(q[1:], q[:-1])) < keyframes.MAX_STEP
    assert np.all(np.sum(q[1:] * q[:-1], axis=1) >= 0.0)
    real = kf.frame >= 0
    assert list(kf.frame[real]) == list(range(p.frames)) and (~real).sum() == 2 * (p.frames - 1)      # 40 deg steps
    assert np.max(R.misorientation(q[real], p.panels[0].q)) < 1e-12
    np.testing.assert_allclose(kf.sim_t, 10.0 * kf.video_t, rtol=1e-12)
    # a steady 12 deg a frame is one slerp: only MAX_STEP asks for keyframes between the ends (every 48 deg)
    assert list(keyframes.choose(_spinning_plan(12.0, 13)).frame) == [0, 4, 8, 12]


# --- the glTF file --------------------------------------------------------------------------
def _accessor(g, blob: bytes, i: int) -> np.ndarray:
    a = g.accessors[i]
    v = g.bufferViews[a.bufferView]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[a.type]
    assert a.componentType == gltf.FLOAT
    data = np.frombuffer(blob, dtype="<f4", count=a.count * width, offset=v.byteOffset + (a.byteOffset or 0))
    return data.reshape(a.count, width) if width > 1 else data


def test_glb_reread_holds_the_videos_poses(glb, plan):
    """Reread with pygltflib: the body's rotation keyframes (x, y, z, w) are the video's poses
    at the keyframe frames to 1e-6 rad; their times are those frames' video seconds, the
    extras give each one's physical time; slerp between them stays within the stated bound at
    every frame; the L arrow's rotation, shaft scale and head offset give the video's arrow;
    each model's 'world' node turns spinviz's +z into glTF's +y; the two models stand side by side."""
    import pygltflib

    g = pygltflib.GLTF2().load(str(glb))
    blob = g.binary_blob()
    nodes = {n.name: n for n in g.nodes}
    anim = g.animations[0]
    frames = np.array(anim.extras["video_frame"])
    tol = math.radians(g.scenes[0].extras["spinviz"]["keyframes"]["tolerance_deg"])
    assert tol == pytest.approx(math.radians(keyframes.TOLERANCE_DEG))
    np.testing.assert_allclose(anim.extras["physical_time"], plan.sim_t[frames], rtol=1e-15)

    def channel(node_name, path):
        idx = g.nodes.index(nodes[node_name])
        ch = next(c for c in anim.channels if c.target.node == idx and c.target.path == path)
        s = anim.samplers[ch.sampler]
        assert s.interpolation == "LINEAR"
        return _accessor(g, blob, s.input), _accessor(g, blob, s.output)

    x = np.array([1.0, 0.0, 0.0])
    for k, panel in enumerate(plan.panels):
        t, q_xyzw = channel(f"{panel.model} body", "rotation")
        q = np.c_[q_xyzw[:, 3], q_xyzw[:, :3]].astype(float)
        np.testing.assert_allclose(t, plan.video_t[frames], rtol=1e-7, atol=1e-7)
        assert np.max(R.misorientation(R.normalize(q), panel.q[frames])) < 1e-6
        assert np.max(R.misorientation(R.slerp_series(t, R.normalize(q), plan.video_t), panel.q)) < tol + 1e-6
        _, qa = channel(f"{panel.model} L", "rotation")
        qa = R.normalize(np.c_[qa[:, 3], qa[:, :3]].astype(float))
        assert np.max(R.angle_between(R.world_from_body(qa, x), panel.L_world[frames])) < 1e-6
        _, scale = channel(f"{panel.model} L shaft", "scale")
        _, shift = channel(f"{panel.model} L head", "translation")
        want = np.array([arrow_length("L", float(v)) for v in np.linalg.norm(panel.L_world[frames], axis=1)])
        np.testing.assert_allclose(scale[:, 0] + ARROWS["L"][1], want, atol=1e-6)
        np.testing.assert_allclose(shift[:, 0] + ARROWS["L"][1], want, atol=1e-6)
        world = nodes[f"{panel.model} world (spinviz z up)"]
        wq = np.array([world.rotation[3], *world.rotation[:3]])
        np.testing.assert_allclose(R.world_from_body(wq, [0.0, 0.0, 1.0]), [0.0, 1.0, 0.0], atol=1e-12)
        assert nodes[panel.model].translation == [gltf.model_offsets(2)[k], 0.0, 0.0]
    assert nodes["reduced"].translation[0] - nodes["truncated"].translation[0] == -gltf.SPACING


def test_cli_writes_what_the_api_writes(scene, glb, tmp_path, capsys):
    """`spinviz render SCENE --out X.glb` and spinviz.render(..., out=X.glb) write the same
    bytes; the command says what it wrote and within what bound."""
    out = tmp_path / "cli.glb"
    assert main(["render", str(scene), "--out", str(out)]) == 0
    assert out.read_bytes() == glb.read_bytes()
    said = capsys.readouterr().out
    assert f"{out}: glTF model (binary)" in said and f"within {keyframes.TOLERANCE_DEG:g} deg of every frame" in said


def test_outputs_refused_with_one_line(scene, tmp_path, capsys):
    """An unknown extension, and a model of a scene that shows no body and no arrow: exit 2,
    one line naming the option or the key."""
    assert main(["render", str(scene), "--out", str(tmp_path / "x.obj")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--out" in err and ".glb or .gltf" in err
    assert main(["render", str(ROOT / "scenes" / "hodograph_askew.toml"), "--out", str(tmp_path / "h.glb")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "show" in err and "none of body, dipole, omega, L" in err
    assert not list(tmp_path.iterdir())


def _validate(path: Path) -> dict:
    node = shutil.which("node")
    if node is None or not (VALIDATOR_DIR / "node_modules" / "gltf-validator").is_dir():
        pytest.fail("the Khronos glTF validator is missing: npm install --prefix .ci/node gltf-validator@2.0.0-dev.3.10 "
                    "(.ci/run does this)", pytrace=False)
    r = subprocess.run([node, str(ROOT / "tests" / "gltf_validate.js"), str(VALIDATOR_DIR), str(path)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


@pytest.mark.slow                      # needs node and the validator, which .ci/run installs before its slow pass
def test_khronos_validator_passes_glb_and_gltf(glb, scene, tmp_path):
    """No error, no warning from gltf-validator on the .glb and on the self-contained .gltf
    (the same document, its buffer as a data URI)."""
    embedded = tmp_path / "askew.gltf"
    spinviz.render(str(scene), out=str(embedded))
    for path in (glb, embedded):
        issues = _validate(path)
        assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]
    doc = json.loads(embedded.read_text())
    assert doc["buffers"][0]["uri"].startswith("data:application/octet-stream;base64,")


@pytest.mark.slow
def test_validator_catches_a_broken_file(glb, tmp_path):
    """The validator check can fail: a rotation keyframe's w set to 2 (not a unit quaternion)
    is reported."""
    import pygltflib

    g = pygltflib.GLTF2().load(str(glb))
    blob = bytearray(g.binary_blob())
    s = g.animations[0].samplers[0]
    v = g.bufferViews[g.accessors[s.output].bufferView]
    blob[v.byteOffset + 12:v.byteOffset + 16] = np.float32(2.0).tobytes()
    g.set_binary_blob(bytes(blob))
    bad = tmp_path / "bad.glb"
    g.save_binary(str(bad))
    issues = _validate(bad)
    assert issues["numErrors"] >= 1 and any("NON_NORMALIZED_QUATERNION" in m["code"] for m in issues["messages"])


# --- the page -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def page(scene, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("page") / "askew.html"
    res = spinviz.render(str(scene), out=str(out))
    assert res.format == "html"
    return out


def check_csp(page: Path) -> str:
    """The page's text, after checking: under 2 MB, every executable script inline and allowed
    by its sha256 in the Content-Security-Policy, which allows nothing else (no remote load,
    no inline handler), the style by its hash."""
    text = page.read_text()
    assert page.stat().st_size < 2_000_000
    csp = re.search(r'<meta http-equiv="Content-Security-Policy" content="([^"]+)">', text).group(1)
    assert "default-src 'none'" in csp and "unsafe" not in csp and "http" not in csp
    scripts = re.findall(r"<script>(.*?)</script>", text, flags=re.S)
    assert len(scripts) == 2
    allowed = re.search(r"script-src ([^;]+)", csp).group(1).split()
    assert sorted(allowed) == sorted("'sha256-" + base64.b64encode(hashlib.sha256(s.encode()).digest()).decode() + "'"
                                     for s in scripts)
    style = re.search(r"<style>(.*?)</style>", text, flags=re.S).group(1)
    assert "'sha256-" + base64.b64encode(hashlib.sha256(style.encode()).digest()).decode() + "'" in csp
    markup = re.sub(r"<script\b[^>]*>.*?</script>", "", text, flags=re.S)
    assert not re.search(r"\son[a-z]+\s*=", markup)
    return text


def test_page_is_self_contained_under_its_csp(page, glb):
    """One file under 2 MB under a hash-only CSP (``check_csp``); the title is text (escaped),
    the data block cannot close its element; the model inside is the .glb, byte for byte."""
    text = check_csp(page)
    assert "<b>" not in re.sub(r"<script\b[^>]*>.*?</script>", "", text, flags=re.S)
    assert "<title>Askew top &lt;b&gt;bold&lt;/b&gt; &amp; &quot;quoted&quot; &lt;/script&gt;</title>" in text
    data = re.search(r'<script type="application/json" id="spinviz-data">(.*?)</script>', text, flags=re.S).group(1)
    assert json.loads(data)["title"] == TITLE
    b64 = re.search(r'<script type="application/octet-stream" id="spinviz-glb">(.*?)</script>', text, flags=re.S).group(1)
    assert base64.b64decode("".join(b64.split())) == glb.read_bytes()


@pytest.mark.slow                      # the validator: installed by .ci/run before its slow pass
def test_committed_model_and_page(tmp_path):
    """renders/dast_cube.glb passes the validator, and the committed page beside it (under
    2 MB, its CSP right) carries that very model: both written by this code from
    scenes/default.toml.  (The documentation site's page is written by its gallery.)"""
    glb = ROOT / "renders" / "dast_cube.glb"
    issues = _validate(glb)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0
    text = check_csp(ROOT / "renders" / "dast_cube_turnable.html")
    b64 = re.search(r'<script type="application/octet-stream" id="spinviz-glb">(.*?)</script>', text, flags=re.S).group(1)
    assert base64.b64decode("".join(b64.split())) == glb.read_bytes()


@pytest.mark.slow
def test_page_in_chromium_turns_to_the_runs_pose(page, scene, plan, tmp_path):
    """Headless Chromium, the page from a file, no network: both crystals are drawn (coloured
    pixels in each half of the view); opened at #frame=N (the slider set to frame N) it shows,
    for both models, render_frame's pose at that frame's time to 1e-6 rad (a keyframe) or
    within the stated bound (a frame between keyframes); nothing is refused by the CSP.
    Without WebGL it says so."""
    from browser import CHROMIUM, WEBGL_FLAGS, chromium, page_text, screenshot

    if CHROMIUM is None:
        pytest.fail("the page test needs chromium (apt-get install chromium; .ci/run does this)", pytrace=False)
    kf = keyframes.choose(plan)
    key = int(kf.frame[len(kf.frame) // 2])
    between = int(next(f for f in range(1, plan.frames) if f not in set(kf.frame.tolist())))
    for f, bound in ((key, 1e-6), (between, math.radians(keyframes.TOLERANCE_DEG) + 1e-6)):
        r = chromium(page, tmp_path, *WEBGL_FLAGS, "--enable-logging=stderr", "--v=0", "--dump-dom", fragment=f"frame={f}")
        assert "Content Security Policy" not in r.stderr and "Uncaught" not in r.stderr, r.stderr[-2000:]
        assert f'data-frame="{f}"' in r.stdout and 'class="ready"' in r.stdout
        t = float(plan.sim_t[f])
        drawn = pipeline.plan(str(scene), t_end=t)          # what render_frame(scene, t) draws
        for k, panel in enumerate(drawn.panels):
            shown = json.loads(re.search(rf'id="panel-{k}" data-pose="([^"]+)"', r.stdout).group(1))
            assert R.misorientation(R.normalize(np.array(shown)), panel.q[-1]) < bound
            if bound > 1e-6:
                assert R.misorientation(R.normalize(np.array(shown)), panel.q[-1]) > 1e-6     # interpolated, not exact
    img = screenshot(page, tmp_path, fragment=f"frame={key}", flags=WEBGL_FLAGS)
    assert img.shape == (900, 1280, 3)
    view = img[175:560].astype(int)                                    # below the headings, above the slider
    body = (view.mean(axis=2) < 200) & (view[..., 0] - view[..., 2] > 15)  # the tan box, lit or shaded
    assert body[:, :640].sum() > 5000 and body[:, 640:].sum() > 5000
    assert (view.mean(axis=2) < 200)[:, 600:680].sum() < 400             # nothing but the divider between them
    _, text = page_text(page, tmp_path, fragment="frame=3")
    assert "no WebGL" not in text
    dom = chromium(page, tmp_path, "--disable-webgl", "--disable-3d-apis", "--dump-dom", fragment="frame=3").stdout
    assert "This browser has no WebGL" in dom and 'data-frame="3"' in dom
    assert os.path.getsize(page) < 2_000_000
