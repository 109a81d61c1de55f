"""Special files where a reader expects a regular one -- a FIFO, a directory, a device, a
socket -- are refused at once, by every reader, with one line saying what the path is: a
FIFO without a writer would hold ``open`` forever, a device never end, a directory or a
socket fail deep inside a parser."""

import os
import shutil
import socket
import stat
import threading

import numpy as np
import pytest

import spinviz
from spinviz.atomic import NotRegularFile, open_regular, read_regular
from spinviz.commands import main
from spinviz.errors import SceneError, TrajectoryFileError

WAIT_S = 10.0            # "at once": a call that blocks is still blocked after this


def special(tmp_path, kind: str):
    """A path of ``kind``: "fifo", "directory", "device" (/dev/null's twin: a symlink to it) or "socket"."""
    p = tmp_path / f"special-{kind}"
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "directory":
        p.mkdir()
    elif kind == "device":
        p.symlink_to("/dev/zero")              # a reader of /dev/zero never reaches its end
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(p))
        s.close()
    return p


WORDS = {"fifo": "is a named pipe (FIFO), not a regular file", "directory": "is a directory, not a regular file",
         "device": "is a character device, not a regular file", "socket": "is a socket, not a regular file"}
KINDS = list(WORDS)


def at_once(fn, path):
    """``fn()``'s exception, raised within ``WAIT_S``; a call still blocked (on a FIFO) is
    released by opening the FIFO's other end, and the test fails."""
    box = {}

    def call():
        try:
            box["value"] = fn()
        except BaseException as e:             # handed to the test
            box["error"] = e

    t = threading.Thread(target=call, daemon=True)
    t.start()
    t.join(WAIT_S)
    if t.is_alive():
        if stat.S_ISFIFO(os.stat(path).st_mode):
            fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)   # the reader gets EOF and returns
            os.close(fd)
        t.join(WAIT_S)
        pytest.fail(f"{fn} blocked on {path} for {WAIT_S} s")
    assert "error" in box, f"{path} was read as if it were a file: {box.get('value')!r}"
    return box["error"]


@pytest.mark.parametrize("kind", KINDS)
def test_the_shared_reader_refuses_what_is_not_a_regular_file(tmp_path, kind):
    p = special(tmp_path, kind)
    e = at_once(lambda: read_regular(p), p)
    assert isinstance(e, NotRegularFile) and e.strerror == WORDS[kind] and e.filename == str(p)
    reg = tmp_path / "plain"
    reg.write_bytes(b"abc")
    with open_regular(reg) as fh:              # a regular file reads as any file does
        assert fh.read() == b"abc"


@pytest.mark.parametrize("kind", KINDS)
def test_trajectory_load_refuses_a_special_file_at_once(tmp_path, kind):
    """``Trajectory.load`` refuses a FIFO at once, as the scene loader does (a reader of a FIFO
    without a writer would wait forever)."""
    p = special(tmp_path, kind)
    e = at_once(lambda: spinviz.Trajectory.load(p), p)
    assert isinstance(e, TrajectoryFileError) and str(e) == f"{p}: {WORDS[kind]}"


@pytest.mark.parametrize("loader, what", [(spinviz.load_scene, "scene"), ("atlas", "atlas spec")])
@pytest.mark.parametrize("kind", KINDS)
def test_scene_and_atlas_spec_refuse_a_special_file_at_once(tmp_path, loader, what, kind):
    from spinviz.inputs.atlas_spec import load_spec

    p = special(tmp_path, kind)
    load = load_spec if loader == "atlas" else loader
    e = at_once(lambda: load(p), p)
    assert isinstance(e, SceneError) and str(e).startswith(f"{p}: (file): {WORDS[kind]}; "), str(e)


@pytest.mark.parametrize("kind", KINDS)
def test_commands_name_a_special_file_in_one_line(tmp_path, capsys, kind):
    p = special(tmp_path, kind)
    rc = {}

    def run():
        rc["code"] = main(["simulate", str(p), "--out", str(tmp_path / "t.npz")])
        raise RuntimeError("done")             # at_once wants an exception: the status is in rc

    at_once(run, p)
    err = capsys.readouterr().err.strip()
    tail = "not a scene file" if kind == "directory" else "a scene is a TOML file"
    assert rc["code"] == 2 and err == f"spinviz: error: {p}: (file): {WORDS[kind]}; {tail}", err


