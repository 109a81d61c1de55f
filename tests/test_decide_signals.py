"""Stop signals at any instant of ``spinviz decide`` -- reading the scene, starting its worker
processes (or its Dask cluster), running the trials, drawing the plot, shutting down -- sent as
a terminal (Ctrl-C, hang-up to the process group) or a supervisor (SIGTERM to the group or the
process) would: always exit status 128 + the signal and exactly one line on stderr, from no
process but the command itself, before or after it ends; no process of the command outlives it;
nothing written.  The instants are drawn over the command's measured span, counted from the
moment it answers stop signals (as tests/test_atlas_signals.py does)."""

import contextlib
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

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "scenes" / "dast_cube.toml"
WAYS = [(signal.SIGTERM, True), (signal.SIGINT, True), (signal.SIGHUP, True), (signal.SIGTERM, False),
        (signal.SIGHUP, False), (signal.SIGINT, False)]
INSTANTS = int(os.environ.get("SPINVIZ_SIGNAL_INSTANTS", "6"))
# the Dask path from a handful of trials (it starts at 2000): the front door's threshold lowered
ON_DASK = ("import sys\nimport spinviz.experiment as E\nE.DASK_TRIALS = 8\nfrom spinviz.commands import entry\n"
           "sys.argv[0] = 'spinviz'\nentry()\n")


def start(out, cwd, dask: bool):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}
    head = [sys.executable, "-c", ON_DASK] if dask else [sys.executable, "-m", "spinviz"]
    cmd = [*head, "decide", str(SCENE), "--trials", "16", "--workers", "2", "--out", str(out)]
    p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    t0 = time.monotonic()
    while not answers_signals(p.pid):
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - t0 < 60
        time.sleep(0.002)
    return p, time.monotonic()


def lines_for(name: str, out) -> set:
    return {f"spinviz: interrupted by {name}; nothing was written",
            f"spinviz: interrupted by {name} after writing {out}_decide.png; nothing else was written",
            f"spinviz: interrupted by {name} as the command ended; it had finished (exit status 0)"}


@pytest.mark.slow
@pytest.mark.parametrize("dask", [False, True], ids=["processes", "dask"])
def test_a_stop_signal_at_any_instant_of_decide(tmp_path, dask):
    """A worker process that took the signal itself would print its traceback beside the
    command's line; one that ignores SIGTERM keeps ``multiprocessing``'s own terminate (which
    sends SIGTERM) waiting forever, so the pool is killed."""
    rng = random.Random(35 + dask)
    p, t0 = start(tmp_path / "whole", tmp_path, dask)               # the whole command, timed once
    _, err = p.communicate(timeout=600)
    assert p.returncode == 0 and "spinviz:" not in err, err
    span = time.monotonic() - t0
    stopped = 0
    for i in range(INSTANTS):
        sig, to_group = WAYS[i % len(WAYS)]
        delay = rng.uniform(0.0, 1.05 * span)                      # a few after the end: the shutdown
        for k in range(4):                                          # a shared machine runs faster than it was timed at
            landed, took = _one_instant(tmp_path / f"d{i}-{k}", tmp_path, dask, sig, to_group, delay, span)
            if landed or delay > span:
                break
            span = min(span, took)
            delay = rng.uniform(0.0, span)
        stopped += landed
    assert stopped >= INSTANTS * 0.6, stopped


def _one_instant(out, cwd, dask, sig, to_group, delay, span) -> tuple:
    """One command stopped ``delay`` s after it answers signals, checked; returns whether the
    signal landed (the command had not finished) and how long the command took."""
    p, t0 = start(out, cwd, dask)
    time.sleep(max(0.0, delay - (time.monotonic() - t0)))
    if p.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            (os.killpg if to_group else os.kill)(p.pid, sig)
    where = f"{signal.Signals(sig).name}{' to the group' if to_group else ''} at {delay:.2f} s of {span:.2f} s"
    try:
        _, err = p.communicate(timeout=60)                           # until every process holding stderr has ended
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        pytest.fail(f"{where}: the command hung")
    took = time.monotonic() - t0
    if p.returncode == 0 and "spinviz:" not in err:
        return False, took                                           # it had finished before the signal
    said = [x for x in err.splitlines() if not x.startswith("  decide: ")]      # where it runs: progress
    assert p.returncode == 128 + sig, f"{where}: exit {p.returncode}, stderr {err!r}"
    assert len(said) == 1 and said[0] in lines_for(signal.Signals(sig).name, out), f"{where}: {err!r}"
    assert gone(p.pid) == [], where                                  # no worker, cluster or tracker left
    if said[0].endswith("nothing was written"):
        assert not os.path.exists(f"{out}_decide.png"), where
    return True, took
