"""Regime atlas on Dask: the store written chunk by chunk, resumed, refused, survived.

One small spec (2 models x 2 x 3 cells x 3 members = 36 runs to tau = 1e8, ~2 s of work) is
computed once as the reference; every other way of computing it must give the same numbers
(only ``run_seconds``, a measurement, may differ)."""

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from atlasdata import SPEC, VARIABLES

from spinviz.errors import UsageError
from spinviz.executors import cluster
from spinviz.inputs.atlas_spec import load_spec
from spinviz.regimes import api
from spinviz.regimes.store import dataset as DS

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def spec_path(small_atlas_spec):
    return small_atlas_spec


@pytest.fixture(scope="module")
def reference(small_atlas_reference):
    return small_atlas_reference


def same_numbers(a, b):
    import xarray as xr

    da, db = xr.open_zarr(a), xr.open_zarr(b)
    for v in VARIABLES:
        x, y = da[v].values, db[v].values
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), v
        else:
            assert np.array_equal(x, y), v
    assert da.attrs == db.attrs


@pytest.mark.slow
def test_store_opens_with_plain_xarray(reference):
    """Plain ``xarray.open_zarr``: dims, every run done, the spec and version recorded, the
    labels readable through their flag meanings."""
    import json

    import xarray as xr

    ds = xr.open_zarr(reference)
    assert dict(ds["regime"].sizes) == {"model": 2, "delta": 2, "chi": 3, "member": 3}
    assert (ds["done"].values == 1).all()
    spec = json.loads(ds.attrs["spec"])
    assert spec["members"]["seed"] == 5 and ds.attrs["seed"] == 5 and ds.attrs["spinviz_version"]
    meanings = dict(zip(ds["regime"].attrs["flag_values"], ds["regime"].attrs["flag_meanings"].split()))
    labels = {meanings[c] for c in np.unique(ds["regime"].values)}
    assert labels <= {"1", "2", "3", "4", "5", "T2", "T4", "Tcone", "TF", "approaching", "other"}
    full = DS.open_atlas(reference)
    # (0.5, 45 deg) reduced: the capture into type 5 happens by 1e8 at |omega0| = 0.05
    assert (full["label"].sel(model="reduced", delta=0.5).isel(chi=1).values == "5").sum() >= 2


@pytest.mark.slow
def test_interrupted_then_resumed_store_is_identical(spec_path, reference, tmp_path):
    """Stop after 2 batches (as Ctrl-C would): the store holds exactly the finished batches,
    consistently; the same call again computes only the rest and gives the same numbers."""
    out = tmp_path / "a.zarr"

    def stop(n, res):
        if n == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        api.atlas(spec_path, out, workers=1, processes=False, progress=False, runs_per_task=3, on_result=stop)
    done = DS.done_mask(str(out))
    assert done.sum() == 6                                      # 2 batches x 3 runs, nothing else
    import xarray as xr

    part = xr.open_zarr(out)
    finished = part["regime"].values[done]
    assert (finished != 0).all() and (part["regime"].values[~done] == 0).all()
    res = api.atlas(spec_path, out, workers=1, processes=False, progress=False, runs_per_task=3)
    assert res.reused == 6 and res.computed == 30
    same_numbers(out, reference)
    again = api.atlas(spec_path, out, workers=1, processes=False, progress=False)
    assert again.computed == 0 and again.reused == 36 and again.cluster == "nothing to compute"


@pytest.mark.slow
def test_store_of_another_spec_is_refused(spec_path, reference, tmp_path):
    other = tmp_path / "other.toml"
    other.write_text(SPEC.replace("seed = 5", "seed = 6"))
    before = sorted((p.relative_to(reference), p.stat().st_mtime_ns) for p in Path(reference).rglob("*"))
    with pytest.raises(UsageError) as e:
        api.atlas(other, reference, workers=1, processes=False, progress=False)
    msg = str(e.value)
    assert "holds an atlas of another spec" in msg and "refusing to mix" in msg and "\n" not in msg
    assert sorted((p.relative_to(reference), p.stat().st_mtime_ns) for p in Path(reference).rglob("*")) == before


