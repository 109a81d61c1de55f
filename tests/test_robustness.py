"""Bad input and odd corners: one line and exit 2, never a traceback or a stray file."""

import math
import os
from pathlib import Path

import numpy as np
import pytest

from spinviz.atomic import AtomicPath
from spinviz.commands import main
from spinviz.driver import simulate
from spinviz.physics import bodies as B
from spinviz.physics import presets as P

SCENES = Path(__file__).resolve().parents[1] / "scenes"

TINY = """
[body]
{body}
[initial]
omega = [0.0, 0.05, 0.1]
[simulation]
{sim}
t_end = 50.0
samples = 6
[render]
duration = 1.0
fps = 8
size = [96, 48]
show = ["dipole"]
"""


def scene(tmp_path, body='delta = 0.3\nchi = 0.5', sim='model = "reduced"', name="s.toml"):
    p = tmp_path / name
    p.write_text(TINY.format(body=body, sim=sim))
    return p


def one_line_error(capsys, argv, contains):
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert "\n" not in err and "Traceback" not in err, err
    assert contains in err, err
    return err


def test_binary_file_as_scene(tmp_path, capsys):
    p = tmp_path / "picture.png"
    p.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe\x00")
    one_line_error(capsys, ["info", p], "(file): not a text (UTF-8) file")


def test_preset_name_and_density_are_used(tmp_path):
    from spinviz.inputs.scene_spec import load_scene

    sc = load_scene(scene(tmp_path, body='preset = "cellulose_rod"\nname = "my rod"\ndensity = 1.5'))
    assert sc.body.name == "my rod"
    assert sc.body.extra["density"] == 1.5
    assert sc.body.I1 == pytest.approx(P.cellulose_rod().I1 * 1.5 / 1.6, rel=1e-12, abs=0)


def test_failed_write_leaves_no_new_directories(tmp_path):
    target = tmp_path / "a" / "b" / "out.mp4"
    t = AtomicPath(target)
    assert (tmp_path / "a" / "b").is_dir()
    t.discard()
    assert list(tmp_path.iterdir()) == []


def test_atomic_path_that_cannot_make_its_temporary_file_leaves_no_directories(tmp_path, monkeypatch):
    import tempfile

    def refuse(*a, **k):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(PermissionError):
        AtomicPath(tmp_path / "a" / "b" / "out.mp4")
    assert list(tmp_path.iterdir()) == []


def test_scene_method_needing_a_step_is_one_line(tmp_path, capsys):
    p = scene(tmp_path, body='delta = 0.3\nchi = 0.0', sim='models = ["reduced", "truncated"]\nmethod = "split4"')
    one_line_error(capsys, ["compare", p, "--out", tmp_path / "c"], "is fixed-step: give step > 0")
    one_line_error(capsys, ["simulate", p, "--out", tmp_path / "x.npz"], "is fixed-step: give step > 0")


def test_render_width_not_divisible_by_panels(tmp_path, capsys):
    p = scene(tmp_path, sim='models = ["reduced", "truncated"]')
    one_line_error(capsys, ["render", p, "--out", tmp_path / "x.gif", "--size", "97x48"], "need a width divisible by 2")
    assert not (tmp_path / "x.gif").exists()


@pytest.mark.parametrize("opt, value, reason", [
    ("--fps", "0", "must lie in [1, 240], got 0"), ("--fps", "1000", "must lie in [1, 240], got 1000"),
    ("--duration", "-5", "must lie in (0, 3600], got -5"), ("--duration", "inf", "must be finite"),
    ("--duration", "4000", "must lie in (0, 3600], got 4000"), ("--size", "8x600", "must be [width, height] in pixels"),
    ("--workers", "-1", "must be at least 1, got -1"), ("--workers", "1000", "must be at most"),
])
def test_render_option_ranges(tmp_path, capsys, opt, value, reason):
    """Out-of-range overrides are refused by the render spec (the one place render inputs are
    validated), named by their option, in one line with exit 2; nothing is written."""
    p = scene(tmp_path)
    one_line_error(capsys, ["render", p, opt, value, "--out", tmp_path / "x.mp4"], f"{opt}: {reason}")
    assert sorted(q.name for q in tmp_path.iterdir()) == [p.name]


