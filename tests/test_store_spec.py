"""An atlas store judged from its spec: ``--verify`` says ok only when every level the spec
implies is present, whole and of this spec; the resume recomputes a missing or damaged level
and refuses a foreign one with the command that removes it; one writer at a time (a lock);
what a kill during the store's creation leaves is recognised and removed."""

import os
import shutil
import signal
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import zarr

from spinviz.commands import main
from spinviz.regimes import api
from spinviz.regimes.faults import ForeignLevel, StoreBusy
from spinviz.regimes.store import dataset as DS
from spinviz.regimes.store import levels as LV
from spinviz.regimes.store.lock import StoreLock, lock_path

# every test here reads the refined atlas (~4 s of CPU to compute once): .ci/run's second pass
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
SKIP = {"run_seconds"}                 # a measurement: differs between two computations of the same atlas


def variables(path) -> dict:
    g = zarr.open_group(str(path), mode="r", zarr_format=2)
    return {k: np.asarray(g[k]) for k in g.array_keys() if k not in SKIP}


def same_atlas(a, b) -> None:
    """Every level of ``b`` is in ``a`` with the same numbers and attributes (run_seconds aside)."""
    la, lb = LV.found(a), LV.found(b)
    assert la == lb, (la, lb)
    for k in [0, *lb]:
        pa, pb = DS.level_path(str(a), k), DS.level_path(str(b), k)
        va, vb = variables(pa), variables(pb)
        assert va.keys() == vb.keys()
        for name in vb:
            assert np.array_equal(va[name], vb[name], equal_nan=va[name].dtype.kind == "f"), (k, name)
        assert dict(zarr.open_group(pa, mode="r").attrs) == dict(zarr.open_group(pb, mode="r").attrs)


def counts(atlas) -> tuple[int, int, int]:
    """(level-0 runs, level-1 cells, level-1 runs) the spec implies: level 0 the whole grid,
    level 1 the children of the cells level 0's labels flag (``levels.wanted``)."""
    from spinviz.inputs.atlas_spec import load_spec

    spec = load_spec(atlas.spec)
    cells = int(LV.wanted(spec, [str(atlas.store)], 1).sum())
    return spec.runs, cells, cells * spec.members


def verify(path, capsys):
    code = main(["atlas", "verify", str(path)])
    return code, capsys.readouterr().out.strip().splitlines()


def resume(atlas, path, **kw):
    return api.atlas(atlas.spec, path, workers=1, processes=False, progress=False, runs_per_task=4, **kw)


@pytest.fixture
def copy(refined_atlas, tmp_path):
    out = tmp_path / "s.zarr"
    shutil.copytree(refined_atlas.store, out)
    return out


def test_the_reference_verifies_ok_over_both_levels(refined_atlas, capsys):
    n0, _, n1 = counts(refined_atlas)
    assert n1 > 0
    code, lines = verify(refined_atlas.store, capsys)
    assert code == 0 and lines[-1] == f"{refined_atlas.store}: ok: {n0 + n1} runs verified over 2 refinement levels"
    assert f"level 1: runs: all {n1} computed" in lines


@pytest.mark.slow
def test_a_deleted_level_is_missing_not_ok_and_the_resume_computes_it(refined_atlas, copy, capsys):
    """``rm -r STORE/level1``: the level's runs gone is not "ok" -- the spec implies level 1,
    so it is named missing, exit 1; the resume computes it, and only it."""
    n0, cells, n1 = counts(refined_atlas)
    shutil.rmtree(copy / "level1")
    code, lines = verify(copy, capsys)
    assert code == 1, lines
    assert f"level 1: MISSING: the labels of level 0 call for {cells} of its cells ([refine] levels = 1)" in lines
    assert lines[-1] == f"{copy}: MISSING LEVEL: level1 missing (the same atlas command computes it)"
    res = resume(refined_atlas, copy)
    assert (res.reused, res.computed) == (n0, n1)
    same_atlas(copy, refined_atlas.store)
    assert verify(copy, capsys)[0] == 0


@pytest.mark.slow
def test_a_level_without_its_zgroup_is_computed_again(refined_atlas, copy, capsys):
    """Only ``level1/.zgroup`` deleted: the level is not a whole store, named so by --verify;
    the resume removes it and computes it again, in one line (a level can always be
    recomputed from the spec and the levels below)."""
    (copy / "level1" / ".zgroup").unlink()
    code, lines = verify(copy, capsys)
    assert code == 1 and "level 1: DAMAGED: no .zgroup: not a whole Zarr store" in lines, lines
    assert lines[-1] == f"{copy}: DAMAGED LEVEL: level1 not a whole store (the same atlas command computes it again)"
    res = resume(refined_atlas, copy)
    assert res.computed == counts(refined_atlas)[2]
    assert capsys.readouterr().err.strip() == (f"spinviz: {copy / 'level1'}: no .zgroup: not a whole Zarr store; the "
                                               f"level is computed again")
    same_atlas(copy, refined_atlas.store)


