"""Stop signals at any instant of an atlas command -- reading its spec, starting the cluster,
creating a level's store, computing level 0 or a refinement level, drawing, shutting down:
always exit status 128 + the signal and one line on stderr, nothing else; no process of the
command outlives it; and the store it leaves is completed by the same command to the
numbers of an uninterrupted run.

The instants are a seeded list of delays spread over the whole command (measured first),
counted from the moment the command answers stop signals (its handlers installed, read from
/proc), so no instant falls in the interpreter's own start-up, before any of spinviz runs."""

import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from procs import gone
from test_store_spec import same_atlas

from spinviz.regimes import api

ROOT = Path(__file__).resolve().parents[1]
INSTANTS = int(os.environ.get("SPINVIZ_SIGNAL_INSTANTS", "12"))
WAYS = [(signal.SIGINT, True), (signal.SIGTERM, False), (signal.SIGHUP, True), (signal.SIGTERM, True),
        (signal.SIGHUP, False), (signal.SIGINT, False)]


def answers_signals(pid: int) -> bool:
    """Whether the process catches SIGTERM (spinviz's handlers are installed)."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("SigCgt:"):
                return bool(int(line.split()[1], 16) >> (signal.SIGTERM - 1) & 1)
    except OSError:
        pass
    return False


def start(spec, out, plot, cwd):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}
    cmd = [sys.executable, "-m", "spinviz", "atlas", str(spec), "--out", str(out), "--workers", "2", "--quiet",
           "--runs-per-task", "4", "--plot", str(plot)]
    p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    t0 = time.monotonic()
    while not answers_signals(p.pid):
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - t0 < 60
        time.sleep(0.002)
    return p, time.monotonic()


def lines_for(name: str, out) -> set:
    """The one line a stopped atlas may end with, by where the signal landed."""
    return {f"spinviz: atlas stopped by {name}; every finished chunk is in {out} and the same command computes only "
            f"what is missing",
            f"spinviz: atlas stopped by {name} before its store was made; nothing was written",
            f"spinviz: interrupted by {name} as the command ended; it had finished (exit status 0)"}


@pytest.mark.slow
def test_a_stop_signal_at_any_instant_of_an_atlas(refined_atlas, tmp_path):
    """Half the instants on a new store (spec, cluster start, level 0, level 1's creation and
    runs, the pictures, shutdown), half on a store holding level 0 only (the cluster started
    for the refinement level).  What can go wrong at such instants: the process ended by the
    signal itself with nothing on stderr (its default action, in the interpreter's shutdown),
    library tracebacks (asyncio's "Future exception was never retrieved"), a worker being
    started when the stop came keeping the command waiting in multiprocessing's exit hook."""
    rng = random.Random(25)
    level0 = tmp_path / "level0.zarr"                         # the reference without its refinement level
    shutil.copytree(refined_atlas.store, level0)
    shutil.rmtree(level0 / "level1")
    spans = {}
    for name, base in (("new", None), ("level0", level0)):     # the whole command, timed once each
        out = tmp_path / f"whole-{name}.zarr"
        if base is not None:
            shutil.copytree(base, out)
        p, t0 = start(refined_atlas.spec, out, tmp_path / f"whole-{name}.png", tmp_path)
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0 and err == "", err
        spans[name] = time.monotonic() - t0
    stopped = 0
    for i in range(INSTANTS):
        kind = "new" if i % 2 == 0 else "level0"
        sig, to_group = WAYS[i % len(WAYS)]
        delay = rng.uniform(0.0, 1.1 * spans[kind])             # a tenth of them after the end: the shutdown
        for _ in range(4):                                       # a shared machine runs faster than it was timed at
            landed, took = _one_instant(refined_atlas, tmp_path, level0, i, kind, sig, to_group, delay, spans)
            if landed or delay > spans[kind]:                    # moments: the command finished first, so its span
                break                                            # is what it took and the instant is drawn again in it
            spans[kind] = min(spans[kind], took)
            delay = rng.uniform(0.0, spans[kind])
        stopped += landed
    assert stopped >= INSTANTS * 0.7, stopped


def _one_instant(refined_atlas, tmp_path, level0, i, kind, sig, to_group, delay, spans) -> tuple:
    """One command stopped at ``delay`` after it answers signals; its exit, line, processes and
    store checked.  Returns whether the signal landed (the command had not finished) and the
    seconds the command took after it answered signals."""
    out = tmp_path / f"s{i}.zarr"
    if kind == "level0":
        shutil.copytree(level0, out)
    p, t0 = start(refined_atlas.spec, out, tmp_path / f"p{i}.png", tmp_path)
    time.sleep(max(0.0, delay - (time.monotonic() - t0)))
    sent = p.poll() is None
    if sent:
        try:
            (os.killpg if to_group else os.kill)(p.pid, sig)
        except ProcessLookupError:
            sent = False
    try:
        _, err = p.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        pytest.fail(f"instant {i} ({signal.Signals(sig).name} at {delay:.2f} s, {kind}): the command hung")
    took = time.monotonic() - t0
    where = f"instant {i} ({signal.Signals(sig).name}{' to the group' if to_group else ''} at {delay:.2f} s of " \
            f"{spans[kind]:.2f} s, {kind} store)"
    landed = not (p.returncode == 0 and err == "")
    if landed:
        assert p.returncode == 128 + sig, f"{where}: exit {p.returncode}, stderr {err!r}"
        assert err.count("\n") == 1 and err.strip() in lines_for(signal.Signals(sig).name, out), f"{where}: {err!r}"
    assert gone(p.pid) == [], where                                 # workers, resource tracker: all gone
    assert [x.name for x in tmp_path.iterdir() if x.name.endswith(".partial")] == [], where
    if out.exists():                                                # what it left, completed
        api.atlas(refined_atlas.spec, out, workers=1, processes=False, progress=False, runs_per_task=4,
                  notify=lambda line: None)
        same_atlas(out, refined_atlas.store)
        shutil.rmtree(out)
    return landed, took
