"""Every reader through the one special-file check (``atomic.open_regular``), measurements
files included, and every JSON or CSV input held to a nesting depth and a size: what breaks a
limit is one line naming the file and the limit, never a parser's recursion error or a wait on
a FIFO that has no writer."""

import json
import os
import signal
import time

import numpy as np
import pytest

from spinviz import experiment
from spinviz.atomic import MAX_JSON_DEPTH, json_depth, loads_json
from spinviz.commands import main
from spinviz.errors import SceneError, TrajectoryFileError
from spinviz.inputs.measurements import read_measurements
from spinviz.trajectory import Trajectory

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CUBE = os.path.join(ROOT, "scenes", "dast_cube.toml")
HEADER = "f_hz,power,sigma_f_hz,sigma_power\n"
ROWS = "".join(f"{7.0e9 + 1e6 * i},{1.3e-19 * (1 + i / 10) ** 4},0.01,2e-21\n" for i in range(6))


@pytest.fixture
def alarm():
    """A reader that blocks fails the test in 2 s instead of hanging it."""
    def ring(signum, frame):
        raise TimeoutError("the reader blocked")

    old = signal.signal(signal.SIGALRM, ring)
    signal.alarm(2)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


@pytest.mark.parametrize("ext", [".csv", ".json"])
def test_a_fifo_as_measurements_is_refused_at_once(tmp_path, alarm, ext):
    """A named pipe with no writer: ``open()`` would wait for one forever."""
    fifo = tmp_path / f"m{ext}"
    os.mkfifo(fifo)
    t0 = time.monotonic()
    with pytest.raises(SceneError) as e:
        read_measurements(fifo)
    assert time.monotonic() - t0 < 1.0
    assert str(e.value) == f"{fifo}: (file): is a named pipe (FIFO), not a regular file; measurements are a CSV or JSON file"


def test_the_command_refuses_a_fifo_in_one_line(tmp_path, alarm, capsys):
    fifo = tmp_path / "m.csv"
    os.mkfifo(fifo)
    assert main(["decide", CUBE, "--measurements", str(fifo)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is a named pipe (FIFO), not a regular file" in err, err


def test_a_directory_as_measurements_is_named(tmp_path):
    d = tmp_path / "m.json"
    d.mkdir()
    with pytest.raises(SceneError, match="is a directory, not a regular file"):
        read_measurements(d)


@pytest.mark.parametrize("doc", ["[" * 100_000 + "]" * 100_000,
                                 '{"f_hz": ' + "[" * 5000 + "]" * 5000 + "}",
                                 '{"f_hz": ' + "[" * 40 + "1" + "]" * 40 + "}"],
                         ids=["array", "inside-an-object", "just-past-the-limit"])
def test_a_deeply_nested_measurements_json_is_named_in_one_line(tmp_path, doc):
    """Python's parser would end in "maximum recursion depth exceeded while decoding a JSON
    array", naming no file."""
    path = tmp_path / "m.json"
    path.write_text(doc)
    with pytest.raises(SceneError) as e:
        read_measurements(path)
    depth = json_depth(doc)
    assert depth > MAX_JSON_DEPTH
    assert str(e.value) == f"{path}: (file): nested {depth} levels deep; a JSON input takes at most {MAX_JSON_DEPTH}"


def test_brackets_inside_strings_do_not_count():
    doc = json.dumps({"power_unit": "[" * 1000, "f_hz": [[1.0]]})
    assert json_depth(doc) == 3 and loads_json(doc)["power_unit"] == "[" * 1000
    assert json_depth(r'["\"[[[[", {"a": [1]}]') == 3


def test_a_csv_field_beyond_the_parsers_limit_is_named(tmp_path, capsys):
    """A 200 kB field: csv's own error would reach the command line as a traceback."""
    path = tmp_path / "m.csv"
    path.write_text(HEADER + '"' + "1" * 200_000 + '",1,1,1\n' + ROWS)
    with pytest.raises(SceneError) as e:
        read_measurements(path)
    assert str(e.value).startswith(f"{path}: row 1 (line 2): ") and "field" in str(e.value), e.value
    assert main(["decide", CUBE, "--measurements", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err


def test_a_csv_written_with_a_byte_order_mark_reads(tmp_path):
    """Spreadsheets write UTF-8 with a BOM; it is not part of the first column's name."""
    path = tmp_path / "m.csv"
    path.write_text("\ufeff" + HEADER + ROWS, encoding="utf-8")
    data, _ = read_measurements(path)
    assert len(data["f_hz"]) == 6


def test_the_front_door_reads_measurements_through_the_same_reader(tmp_path, alarm):
    fifo = tmp_path / "m.csv"
    os.mkfifo(fifo)
    with pytest.raises(SceneError, match="named pipe"):
        experiment.test_measurements(CUBE, fifo)


def test_a_trajectory_whose_metadata_nests_too_deep_is_named(tmp_path):
    path = tmp_path / "t.npz"
    np.savez(path, metadata=np.array("[" * 50_000 + "]" * 50_000), t=np.zeros(3))
    with pytest.raises(TrajectoryFileError) as e:
        Trajectory.load(path)
    assert str(e.value) == (f"{path}: metadata nested 50000 levels deep; a JSON input takes at most "
                            f"{MAX_JSON_DEPTH}"), e.value


def test_a_trajectory_whose_metadata_is_too_large_is_named(tmp_path, monkeypatch):
    import spinviz.trajectory as TJ

    monkeypatch.setattr(TJ, "MAX_METADATA_BYTES", 1000)
    path = tmp_path / "t.npz"
    np.savez(path, metadata=np.array("x" * 2000), t=np.zeros(3))
    with pytest.raises(TrajectoryFileError, match="metadata of 8128 bytes; a trajectory's are at most 1000"):
        Trajectory.load(path)


def test_a_store_record_that_nests_too_deep_is_a_damaged_record(tmp_path):
    from spinviz.regimes.store.integrity import read_json

    path = tmp_path / "r.json"
    path.write_text("[" * 50_000 + "]" * 50_000)
    with pytest.raises(ValueError, match="nested 50000 levels deep"):
        read_json(str(path))