def test_a_level_carrying_another_atlas_identity_is_foreign(refined_atlas, copy, capsys, tmp_path):
    """Fast: level 1 relabelled, checksums and all, as the level of the same grid from seed 4
    (the identity a copied level of that atlas carries): --verify says FOREIGN, exit 1."""
    import tomllib

    from atlasdata import refined_spec

    from spinviz.inputs.atlas_spec import parse_spec
    from spinviz.regimes.store import integrity as IN

    other = parse_spec(tomllib.loads(refined_spec(4)), str(tmp_path / "other.toml"))
    level = copy / "level1"

    def write():
        g = zarr.open_group(str(level), mode="r+", zarr_format=2)
        g.attrs["spec"] = LV.level_spec(other, 1).canonical_json()
        g.attrs["spec_sha256"] = LV.level_identity(other, 1)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")           # zarr on the store's .checksums: not one of its arrays
            zarr.consolidate_metadata(str(level), zarr_format=2)

    IN.rewrite_metadata(str(level), [".zattrs", ".zmetadata"], write)
    code, lines = verify(copy, capsys)
    assert code == 1 and any(x.startswith("level 1: FOREIGN: holds a level of another atlas") for x in lines), lines
    with pytest.raises(ForeignLevel, match=r"level1: holds a refinement level of another atlas"):
        resume(refined_atlas, copy)


@pytest.mark.slow
def test_a_level_of_another_atlas_is_foreign_refused_and_named(refined_atlas, copy, capsys):
    """A level copied from an atlas of another seed is whole and checksummed, but of another
    atlas: --verify names it FOREIGN (both identities), and the resume refuses it -- touching
    nothing -- with the one command that removes it; after which it computes this atlas's."""
    shutil.rmtree(copy / "level1")
    shutil.copytree(refined_atlas.foreign / "level1", copy / "level1")
    code, lines = verify(copy, capsys)
    want = LV.level_identity(LV.recorded_spec(str(copy)), 1)
    have = LV.recorded_identity(str(copy / "level1"))
    assert code == 1 and have != want
    assert f"level 1: FOREIGN: holds a level of another atlas (sha256 {have[:12]}; this atlas's level 1: {want[:12]})" \
        in lines, lines
    before = sorted((str(p), p.stat().st_mtime_ns) for p in copy.rglob("*"))
    with pytest.raises(ForeignLevel) as e:
        resume(refined_atlas, copy)
    assert str(e.value) == (f"{copy / 'level1'}: holds a refinement level of another atlas (sha256 {have[:12]}; this "
                            f"spec's level 1: {want[:12]}); refusing to mix them: remove it (rm -r {copy / 'level1'}) "
                            f"and the same command computes this spec's")
    assert sorted((str(p), p.stat().st_mtime_ns) for p in copy.rglob("*")) == before
    shutil.rmtree(copy / "level1")                            # what the line says to do
    resume(refined_atlas, copy)
    same_atlas(copy, refined_atlas.store)


def test_a_level_beyond_the_spec_is_named(refined_atlas, copy, capsys):
    shutil.copytree(copy / "level1", copy / "level2")
    code, lines = verify(copy, capsys)
    assert code == 1 and lines[-1] == f"{copy}: NOT OK: level2 is not part of this atlas (rm -r {copy / 'level2'})"
    with pytest.raises(ForeignLevel, match=r"level2: not a refinement level of this spec \(\[refine\] levels = 1\)"):
        resume(refined_atlas, copy)


def test_an_incomplete_store_is_not_ok(refined_atlas, tmp_path, capsys):
    """An interrupted atlas holds every finished chunk and nothing false -- but it is not the
    atlas its spec implies: --verify says how many runs are missing, exit 1."""
    out = tmp_path / "i.zarr"

    def stop(n, res):
        if n == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        resume(refined_atlas, out, on_result=stop)
    done = int(DS.done_mask(str(out)).sum())
    code, lines = verify(out, capsys)
    n0 = counts(refined_atlas)[0]
    assert code == 1 and 0 < done < n0
    assert f"runs: INCOMPLETE ({n0 - done} of {n0} not computed yet)" in lines
    assert lines[-1] == f"{out}: INCOMPLETE: {n0 - done} run(s) not computed yet; the same atlas command computes them"


def test_a_changed_record_of_the_spec_is_damage(refined_atlas, copy, capsys):
    """The attributes' spec no longer gives its own hash (written by hand, checksums recorded
    again): the spec the store claims cannot be trusted."""
    from spinviz.regimes.store import integrity as IN

    def write():
        g = zarr.open_group(str(copy), mode="r+", zarr_format=2)
        spec = g.attrs["spec"].replace('"seed":3', '"seed":4')
        g.attrs["spec"] = spec
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")           # zarr on the store's .checksums: not one of its arrays
            zarr.consolidate_metadata(str(copy), zarr_format=2)

    IN.rewrite_metadata(str(copy), [".zattrs", ".zmetadata"], write)
    code, lines = verify(copy, capsys)
    assert code == 1 and lines[1] == ("level 0: spec: DAMAGED (spec_sha256: does not match the recorded spec (the "
                                      "attributes were changed))"), lines
    assert lines[-1] == f"{copy}: DAMAGED: the recorded spec does not hold; compute the atlas again into a new store"


