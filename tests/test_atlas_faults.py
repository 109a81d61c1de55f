"""Faults of the atlas: a damaged store, a lost scheduler or worker, a killed command, stop
signals -- and after each, the same command gives the numbers of an uninterrupted run.

The spec (2 models x 2 x 3 cells x 3 members = 36 runs to tau = 1e8, ~2 s of work) is
test_atlas_cluster.py's; its storage chunks are 4 (model x delta) of 9 runs.  The reference
is computed once, in one go; "the same numbers" means every variable but ``run_seconds`` (a
measurement) bit for bit, and the store's attributes equal."""

import contextlib
import gc
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from atlasdata import VARIABLES
from procs import gone

from spinviz import interrupt
from spinviz.commands import main as cli_main
from spinviz.errors import OptionError
from spinviz.executors import cluster
from spinviz.regimes import api
from spinviz.regimes import cluster as atlas_cluster
from spinviz.regimes.engine import runs as RN
from spinviz.regimes.faults import AtlasIncomplete, StoreDamaged
from spinviz.regimes.store import dataset as DS
from spinviz.regimes.store import integrity, levels

# every test here reads or breaks the small atlas computed once (~1 s) or starts a cluster: .ci/run's second pass
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""), "PYTHONUNBUFFERED": "1"}
DASK = str(Path(sys.executable).parent / "dask")


@pytest.fixture(scope="module")
def spec_path(small_atlas_spec):
    return small_atlas_spec


@pytest.fixture(scope="module")
def reference(small_atlas_reference):
    return small_atlas_reference


def arrays(path):
    import xarray as xr

    ds = xr.open_zarr(path)
    return {v: ds[v].values for v in VARIABLES}, dict(ds.attrs)


def same_numbers(a, b):
    (xa, attrs_a), (xb, attrs_b) = arrays(a), arrays(b)
    for v in VARIABLES:
        assert np.array_equal(xa[v], xb[v], equal_nan=xa[v].dtype.kind == "f"), v
    assert attrs_a == attrs_b


def done_runs_match(path, reference):
    """Every run the store marks done holds the reference's numbers (nothing lost was written)."""
    done = DS.done_mask(str(path))
    (x, _), (r, _) = arrays(path), arrays(reference)
    for v in VARIABLES:
        if x[v].ndim >= 4:
            assert np.array_equal(x[v][done], r[v][done], equal_nan=x[v].dtype.kind == "f"), v
    return done


def copy_store(reference, tmp_path) -> Path:
    out = tmp_path / "s.zarr"
    shutil.copytree(reference, out)
    return out


def verify(path, capsys):
    rc = cli_main(["atlas", "verify", str(path)])
    return rc, capsys.readouterr().out.splitlines()


def partials(root) -> list:
    return sorted(str(p) for p in Path(root).rglob("*") if ".partial" in p.name)


# --- the store's checksums --------------------------------------------------------------------
def _flip(rel):
    def damage(s):
        p = s / rel
        data = bytearray(p.read_bytes())
        data[len(data) // 2] ^= 0xFF
        p.write_bytes(bytes(data))
    return damage


def _truncate(rel):
    def damage(s):
        p = s / rel
        p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])
    return damage


def _delete(rel):
    return lambda s: (s / rel).unlink()


def _write(rel, text):
    return lambda s: (s / rel).write_text(text)