def test_render_workers_not_a_number(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:                    # not a number at all: argparse says so
        main(["render", str(scene(tmp_path)), "--workers", "two"])
    assert e.value.code == 2 and "argument --workers: expected a whole number, got 'two'" in capsys.readouterr().err


def test_sample_keeps_the_slow_frame_with_four_samples():
    """With exactly four stored instants the (4,) q_L must not be taken for a time series."""
    cube = P.dast_cube()
    W = math.pi * 1e10
    tr = simulate(cube, "reduced", (0.0, W, W), t_end=1.0 / (cube.tau0 * W * W), samples=4)
    assert tr.stats["method"] == "secular"
    s = tr.sample(tr.t)
    np.testing.assert_array_equal(s.slow["q_L"], tr.slow["q_L"])


def test_method_names_are_case_insensitive_and_unknown_ones_are_value_errors():
    body = B.symmetric_top(0.3, 0.5)
    a = simulate(body, "reduced", (0.0, 0.05, 0.1), t_end=10.0, samples=3, method="AUTO")
    assert a.stats["method"] == "taylor"
    with pytest.raises(ValueError, match="unknown method 'rk99'"):
        simulate(body, "reduced", (0.0, 0.05, 0.1), t_end=10.0, samples=3, method="rk99")


def test_truncated_start_beyond_the_singular_surface_is_one_line(tmp_path, capsys):
    """(2.5) at 1 + (g x Omega).J^-1 g < 0 (tau0 |Omega| ~ 1): the run is refused in one line
    naming the scene and the singularity, exit 1 (a run that cannot be done, not a typo)."""
    p = tmp_path / "singular.toml"
    p.write_text(TINY.format(body="inertia = [1.0, 1.0, 0.3]\ndipole = [0.6, 0.0, 0.8]", sim='model = "truncated"')
                 .replace("omega = [0.0, 0.05, 0.1]", "omega = [0.3, -0.8937, 0.2]"))
    code = main(["simulate", str(p), "--out", str(tmp_path / "t.npz")])
    err = capsys.readouterr().err.strip()
    assert code == 1 and "\n" not in err and "Traceback" not in err
    assert str(p) in err and "(2.5) is singular at the initial state" in err
    assert not (tmp_path / "t.npz").exists()


def test_a_group_of_outputs_lands_together_even_when_a_rename_fails(tmp_path, monkeypatch):
    """The second rename of a group fails: the first output is put back as it was."""
    from spinviz.atomic import Outputs

    a, b = tmp_path / "v.mp4", tmp_path / "v.png"
    a.write_bytes(b"old video")
    b.write_bytes(b"old poster")
    real = os.replace
    calls = []

    def flaky(src, dst):
        calls.append(dst)
        if str(dst) == str(b) and len(calls) == 2:
            raise OSError(28, "No space left on device")
        return real(src, dst)

    monkeypatch.setattr(os, "replace", flaky)
    with pytest.raises(OSError, match="No space left"):
        with Outputs([a, b]) as (ta, tb):
            open(ta, "wb").write(b"new video")
            open(tb, "wb").write(b"new poster")
    assert a.read_bytes() == b"old video" and b.read_bytes() == b"old poster"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.mp4", "v.png"]


@pytest.mark.slow
def test_a_crashing_render_worker_fails_the_render_in_one_line(tmp_path):
    """A render worker whose drawing stack cannot load (here: a vtkmodules that raises, as a
    missing libGL would) ends the render with exit status 1 and one line naming the worker and
    the cause; nothing is left in the output folder (no video, poster, segment or temp file)."""
    import subprocess
    import sys

    fake = tmp_path / "fake"
    (fake / "vtkmodules").mkdir(parents=True)
    (fake / "vtkmodules" / "__init__.py").write_text('raise ImportError("libGL.so.1: cannot open (simulated)")\n')
    out = tmp_path / "out"
    out.mkdir()
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(fake), str(root)]))
    r = subprocess.run([sys.executable, "-m", "spinviz", "render", str(root / "scenes" / "askew_example.toml"),
                        "--out", str(out / "a.mp4"), "--size", "160x90", "--duration", "1", "--fps", "10",
                        "--workers", "2"], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr
    assert "render worker" in lines[0] and "ImportError: libGL.so.1: cannot open (simulated)" in lines[0]
    assert list(out.iterdir()) == []
