"""Stop signals during real runs, sent as a terminal (Ctrl-C to the process group) or a
supervisor (SIGTERM, SIGHUP to the process) would: one line, exit 128 + the signal, nothing
left behind, nothing replaced, and no process of the command outlives it."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from procs import gone

ROOT = Path(__file__).resolve().parents[1]

SCENE = """
title = "signals"
[body]
delta = -0.6
chi_deg = 55.0
[initial]
omega = [0.02, 0.05, 0.03]
[simulation]
models = ["reduced", "truncated"]
t_end = 600.0
samples = 50
[render]
duration = 8.0
fps = 30
size = [192, 96]
show = ["body", "dipole", "trail", "sphere", "axes", "hud"]
"""


def start(argv, cwd):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.Popen([sys.executable, "-m", "spinviz", *map(str, argv)], cwd=cwd, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)


def wait_for(proc, text, timeout=90.0):
    """Read stderr lines until one contains ``text``; returns the lines read."""
    seen, end = [], time.monotonic() + timeout
    while time.monotonic() < end:
        line = proc.stderr.readline()
        if not line:
            break
        seen.append(line)
        if text in line:
            return seen
    proc.kill()
    raise AssertionError(f"never saw {text!r}: {seen}")


# the MP4 cases start two render workers and ffmpeg each (1-3.5 s): slow, like the atlas's stop signals
@pytest.mark.parametrize("sig,to_group,ext", [
    pytest.param(signal.SIGINT, True, ".mp4", marks=pytest.mark.slow, id="ctrl-c-to-group"),
    pytest.param(signal.SIGTERM, False, ".mp4", marks=pytest.mark.slow, id="sigterm"),
    pytest.param(signal.SIGHUP, False, ".mp4", marks=pytest.mark.slow, id="sighup"),
    pytest.param(signal.SIGINT, True, ".gif", id="ctrl-c-gif-in-process"),
])
def test_stop_signal_mid_render(tmp_path, sig, to_group, ext):
    """MP4s render in two worker processes; a GIF in this process, where a signal can land
    inside a VTK callback (which swallowed it: the render ran to the end and replaced the
    old GIF in 7 of ~126 tries before the fix)."""
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE)
    old = {f"out{ext}": b"the previous video", "out.png": b"the previous poster"}
    for name, data in old.items():
        (tmp_path / name).write_bytes(data)
    proc = start(["render", scene, "--out", tmp_path / f"out{ext}", "--workers", "2"], tmp_path)
    wait_for(proc, "25 %")
    (os.killpg if to_group else os.kill)(proc.pid, sig)
    _, err = proc.communicate(timeout=30)
    lines = [x for x in err.splitlines() if " frames (" not in x]       # progress lines are not messages
    assert proc.returncode == 128 + sig, err
    assert lines == [f"spinviz: interrupted by {signal.Signals(sig).name}; nothing was written"], err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.name != "s.toml"} == old   # no leftovers either
    assert gone(proc.pid) == []                                           # no worker, tracker or ffmpeg left


@pytest.mark.slow
def test_sigterm_stops_a_compiled_run_promptly(tmp_path):
    """An asymmetric body over ~5e6 turns resolved by Taylor's method (asked for: ``auto`` would
    average it; about a minute of compiled loop, ~3 s per 1e5 turns measured): SIGTERM ends it
    within a second with nothing written."""
    scene = tmp_path / "long.toml"
    scene.write_text("""
[body]
inertia = [1.0, 0.8, 0.5]
dipole = [0.3, 0.2, 0.9]
[initial]
omega = [0.0, 0.001, 0.002]
[simulation]
model = "reduced"
method = "taylor"
t_end = 1e14
samples = 10
""")
    proc = start(["simulate", scene, "--out", tmp_path / "t.npz"], tmp_path)
    time.sleep(3.0)                                   # imports, compilation (cached), into the loop
    assert proc.poll() is None
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=10)
    assert time.monotonic() - t0 < 1.5
    assert proc.returncode == 143 and err.strip() == "spinviz: interrupted by SIGTERM; nothing was written"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.toml"]