DAMAGE = [
    # (what is done, variable line of --verify, the notice's chunk list)
    (_delete("regime/0.1.0.0"), "regime: DAMAGED (1 chunk: regime/0.1.0.0 (missing))",
     "1 damaged chunk (regime/0.1.0.0 (missing))"),
    (_flip("done/1.0.0.0"), "done: DAMAGED (1 chunk: done/1.0.0.0 (checksum mismatch))",
     "1 damaged chunk (done/1.0.0.0 (checksum mismatch))"),
    (_truncate("evidence/1.1.0.0.0"), "evidence: DAMAGED (1 chunk: evidence/1.1.0.0.0 (checksum mismatch))",
     "1 damaged chunk (evidence/1.1.0.0.0 (checksum mismatch))"),
    (_write("nfev/0.0.0.0", "junk"), "nfev: DAMAGED (1 chunk: nfev/0.0.0.0 (not recorded))",
     "1 damaged chunk (nfev/0.0.0.0 (not recorded))"),
    (_delete(".checksums/chunks/0.0.0.0.json"),
     "checksums: 1 chunk with runs marked done and no usable record (.checksums/chunks/0.0.0.0.json (no record))",
     "1 unverified chunk (.checksums/chunks/0.0.0.0.json (no record))"),
    (_write(".checksums/chunks/1.1.0.0.json", "{"),
     "checksums: 1 chunk with runs marked done and no usable record (.checksums/chunks/1.1.0.0.json (record unreadable))",
     "1 damaged chunk (.checksums/chunks/1.1.0.0.json (record unreadable))"),
]


@pytest.mark.parametrize("damage, verify_line, notice", DAMAGE,
                         ids=["regime-deleted", "done-flipped", "evidence-truncated", "nfev-stray-file",
                              "record-deleted", "record-garbage"])
def test_damaged_chunk_is_named_and_recomputed(spec_path, reference, tmp_path, capsys, damage, verify_line, notice):
    """A chunk file deleted, flipped, truncated or planted, or its record gone: the resume says
    which in one line and recomputes that chunk's 9 runs (not the 27 others), and the store
    is then the reference's bit for bit; ``--verify`` names the file before (exit 1), and
    says ok after (exit 0).  (Before checksums the resume accepted the damage: a deleted
    ``regime`` chunk read as 0 beside ``done`` = 1, a flipped ``done`` chunk failed in blosc.)"""
    s = copy_store(reference, tmp_path)
    damage(s)
    damaged = tmp_path / "damaged.zarr"
    shutil.copytree(s, damaged)
    res = api.atlas(spec_path, s, workers=1, processes=False, progress=False, runs_per_task=3)
    err = capsys.readouterr().err.strip()
    same_numbers(s, reference)
    assert err == f"spinviz: {s}: {notice}; its 9 runs are recomputed"
    assert (res.repaired, res.computed, res.reused) == (9, 9, 27)
    rc, lines = verify(s, capsys)
    assert rc == 0 and lines[-1] == f"{s}: ok: 36 runs verified"
    rc, lines = verify(damaged, capsys)
    assert rc == 1 and verify_line in lines and lines[-1] == (
        f"{damaged}: DAMAGED: 1 chunk(s) to recompute; the same atlas command recomputes their runs"), lines


def test_verify_a_clean_store(reference, capsys):
    """The metadata, the spec the store records (its hash), one line per variable with its
    chunks, the runs the spec implies, the verdict; exit 0."""
    rc, lines = verify(reference, capsys)
    assert rc == 0
    sha = levels.identity(levels.recorded_spec(str(reference)))
    assert lines == ["metadata: ok", f"spec: ok (sha256 {sha[:12]}, [refine] levels = 0)"] + [
        f"{v}: ok (4 chunks)" for v in DS.run_variables(str(reference))] + [
        "runs: all 36 computed", f"{reference}: ok: 36 runs verified"]


def test_verify_refuses_what_is_not_a_store(tmp_path, capsys):
    assert cli_main(["atlas", "verify", str(tmp_path / "nothing.zarr")]) == 2
    assert capsys.readouterr().err.strip() == (f"spinviz: error: --verify {tmp_path / 'nothing.zarr'}: not an atlas "
                                               f"store (no such directory, or no .zgroup in it)")


@pytest.mark.parametrize("rel, what", [("paper/0.0.0", "checksum mismatch"), (".zattrs", "checksum mismatch"),
                                       ("regime/.zarray", "missing")])