@pytest.mark.slow
def test_killed_worker_still_completes_the_store(spec_path, reference, tmp_path):
    """Two worker processes; the one that delivered the first batch is killed (SIGKILL) while
    it holds more: Dask reruns its batches elsewhere and the store is complete and identical."""
    out = tmp_path / "k.zarr"
    killed = []

    def kill(n, res):
        if not killed and res["worker_pid"] > 0:
            os.kill(res["worker_pid"], signal.SIGKILL)
            killed.append(res["worker_pid"])

    res = api.atlas(spec_path, out, workers=2, progress=False, runs_per_task=3, on_result=kill)
    assert killed and res.failed == 0 and res.computed == 36
    same_numbers(out, reference)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_existing_scheduler_with_two_workers(spec_path, reference, tmp_path):
    """The stock ``dask scheduler`` and two ``dask worker`` processes on localhost; the atlas
    through ``--scheduler`` gives the reference's numbers."""
    dask = str(Path(sys.executable).parent / "dask")
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    procs = []
    try:
        procs.append(subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                                      env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", addr, "--nthreads", "1", "--no-dashboard"], env=env,
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client

        with Client(addr, timeout=30) as c:
            c.wait_for_workers(2, timeout=60)
        out = tmp_path / "s.zarr"
        res = api.atlas(spec_path, out, scheduler=addr, progress=False, runs_per_task=3)
        assert "cluster at" in res.cluster and "2 workers" in res.cluster and res.computed == 36
        import xarray as xr

        assert len({int(p) for p in np.unique(xr.open_zarr(out)["nsteps"].values)}) > 1
        same_numbers(out, reference)
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()


@pytest.mark.slow
def test_unreachable_scheduler_exit_2_nothing_written(spec_path, tmp_path, monkeypatch, capsys):
    from spinviz.commands import main

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT_S", 1.0)
    out = tmp_path / "u.zarr"
    addr = f"tcp://127.0.0.1:{_free_port()}"
    assert main(["atlas", str(spec_path), "--out", str(out), "--scheduler", addr, "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"spinviz: error: --scheduler: {addr}: cannot connect") and "\n" not in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_sigterm_stops_cleanly_and_resume_completes(spec_path, reference, tmp_path):
    """The command in a subprocess, stopped by SIGTERM once the first chunk is on disk:
    exit 143, a one-line note, the cluster gone; the same command then completes the store."""
    out = tmp_path / "t.zarr"
    spec = load_spec(spec_path)
    slow = tmp_path / "slow.toml"
    slow.write_text(SPEC)
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    cmd = [sys.executable, "-m", "spinviz", "atlas", str(slow), "--out", str(out), "--workers", "2", "--quiet",
           "--runs-per-task", "1"]
    p = subprocess.Popen(cmd, env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    try:
        t0 = time.monotonic()
        while time.monotonic() - t0 < 60:
            if (out / "done").exists() and DS.done_mask(str(out)).any():
                break
            if p.poll() is not None:
                break
            time.sleep(0.05)
        p.send_signal(signal.SIGTERM)
        _, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
    if p.returncode == 0:
        pytest.skip("the atlas finished before the signal")            # a very fast machine
    assert p.returncode == 143, err
    assert "atlas stopped" in err and "Traceback" not in err
    done = DS.done_mask(str(out))
    assert 0 < done.sum() < spec.runs
    res = api.atlas(slow, out, workers=1, processes=False, progress=False)       # the same call, in-process
    assert res.reused == int(done.sum()) and res.computed == spec.runs - res.reused
    same_numbers(out, reference)


@pytest.mark.slow
def test_plots_show_every_member(reference, tmp_path):
    """The diagram's shares add up to 1 in every cell; one hodograph per type found as tau -> oo."""
    from PIL import Image

    from spinviz.regimes.figures import cells, draw, hodographs

    ds = DS.open_atlas(reference)
    for model in ("reduced", "truncated"):
        total = sum(cells.shares(ds, model).values())
        assert np.allclose(total, 1.0)
    reps = hodographs.representatives(ds)
    found = {(m, lab) for m, lab, *_ in reps}
    # one panel per type the diagram shows: the types as tau -> oo (cells.cell_types), not the
    # labels at tau_end, which can name a stage a slow run has not left ("Tcone")
    labels = {(m, str(x)) for m in ("reduced", "truncated") for x in np.unique(cells.cell_types(ds, m)[0])}
    assert found == {x for x in labels if x[1] not in ("other", "failed", "missing", "approaching")}
    paths = draw.draw(str(reference), [str(tmp_path / "d.png"), str(tmp_path / "d_hodographs.png")])
    w, h = Image.open(paths[0]).size
    assert (w, h) == (2 * 792, 836)                              # two panels at 7.2 x 7.6 in, 110 dpi
    assert os.path.getsize(paths[0]) < 300_000 and os.path.getsize(paths[1]) < 300_000
