"""Rendering, checked from the pictures: arrow tips against the camera projection of O d,
two panels, frame counts and sizes, atomic outputs, and what is (not) built.

Small frames (a few hundred pixels) keep these fast; off-screen software OpenGL (EGL)."""

import math
import pathlib
import tomllib

import numpy as np
import pytest

from spinviz import pipeline
from spinviz import rotations as R
from spinviz.errors import RenderError
from spinviz.inputs.scene_spec import parse_scene
from spinviz.rendering import timeline
from spinviz.rendering.video import render_frames, render_video

DIPOLE_RGB = np.array([0.86, 0.08, 0.24]) * 255


def scene_from(text: str, path="test.toml"):
    return parse_scene(tomllib.loads(text), path)


ASKEW = """
title = "askew"
[body]
delta = -0.6
chi_deg = 55.0
[initial]
omega = [0.02, 0.05, 0.03]
euler_zxz = [0.3, 1.1, -0.4]
[simulation]
{models}
t_end = 60.0
samples = 50
[render]
duration = 1.0
fps = 12
size = [{w}, {h}]
show = {show}
spin = "true"
"""


def askew(models='model = "reduced"', show='["dipole"]', w=320, h=240):
    return scene_from(ASKEW.format(models=models, show=show, w=w, h=h))


def dipole_mask(img):
    """Pixels the dipole arrow covers, even partly: red clearly above green and blue (the
    arrow is the only red thing; anti-aliased edge pixels of ~25 % coverage still qualify)."""
    px = img.astype(int)
    return (px[..., 0] - px[..., 1] > 30) & (px[..., 0] - px[..., 2] > 25)


def tip_pixel(mask, origin):
    """The masked pixel farthest from ``origin`` (column, row): the arrow's tip."""
    rows, cols = np.nonzero(mask)
    d = (cols - origin[0]) ** 2 + (rows - origin[1]) ** 2
    i = int(np.argmax(d))
    return np.array([cols[i], rows[i]], dtype=float)


def test_dipole_arrow_tip_follows_the_simulated_orientation():
    """For several frames, the arrow tip found in the pixels lies within 2.5 px of the camera
    projection of O d (the simulated orientation applied to the body-frame dipole)."""
    sc = askew()
    spec = sc.render
    trajs = pipeline.scene_trajectories(sc, spec)
    plan = timeline.plan_frames(spec, trajs)
    assert plan.spin_mode == "true"
    frames = [0, 5, 11]
    imgs, session = render_frames(plan, frames)
    try:
        for f, img in zip(frames, imgs):
            q = trajs[0].sample(plan.sim_t[f:f + 1]).q[0]
            d_world = R.world_from_body(q, sc.body.dipole_direction)
            np.testing.assert_allclose(plan.panels[0].d_world[f], d_world, atol=1e-12)
            want = np.array(session.project(0, d_world))
            origin = session.project(0, (0.0, 0.0, 0.0))
            got = tip_pixel(dipole_mask(img), origin)
            assert np.linalg.norm(got - want) < 2.5, (f, got, want)
    finally:
        session.close()


def test_two_models_are_two_panels_with_their_own_orientations():
    """A two-model scene renders two side-by-side panels; each arrow tip matches its own
    model's projected dipole (a shared frame buffer would show the same picture twice)."""
    sc = scene_from("""
[body]
preset = "dast_cube"
[initial]
omega = [0.0, 3.141592653589793e10, 3.141592653589793e10]
euler_zxz_deg = [0.0, 45.0, 0.0]
[simulation]
models = ["reduced", "truncated"]
t_end_Theta = 4.0
samples = 10
[render]
duration = 1.0
fps = 10
size = [480, 200]
show = ["dipole", "hud"]
""")
    plan = pipeline.plan(sc)
    assert [p.model for p in plan.panels] == ["reduced", "truncated"]
    assert plan.spin_mode == "slowed"                  # 1e16 turns: the phase is beyond float64
    f = plan.frames - 1
    (img,), session = render_frames(plan, [f])
    try:
        assert img.shape == (200, 480, 3)
        tips = []
        for k in range(2):
            view = np.zeros(img.shape[:2], dtype=bool)           # the panel's 3-D view: not its red legend chip
            x0, y0, x1, y1 = session.picture.layout.views[k]
            view[y0:y1, x0:x1] = True
            mask = dipole_mask(img) & view
            want = np.array(session.project(k, plan.panels[k].d_world[f]))
            got = tip_pixel(mask, session.project(k, (0.0, 0.0, 0.0)))
            assert np.linalg.norm(got - want) < 2.5, (k, got, want)
            tips.append(got - [k * 240, 0])
        # the physics shows: reduced has d almost on the axis (theta -> 0), truncated keeps 45 deg;
        # the phases are re-timed, so the HUD has the swing over a turn (one value: chi = 0)
        assert plan.panels[0].angle_dL_deg is None
        assert plan.panels[0].angle_dL_range_deg[f, 1] < 3.0
        np.testing.assert_allclose(plan.panels[1].angle_dL_range_deg[f], 45.0, atol=1e-6)
        assert np.linalg.norm(tips[0] - tips[1]) > 10.0
    finally:
        session.close()