def test_damaged_metadata_refused_untouched(spec_path, reference, tmp_path, capsys, rel, what):
    """Metadata and the fixed arrays cannot be recomputed from runs: the resume refuses with
    one line naming the file and changes nothing; ``--verify`` says so, exit 1."""
    s = copy_store(reference, tmp_path)
    (_delete(rel) if what == "missing" else _flip(rel))(s)
    before = sorted((str(p), p.stat().st_mtime_ns) for p in s.rglob("*"))
    with pytest.raises(StoreDamaged) as e:
        api.atlas(spec_path, s, workers=1, processes=False, progress=False)
    assert str(e.value) == (f"{s}: its metadata are damaged ({rel} ({what})); they cannot be recomputed from "
                            f"the runs: move it away and compute the atlas again")
    assert sorted((str(p), p.stat().st_mtime_ns) for p in s.rglob("*")) == before
    rc, lines = verify(s, capsys)
    assert rc == 1 and lines[0] == f"metadata: DAMAGED ({rel} ({what}))"


def test_store_without_checksums_refused(spec_path, reference, tmp_path, capsys):
    s = copy_store(reference, tmp_path)
    shutil.rmtree(s / integrity.DIR)
    assert cli_main(["atlas", str(spec_path), "--out", str(s), "--quiet", "--workers", "1"]) == 2
    assert capsys.readouterr().err.strip() == (
        f"spinviz: error: {s}: carries no checksums (made by an earlier spinviz, or its .checksums was deleted), "
        f"so its runs cannot be trusted; move it away and compute the atlas again")


@pytest.mark.slow
def test_write_cut_before_its_checksums_is_recomputed(spec_path, reference, tmp_path, monkeypatch, capsys):
    """A process killed between a chunk's files and its record (simulated: the record's write
    raises): that chunk has runs marked done and nothing vouching for them; the resume
    recomputes exactly them and the store is the reference's."""
    s = tmp_path / "c.zarr"
    real = integrity.record
    calls = []

    def cut(*a, **k):
        calls.append(a)
        if len(calls) == 2:
            raise KeyboardInterrupt            # as a SIGKILL would: after the data, before the record
        return real(*a, **k)

    monkeypatch.setattr(integrity, "record", cut)
    with pytest.raises(KeyboardInterrupt):
        api.atlas(spec_path, s, workers=1, processes=False, progress=False, runs_per_task=3)
    monkeypatch.setattr(integrity, "record", real)
    assert DS.done_mask(str(s))[0, 1].all()                          # the cut chunk says "done"
    res = api.atlas(spec_path, s, workers=1, processes=False, progress=False, runs_per_task=3)
    assert capsys.readouterr().err.strip() == (f"spinviz: {s}: 1 unverified chunk (.checksums/chunks/0.1.0.0.json "
                                               f"(no record)); its 9 runs are recomputed")
    assert res.repaired == 9 and res.reused + res.computed == 36
    same_numbers(s, reference)


# --- tasks that do not finish -------------------------------------------------------------------
@pytest.mark.slow
def test_failed_task_is_not_written_and_the_call_fails(spec_path, reference, tmp_path, monkeypatch):
    """A task that raises outside the runs (here: a broken worker environment) is not a result:
    its 3 runs stay "not computed" (before: recorded as "failed" and done, so the same
    command never computed them), ``AtlasIncomplete`` says so in one line naming no
    command-line flag, and the same call then completes the store with the reference's
    numbers."""
    s = tmp_path / "f.zarr"
    real = RN.run_batch

    def broken(batch):
        if batch.region == (1, (0, 1), (1, 2), (0, 3)):
            raise RuntimeError("worker environment broken")
        return real(batch)

    monkeypatch.setattr(RN, "run_batch", broken)
    with pytest.raises(AtlasIncomplete) as e:
        api.atlas(spec_path, s, workers=1, processes=False, progress=False, runs_per_task=3)
    assert str(e.value) == (f"a task raised RuntimeError: worker environment broken: 3 of 36 runs not computed; the "
                            f"store {s} holds the 33 finished, and the same call computes only what is missing")
    assert e.value.exit_status == 1 and not e.value.cluster_lost and "--" not in str(e.value)
    done = done_runs_match(s, reference)
    assert done.sum() == 33 and not done[1, 0, 1].any()
    monkeypatch.setattr(RN, "run_batch", real)
    res = api.atlas(spec_path, s, workers=1, processes=False, progress=False, runs_per_task=3)
    assert (res.reused, res.computed) == (33, 3)
    same_numbers(s, reference)


