"""The atlas store as a state machine: compute, kill (mid-run, or between a chunk's data and
its checksum record), corrupt a chunk, delete a level or its .zgroup, plant a level of another
atlas, leave what a killed creation leaves, resume -- in any order Hypothesis finds.

Invariants, after every step:

* ``--verify`` says ok exactly when every chunk the spec implies is present, matches its
  checksum and carries this spec's hash -- judged here without --verify's code: the store's
  numbers, level by level, against a reference computed once in one go, and the damage this
  machine itself did and nothing has repaired yet;
* after any resume the store equals that uninterrupted run (run_seconds, a measurement,
  aside), and nothing of an interrupted creation is left; a store holding a foreign level is
  refused, untouched, until the level is removed as the refusal says.

Slow (each resume starts a cluster: ~1-3 s); ``HYPOTHESIS_PROFILE=fuzz`` runs many more
sequences."""

import os
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, precondition, rule, run_state_machine_as_test
from test_store_spec import same_atlas

from spinviz.regimes import api
from spinviz.regimes.faults import ForeignLevel
from spinviz.regimes.store import integrity as IN
from spinviz.regimes.store import verify as VF


class Stop(KeyboardInterrupt):
    """A kill, as the store sees it: the command stops where it is."""


def snapshot(path: Path) -> list:
    return sorted((str(p), p.stat().st_size, p.stat().st_mtime_ns) for p in path.rglob("*"))


def partials(store: Path) -> list:
    near = [p for p in store.parent.iterdir() if p.name.endswith(".partial")]
    return near + ([p for p in store.iterdir() if p.name.endswith(".partial")] if store.is_dir() else [])


