"""Standard streams and echoed text: a closed or full stdout or stderr never
costs the output file nor crashes a command, and every name echoed to the terminal is one
escaped line.  Each test here failed on the code before."""

import errno
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spinviz
from spinviz.commands import main

ROOT = Path(__file__).resolve().parents[1]
SCENE = """
[body]
delta = 0.3
chi = 0.7
[initial]
omega = [0.0, 0.05, 0.3]
[simulation]
model = "reduced"
t_end = 50.0
samples = 6
[render]
duration = 1.0
fps = 8
size = [64, 48]
show = ["dipole", "hud"]
"""


def scene(tmp_path) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(SCENE)
    return p


def spinviz_cmd(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, close=(), env=None):
    """``python -m spinviz ARGS`` with the given streams; ``close``: descriptors closed in the
    child before it starts (as ``>&-`` does)."""
    def closer():
        for fd in close:
            os.close(fd)

    return subprocess.run([sys.executable, "-m", "spinviz", *args], stdout=stdout, stderr=stderr, cwd=ROOT,
                          preexec_fn=closer if close else None, timeout=600,
                          env={**os.environ, "PYTHONIOENCODING": "utf-8:strict", **(env or {})})


@pytest.mark.slow
def test_a_closed_stdout_gives_one_line_and_keeps_the_output(tmp_path):
    """Closed stdout: an AttributeError traceback.  Now: the output is written, stderr says
    in one line that the report could not be, exit status 1 (as a Unix tool does)."""
    r = spinviz_cmd(["methods"], stdout=None, close=(1,))
    assert (r.returncode, r.stderr.decode()) == (1, "spinviz: cannot write to standard output: Bad file descriptor\n")
    out = tmp_path / "t.npz"
    r = spinviz_cmd(["simulate", str(scene(tmp_path)), "--out", str(out)], stdout=None, close=(1,))
    assert (r.returncode, r.stderr.decode()) == (1, "spinviz: cannot write to standard output: Bad file descriptor\n")
    assert spinviz.Trajectory.load(out).t.size == 6
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "t.npz"]


@pytest.mark.slow
def test_a_full_stdout_names_the_stream_and_keeps_the_output(tmp_path):
    """stdout on a full device (``> /dev/full``): one line naming standard output and the
    reason, exit status 1; the trajectory is on disk."""
    out = tmp_path / "t.npz"
    with open("/dev/full", "w") as full:
        r = spinviz_cmd(["simulate", str(scene(tmp_path)), "--out", str(out)], stdout=full)
    assert (r.returncode, r.stderr.decode()) == (1, "spinviz: cannot write to standard output: No space left on device\n")
    assert spinviz.Trajectory.load(out).t.size == 6


@pytest.mark.slow
@pytest.mark.parametrize("how", ["closed", "full"])
def test_a_closed_or_full_stderr_never_costs_the_video(tmp_path, how):
    """``2>/dev/full`` or a closed stderr never costs the video: the progress bar, which cannot
    be drawn, is skipped and the video is made."""
    out = tmp_path / "v.gif"
    args = ["render", str(scene(tmp_path)), "--out", str(out)]
    if how == "closed":
        r = spinviz_cmd(args, stderr=None, close=(2,))
    else:
        with open("/dev/full", "w") as full:
            r = spinviz_cmd(args, stderr=full)
    assert r.returncode == 0, r.stdout
    assert r.stdout.decode().startswith(f"{out}: 8 frames 64x48")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "v.gif", "v.png"]


NAMES = [
    (b"new\nline", "new\\nline"), (b"carriage\rreturn", "carriage\\rreturn"), (b"fs\x1csep", "fs\\x1csep"),
    (b"gs\x1dsep", "gs\\x1dsep"), ("line\u2028sep".encode(), "line\\u2028sep"), ("bidi\u202eexe".encode(), "bidi\\u202eexe"),
    (b"csi\x9b31m", "csi\\x9b31m"), (b"byte\xff", "byte\\xff"), (b"esc\x1b[2J", "esc\\x1b[2J"),
]
FAST_NAMES = ("new\\nline",)    # one in the default run (each a process of its own); the rest slow


@pytest.mark.parametrize("raw, shown", [pytest.param(*n, id=n[1], marks=() if n[1] in FAST_NAMES else pytest.mark.slow)
                                        for n in NAMES])
def test_every_echoed_name_is_one_escaped_line(tmp_path, raw, shown):
    """Newline, carriage return, \\x1c, \\x1d, U+2028, U+202E and 0x9b in paths are echoed
    escaped (no line split or reordered on screen), and with a 0xff file name on a strict
    UTF-8 stdout the output is written and its name echoed escaped; errors naming it are
    escaped alike."""
    out = bytes(tmp_path) + b"/" + raw + b".npz"
    r = spinviz_cmd(["simulate", os.fsencode(scene(tmp_path)), "--out", out])
    assert r.returncode == 0, r.stderr
    line = r.stdout.decode("utf-8")
    assert line.count("\n") == 1 and line.startswith(f"{tmp_path}/{shown}.npz: 6 samples"), line
    assert os.path.exists(out)
    bad = bytes(tmp_path) + b"/" + raw + b".txt"
    r = spinviz_cmd(["simulate", os.fsencode(scene(tmp_path)), "--out", bad])
    err = r.stderr.decode("utf-8")
    assert r.returncode == 2 and err.count("\n") == 1, err
    assert err.startswith(f"spinviz: error: --out: {tmp_path}/{shown}.txt: a trajectory is written as .npz"), err


def test_a_full_disk_is_reported_with_the_path_and_leaves_nothing(tmp_path, monkeypatch, capsys):
    """ENOSPC while writing the output: one line naming the path and the reason, exit status
    1 (the run could not be completed, the input was fine), no file nor temporary left."""
    p = scene(tmp_path)
    out = tmp_path / "t.npz"

    def full(*a, **k):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(np, "savez", full)
    code = main(["simulate", str(p), "--out", str(out)])
    err = capsys.readouterr().err
    assert (code, err) == (1, f"spinviz: error: {out}: cannot write: No space left on device\n")
    assert sorted(q.name for q in tmp_path.iterdir()) == ["s.toml"]