# --- options ---------------------------------------------------------------------------------------
def test_workers_beyond_the_cores_refused(spec_path, tmp_path, capsys):
    """``--workers 1000`` (1000 processes on 2 cores): one line naming the option, exit 2,
    nothing written; the library names ``workers``.  (The bound is the schema's; ``Cluster``
    made directly checks it too.)"""
    from spinviz.errors import SpecError

    cores = len(os.sched_getaffinity(0))
    out = tmp_path / "w.zarr"
    reason = f"must be at most {cores}, the cores this process may use (more workers than cores only share them), got 1000"
    assert cli_main(["atlas", str(spec_path), "--out", str(out), "--workers", "1000", "--quiet"]) == 2
    assert capsys.readouterr().err.strip() == f"spinviz: error: --workers: {reason}"
    for call in (lambda: api.atlas(spec_path, out, workers=1000, progress=False), lambda: cluster.Cluster(None, 1000)):
        with pytest.raises(SpecError) as e:
            call()
        assert str(e.value) == f"workers: {reason}"
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.slow
def test_unreachable_scheduler_library_names_the_parameter(spec_path, tmp_path, monkeypatch):
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT_S", 1.0)
    addr = f"tcp://127.0.0.1:{_free_port()}"
    with pytest.raises(OptionError) as e:
        api.atlas(spec_path, tmp_path / "u.zarr", scheduler=addr, progress=False)
    assert str(e.value).startswith(f"scheduler='{addr}': cannot connect") and "--" not in str(e.value)


def test_no_dashboard_port_warning(tmp_path):
    """No dashboard is asked for, so none is looked for: with port 8787 taken, starting the
    embedded cluster warns nothing (no "Port 8787 is already in use", even while another
    cluster holds the port)."""
    holder = socket.socket()
    with contextlib.suppress(OSError):                  # already taken by someone else: as good
        holder.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        holder.bind(("", 8787))
        holder.listen(1)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with cluster.Cluster(None, 1, processes=False) as cl:
                assert cl.nthreads == 1
        assert [str(w.message) for w in caught if "8787" in str(w.message) or "in use" in str(w.message)] == []
    finally:
        holder.close()


# --- an external cluster: the stock dask scheduler and workers ------------------------------------
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class External:
    """``dask scheduler`` and ``dask worker`` processes (each in its own session, as on other
    machines), stopped at the end whatever happened."""

    def __init__(self, workers: int = 2, worker_args=(), env=None):
        self.port = _free_port()
        self.addr = f"tcp://127.0.0.1:{self.port}"
        self.env = {**ENV, **(env or {})}
        self.scheduler = self._start([DASK, "scheduler", "--host", "127.0.0.1", "--port", str(self.port),
                                      "--no-dashboard"])
        self.workers = [self._start([DASK, "worker", self.addr, "--nthreads", "1", "--no-dashboard", *worker_args])
                        for _ in range(workers)]
        from distributed import Client

        with Client(self.addr, timeout=30) as c:
            c.wait_for_workers(workers, timeout=60)

    def _start(self, cmd):
        return subprocess.Popen(cmd, env=self.env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True)

    def kill_group(self, p, sig=signal.SIGKILL):
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, sig)

    def close(self):
        for p in [self.scheduler, *self.workers]:
            self.kill_group(p)
        for p in [self.scheduler, *self.workers]:
            with contextlib.suppress(subprocess.TimeoutExpired):
                p.wait(10)


@pytest.fixture
def external():
    made = []

    def make(workers=2, **kw):
        made.append(External(workers, **kw))
        return made[-1]

    yield make
    for e in made:
        e.close()


