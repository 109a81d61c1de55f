"""One escaping and one number format for everything a command echoes: every path and value
goes through ``errors.printable`` (a newline, a bidi override or an ANSI escape in a file name
never reaches the terminal raw, nor splits a line), and a value refused for lying outside a
bound is printed with the digits that show it is outside ("got 1.0000001e+20", not the
"got 1e+20" that equals the bound it broke)."""

import math

import numpy as np
import pytest

from spinviz.commands import main
from spinviz.commands.shared import progress
from spinviz.errors import SceneError, SpecError
from spinviz.inputs.base import shown

HOSTILE = "a\nb\u202ec\x1b[31md"            # a line break, a right-to-left override, an ANSI colour
ESCAPED = "a\\nb\\u202ec\\x1b[31md"
SCENE = """
[body]
delta = 0.3
chi = 0.7
[initial]
omega = [0.0, 0.05, 0.3]
[simulation]
model = "reduced"
t_end = 50.0
samples = 20
[render]
duration = 1.0
fps = 10
size = [64, 48]
"""


@pytest.mark.parametrize("ext", [".glb", ".html"])
def test_an_export_prints_its_path_escaped_on_one_line(tmp_path, capsys, ext):
    """The glTF and page exports' lines escape their path as the video's and the WAV's do."""
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE)
    out = tmp_path / f"{HOSTILE}{ext}"
    assert main(["render", str(scene), "--out", str(out), "--quiet"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith(f"{tmp_path}/{ESCAPED}{ext}: "), lines
    assert not any(ch in "".join(lines) for ch in "\x1b\u202e")
    assert out.exists()


def test_progress_lines_are_escaped(capsys):
    progress(f"reading {HOSTILE}")
    assert capsys.readouterr().err == f"  reading {ESCAPED}\n"


@pytest.mark.parametrize("value, bounds, text", [
    (1.0000001e20, (0.0, 1e20), "1.0000001e+20"),
    (20.000000001, (0.0, 20.0), "20.000000001"),
    (-1e-9, (0.0, 20.0), "-1e-09"),
    (0.5, (1.0, 2.0), "0.5"),                              # ordinary values keep the short form
    (1e300, (0.0, 1e20), "1e+300"),
    (2**63, (0, 2**63 - 1), "9223372036854775808"),        # whole numbers exactly
    (math.pi, (), "3.14159"),
])
def test_a_value_is_shown_with_the_digits_that_tell_it_from_its_bounds(value, bounds, text):
    assert shown(value, *bounds) == text


def test_a_horizon_just_past_its_bound_is_printed_as_itself():
    from spinviz.inputs.atlas_spec import parse_spec

    spec = {"models": ["reduced"], "grid": {"delta": [0.3], "chi_deg": [30.0]},
            "members": {"count": 2, "seed": 1, "omega": 0.1}, "run": {"tau_end": 1.0000001e20}}
    with pytest.raises(SceneError) as e:
        parse_spec(spec, "s.toml")
    assert str(e.value) == "s.toml: [run].tau_end: must lie in (0, 1e+20], got 1.0000001e+20"


def test_a_seed_just_past_its_bound_is_printed_as_itself():
    from spinviz.inputs.decide import DecideArguments

    with pytest.raises(SpecError) as e:
        DecideArguments(seed=2**63)
    assert e.value.reason == "must lie in [0, 9223372036854775807], got 9223372036854775808"


def test_a_sample_time_just_past_the_run_is_printed_as_itself():
    from spinviz import simulate
    from spinviz.physics import bodies as B

    tr = simulate(B.symmetric_top(0.3, 0.7), "reduced", [0.0, 0.05, 0.3], t_end=20.0, samples=5, method="rk45")
    with pytest.raises(SpecError) as e:
        tr.sample(np.array([20.0 + 1e-9]))
    assert e.value.reason.endswith("got 20.000000001"), e.value.reason


def test_a_receiver_distance_just_past_its_bound_is_printed_as_itself():
    from spinviz.inputs.receiver import ReceiverSpec

    with pytest.raises(SpecError) as e:
        ReceiverSpec(distance_cm=1.0000001e30)
    assert e.value.reason == "must lie in [0.0001, 1e+30] (from a micron to a megaparsec), got 1.0000001e+30"
