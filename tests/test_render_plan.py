"""The render plan, checked without OpenGL: frame times, the camera fitted over the whole video,
the layout of text (disjoint, inside the frame, legible at 360 rows), the words, the colours
and the poses.  A hand-made frame plan gives exact expected values; the shipped scenes give
real content.  Pillow measures text (the fonts are the drawing layer's); nothing here opens a
GL window."""

import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from spinviz import pipeline
from spinviz import units as U
from spinviz.inputs.render import RenderSpec
from spinviz.presentation import style as model_style
from spinviz.rendering.camera import Camera
from spinviz.rendering.captions import texts_of
from spinviz.rendering.fonts import Fonts
from spinviz.rendering.frameplan import FramePlan, Panel, ShapeInfo
from spinviz.rendering.layout import TextSizes
from spinviz.rendering.overlay import Fill, Text
from spinviz.rendering.picture import plan_picture
from spinviz.rendering.stage import ARROW_VECTORS, EDGE_PX, arrow_length, content_points
from spinviz.rendering.style import theme
from spinviz.rendering.timeline import frame_times
from spinviz.rotations import matrix_from_quat

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCENES = sorted(p for p in (ROOT / "scenes").glob("*.toml") if not p.name.startswith("atlas_"))
ALL_SHOWN = ("body", "dipole", "omega", "L", "axes", "trail", "sphere", "hud")
POWER_DECADES_FALL = {"reduced": 6.0, "truncated": 2.0}


def made_plan(size=(640, 360), show=ALL_SHOWN, captions="outreach", background="white", time_map="linear",
              fps=10, duration=2.0) -> FramePlan:
    """Two panels over 10 days: the body (a stand-in box) turns once about z, |Omega| =
    2 pi 5e9 rad/s in the first panel and falls linearly to half in the second; d-L at
    30 deg; spin slowed 1.3e15 x; the time bar's unit is Theta = 3.2 days.  The radiated power
    falls from 1.5e-10 erg/s by 6 decades (reduced) and 2 decades (truncated), straight lines
    in log P against time."""
    spec = RenderSpec(duration=duration, fps=fps, size=size, show=show, captions=captions, background=background,
                      time_map=time_map, title="a test crystal")
    video_t, sim_t, _ = frame_times(spec, 10 * U.DAY)
    F = sim_t.size
    a = np.linspace(0.0, 2 * np.pi, F)
    q = np.stack([np.cos(a / 2), 0 * a, 0 * a, np.sin(a / 2)], axis=-1)
    R = matrix_from_quat(q)
    d_body = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    panels = []
    for k, model in enumerate(("reduced", "truncated")):
        ratio = 1.0 - 0.5 * k * sim_t / sim_t[-1]
        panels.append(Panel(model=model, omega_mag=2 * np.pi * 5e9 * ratio, q=q, R_world_from_body=R,
                            d_world=R @ d_body, omega_world=np.c_[0 * a, 0 * a, ratio],
                            L_world=np.c_[0.3 * ratio, 0 * a, ratio], angle_dL_deg=np.full(F, 30.0),
                            power=1.5e-10 * 10.0 ** (-POWER_DECADES_FALL[model] * sim_t / sim_t[-1])))
    shape = ShapeInfo(kind="box", dims=(1.0, 1.0, 1.0), label="box with the top's inertia")
    return FramePlan(spec=spec, video_t=video_t, sim_t=sim_t, panels=panels, units="cgs", body_name="DAST cube",
                     shape=shape, d_body=d_body, spin_mode="slowed", slowdown=np.full(F, 1.3e15),
                     time_scale=("Θ", 3.2 * U.DAY), phase_resolved=False)


def picture_of(plan):
    return plan_picture(plan, Fonts.for_height(plan.spec.size[1]))


SLOW_SCENES = {"dast_box"}       # ~2 s to plan (two averaged runs of ~4e15 turns, 480 frames): with the slow tests


def scene_stems():
    """The shipped scenes' stems, the slow ones marked."""
    return [pytest.param(p.stem, marks=pytest.mark.slow) if p.stem in SLOW_SCENES else p.stem for p in SCENES]