class StoreMachine(RuleBasedStateMachine):
    atlas = None                       # the session's refined_atlas (spec, store, foreign)
    steps: list = []                   # every step taken, over all the sequences (what was covered)

    @initialize(start=st.sampled_from(["computed", "nothing"]))
    def fresh(self, start):
        """A store already computed (a copy of the reference), or none yet."""
        self.dir = Path(tempfile.mkdtemp(prefix="spinviz-store-machine-"))
        self.store = self.dir / "s.zarr"
        self.damage: set = set()           # what this machine broke and nothing has repaired yet
        if start == "computed":
            shutil.copytree(self.atlas.store, self.store)

    def teardown(self):
        shutil.rmtree(getattr(self, "dir", "/nonexistent"), ignore_errors=True)

    def _atlas(self, **kw):
        return api.atlas(self.atlas.spec, self.store, workers=1, processes=False, progress=False, runs_per_task=4,
                         notify=lambda line: None, **kw)

    # --- what happens to a store --------------------------------------------------------------
    @rule()
    def resume(self):
        self.steps.append("resume")
        if "foreign" in self.damage:
            before = snapshot(self.store)
            with pytest.raises(ForeignLevel):
                self._atlas()
            assert snapshot(self.store) == before                       # refused, untouched
            return
        self._atlas()
        same_atlas(self.store, self.atlas.store)
        assert partials(self.store) == []
        self.damage.clear()

    @precondition(lambda self: not self.damage)
    @rule(after=st.integers(1, 12))
    def kill_mid_run(self, after):
        self.steps.append("kill_mid_run")
        def stop(n, res):
            if n == after:
                raise Stop

        try:
            self._atlas(on_result=stop)
        except Stop:
            pass

    @precondition(lambda self: not self.damage)
    @rule(at=st.integers(1, 8))
    def kill_between_data_and_record(self, at):
        """The ``at``-th chunk write loses its record, as a SIGKILL between the two would."""
        self.steps.append("kill_between_data_and_record")
        real, calls = IN.record, []

        def cut(*a, **k):
            calls.append(a)
            if len(calls) == at:
                raise Stop
            return real(*a, **k)

        IN.record = cut
        try:
            self._atlas()
        except Stop:
            self.damage.add("unrecorded chunk")
        finally:
            IN.record = real

    @precondition(lambda self: self.store.is_dir())
    @rule(data=st.data())
    def corrupt_chunk(self, data):
        self.steps.append("corrupt_chunk")
        files = sorted(p for p in self.store.rglob("*") if p.is_file() and not p.name.startswith(".")
                       and "/.checksums/" not in str(p) and p.parent.name not in ("omega0", "paper", "delta", "chi",
                                                                                  "chi_deg", "member", "axis", "quantity",
                                                                                  "formula", "model", "start", "tau"))
        if not files:
            return
        f = data.draw(st.sampled_from(files))
        how = data.draw(st.sampled_from(["flip", "truncate", "delete", "fifo"]))
        raw = f.read_bytes()
        if how == "flip":
            f.write_bytes(bytes([raw[0] ^ 0xFF]) + raw[1:])
        elif how == "truncate":
            f.write_bytes(raw[: len(raw) // 2])
        else:
            f.unlink()
            if how == "fifo":
                os.mkfifo(f)
        self.damage.add(f"{how} {f.relative_to(self.store)}")

    @precondition(lambda self: (self.store / "level1").exists() and "foreign" not in self.damage)
    @rule()
    def delete_level(self):
        self.steps.append("delete_level")
        shutil.rmtree(self.store / "level1")

    @precondition(lambda self: (self.store / "level1" / ".zgroup").exists() and "foreign" not in self.damage)
    @rule()
    def delete_zgroup(self):
        self.steps.append("delete_zgroup")
        (self.store / "level1" / ".zgroup").unlink()
        self.damage.add("level1/.zgroup")

    @precondition(lambda self: self.store.is_dir() and "foreign" not in self.damage)
    @rule()
    def plant_foreign_level(self):
        self.steps.append("plant_foreign_level")
        shutil.rmtree(self.store / "level1", ignore_errors=True)
        shutil.copytree(self.atlas.foreign / "level1", self.store / "level1")
        self.damage.add("foreign")

    @precondition(lambda self: "foreign" in self.damage)
    @rule()
    def remove_foreign_level(self):
        self.steps.append("remove_foreign_level")
        shutil.rmtree(self.store / "level1")                         # as the refusal says
        self.damage.discard("foreign")

    @rule(inside=st.booleans())
    def leave_what_a_killed_creation_leaves(self, inside):
        """``.NAME.XXXXXXXX.partial/atlas.zarr``: a store's skeleton that never got its rename."""
        self.steps.append("leave_what_a_killed_creation_leaves")
        where = self.store if inside and self.store.is_dir() else self.dir
        name = "level1" if where == self.store else self.store.name
        skeleton = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=".partial", dir=where)) / "atlas.zarr"
        skeleton.mkdir()
        (skeleton / ".zgroup").write_text('{"zarr_format": 2}')

    # --- what --verify must say -----------------------------------------------------------------
    @invariant()
    def verify_says_ok_exactly_when_the_store_is_the_whole_atlas(self):
        if not hasattr(self, "store"):
            return
        if not (self.store / ".zgroup").exists():
            return                                                       # no store yet: not an atlas store (exit 2)
        ok = VF.report(str(self.store))["ok"]
        if self.damage:
            assert not ok, self.damage
            return
        try:
            same_atlas(self.store, self.atlas.store)
            whole = True
        except AssertionError:
            whole = False
        assert ok == whole, (ok, whole)


@pytest.mark.slow
def test_the_store_as_a_state_machine(refined_atlas):
    StoreMachine.atlas, StoreMachine.steps = refined_atlas, []
    run_state_machine_as_test(StoreMachine, settings=settings(
        max_examples=max(6, settings.default.max_examples // 10), stateful_step_count=10, deadline=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much]))
    taken = {s: StoreMachine.steps.count(s) for s in set(StoreMachine.steps)}
    print(f"store machine: {len(StoreMachine.steps)} steps {taken}")
    assert taken.get("resume", 0) >= 2 and len(taken) >= 5, taken          # the sequences did go somewhere