def wait_for_done(out: Path, proc, at_least: int = 1, timeout: float = 90.0) -> int:
    """Poll the store until ``at_least`` runs are done (or the process ended)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end and proc.poll() is None:
        if (out / "done").exists():
            with contextlib.suppress(Exception):
                n = int(DS.done_mask(str(out)).sum())
                if n >= at_least:
                    return n
        time.sleep(0.02)
    return -1


def command(spec_path, out, *extra, cwd):
    return subprocess.Popen([sys.executable, "-m", "spinviz", "atlas", str(spec_path), "--out", str(out), "--quiet",
                             *map(str, extra)], env=ENV, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_scheduler_killed_mid_atlas_fails_in_one_line_and_resumes(spec_path, reference, tmp_path, external, sig):
    """The stock ``dask scheduler`` killed (SIGKILL) or stopped (SIGTERM, it exits 0) while the
    atlas runs: exit 75, one line saying what was lost and how to resume; every run marked
    done holds the reference's numbers (the runs in flight are not written, neither as done
    nor as failed); the same command then completes the store with the reference's numbers."""
    ext = external()
    out = tmp_path / "x.zarr"
    p = command(spec_path, out, "--scheduler", ext.addr, "--runs-per-task", "1", cwd=tmp_path)
    try:
        assert wait_for_done(out, p) > 0, p.communicate()[1]
        ext.kill_group(ext.scheduler, sig)
        _, err = p.communicate(timeout=30)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
    done = done_runs_match(out, reference)
    n = int(done.sum())
    assert p.returncode == 75, err
    assert err.strip() == (f"spinviz: atlas incomplete: the scheduler at {ext.addr} went away: {36 - n} of 36 runs not "
                           f"computed; {out} holds the {n} finished; rerun the same command to resume")
    assert 0 < n < 36 and DS.verify(str(out)).clean
    res = api.atlas(spec_path, out, workers=1, processes=False, progress=False)       # the same command, resumed
    assert (res.reused, res.computed) == (n, 36 - n)
    same_numbers(out, reference)


@pytest.mark.slow
def test_workers_killed_at_random_points_same_numbers(spec_path, reference, tmp_path, external, rng):
    """The worker that delivered a result is killed (SIGKILL) after three random results: Dask
    reruns its tasks on the other one (or on its restarted self); the store is complete and
    the reference's."""
    ext = external()
    out = tmp_path / "w.zarr"
    at = set(rng.choice(np.arange(1, 30), size=3, replace=False).tolist())
    killed = []

    def kill(n, res):
        if n in at and res["worker_pid"] > 0:
            with contextlib.suppress(ProcessLookupError):
                os.kill(res["worker_pid"], signal.SIGKILL)
                killed.append(n)

    res = api.atlas(spec_path, out, scheduler=ext.addr, progress=False, runs_per_task=1, on_result=kill)
    assert len(killed) == 3 and res.computed == 36 and res.failed == 0
    same_numbers(out, reference)


CRASHER = """
import os
from spinviz.regimes.engine import runs

_real = getattr(runs, "_unpatched_run_batch", runs.run_batch)     # Dask may load a preload twice
runs._unpatched_run_batch = _real


def run_batch(batch):
    if batch.region == (0, (1, 2), (2, 3), (0, 3)):
        os._exit(9)                                     # as a segfault in a compiled kernel would
    return _real(batch)


runs.run_batch = run_batch
"""


@pytest.mark.slow
def test_task_that_kills_its_worker_is_not_written(spec_path, reference, tmp_path, external):
    """A batch that kills the worker running it (a crash in compiled code), on a cluster that
    gives a task one attempt and a worker one task at a time: Dask gives up on it
    (KilledWorker); its 3 runs are not written, the 33 others are, exit status 1 with the
    reason; the same call (here on a sound cluster) completes the store with the reference's
    numbers."""
    crasher = tmp_path / "crasher.py"
    crasher.write_text(CRASHER)
    ext = external(worker_args=["--preload", str(crasher)],
                   env={"DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": "0",
                        "DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION": "1.0"})
    out = tmp_path / "c.zarr"
    with pytest.raises(AtlasIncomplete) as e:
        api.atlas(spec_path, out, scheduler=ext.addr, progress=False, runs_per_task=3)
    assert str(e.value).startswith("a task killed the worker that ran it (1 time): 3 of 36 runs not computed; ")
    assert e.value.exit_status == 1 and not e.value.cluster_lost
    done = done_runs_match(out, reference)
    assert done.sum() == 33 and not done[0, 1, 2].any()
    res = api.atlas(spec_path, out, workers=1, processes=False, progress=False)
    assert (res.reused, res.computed) == (33, 3)
    same_numbers(out, reference)