class _Pictures(dict):
    """Each shipped scene planned at 640x360 when first asked for (simulated once; no GL)."""

    def __missing__(self, stem):
        self[stem] = pic = picture_of(pipeline.plan(next(p for p in SCENES if p.stem == stem), size=(640, 360)))
        return pic


@pytest.fixture(scope="module")
def scene_pictures():
    """The shipped scenes' pictures, planned on first use."""
    return _Pictures()


# --- frame times -----------------------------------------------------------------------------
def test_frame_times_follow_the_time_map_and_its_inverse():
    """Linear: t = t_end v / duration; log: t = k ((1 + t_end/k)^(v/duration) - 1) with the knee
    k = t_end / 1000; the last frame is exactly t_end, and spec.video_fraction inverts the map."""
    t_end = 7.3e5
    lin = RenderSpec(duration=3.0, fps=20)
    v, t, slope = frame_times(lin, t_end)
    assert v.size == 60 and t[-1] == t_end
    np.testing.assert_allclose(t, t_end * v / 3.0, rtol=1e-15)
    np.testing.assert_allclose(slope, t_end / 3.0)
    log = RenderSpec(duration=3.0, fps=20, time_map="log")
    v, t, slope = frame_times(log, t_end)
    k = t_end / 1000
    assert t[0] == 0.0 and t[-1] == t_end and np.all(np.diff(t) > 0)
    np.testing.assert_allclose(t[:-1], k * ((1 + t_end / k) ** (v[:-1] / 3.0) - 1), rtol=1e-12)
    np.testing.assert_allclose(slope[1:-1], np.gradient(t, v)[1:-1], rtol=0.02)
    frac = np.array([log.video_fraction(x, t_end) for x in t])
    np.testing.assert_allclose(frac, v / 3.0, atol=1e-12)
    assert lin.video_fraction(t_end / 4, t_end) == 0.25


# --- the camera ------------------------------------------------------------------------------
@pytest.mark.parametrize("stem", scene_stems())
def test_the_camera_keeps_every_frame_in_view_and_fills_it(scene_pictures, stem):
    """Every frame's drawn content -- arrow tips from the planned poses, the body's bounding
    sphere, the cage and the axes -- projects inside the 3-D view with EDGE_PX free at each
    side; and the fit is tight: the content stays within the margin it was fitted to, and
    along the limiting axis reaches it within a pixel (a camera merely far away would not)."""
    pic = scene_pictures[stem]
    cam, lay = pic.camera, pic.layout
    for k, poses in enumerate(pic.stage.poses):
        x0, y0, x1, y1 = lay.views[k]
        tips = [rot[:, :, 0] * length[:, None] for key, (rot, length) in
                ((key, p) for key, p in poses.items() if key in ("dipole", "L", "omega"))]
        pts = np.vstack(tips + [content_points(pic.plan)])
        px = pic.project(k, pts)
        assert px[:, 0].min() >= x0 + EDGE_PX - 0.5 and px[:, 0].max() <= x1 - EDGE_PX + 0.5, stem
        assert px[:, 1].min() >= y0 + EDGE_PX - 0.5 and px[:, 1].max() <= y1 - EDGE_PX + 0.5, stem
    if pic.plan.spec.zoom == 1.0:
        w, h = lay.views[0][2] - lay.views[0][0], lay.views[0][3] - lay.views[0][1]
        lo, hi = cam.extent(content_points(pic.plan), cam.distance)
        fill = np.array([(hi[0] - lo[0]) / 2, (hi[1] - lo[1]) / 2])
        border = np.array([EDGE_PX + 1.4 * 0.9 * lay.sizes.size, EDGE_PX + 0.6 * 0.9 * lay.sizes.size]) \
            if "axes" in pic.plan.spec.show else np.array([EDGE_PX, EDGE_PX])
        target = 1.0 - np.minimum(0.5, 0.02 + 2 * border / np.array([w, h]))
        slack_px = (target - fill) * np.array([w, h]) / 2
        assert np.all(slack_px > -0.5) and slack_px.min() < 1.0, (stem, fill, target)