# --- the atlas store -----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def store(small_atlas_reference):
    return small_atlas_reference


@pytest.mark.parametrize("kind", ["fifo", "directory", "device", "socket"])
@pytest.mark.parametrize("rel, line", [
    ("regime/0.1.0.0", "regime: DAMAGED (1 chunk: regime/0.1.0.0 ({what}))"),
    (".zattrs", "metadata: DAMAGED (.zattrs ({what}))"),
    (".checksums/chunks/0.0.0.0.json", "checksums: 1 chunk with runs marked done and no usable record "
                                       "(.checksums/chunks/0.0.0.0.json (record unreadable))"),
])
@pytest.mark.slow
def test_verify_names_a_special_file_planted_in_the_store(store, tmp_path, capsys, kind, rel, line):
    """--verify read every chunk file with open(): a FIFO in place of one held it forever."""
    s = tmp_path / "s.zarr"
    shutil.copytree(store, s)
    target = s / rel
    target.unlink()
    made = special(tmp_path, kind)
    os.replace(made, target) if kind != "device" else target.symlink_to("/dev/zero")
    rc = {}

    def run():
        rc["code"] = main(["atlas", "verify", str(s)])
        raise RuntimeError("done")

    at_once(run, target)
    out = capsys.readouterr().out.splitlines()
    assert rc["code"] == 1
    assert line.format(what=WORDS[kind]) in out, out


@pytest.mark.slow
def test_resume_recomputes_a_chunk_a_fifo_replaced(store, small_atlas_spec, tmp_path, capsys):
    """The resume treats the FIFO as damage: removed, its runs computed again, the same numbers."""
    from spinviz.regimes import api
    from spinviz.regimes.store import dataset as DS

    s = tmp_path / "s.zarr"
    shutil.copytree(store, s)
    (s / "regime/0.1.0.0").unlink()
    os.mkfifo(s / "regime/0.1.0.0")
    box = {}

    def run():
        box["res"] = api.atlas(small_atlas_spec, s, workers=1, processes=False, progress=False, runs_per_task=3)
        raise RuntimeError("done")

    at_once(run, s / "regime/0.1.0.0")
    assert box["res"].repaired == 9 and box["res"].computed == 9
    assert np.array_equal(DS.regime_codes(str(s)), DS.regime_codes(str(store)))
    assert "regime/0.1.0.0 (is a named pipe (FIFO), not a regular file)" in capsys.readouterr().err


# --- outputs ------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["fifo", "device", "socket"])
def test_an_output_is_never_renamed_over_a_special_file(tmp_path, kind):
    """An output lands by renaming a finished file over its path: over a FIFO, a device or a
    socket that would replace the node itself (as root, /dev/null), so it is refused -- before
    any work by the commands' output checks, and by the atomic write itself."""
    from spinviz.atomic import check_outputs, write_text
    from spinviz.errors import UsageError

    p = special(tmp_path, kind)
    before = os.lstat(p)
    for call in (lambda: check_outputs([p]), lambda: write_text(p, "x")):
        with pytest.raises(UsageError, match="not a regular file; an output is a file written whole"):
            call()
    after = os.lstat(p)
    assert (after.st_ino, after.st_mode) == (before.st_ino, before.st_mode)
    assert [x.name for x in tmp_path.iterdir() if "partial" in x.name] == []


@pytest.mark.parametrize("argv", [["bench", "--json", "{p}"], ["report", "--out", "{p}"],
                                  ["atlas", "{spec}", "--out", "{p}"]])
def test_commands_refuse_a_special_output_before_any_work(tmp_path, capsys, small_atlas_spec, argv):
    p = special(tmp_path, "fifo")
    argv = [a.replace("{p}", str(p)).replace("{spec}", str(small_atlas_spec)) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(p) in err and "named pipe (FIFO)" in err, err