@pytest.mark.slow
def test_video_has_the_expected_frames_and_size(tmp_path):
    """MP4 through two worker processes (segments joined by stream copy, in a directory whose
    name needs the concat list's quoting) and a GIF: the frame count, size, codec and pixel
    format are what was asked for; a poster PNG is written; no segment folder is left.
    (The one test that starts worker processes: each imports VTK, seconds of start-up.)"""
    import imageio

    sc = askew(show='["body", "dipole", "trail", "sphere", "axes", "hud"]', w=160, h=96)
    plan = pipeline.plan(sc, fps=16, duration=1.5)
    d = tmp_path / "it's here"
    out = d / "v.mp4"
    res = render_video(plan, str(out), workers=2, progress=False)
    assert res.workers == 2 and res.frames == 24
    assert sorted(p.name for p in d.iterdir()) == ["v.mp4", "v.png"]
    r = imageio.get_reader(str(out))
    meta = r.get_meta_data()
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p")
    assert tuple(meta["size"]) == (160, 96) and r.count_frames() == 24
    r.close()
    from PIL import Image

    assert Image.open(res.poster).size == (160, 96)
    gif = tmp_path / "v.gif"
    render_video(plan, str(gif), progress=False, poster=False)
    im = Image.open(gif)
    assert im.size == (160, 96) and im.n_frames == 24


def test_failed_render_leaves_the_previous_file_intact(tmp_path, monkeypatch):
    """An error in the middle of a render deletes the partial output and keeps the old file."""
    from spinviz.rendering import session as SE

    sc = askew(w=64, h=48)
    plan = pipeline.plan(sc)
    out = tmp_path / "old.mp4"
    out.write_bytes(b"previous video")
    (tmp_path / "old.png").write_bytes(b"previous poster")
    calls = {"n": 0}
    original = SE.RenderSession.frame

    def failing(self, f):
        calls["n"] += 1
        if calls["n"] == 5:
            raise RuntimeError("disk on fire")
        return original(self, f)

    monkeypatch.setattr(SE.RenderSession, "frame", failing)
    with pytest.raises(RenderError, match="rendering frame 4 failed: disk on fire"):
        render_video(plan, str(out), workers=1, progress=False)
    assert out.read_bytes() == b"previous video"
    assert (tmp_path / "old.png").read_bytes() == b"previous poster"    # video and poster land together
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.mp4", "old.png"]


def test_only_listed_actors_are_built():
    sc = askew(show='["dipole"]', w=64, h=48)
    plan = pipeline.plan(sc)
    _, session = render_frames(plan, [0])
    try:
        view = session.views[0]
        assert set(view.solids.parts) == {"dipole_shaft", "dipole_head"}
        assert view.curves == {}
        assert len(view.window.actors) == 1                           # no sphere, axes, trail, body
        assert view.window.renderer.GetActors().GetNumberOfItems() == 1
        assert plan.panels[0].omega_world is None and plan.panels[0].L_world is None   # not computed either
    finally:
        session.close()