def test_narrowed_views_are_even_centred_and_share_one_camera(scene_pictures):
    """A view narrower than its panel (GL pixels cost) is centred in it, and both panels of a
    two-model scene use one camera, so the same world point lands at the same place in each."""
    pic = scene_pictures["default"]
    lay = pic.layout
    for k, (x0, _, x1, _) in enumerate(lay.views):
        assert (x1 - x0) % 2 == 0 and x1 - x0 <= lay.panel_width
        assert abs((x0 - lay.panel_x(k)) - (lay.panel_x(k) + lay.panel_width - x1)) <= 1
    a, b = pic.project(0, [0.3, -0.2, 0.5])[0], pic.project(1, [0.3, -0.2, 0.5])[0]
    np.testing.assert_allclose(b - a, [lay.views[1][0] - lay.views[0][0], 0.0], atol=1e-9)


def test_camera_fit_is_solved_not_guessed():
    """Points on a ring seen edge-on fit the view's width to the margin asked for."""
    ring = np.c_[np.cos(np.linspace(0, 2 * np.pi, 50)), np.sin(np.linspace(0, 2 * np.pi, 50)), np.zeros(50)]
    cam = Camera([1.0, 0.0, 0.0], 16 / 9, ring, (0.1, 0.1))
    lo, hi = cam.extent(ring, cam.distance)
    assert max((hi - lo) / 2 / 0.9) == pytest.approx(1.0, abs=2e-4)


# --- the layout of text ----------------------------------------------------------------------
def _ink(fonts, text, xy, role, anchor):
    """The box Pillow's glyphs of ``text`` cover when stamped at ``xy`` (as the HUD stamps it)."""
    l, t, r, b = fonts.font(role).getbbox(text, anchor=anchor)
    x, y = int(xy[0]), int(xy[1])
    return (x + l, y + t, x + r, y + b)


def _texts_at(pic, f):
    """(text, ink box, clip) of every text on frame f: static, inset labels, per-frame lines."""
    fonts = Fonts(pic.layout.sizes)
    items = [t for t in pic.overlay.static if isinstance(t, Text)]
    items += pic.overlay.inset.labels if pic.overlay.inset is not None else []
    items += [Text(line.texts[f], line.xy, line.color, line.anchor, "small", line.clip) for line in pic.overlay.lines]
    return [(t.text, _ink(fonts, t.text, t.xy, t.role, t.anchor), t.clip) for t in items if t.text]


def _overlap(a, b):
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


