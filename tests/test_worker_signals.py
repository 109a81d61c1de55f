"""The worker processes of every pool stop as the command does: a stop signal to the whole
process group (a terminal's Ctrl-C or hang-up, ``kill -TERM -PGID``) at any instant -- while
the workers start (spawned interpreters importing the drawing stack), while they draw, while
the parent joins the video -- ends the command with 128 + the signal and exactly one line on
stderr: no worker's traceback, none from multiprocessing's resource tracker, before or after
the command ends, and no process left."""

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from procs import gone
from test_atlas_signals import answers_signals
from test_signals import SCENE

from spinviz.executors.processes import ProcessMapper

ROOT = Path(__file__).resolve().parents[1]
WAYS = [signal.SIGINT, signal.SIGHUP, signal.SIGTERM]
INSTANTS = int(os.environ.get("SPINVIZ_SIGNAL_INSTANTS", "9"))


def _render(scene, out, cwd):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}
    p = subprocess.Popen([sys.executable, "-m", "spinviz", "render", str(scene), "--out", str(out), "--workers", "2",
                          "--quiet"], cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    t0 = time.monotonic()
    while not answers_signals(p.pid):
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - t0 < 60
        time.sleep(0.002)
    return p, time.monotonic()


@pytest.mark.slow
def test_a_stop_signal_to_the_group_of_a_parallel_render(tmp_path):
    """A spawned render worker that took a Ctrl-C while importing would print a
    KeyboardInterrupt traceback, and a resource tracker killed by a hang-up is relaunched and
    prints KeyErrors: both are born with the signals blocked."""
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE)
    p, t0 = _render(scene, tmp_path / "whole.mp4", tmp_path)
    _, err = p.communicate(timeout=300)
    assert p.returncode == 0 and err == "", err
    span = time.monotonic() - t0
    rng = random.Random(35)
    for i in range(INSTANTS):
        sig = WAYS[i % len(WAYS)]
        delay = rng.uniform(0.0, 0.5 * span) if i % 2 else rng.uniform(0.0, 1.0)   # half in the workers' start-up
        out = tmp_path / f"o{i}.mp4"
        p, t0 = _render(scene, out, tmp_path)
        time.sleep(max(0.0, delay - (time.monotonic() - t0)))
        if p.poll() is None:
            os.killpg(p.pid, sig)
        where = f"{signal.Signals(sig).name} to the group at {delay:.2f} s of {span:.2f} s"
        try:
            _, err = p.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            pytest.fail(f"{where}: the command hung")
        assert gone(p.pid) == [], where
        if p.returncode == 0 and err == "":
            continue
        assert p.returncode == 128 + sig, f"{where}: exit {p.returncode}, {err!r}"
        assert err == f"spinviz: interrupted by {signal.Signals(sig).name}; nothing was written\n", f"{where}: {err!r}"
        assert not out.exists(), where


def _square(x):
    time.sleep(0.02)
    return x * x


@pytest.fixture
def alarm():
    """A stop that hangs fails the test in 10 s instead of hanging it."""
    def ring(signum, frame):
        raise TimeoutError("stopping the pool hung")

    old = signal.signal(signal.SIGALRM, ring)
    signal.alarm(10)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


@pytest.mark.slow
def test_a_process_mapper_stops_at_once_whatever_its_workers_ignore(alarm):
    """The pool's workers ignore SIGTERM (the parent alone answers a terminal's signals), so
    ``multiprocessing``'s own terminate, which sends SIGTERM, would wait for them forever:
    stopping the mapper on an exception kills them, at once."""
    t0 = time.monotonic()
    with pytest.raises(RuntimeError, match="stop"):
        with ProcessMapper(2) as m:
            workers = list(m.pool._pool)
            assert m(_square, [1, 2, 3]) == [1, 4, 9]
            raise RuntimeError("stop")
    assert time.monotonic() - t0 < 5.0
    assert all(w.exitcode is not None for w in workers), [w.exitcode for w in workers]   # ended and reaped
