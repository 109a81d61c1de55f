"""The README's Python snippets run as written, in order, in a scratch directory."""

import os
import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def python_blocks() -> list[str]:
    text = (ROOT / "README.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


@pytest.mark.slow
def test_readme_python_snippets_run(tmp_path, monkeypatch, capsys):
    blocks = python_blocks()
    assert len(blocks) >= 1                     # the "Python" section: simulate, save, plot, compare, a frame
    shutil.copytree(ROOT / "scenes", tmp_path / "scenes")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for code in blocks:
        exec(compile(code, "README.md", "exec"), namespace)      # noqa: S102
    out = capsys.readouterr().out
    assert out.startswith("Trajectory(reduced, 'symmetric top', 400 samples, t = 0..1200 tau0, |omega| 0.3041 -> ")
    assert "first time the models differ by" in out and "residual rotation about the dipole" in out
    assert (tmp_path / "askew_plot.png").stat().st_size > 10_000
    assert sorted(p for p in os.listdir(tmp_path) if p.endswith((".npz", ".png"))) == [
        "askew.npz", "askew_plot.png", "cube_compare.png", "cube_hodograph.png"]