@pytest.mark.parametrize("stem", scene_stems())
def test_text_boxes_are_disjoint_and_whole_inside_the_frame(scene_pictures, stem):
    """At 640x360, on the first, middle and last frames: no two texts' ink overlaps, and no text
    is cut -- each lies whole inside its clip box (a panel, a legend chip) and the frame."""
    pic = scene_pictures[stem]
    W, H = pic.size
    F = pic.frames
    for f in (0, F // 2, F - 1):
        boxes = _texts_at(pic, f)
        for text, box, clip in boxes:
            cx0, cy0, cx1, cy1 = clip or (0, 0, W, H)
            assert max(0, cx0) <= box[0] and box[2] <= min(W, cx1), (stem, f, text, box, clip)
            assert max(0, cy0) <= box[1] and box[3] <= min(H, cy1), (stem, f, text, box, clip)
        for i, (ta, a, _) in enumerate(boxes):
            for tb, b, _ in boxes[i + 1:]:
                assert not _overlap(a, b), (stem, f, ta, a, tb, b)


@pytest.mark.parametrize("stem", scene_stems())
def test_the_time_never_runs_into_its_bar(scene_pictures, stem):
    """The bar starts after the widest time text of 40 sampled frames: every frame's time text
    ends left of it, and the scale text starts right of it; the fill grows from one column at
    the first frame to the whole bar at the last."""
    pic = scene_pictures[stem]
    bar = pic.overlay.bar
    if bar is None:
        pytest.skip("no time bar at this size")
    fonts = Fonts(pic.layout.sizes)
    time_line = next(line for line in pic.overlay.lines if line.xy == (pic.layout.pad, bar.y + bar.h // 2))
    right = max(_ink(fonts, t, time_line.xy, "small", "lm")[2] for t in time_line.texts)
    assert right <= bar.x0, (stem, right, bar.x0)
    assert bar.cuts[0] == 1 and bar.cuts[-1] == bar.x1 - bar.x0 and np.all(np.diff(bar.cuts) >= 0)


def test_type_is_legible_at_360_rows_and_scales_with_the_frame():
    """15 px body text and 18 px headings at 360 rows, twice that at 720; never below 8 px.  At
    640x360 the subtitles take two lines and the title goes (the 3-D view keeps half the
    height); at 960x360 they fit on one and the title stays."""
    assert TextSizes.for_height(360) == TextSizes(size=15, heading_size=18, line=19, heading_line=24)
    assert TextSizes.for_height(720) == TextSizes(size=30, heading_size=36, line=38, heading_line=47)
    assert TextSizes.for_height(96).size == 8
    pic = picture_of(made_plan())
    lay = pic.layout
    assert lay.sizes.size >= 14 and lay.text
    assert [r.kind for r in lay.rows] == ["legend", "timebar", "notes"]
    assert [len(items) for items in lay.headings] == [3, 3]                # heading and two subtitle lines
    wide = picture_of(made_plan(size=(960, 360))).layout
    assert [r.kind for r in wide.rows] == ["legend", "timebar", "notes", "title"]
    assert [len(items) for items in wide.headings] == [2, 2]
    assert lay.views[0][3] - lay.views[0][1] >= 0.5 * 360                 # the 3-D view keeps half the height


def test_small_frames_drop_the_least_needed_bands_first():
    """At 320x120 the title, subtitles, notes and legend go; the time bar, the numbers and the
    headings stay, and the 3-D view keeps half the height."""
    lay = picture_of(made_plan(size=(320, 120))).layout
    assert [r.kind for r in lay.rows] == ["timebar"]
    assert [[role for _, role, _, _ in items] for items in lay.headings] == [["main"], ["main"]]
    assert lay.readout_lines == 2
    assert lay.views[0][3] - lay.views[0][1] >= 0.5 * 120


# --- words, colours, poses -------------------------------------------------------------------
def test_the_words_of_each_frame():
    """Outreach register: the time in people's units, the spin rate in words, the angle, the
    slowed spin's factor, a bar marked in whole Theta; physics register: symbols and powers."""
    plan = made_plan()
    texts = texts_of(plan)
    F = plan.frames
    assert texts.time[0] == "start, 0 s" and texts.time[-1] == "after 10 days"
    assert texts.readouts[0][0] == ["turns 5 billion times a second", "angle d–L = 30°"]
    assert texts.readouts[1][-1][0] == "turns 2.5 billion times a second"
    assert texts.notes[F // 2] == ["spin shown 1.3 × 10¹⁵ times slower"]
    assert texts.scale == "Θ = 3.2 days"
    np.testing.assert_allclose([p for p, _ in texts.bar_ticks], [1 / 3.125, 2 / 3.125, 3 / 3.125])
    assert [label for _, label in texts.bar_ticks] == ["1 Θ", "2 Θ", "3 Θ"]
    assert texts.headings == [("Reduced equation", "(2.2)+(2.3)"), ("Truncated equation", "(2.5)")]
    assert texts.legend == [("dipole", "d", "dipole"), ("L", "L", "angular momentum"), ("omega", "Ω", "rotation"),
                            ("body", "box", "with the top's inertia")]
    phys = texts_of(made_plan(captions="physics"))
    assert phys.readouts[0][0] == ["|Ω| = 3.14 × 10¹⁰ rad/s", "∠(d, L) = 30°"]
    assert phys.time[-1] == "t = 10 days = 3.12 Θ" and phys.notes[0] == ["spin shown slowed 1.3 × 10¹⁵×"]
    log = texts_of(made_plan(time_map="log"))
    assert log.notes[0] == ["spin shown 1.3 × 10¹⁵ times slower", "log time: ticks 10× apart"]
    assert [label for _, label in log.bar_ticks] == ["0.01 Θ", "0.1 Θ", "1 Θ"]        # decades from the knee


def test_colours_of_chips_headings_and_trail():
    """Legend chips carry each arrow's colour (and a darker body colour); headings the model's
    colour on white and the foreground on black; the trail fades from near the background
    to the dipole's red."""
    th = theme("white", "DAST cube")
    assert th.chips == {"dipole": (219, 20, 61), "omega": (31, 89, 217), "L": (26, 148, 64), "body": (147, 80, 24)}
    white, black = picture_of(made_plan()), picture_of(made_plan(background="black"))
    heads = [t for t in white.overlay.static if isinstance(t, Text) and t.role == "main"]
    assert [h.color for h in heads] == [(0, 128, 128), (136, 60, 180)]
    heads = [t for t in black.overlay.static if isinstance(t, Text) and t.role == "main"]
    assert [h.color for h in heads] == [(235, 235, 235)] * 2
    chips = [m for m in white.overlay.static if isinstance(m, Fill) and m.color in th.chips.values()]
    assert [c.color for c in chips] == [(219, 20, 61), (26, 148, 64), (31, 89, 217), (147, 80, 24)]
    assert all(a.box[2] < b.box[0] for a, b in zip(chips, chips[1:]))          # side by side, apart
    trail = white.stage.trail_rgb
    assert tuple(trail[-1]) == (219, 20, 61) and tuple(trail[0]) == (252, 240, 243)
    assert tuple(black.stage.trail_rgb[0]) == (15, 4, 6)


def test_poses_point_the_arrows_along_their_vectors():
    """The planned rotation of each arrow takes +x onto its vector; the body's rotation is the
    display orientation; Omega's arrow shortens as |Omega| falls (half at the end here)."""
    pic = picture_of(made_plan())
    for k, panel in enumerate(pic.plan.panels):
        poses = pic.stage.poses[k]
        R = poses["body"]
        np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
        np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
        for key in ("dipole", "L", "omega"):
            rot, length = poses[key]
            v = getattr(panel, ARROW_VECTORS[key])
            np.testing.assert_allclose(rot[:, :, 0], v / np.linalg.norm(v, axis=1, keepdims=True), atol=1e-12)
    _, length = pic.stage.poses[1]["omega"]
    assert length[0] == arrow_length("omega", 1.0) == 1.6
    assert length[-1] == pytest.approx(arrow_length("omega", 0.5)) == pytest.approx(0.55 + 1.05 * 0.5)
    _, length = pic.stage.poses[1]["dipole"]
    assert np.all(length == 1.0)


@pytest.mark.slow
def test_planning_needs_no_drawing_library():
    """A picture is planned -- words, layout, camera, poses -- in a process that never loads
    Pillow, VTK, pyvista, imageio or matplotlib (text widths from a stand-in metrics)."""
    code = f"""
import sys
sys.path.insert(0, {str(ROOT)!r})
from spinviz import pipeline
from spinviz.rendering.layout import TextSizes
from spinviz.rendering.picture import plan_picture

class Mono:
    sizes = TextSizes.for_height(360)
    def width(self, text, role="small"):
        return 0.6 * (self.sizes.heading_size if role == "main" else self.sizes.size) * len(text)

pic = plan_picture(pipeline.plan("scenes/default.toml", size=(640, 360)), Mono())
assert pic.overlay.bar is not None and len(pic.stage.labels) == 6
print(sorted(m for m in ("PIL", "vtk", "vtkmodules", "pyvista", "imageio", "matplotlib") if m in sys.modules))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


# --- the power inset --------------------------------------------------------------
def _rows_of(value_w, box, scale):
    """The pixel row (float) of a power ``value_w`` (W) in a log plot ``box`` of ``scale``."""
    _, lo, hi = scale
    return box[3] - 1 - (math.log10(value_w) - lo) / (hi - lo) * (box[3] - box[1] - 1)


def test_power_plot_is_planned_in_watts_on_whole_decades_and_lines_up_with_the_time_bar():
    """show = [..., "power"]: one log plot of P in W (the plan keeps erg/s) over whole decades,
    1.5e-17 W at the start down to 1.5e-23 W (reduced) -> 10^-23 .. 10^-16; each model's curve
    and dot in its colour at the row its log P says; the reduced curve ends far below the
    truncated one; alone, the plot spans the time bar's columns, so its cursor is the bar's
    cursor column at every frame; faint rules at the six inner decades and at the bar's ticks."""
    plan = made_plan(show=ALL_SHOWN + ("power",))
    pic = picture_of(plan)
    inset, bar = pic.overlay.inset, pic.overlay.bar
    assert [r.kind for r in pic.layout.rows][0] == "inset" and inset.plots == ("power",)
    assert inset.scales == [("log", -23, -16)]
    box = inset.boxes[0]
    assert (box[0], box[2]) == (bar.x0, bar.x1)
    np.testing.assert_array_equal(inset.cursor[0], bar.x0 + bar.cuts - 1)      # the bar draws its cursor there
    texts = {t.text: t for t in inset.labels}
    assert texts["radio power (W)"].xy == (box[0], pic.layout.rows[0].y)
    assert texts["10⁻¹⁶"].anchor == "ra" and texts["10⁻²³"].anchor == "rd"
    assert [t.text for t in inset.labels if t.color in ((0, 128, 128), (136, 60, 180))] == ["truncated", "reduced"]
    curves = [sh for sh in inset.shapes if sh[0] == "curve"]
    assert [c[1] for c in curves] == [(0, 128, 128), (136, 60, 180)]
    s = plan.sim_t / plan.sim_t[-1]
    for (color, _, rows), panel in zip(inset.dots, plan.panels):
        assert color == model_style(panel.model).color
        want = [_rows_of(1.5e-17 * 10.0 ** (-POWER_DECADES_FALL[panel.model] * x), box, inset.scales[0]) for x in s]
        np.testing.assert_allclose(rows, want, atol=0.5)
        np.testing.assert_allclose(panel.power[0], 1.5e-10)                      # erg/s in the plan
    reduced, truncated = (rows for _, _, rows in inset.dots)
    assert reduced[0] == truncated[0] and reduced[-1] - truncated[-1] > 0.5 * (box[3] - box[1])
    rules = [sh[2] for sh in inset.shapes if sh[0] == "rule"]
    across = sorted(r[1] for r in rules if r[1] == r[3])
    down = sorted(r[0] for r in rules if r[0] == r[2])
    assert len(across) == 6
    np.testing.assert_allclose(across, sorted(_rows_of(10.0 ** e, box, inset.scales[0]) for e in range(-22, -16)),
                               atol=0.5)
    assert down == [bar.x0 + x for x, _, _ in bar.ticks]
    phys = picture_of(made_plan(show=ALL_SHOWN + ("power",), captions="physics"))
    assert "P (W)" in [t.text for t in phys.overlay.inset.labels]


def test_power_beside_the_other_plots_and_for_a_single_model():
    """With "inset" too the row holds three plots side by side, left to right angle, |Omega|,
    power, disjoint and inside the frame; a single-model scene draws one power curve and one dot;
    a panel that radiates nothing (P = 0) sits on the bottom edge."""
    plan = made_plan(show=ALL_SHOWN + ("inset", "power"))
    inset = picture_of(plan).overlay.inset
    assert inset.plots == ("angle", "omega", "power") and [k for k, _, _ in inset.scales] == ["linear", "linear", "log"]
    for a, b in zip(inset.boxes, inset.boxes[1:]):
        assert a[2] < b[0]
    assert inset.boxes[0][0] > 0 and inset.boxes[-1][2] <= plan.spec.size[0]
    plan.panels = plan.panels[:1]
    plan.panels[0].power = np.zeros(plan.frames)
    one = picture_of(plan).overlay.inset
    power_dots = [rows for _, j, rows in one.dots if j == 2]
    assert len(power_dots) == 1 and len([sh for sh in one.shapes if sh[0] == "curve"]) == 3
    assert one.scales[2] == ("log", -1, 0) and np.all(power_dots[0] == one.boxes[2][3] - 1)


def test_the_band_names_the_radiation_for_people():
    """"radio power" at the DAST cube's 7 GHz; infrared and light for faster spins."""
    from spinviz.rendering.captions import decade, radiation_band

    assert radiation_band(2 * np.pi * 7.07e9) == "radio"
    assert radiation_band(2 * np.pi * 1e13) == "infrared" and radiation_band(2 * np.pi * 1e15) == "light"
    assert (decade(-17), decade(0), decade(1), decade(3)) == ("10⁻¹⁷", "1", "10", "10³")


def test_small_frames_drop_the_power_inset_and_keep_text_apart():
    """At 320x180 the inset row goes (with the title and subtitles) and the 3-D view keeps
    half the height; at 640x360 it stays, above the legend, and its texts -- title, decades,
    model names -- overlap nothing on the first, middle and last frames.  A subtitle cut to one
    line to make room ends with an ellipsis."""
    small = picture_of(made_plan(size=(320, 180), show=ALL_SHOWN + ("power",)))
    assert small.overlay.inset is None and "inset" not in [r.kind for r in small.layout.rows]
    assert small.layout.views[0][3] - small.layout.views[0][1] >= 0.5 * 180
    pic = picture_of(made_plan(show=ALL_SHOWN + ("inset", "power")))
    assert [r.kind for r in pic.layout.rows][:2] == ["inset", "legend"]
    W, H = pic.size
    for f in (0, pic.frames // 2, pic.frames - 1):
        boxes = _texts_at(pic, f)
        for i, (ta, a, _) in enumerate(boxes):
            assert 0 <= a[0] and a[2] <= W and 0 <= a[1] and a[3] <= H, (ta, a)
            for tb, b, _ in boxes[i + 1:]:
                assert not _overlap(a, b), (f, ta, a, tb, b)
    subtitle = [text for text, role, _, _ in pic.layout.headings[0] if role == "small"]
    assert len(subtitle) == 1 and subtitle[0].endswith("…"), subtitle


@pytest.mark.parametrize("size, kept", [((720, 720), ("angle", "omega")), ((1080, 1920), ("angle",))])
def test_a_narrow_frame_keeps_the_plots_that_fit(size, kept):
    """Type scales with the height, so a square or portrait frame has room for fewer plots side
    by side: the rightmost go first, and each kept plot's title stays inside its own column --
    it ends before the next plot's labels begin."""
    pic = picture_of(made_plan(size=size, show=ALL_SHOWN + ("inset", "power")))
    inset = pic.overlay.inset
    assert inset.plots == kept
    fonts = Fonts(pic.layout.sizes)
    titles = [t for t in inset.labels if t.text in texts_of(pic.plan).plot_titles.values()]
    assert len(titles) == len(kept)
    for (bx0, _, bx1, _), t in zip(inset.boxes, titles):
        assert t.xy[0] == bx0 and bx0 + fonts.width(t.text) <= bx1, (t.text, inset.boxes)
    assert picture_of(made_plan(size=size, show=ALL_SHOWN + ("power",))).overlay.inset.plots == ("power",)


def test_the_parent_computes_the_power_once_per_trajectory(monkeypatch):
    """plan_frames calls trajectory.radiated_power once per run, with that run sampled at the
    frame times, and keeps its values (erg/s) in the plan: the render workers only draw them.
    A scene that does not show the power never computes it."""
    from spinviz import trajectory
    from spinviz.inputs.scene_spec import load_scene
    from spinviz.rendering import timeline

    calls = []

    def spy(trajs, times=None):
        calls.append((len(trajs), trajs[0].t.size))
        return trajectory.radiated_power(trajs, times)

    monkeypatch.setattr(timeline, "radiated_power", spy)
    plan = pipeline.plan(ROOT / "scenes" / "default.toml", size=(320, 180), fps=10, duration=1.0)
    assert "power" in plan.spec.show and calls == [(1, 10), (1, 10)]
    sc = load_scene(ROOT / "scenes" / "default.toml")
    runs = pipeline.scene_trajectories(sc, plan.spec)
    for panel, run in zip(plan.panels, runs):
        np.testing.assert_allclose(panel.power, run.radiated_power(), rtol=1e-12)
    assert plan.panels[0].power[-1] < 1e-3 * plan.panels[1].power[-1]       # the reduced cube goes dark (2.6e-4)
    calls.clear()
    pipeline.plan(ROOT / "scenes" / "dast_family1.toml", size=(320, 180), fps=10, duration=1.0)
    assert calls == []


def test_coarse_runs_with_unresolved_phase_are_drawn_from_their_slow_geometry():
    """The cellulose rod's secular runs stored at 200 instants 1e12 s apart (the phase
    unresolved): the frames between them show the slow motion -- |Omega| within 1e-3 of the
    plan of the scene itself, simulated at the frame times -- not Hermite steps with an
    Omega_dot that turns with the precession ~1e22 times between nodes."""
    import spinviz

    sc = spinviz.load_scene(ROOT / "scenes" / "cellulose_rod.toml")
    runs = [spinviz.simulate(sc.body, m, sc.omega0, t_end=sc.t_end, samples=200, q0=sc.q0) for m in sc.models]
    assert not any(r.phase_resolved for r in runs)
    coarse = pipeline.plan(runs, fps=4, duration=2.0)
    fine = pipeline.plan(sc, fps=4, duration=2.0)
    for a, b in zip(coarse.panels, fine.panels):
        np.testing.assert_allclose(a.omega_mag, b.omega_mag, rtol=1e-3)


def test_an_asymmetric_tumbling_is_shown_slowed_with_its_polhode_and_L_exact():
    """An asymmetric body whose phase is not resolved (as after 1e15 turns): the spin mode is
    "slowed", and at every frame the shown state lies on the simulated polhode (|L|^2 and 2E the
    same) with L_world in the simulated direction -- only the two phases of the tumbling are
    re-timed."""
    from spinviz.physics import bodies as B
    from spinviz.physics import polhode as PH
    from spinviz.rendering.timeline import plan_frames
    from spinviz.trajectory import Trajectory

    J = (1.0, 1.36, 1.64)
    body = B.custom(J, (0.82, 0.0, 0.57), units="dimensionless")
    pol = PH.polhode_of(J, np.array([0.3, 0.5, 0.81]))
    t = np.linspace(0.0, 100.0, 21)
    u = np.linspace(0.0, 40.0, t.size) ** 1.3                       # phases at random, as an averaged run leaves them
    q_L = np.array([0.9, 0.1, -0.2, 0.1]) / np.linalg.norm([0.9, 0.1, -0.2, 0.1])
    w, q = pol.pose(q_L, 3.0 * u, u)
    tr = Trajectory(t=t, omega=w * (1.0 - 0.01 * t[:, None] / 100.0), q=q, body=body, model="reduced",
                    stats={"phases_resolved": False})
    spec = RenderSpec(duration=2.0, fps=10, size=(320, 180), show=("body", "dipole", "omega", "L", "hud"))
    plan = plan_frames(spec, [tr])
    assert plan.spin_mode == "slowed"
    s = tr.sample(plan.sim_t)
    panel = plan.panels[0]
    L_sim = s.angular_momentum_world()
    cos = np.sum(panel.L_world * L_sim, axis=1) / (np.linalg.norm(panel.L_world, axis=1) * np.linalg.norm(L_sim, axis=1))
    assert np.all(cos > 1.0 - 1e-12)
    w_shown = np.einsum("fji,fj->fi", panel.R_world_from_body, panel.omega_world) * np.linalg.norm(tr.omega[0])
    Jv = np.asarray(J)
    np.testing.assert_allclose(np.sum((Jv * w_shown) ** 2, axis=1), np.sum((Jv * s.omega) ** 2, axis=1), rtol=1e-10)
    np.testing.assert_allclose(np.sum(Jv * w_shown**2, axis=1), np.sum(Jv * s.omega**2, axis=1), rtol=1e-10)