DEEP = """
from spinviz.regimes.engine import runs

_real = getattr(runs, "_unpatched_run_batch", runs.run_batch)
runs._unpatched_run_batch = _real


def _deeper(n):
    return _deeper(n + 1)


def run_batch(batch):
    if batch.region == (1, (0, 1), (0, 1), (0, 3)):
        _deeper(0)                                      # RecursionError, a traceback ~1000 frames deep
    return _real(batch)


runs.run_batch = run_batch
"""


@pytest.mark.slow
def test_task_error_that_never_reaches_the_client(spec_path, reference, tmp_path, external, monkeypatch):
    """A task whose error report distributed cannot read on the client (a RecursionError: its
    deep traceback fails distributed's check, and the future would stay pending forever):
    after ``STALL_S`` without a result (here 1 s) the scheduler's log is asked, the task
    counted as failed, the others computed; exit status 1; the same call completes the store."""
    monkeypatch.setattr(atlas_cluster, "STALL_S", 1.0)
    deep = tmp_path / "deep.py"
    deep.write_text(DEEP)
    ext = external(worker_args=["--preload", str(deep)])
    out = tmp_path / "d.zarr"
    t0 = time.monotonic()
    with pytest.raises(AtlasIncomplete) as e:
        api.atlas(spec_path, out, scheduler=ext.addr, progress=False, runs_per_task=3)
    assert time.monotonic() - t0 < 30
    assert e.value.exit_status == 1 and not e.value.cluster_lost
    assert str(e.value).startswith("a task failed on the cluster and its error never reached this client: 3 of 36 "
                                   "runs not computed; ")
    done = done_runs_match(out, reference)
    assert done.sum() == 33 and not done[1, 0, 0].any()
    res = api.atlas(spec_path, out, workers=1, processes=False, progress=False)
    assert (res.reused, res.computed) == (33, 3)
    same_numbers(out, reference)


@pytest.mark.slow
def test_all_workers_gone_fails_then_resumes(spec_path, reference, tmp_path, external, monkeypatch):
    """Every worker of an existing cluster killed with its nanny: the atlas waits ``NO_WORKER_S``
    for one to come back (here 2 s), then ends with ``AtlasIncomplete`` (exit status 75)
    instead of waiting forever; nothing lost is written; the same call completes it."""
    monkeypatch.setattr(cluster, "NO_WORKER_S", 2.0)
    ext = external()
    out = tmp_path / "g.zarr"

    def kill_all(n, res):
        if n == 2:
            for w in ext.workers:
                ext.kill_group(w)

    with pytest.raises(AtlasIncomplete) as e:
        api.atlas(spec_path, out, scheduler=ext.addr, progress=False, runs_per_task=1, on_result=kill_all)
    assert e.value.cluster_lost and e.value.exit_status == 75
    assert re.fullmatch(rf"no worker at the scheduler at {ext.addr} for [23] s: \d+ of 36 runs not computed; .*",
                        str(e.value)), str(e.value)
    done = done_runs_match(out, reference)
    assert 2 <= done.sum() < 36
    res = api.atlas(spec_path, out, workers=1, processes=False, progress=False)
    assert res.reused == int(done.sum())
    same_numbers(out, reference)