# --- one writer at a time -------------------------------------------------------------------------
@pytest.mark.slow
def test_a_second_command_on_a_store_being_written_is_refused_at_once(refined_atlas, copy, capsys):
    """Another holder of the lock (here: this test, as another process would): the atlas and
    --verify are refused at once with one line, exit 75, the store untouched; once the lock
    is given back both work, and no lock file is left."""
    shutil.rmtree(copy / "level1")
    before = sorted((str(p), p.stat().st_mtime_ns) for p in copy.rglob("*"))
    with StoreLock(str(copy), exclusive=True):
        assert main(["atlas", str(refined_atlas.spec), "--out", str(copy), "--quiet", "--workers", "1"]) == 75
        err = capsys.readouterr().err.strip()
        assert err == (f"spinviz: error: {copy}: another spinviz (pid {os.getpid()}) is using this store; this atlas "
                       f"command refused (never two at once): run it again when that command has finished")
        assert main(["atlas", "verify", str(copy)]) == 75
        assert "is writing this store; --verify refused" in capsys.readouterr().err
        with pytest.raises(StoreBusy):
            resume(refined_atlas, copy)
    assert sorted((str(p), p.stat().st_mtime_ns) for p in copy.rglob("*")) == before
    resume(refined_atlas, copy)
    assert verify(copy, capsys)[0] == 0
    assert not os.path.exists(lock_path(str(copy)))


def test_two_verifications_share_the_store(refined_atlas, copy, capsys):
    with StoreLock(str(copy), exclusive=False):
        assert verify(copy, capsys)[0] == 0
    assert not os.path.exists(lock_path(str(copy)))


@pytest.mark.slow
def test_two_atlas_processes_never_interleave(refined_atlas, tmp_path):
    """Two real commands on one new store, the second started while the first writes: it is
    refused in one line (exit 75) and the first finishes the reference's atlas."""
    out = tmp_path / "two.zarr"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-m", "spinviz", "atlas", str(refined_atlas.spec), "--out", str(out), "--workers", "1",
           "--quiet", "--runs-per-task", "4"]
    first = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        while not os.path.exists(lock_path(str(out))):             # the first holds the lock
            assert first.poll() is None, first.communicate()
        second = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
        assert second.returncode == 75, second.stderr
        assert second.stderr.count("\n") == 1 and f"another spinviz (pid {first.pid}) is using this store" in second.stderr
    finally:
        _, err = first.communicate(timeout=120)
    assert first.returncode == 0, err
    same_atlas(out, refined_atlas.store)


# --- what a kill leaves ---------------------------------------------------------------------------
KILL_AT_CREATION = """
import os, signal, sys
from spinviz.regimes import api
from spinviz.regimes.store import dataset, integrity
real, calls = integrity.record_skeleton, []
def record_then_die(path):
    real(path)
    calls.append(path)
    if len(calls) == int(sys.argv[3]):              # the level's skeleton is in the temporary directory
        os.kill(os.getpid(), signal.SIGKILL)
dataset.IN.record_skeleton = record_then_die
api.atlas(sys.argv[1], sys.argv[2], workers=1, processes=False, progress=False, runs_per_task=4)
"""


@pytest.mark.slow
@pytest.mark.parametrize("creation", [1, 2], ids=["store", "level1"])
def test_a_kill_during_creation_leaves_what_the_next_command_removes(refined_atlas, tmp_path, capsys, creation):
    """SIGKILL while the store (or level 1) is being created, before its rename: the temporary
    directory it leaves (``.s.zarr.XXXXXXXX.partial`` beside the store, ``.level1...partial``
    inside it) is named by --verify and removed by the next command, which finishes the
    reference's atlas."""
    out = tmp_path / "s.zarr"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", KILL_AT_CREATION, str(refined_atlas.spec), str(out), str(creation)],
                       env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == -signal.SIGKILL, r.stderr
    where = tmp_path if creation == 1 else out
    left = [p.name for p in where.iterdir() if p.name.endswith(".partial")]
    assert len(left) == 1 and left[0].startswith(".s.zarr." if creation == 1 else ".level1."), left
    if creation == 1:
        assert main(["atlas", "verify", str(out)]) == 2
        assert f"{tmp_path / left[0]} is what an interrupted creation left" in capsys.readouterr().err
    else:
        code, lines = verify(out, capsys)
        cells = counts(refined_atlas)[1]
        assert code == 1 and f"level 1: MISSING: the labels of level 0 call for {cells} of its cells ([refine] levels = 1)" \
            in lines, lines
        assert f"level 0: leftovers: 1 temporary file(s) of an interrupted write (removed on resume: {left[0]})" in lines
    resume(refined_atlas, out)
    err = capsys.readouterr().err
    assert left[0] in err and "interrupted" in err, err
    assert [p.name for p in where.iterdir() if p.name.endswith(".partial")] == []
    same_atlas(out, refined_atlas.store)
