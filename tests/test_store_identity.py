"""A store's lock belongs to the store, not to the spelling of its path: a symbolic link to it
(or to its folder) takes the same lock, so a second writer through an alias is refused and
``--verify`` through one answers "busy" (75) as the real name does; and every command that
writes a store -- ``atlas evidence KIND --out STORE`` included -- takes the lock before any work,
so one that cannot have it is refused at once, not after its study."""

import os
import shutil
import time

import pytest

from spinviz.commands import main
from spinviz.regimes.faults import StoreBusy
from spinviz.regimes.store.lock import StoreLock, lock_path
from spinviz.validation.atlas import convergence as CV
from spinviz.validation.atlas import evidence


@pytest.fixture
def store(tmp_path):
    """A folder that ``--verify`` takes for a store (it looks for .zgroup before the lock)."""
    real = tmp_path / "real.zarr"
    real.mkdir()
    (real / ".zgroup").write_text('{"zarr_format": 2}')
    return real


@pytest.mark.parametrize("alias_of", ["store", "folder"])
def test_an_alias_is_refused_as_a_second_writer(store, tmp_path, alias_of):
    """A link to the store, or to the folder holding it: the same store, the same lock."""
    if alias_of == "store":
        alias = tmp_path / "alias.zarr"
        alias.symlink_to(store)
    else:
        (tmp_path / "elsewhere").symlink_to(tmp_path, target_is_directory=True)
        alias = tmp_path / "elsewhere" / "real.zarr"
    assert lock_path(str(alias)) == lock_path(str(store))
    with StoreLock(str(store), exclusive=True):
        with pytest.raises(StoreBusy, match="is using this store"):
            StoreLock(str(alias), exclusive=True).__enter__()
    with StoreLock(str(alias), exclusive=True):                 # and the other way round
        with pytest.raises(StoreBusy):
            StoreLock(str(store), exclusive=True).__enter__()
    assert not os.path.exists(lock_path(str(store)))


def test_a_link_to_a_store_not_made_yet_shares_its_lock(tmp_path):
    """The first writer creates the store through a dangling link; a second, by the real name,
    is refused."""
    alias = tmp_path / "alias.zarr"
    alias.symlink_to(tmp_path / "new.zarr")
    with StoreLock(str(alias), exclusive=True):
        with pytest.raises(StoreBusy):
            StoreLock(str(tmp_path / "new.zarr"), exclusive=True).__enter__()


def test_verify_through_an_alias_during_a_write_answers_busy(store, tmp_path, capsys):
    """Judged in the middle of a write, a store would look damaged ("DAMAGED: 1 chunk(s) to
    recompute")."""
    alias = tmp_path / "alias.zarr"
    alias.symlink_to(store)
    with StoreLock(str(store), exclusive=True):
        for name in (store, alias):
            assert main(["atlas", "verify", str(name)]) == 75
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and "is writing this store; --verify refused" in err, err


class Reached(Exception):
    """The study started."""


@pytest.mark.slow
def test_evidence_is_refused_at_once_on_a_held_lock(refined_atlas, tmp_path, monkeypatch, capsys):
    """Another command writes the store: ``atlas evidence convergence --out STORE`` is refused before
    its study starts (refused after it, minutes of work would be thrown away), by the store's
    real name and through a link to it."""
    copy = tmp_path / "s.zarr"
    shutil.copytree(refined_atlas.store, copy)
    alias = tmp_path / "alias.zarr"
    alias.symlink_to(copy)

    def study(*a, **k):
        raise Reached

    monkeypatch.setattr(CV, "study", study)
    with StoreLock(str(copy), exclusive=True):
        for name in (copy, alias):
            t0 = time.process_time()
            with pytest.raises(StoreBusy, match="evidence convergence --out refused"):
                evidence.run("convergence", members=1, out=str(name))
            assert time.process_time() - t0 < 0.5
            assert main(["atlas", "evidence", "convergence", "--members", "1", "--out", str(name)]) == 75
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and "another spinviz" in err, err
    with pytest.raises(Reached):                                   # free again: the study starts
        evidence.run("convergence", members=1, out=str(alias))