@pytest.mark.slow
def test_command_killed_at_random_points_resumes_to_the_same_numbers(spec_path, reference, tmp_path, rng):
    """``kill -9`` of the whole command (its process group: client and workers) at random
    moments, three times over the same store, then the command to the end: the store is the
    reference's, verifies clean, and no temporary file is left."""
    out = tmp_path / "k.zarr"
    cut = []                                          # runs on disk after each kill
    for _ in range(3):
        before = int(DS.done_mask(str(out)).sum()) if (out / "done").exists() else 0
        if before == 36:
            break
        p = command(spec_path, out, "--workers", "2", "--runs-per-task", "1", cwd=tmp_path)
        try:
            wait_for_done(out, p, at_least=before + 1)
            time.sleep(float(rng.uniform(0.0, 0.15)))  # the 36 runs take ~1 s: a chunk of 9 every ~0.25 s
        finally:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGKILL)
            p.communicate(timeout=30)
        cut.append(int(DS.done_mask(str(out)).sum()))
    assert sum(0 < n < 36 for n in cut) >= 2, cut          # killed mid-atlas, not after it
    p = command(spec_path, out, "--workers", "2", cwd=tmp_path)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 0, err
    same_numbers(out, reference)
    assert DS.verify(str(out)).clean and partials(tmp_path) == []


# --- stop signals ---------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("sig, to_group", [(signal.SIGINT, True), (signal.SIGTERM, False), (signal.SIGHUP, True),
                                           (signal.SIGHUP, False)],
                         ids=["ctrl-c-to-group", "sigterm", "sighup-to-group", "sighup"])
def test_stop_signal_mid_atlas(spec_path, reference, tmp_path, sig, to_group):
    """On the embedded cluster (2 worker processes): the command stops within 1 s with exit
    128 + n and one line, no process of its session (workers, resource tracker) outlives it,
    no temporary file is left, the store verifies clean; and the same command completes it.
    (Before: SIGHUP to the group printed a dozen tracebacks and a resource-tracker warning.)"""
    out = tmp_path / "z.zarr"
    p = command(spec_path, out, "--workers", "2", "--runs-per-task", "1", cwd=tmp_path)
    try:
        assert wait_for_done(out, p) > 0, p.communicate()[1]
        t0 = time.monotonic()
        (os.killpg if to_group else os.kill)(p.pid, sig)
        _, err = p.communicate(timeout=30)
        took = time.monotonic() - t0
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
    assert p.returncode == 128 + sig, err
    assert err.strip() == (f"spinviz: atlas stopped by {signal.Signals(sig).name}; every finished chunk is in {out} "
                           f"and the same command computes only what is missing")
    assert took < 1.0, took
    assert gone(p.pid) == []
    assert partials(tmp_path) == []
    n = int(done_runs_match(out, reference).sum())
    assert 0 < n < 36 and DS.verify(str(out)).clean
    if sig == signal.SIGHUP and to_group:
        res = api.atlas(spec_path, out, workers=1, processes=False, progress=False)
        assert (res.reused, res.computed) == (n, 36 - n)
        same_numbers(out, reference)


@pytest.mark.slow
def test_signal_inside_a_swallowing_callback_is_not_lost(spec_path, tmp_path, monkeypatch):
    """SIGTERM delivered while the main thread runs a callback whose exceptions are swallowed
    (a garbage-collection hook, as distributed's GC monitor installs): it is recorded, not
    raised there, and the atlas stops at once (before: the exception died in the hook, an
    "Exception ignored" traceback; the atlas went on until the next result)."""
    unraisable = []
    monkeypatch.setattr(sys, "unraisablehook", unraisable.append)
    armed, sent = [False], []

    def hook(phase, info):
        if armed[0] and phase == "start" and threading.current_thread() is threading.main_thread():
            armed[0] = False
            sent.append(time.monotonic())
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(20000):                     # the handler runs here, inside the hook
                pass

    def on_result(n, res):
        if n == 1:
            armed[0] = True
            gc.collect()

    gc.callbacks.append(hook)
    try:
        with interrupt.handlers(), pytest.raises(interrupt.Interrupted) as e:
            api.atlas(spec_path, tmp_path / "g.zarr", workers=1, processes=False, progress=False, runs_per_task=1,
                      on_result=on_result)
    finally:
        gc.callbacks.remove(hook)
    stopped = time.monotonic()
    assert sent and e.value.signum == signal.SIGTERM
    assert stopped - sent[0] < 1.0
    assert unraisable == []
