"""Blender plays the model whole and renders it through the file's camera and lights.

Blender as a Python module (``bpy``, 5.x) needs a Python of its own (3.13): the test runs it
from ``SPINVIZ_BLENDER_PYTHON``, else ``.ci/bpy/bin/python`` (.ci/run installs bpy there).
That Python opens the model with the script spinviz writes beside it (``tests/blender_drive.py``
runs it), reads every body's pose at chosen frames, and renders one frame with Cycles on the
CPU at 160 x 90.  A 300-frame video (10 s at 30 fps: past Blender's default frames 1-250 and
24 fps) must play to its last frame at 30 fps, each pose within the stated angle of the
video's.  Skipped, saying why, only where bpy cannot be imported; CI must run it.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import spinviz
from spinviz import pipeline
from spinviz import rotations as R
from spinviz.rendering import framing, gltf, keyframes

from media import ROOT, load, write_scene

BPY_PYTHON = Path(os.environ.get("SPINVIZ_BLENDER_PYTHON") or ROOT / ".ci" / "bpy" / "bin" / "python")
INSTALL = "python3.13 -m venv .ci/bpy && .ci/bpy/bin/pip install bpy (.ci/run does this), or set SPINVIZ_BLENDER_PYTHON"


def blender_python() -> Path:
    """A Python that imports bpy, or a skip (a failure under CI) saying how to get one."""
    why = None
    if not BPY_PYTHON.exists():
        why = f"no Python with bpy at {BPY_PYTHON}"
    else:
        r = subprocess.run([str(BPY_PYTHON), "-c", "import bpy"], capture_output=True, text=True, timeout=300)
        if r.returncode != 0:
            why = f"{BPY_PYTHON} cannot import bpy: {r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode}"
    if why is None:
        return BPY_PYTHON
    if os.environ.get("CI"):
        pytest.fail(f"CI must run the Blender test, but {why}: {INSTALL}", pytrace=False)
    pytest.skip(f"{why}: {INSTALL}")


@pytest.mark.slow
def test_blender_plays_the_whole_video_through_the_files_camera(tmp_path):
    python = blender_python()
    scene = write_scene(tmp_path / "long.toml", duration=10.0)
    out = tmp_path / "long.glb"
    res = spinviz.render(str(scene), out=str(out))
    plan = pipeline.plan(str(scene))
    F, fps = plan.frames, plan.spec.fps
    assert F == 300 and fps == 30
    g, _ = load(out)
    frames = g.animations[0].extras["video_frame"]
    between = [f for f in range(F) if f not in frames]
    check = sorted({0, frames[len(frames) // 2], between[0], between[len(between) // 2], between[-1], F - 1})
    request = {"script": res.script, "frames": check, "render_frame": F // 2, "size": [160, 90], "samples": 8,
               "out": str(tmp_path / "frame.png")}
    (tmp_path / "request.json").write_text(json.dumps(request))
    r = subprocess.run([str(python), str(ROOT / "tests" / "blender_drive.py"), str(tmp_path / "request.json")],
                       capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-3000:]
    report = json.loads(r.stdout.split("SPINVIZ-REPORT ", 1)[1].splitlines()[0])

    # the video's rate and all of its frames; the file's camera; the video's lights; the scenes open before kept
    assert (report["fps"], report["fps_base"], report["frame_start"], report["frame_end"]) == (30, 1.0, 0, F - 1)
    assert report["key_range"] == pytest.approx([0.0, F - 1], abs=1e-3)
    assert report["camera"] == gltf.CAMERA_NAME and report["camera_type"] == "PERSP"
    assert report["resolution"] == list(plan.spec.size) and report["view_transform"] == "Standard"
    want = sorted([name, "SUN", pytest.approx(w * math.pi, rel=1e-6)] for name, _, w in framing.SUN_STRENGTH)
    assert report["lights"] == want
    assert report["scenes"] == sorted(["Scene", "long"])

    # every pose is the video's: exact at a keyframe, within the stated angle between them.  Blender's world
    # is z up like spinviz's, each model turned about the vertical by its node's yaw; the importer keeps an
    # object's mesh in Blender's axes (glTF's (x, y, z) as (x, -z, y): a quarter turn C about x), so a body
    # vector v lands at matrix_world C v
    tol = math.radians(keyframes.TOLERANCE_DEG)
    C = np.array([math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0])
    for panel in plan.panels:
        yaw = math.radians(next(n for n in g.nodes if n.name == panel.model).extras["yaw_deg"])
        turn = np.array([math.cos(0.5 * yaw), 0.0, 0.0, math.sin(0.5 * yaw)])
        got = R.multiply(R.normalize(np.array(report["bodies"][f"{panel.model} body"])), C)
        err = R.misorientation(got, R.multiply(turn, panel.q[check]))
        assert np.all(err <= tol + 1e-5), np.degrees(err)
        exact = [i for i, f in enumerate(check) if f in frames]
        assert np.all(err[exact] < 1e-5)
        assert np.any(err > 1e-4)                      # between keyframes Blender interpolates (the check can fail)

    # the render: the white background, and both crystals drawn and lit
    from PIL import Image

    img = np.asarray(Image.open(request["out"]).convert("RGB")).astype(int)
    assert img.shape == (90, 160, 3)
    assert img[:6, :6].mean() > 245 and img[-6:, -6:].mean() > 245          # (8 samples: a little noise)
    body = (img.mean(axis=2) < 215) & (img[..., 0] - img[..., 2] > 12)       # the tan box, lit or shaded
    assert body[:, :80].sum() > 40 and body[:, 80:].sum() > 40
    assert img[body].mean() > 70                                             # lit, not black