def test_hodograph_only_scene_integrates_no_orientation(monkeypatch):
    """show = ["hodograph"]: the trajectories carry no orientation (kinematics "none")."""
    import spinviz.pipeline as PIPE

    seen = []
    real = PIPE.simulate_request

    def spy(request):
        seen.append(request.kinematics)
        return real(request)

    monkeypatch.setattr(PIPE, "simulate_request", spy)
    sc = askew(models='models = ["reduced", "truncated"]', show='["hodograph", "axes"]', w=128, h=64)
    trajs = PIPE.scene_trajectories(sc, sc.render)
    assert seen == ["none", "none"] and all(t.q is None for t in trajs)
    plan = timeline.plan_frames(sc.render, trajs)
    (img,), session = render_frames(plan, [plan.frames - 1])
    session.close()
    assert plan.panels[0].q is None and plan.panels[0].omega_body is not None
    blue = (img[..., 2] > 150) & (img[..., 0] < 100)
    assert blue[:, :64].any() and blue[:, 64:].any()               # a hodograph curve in each panel


def test_log_time_map_and_slowed_spin_label():
    """Log time map: starts at 0, ends at t_end, increasing; the slowed-spin factor is the
    true precession rate (rad per video second) over the shown one, the same in both panels."""
    spec = scene_from(ASKEW.format(models='model = "reduced"', show='["dipole"]', w=64, h=48)).render
    spec = spec.with_(time_map="log", log_knee=0.5, duration=2.0, fps=10, spin="slowed", spin_turns_per_second=0.5)
    v, t, slope = timeline.frame_times(spec, 60.0)
    assert t[0] == 0.0 and t[-1] == 60.0 and np.all(np.diff(t) > 0)
    np.testing.assert_allclose(np.gradient(t, v)[5:-5], slope[5:-5], rtol=0.05)
    sc = askew(w=64, h=48)
    trajs = pipeline.scene_trajectories(sc, spec)
    plan = timeline.plan_frames(spec, trajs)
    assert plan.spin_mode == "slowed"
    w0 = trajs[0].omega[0]
    J3 = sc.body.I3 / sc.body.I1
    phidot0 = math.hypot(math.hypot(w0[0], w0[1]), J3 * w0[2])
    np.testing.assert_allclose(plan.slowdown, phidot0 * slope / (2 * math.pi * 0.5), rtol=1e-12)
    factor = 1.0 / plan.slowdown[3]                    # this slow top is shown faster than it turns
    assert f"spin shown {factor:.2g} times faster" in plan.hud_lines(0, 3), plan.hud_lines(0, 3)
    # the slow geometry is kept: the angle between e3 and L is the simulated one
    s = trajs[0].sample(plan.sim_t)
    L = s.angular_momentum_world()
    e3_true = R.world_from_body(s.q, [0.0, 0.0, 1.0])
    e3_shown = R.world_from_body(plan.panels[0].q, [0.0, 0.0, 1.0])
    Lh = L / np.linalg.norm(L, axis=1, keepdims=True)
    np.testing.assert_allclose(np.sum(e3_shown * Lh, 1), np.sum(e3_true * Lh, 1), atol=1e-9)


