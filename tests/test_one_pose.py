"""One pose for one instant: where the spin is slowed for the eye, ``render_frame(scene, t)``,
the MP4's frame, the glTF model and the page all show the same crystal at t.

A slowed spin's shown phase is the time integral of the shown rate over the whole video, so
the frame at t of the scene's video differs from the last frame of a video of [0, t] (20-174
deg for the default scene); here, at five instants of a slowed scene, each medium is checked
against the scene's own frame plan: the MP4's frame (decoded) is render_frame's picture, the
model's interpolated pose and the page's pose are the plan's within the stated angle (exact at
a keyframe) -- and the last frame of a shorter video is not, so the check can fail.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

import spinviz
from spinviz import pipeline
from spinviz import rotations as R
from spinviz.rendering import keyframes

from media import channel, componentwise, load, write_scene

FRAMES = (0, 13, 27, 44, 59)


@pytest.mark.slow
def test_mp4_render_frame_gltf_and_page_agree_where_the_spin_is_slowed(tmp_path):
    from browser import CHROMIUM, WEBGL_FLAGS, chromium

    if CHROMIUM is None:
        pytest.fail("the page check needs chromium (apt-get install chromium; .ci/run does this)", pytrace=False)
    import imageio.v3 as iio

    scene = write_scene(tmp_path / "slowed.toml", title="slowed", spin="slowed", duration=2.0, fps=30, size=[320, 180])
    plan = pipeline.plan(str(scene))
    assert plan.spin_mode == "slowed" and plan.frames == 60
    fps, tol = plan.spec.fps, math.radians(keyframes.TOLERANCE_DEG)
    video = spinviz.render(str(scene), out=str(tmp_path / "slowed.mp4"), workers=1)
    mp4 = iio.imread(video.path, plugin="pyav") if _has_pyav() else np.stack(list(iio.imiter(video.path)))
    assert mp4.shape == (60, 180, 320, 3)
    spinviz.render(str(scene), out=str(tmp_path / "slowed.glb"))
    spinviz.render(str(scene), out=str(tmp_path / "slowed.html"))
    g, blob = load(tmp_path / "slowed.glb")
    keys = set(g.animations[0].extras["video_frame"])
    assert any(f in keys for f in FRAMES[1:-1]) and any(f not in keys for f in FRAMES)

    for f in FRAMES:
        t = float(plan.sim_t[f])
        # render_frame's picture is the MP4's frame f (to the codec's loss), and no other frame's
        img = spinviz.render_frame(str(scene), t=t, size=(320, 180)).astype(float)
        diff = np.abs(mp4.astype(float) - img[None]).mean(axis=(1, 2, 3))
        assert int(np.argmin(diff)) == f and diff[f] < 2.0, (f, diff[f], np.sort(diff)[:3])
        # the model and the page hold the plan's pose at frame f
        r = chromium(tmp_path / "slowed.html", tmp_path, *WEBGL_FLAGS, "--dump-dom", fragment=f"frame={f}")
        assert f'data-frame="{f}"' in r.stdout and 'class="ready"' in r.stdout
        for k, panel in enumerate(plan.panels):
            tk, qk = channel(g, blob, f"{panel.model} body", "rotation")
            qk = R.normalize(np.c_[qk[:, 3], qk[:, :3]].astype(float))
            for between in (R.slerp_series(tk, qk, [f / fps]), componentwise(tk.astype(float), qk, np.array([f / fps]))):
                err = float(R.misorientation(between[0], panel.q[f]))
                assert err < (1e-6 if f in keys else tol + 1e-6), (f, k, math.degrees(err))
            shown = json.loads(re.search(rf'id="panel-{k}"[^>]* data-pose="([^"]+)"', r.stdout).group(1))
            err = float(R.misorientation(R.normalize(np.array(shown)), panel.q[f]))
            assert err < (1e-6 if f in keys else tol + 1e-6), (f, k, math.degrees(err))
            if 0 < f < plan.frames - 1:
                # the last frame of a video that ends at t is another crystal: the check can fail
                short = pipeline.plan(str(scene), t_end=t).panels[k].q[-1]
                assert math.degrees(float(R.misorientation(short, panel.q[f]))) > 5.0


def _has_pyav() -> bool:
    import importlib.util

    return importlib.util.find_spec("av") is not None