def test_render_command_errors_are_one_line(tmp_path, capsys):
    from spinviz.commands import main

    good = tmp_path / "s.toml"
    good.write_text(ASKEW.format(models='model = "reduced"', show='["dipole"]', w=64, h=48))
    assert main(["render", str(good), "--out", str(tmp_path / "x.mp4"), "--size", "65x48"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("MP4 (H.264, yuv420p) needs an even width and height, got 65x48") and "\n" not in err
    assert main(["render", str(good), "--out", str(tmp_path / "x.avi")]) == 2
    assert "use .mp4 or .gif" in capsys.readouterr().err
    bad = tmp_path / "b.toml"
    bad.write_text(ASKEW.format(models='model = "reduced"', show='["dipole", "halo"]', w=64, h=48))
    assert main(["render", str(bad)]) == 2
    assert capsys.readouterr().err.strip() == f"spinviz: error: {bad}: [render].show: unknown item 'halo'; valid: " \
        "body, dipole, omega, L, axes, trail, sphere, hud, hodograph, inset, power"
    assert not any(p.suffix == ".mp4" for p in tmp_path.iterdir())


def test_progress_is_reported_while_rendering(tmp_path, capsys):
    sc = askew(w=64, h=48)
    plan = pipeline.plan(sc, fps=8, duration=1.0)
    render_video(plan, str(tmp_path / "p.mp4"), workers=1, progress=True, poster=False)
    err = capsys.readouterr().err.splitlines()
    assert [line.split(": ", 1)[1].split(",")[0] for line in err] == ["2/8 frames (25 %)", "4/8 frames (50 %)",
                                                                      "6/8 frames (75 %)", "8/8 frames (100 %)"]


# --- pictures a viewer can read ---------------------------------------------------
SCENES = sorted(p for p in (pathlib.Path(__file__).resolve().parents[1] / "scenes").glob("*.toml")
                if not p.name.startswith("atlas_"))           # atlas specs are not scenes

def arrow_rgb(key):
    """The legend chip's colour: the arrow's colour, in 8 bits."""
    from spinviz.rendering.style import ARROW_COLORS

    return tuple(int(round(255 * c)) for c in ARROW_COLORS[key])


def scene_frames(path, frames=("first", "middle", "last"), size=(640, 360), **overrides):
    """(plan, {name: image}, session) of a shipped scene at ``size``; caller closes the session."""
    from spinviz.inputs.scene_spec import load_scene

    plan = pipeline.plan(load_scene(path), size=size, **overrides)
    n = plan.frames
    index = {"first": 0, "middle": n // 2, "last": n - 1}
    idx = [index.get(f, f) for f in frames]
    imgs, session = render_frames(plan, idx)
    return plan, dict(zip(frames, imgs)), session


# three scenes in the default run (a symmetric top, the rod, the cube comparison); every scene in .ci/run's second pass
FAST_SCENES = ("askew_example", "cellulose_rod", "default")


@pytest.mark.parametrize("path", [p if p.stem in FAST_SCENES else pytest.param(p, marks=pytest.mark.slow) for p in SCENES],
                         ids=[p.stem for p in SCENES])
def test_every_scene_keeps_its_frame_edges_clear_and_labels_its_arrows(path):
    """At 640x360, the first, middle and last frames of every shipped scene leave the outermost
    2 rows and columns pure background (nothing clipped at the edge); every drawn arrow has its
    legend chip -- a box of the arrow's own colour, at least 14 px high, with white text in it;
    and the camera keeps every arrow tip of every frame inside the panel's 3-D view."""
    plan, imgs, session = scene_frames(path)
    try:
        for name, img in imgs.items():
            border = np.concatenate([img[:2].reshape(-1, 3), img[-2:].reshape(-1, 3), img[:, :2].reshape(-1, 3),
                                     img[:, -2:].reshape(-1, 3)])
            assert (border == 255).all(), (path.name, name, np.argwhere((border != 255).any(axis=1))[:5])
        img = imgs["last"]
        for key in ("dipole", "L", "omega"):
            if key not in plan.spec.show:
                continue
            box = np.all(img == arrow_rgb(key), axis=-1)
            rows = np.nonzero(box.sum(axis=1) >= 30)[0]
            assert rows.size >= 14, (path.name, key, rows.size)          # a filled box of the arrow's colour ...
            cols = np.nonzero(box[rows].any(axis=0))[0]
            inside = img[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
            assert np.all(inside == 255, axis=-1).sum() > 20, (path.name, key)   # ... with white text inside
        from spinviz.rendering.fonts import Fonts
        from spinviz.rendering.stage import ARROW_VECTORS, arrow_length

        picture = session.picture
        for k, panel in enumerate(plan.panels):
            x0, y0, x1, y1 = picture.layout.views[k]
            for key in ("dipole", "L", "omega"):
                v = getattr(panel, ARROW_VECTORS[key])
                if v is None:
                    continue
                n = np.linalg.norm(v, axis=1)
                tips = v / np.maximum(n, 1e-300)[:, None] * np.array([arrow_length(key, x) for x in n])[:, None]
                px = picture.project(k, tips)
                assert (px[:, 0] >= x0).all() and (px[:, 0] <= x1).all(), (path.name, key)
                assert (px[:, 1] >= y0).all() and (px[:, 1] <= y1).all(), (path.name, key)
        font = Fonts(picture.layout.sizes).small
        views = picture.layout.views
        for text, (x, y) in picture.stage.labels:            # axis names and values stay inside a 3-D view
            l, t, r, b = font.getbbox(text, anchor="mm")
            assert any(v[0] <= x + l and x + r <= v[2] and v[1] <= y + t and y + b <= v[3]
                       for v in views), (path.name, text, (x, y), views)
    finally:
        session.close()


@pytest.mark.parametrize("size", [(640, 360), (1280, 720)])
def test_text_bands_never_overlap_and_type_scales_with_the_frame(size):
    """Heading, subtitle, 3-D views, panel numbers, legend, time bar and notes occupy disjoint
    bands; the divider between the panels stops above the shared bands; the ink of the time
    line ("after 9.5 days": ascenders and a descender) is at least 14 px high at 360 rows and
    scales with the frame height."""
    plan, imgs, session = scene_frames(SCENES[[p.stem for p in SCENES].index("default")], frames=("middle",),
                                       size=size)
    try:
        lay = session.picture.layout
        W, H = size
        bands = [(0, max(y + (lay.sizes.heading_line if w == "main" else lay.sizes.line)
                         for items in lay.headings for _, w, y, _ in items))]
        bands += [(lay.views[0][1], lay.views[0][3])]
        bands += [(lay.readout_y, lay.readout_y + lay.readout_lines * lay.sizes.line)]
        bands += [(r.y, r.y + r.height) for r in lay.rows]
        for (a0, a1), (b0, b1) in zip(bands, bands[1:]):
            assert a0 < a1 <= b0 < b1 <= H, bands
        assert {r.kind for r in lay.rows} >= {"legend", "timebar", "notes"}
        assert lay.divider[1] <= lay.rows[0].y
        img = imgs["middle"]
        bar = next(r for r in lay.rows if r.kind == "timebar")
        text_w = session.picture.overlay.bar.x0
        band = img[bar.y:bar.y + bar.height, lay.pad:text_w]
        dark = np.nonzero((band.max(axis=-1) < 120).any(axis=1))[0]
        ink = dark[-1] - dark[0] + 1
        assert ink >= 14 * H / 360, (ink, plan.hud_lines(0, plan.frames // 2))
    finally:
        session.close()


def test_rod_panels_differ_where_the_axial_spin_shows():
    """The cellulose rod: both equations brake the flatwise rotation alike, so the two panels
    show the rod in the same place; only the painted halves differ -- identical at t = 0,
    measurably different after 1 T (the reduced rod keeps its axial spin, the truncated one loses
    it), in the rod's own pixels."""
    path = SCENES[[p.stem for p in SCENES].index("cellulose_rod")]
    from spinviz.inputs.scene_spec import load_scene

    plan = pipeline.plan(load_scene(path), size=(640, 360))
    T = plan.time_scale[1]
    assert plan.time_scale[0] == "T"
    after = [int(np.searchsorted(plan.sim_t, k * T)) for k in (1.0, 1.5, 2.0, 2.5)]
    imgs, session = render_frames(plan, [0, *after])
    try:
        views = session.picture.layout.views
        diffs = []
        for img in imgs:
            a, b = (img[y0:y1, x0:x1].astype(int) for x0, y0, x1, y1 in views)
            body = (np.abs(a - 255).sum(-1) > 60) | (np.abs(b - 255).sum(-1) > 60)
            diffs.append(float(np.abs(a - b).sum(-1)[body].mean()))
        assert diffs[0] < 2.0, diffs                       # same start, same picture
        assert max(diffs[1:]) > 25.0, diffs                # one rod shows its dark half, the other not
    finally:
        session.close()


def test_arrow_length_follows_the_spin_rate():
    """DAST cube, truncated panel: |Omega| falls to about a quarter over 6 Theta, and the drawn
    Omega arrow (blue pixels, tip farthest from the centre) gets shorter with it, as
    stage.arrow_length says; the dipole arrow keeps its length."""
    path = SCENES[[p.stem for p in SCENES].index("dast_cube")]
    plan, imgs, session = scene_frames(path, frames=("first", "last"))
    try:
        from spinviz.rendering.stage import arrow_length

        k = 1
        ratio = plan.panels[k].omega_mag[-1] / plan.panels[k].omega_mag[0]
        assert ratio < 0.4
        x0, y0, x1, y1 = session.picture.layout.views[k]
        origin = np.array(session.project(k, (0.0, 0.0, 0.0)))
        lengths = []
        for name in ("first", "last"):
            px = imgs[name][y0:y1, x0:x1].astype(int)
            blue = (px[..., 2] - px[..., 0] > 80) & (px[..., 2] - px[..., 1] > 60)
            tip = tip_pixel(blue, origin - [x0, y0]) + [x0, y0]
            lengths.append(float(np.linalg.norm(tip - origin)))
        want = arrow_length("omega", ratio) / arrow_length("omega", 1.0)
        assert lengths[1] < 0.8 * lengths[0], lengths
        assert lengths[1] / lengths[0] == pytest.approx(want, abs=0.08), (lengths, want)
    finally:
        session.close()


def test_angle_between_d_and_L_is_the_true_one_or_its_swing():
    """True spin: the HUD's angle is Trajectory.angle_d_L() at the frame; slowed spin (phases
    re-timed): the range of Trajectory.angle_d_L_range() over a turn, labelled as a swing."""
    sc = askew(show='["dipole", "hud"]', w=320, h=180)
    plan = pipeline.plan(sc)
    assert plan.spin_mode == "true"
    tr = pipeline.scene_trajectories(sc, sc.render)[0]
    np.testing.assert_allclose(plan.panels[0].angle_dL_deg, np.degrees(tr.angle_d_L()), atol=1e-9)
    slowed = pipeline.plan(sc, spin="slowed")
    lo, hi = tr.angle_d_L_range()
    np.testing.assert_allclose(slowed.panels[0].angle_dL_range_deg, np.degrees(np.c_[lo, hi]), atol=1e-9)
    line = slowed.hud_lines(0, 5)[2]
    from spinviz.rendering.captions import _deg

    assert line == f"angle d–L swings {_deg(np.degrees(lo[5]))}–{_deg(np.degrees(hi[5]))} each turn", line
    assert 1.0 < np.degrees(hi[5] - lo[5])                      # an askew top: a real swing
    phys = pipeline.plan(sc, spin="slowed", captions="physics").hud_lines(0, 5)[2]
    assert phys.startswith("∠(d, L) swings ") and phys.endswith(" each turn")


def test_numbers_for_people():
    from spinviz.rendering import captions as CAP

    assert CAP.sci(3.8e15) == "3.8 × 10¹⁵" and CAP.sci(1.2e-7) == "1.2 × 10⁻⁷" and CAP.sci(42.0) == "42"
    assert CAP.words(5.0e9) == "5 billion" and CAP.words(1.34e6) == "1.3 million" and CAP.words(870) == "870"
    year = 365.25 * 86400
    assert CAP.people_time(1.34e6 * year) == "1.3 million years" and CAP.people_time(4.2 * 86400) == "4.2 days"
    assert CAP.people_time(22.7 * 60) == "23 minutes"


def test_captions_key_is_validated():
    from spinviz.errors import SpecError
    from spinviz.inputs.render import RenderSpec

    assert RenderSpec(captions="physics").captions == "physics"
    with pytest.raises(SpecError, match="captions: unknown value 'poetry'; valid: outreach, physics"):
        RenderSpec(captions="poetry")
    with pytest.raises(SpecError, match="subtitles"):
        RenderSpec(subtitles=("a", "b", "c"))


@pytest.mark.slow
def test_render_workers_import_no_simulation_stack():
    """A render worker imports the drawing stack and unpickles a picture without loading numba,
    scipy or numpy-quaternion (about 1.5 s), nor pyvista's plotting module and matplotlib
    (about 0.9 s): start-up is VTK, pyvista's meshes, Pillow and imageio-ffmpeg only.  It draws
    the power plot from the picture's numbers, without the physics that computes them."""
    import pickle
    import subprocess
    import sys

    from spinviz.rendering.video import picture_of

    picture = picture_of(pipeline.plan(askew(show='["dipole", "hud", "power"]', w=320, h=240)))
    assert picture.overlay.inset is not None and picture.overlay.inset.plots == ("power",)
    code = ("import pickle, sys\n"
            "from spinviz.rendering import encode, session\n"
            "picture = pickle.loads(sys.stdin.buffer.read())\n"
            "session.RenderSession(picture).frame(0)\n"
            "print(sorted(m for m in ('numba', 'scipy', 'quaternion', 'matplotlib', 'pyvista.plotting',"
            " 'spinviz.trajectory', 'spinviz.physics.radiation') if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], input=pickle.dumps(picture), capture_output=True)
    assert r.returncode == 0, r.stderr.decode()
    assert r.stdout.decode().strip() == "[]"


@pytest.mark.slow
def test_render_starts_its_workers_before_it_simulates(tmp_path, monkeypatch):
    """pipeline.render opens the render processes first, so that their imports overlap the
    simulation: when the first model is integrated, the workers are already running; and the
    video comes out whole (frame count) through the pre-started pool."""
    import multiprocessing

    import imageio

    seen = []
    real = pipeline.simulate_request

    def spy(request):
        seen.append(len(multiprocessing.active_children()))
        return real(request)

    monkeypatch.setattr(pipeline, "simulate_request", spy)
    sc = askew(models='models = ["reduced", "truncated"]', show='["body", "dipole", "hud"]', w=160, h=96)
    out = tmp_path / "v.mp4"
    res = pipeline.render(sc, str(out), fps=12, duration=1.0, workers=2)
    assert seen and seen[0] >= 2, seen
    assert res.workers == 2 and imageio.get_reader(str(out)).count_frames() == 12
    assert multiprocessing.active_children() == []


# --- the power inset --------------------------------------------------------------
def _near(px, rgb, tol=40):
    """Pixels within ``tol`` (sum of channel differences) of a colour."""
    return np.abs(px.astype(int) - np.array(rgb)).sum(axis=-1) <= tol


@pytest.mark.parametrize("size", [(640, 360), (1280, 720)])
def test_power_inset_pixels_in_the_default_scene(size):
    """The default scene (the quick start's), in its pixels: inside the power plot's box both model colours
    are drawn; the cursor (a muted column) stands where the plan puts it -- right above the time
    bar's cursor -- at the first, middle and last frames, with each model's dot on it; and late in
    the run the reduced (teal) curve runs far below the truncated (purple) one: its residual
    rotation about the dipole does not radiate."""
    from spinviz.presentation import style as model_style

    plan, imgs, session = scene_frames(SCENES[[p.stem for p in SCENES].index("default")], size=size)
    try:
        inset, bar = session.picture.overlay.inset, session.picture.overlay.bar
        pal = session.picture.theme.hud
        assert inset.plots == ("power",)
        x0, y0, x1, y1 = inset.boxes[0]
        teal, purple = model_style("reduced").color, model_style("truncated").color
        index = {"first": 0, "middle": plan.frames // 2, "last": plan.frames - 1}
        for name, img in imgs.items():
            f = index[name]
            box = img[y0 + 1:y1 - 1, x0 + 1:x1 - 1]
            assert _near(box, teal).sum() > 0.5 * (x1 - x0) and _near(box, purple).sum() > 0.5 * (x1 - x0), name
            xc = int(inset.cursor[0, f])
            assert xc == bar.x0 + int(bar.cuts[f]) - 1
            column = img[y0 + 1:y1 - 1, xc]
            assert (_near(column, pal.muted, 12) | _near(column, teal) | _near(column, purple)).mean() > 0.9, name
            r = inset.dot_radius
            for i, (color, _, rows) in enumerate(inset.dots):
                if any(abs(int(later[f]) - int(rows[f])) <= 2 * r for _, _, later in inset.dots[i + 1:]):
                    continue                # at the start both models radiate alike: the later dot covers this one
                dot = img[int(rows[f]) - r:int(rows[f]) + r + 1, xc - r:xc + r + 1]
                assert _near(dot, color, 12).mean() > 0.5, (name, color)
        last = imgs["last"][y0 + 1:y1 - 1, x1 - 8 - size[0] // 40:x1 - 8]      # a strip left of the last dots
        rows_teal = np.nonzero(_near(last, teal).any(axis=1))[0]
        rows_purple = np.nonzero(_near(last, purple).any(axis=1))[0]
        assert rows_teal.min() > rows_purple.max() + 0.3 * (y1 - y0), (rows_teal, rows_purple)
    finally:
        session.close()
