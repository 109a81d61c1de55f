"""The README's Python snippets run as written, in order, in a scratch directory."""

import os
import re
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def python_blocks() -> list[str]:
    text = (ROOT / "README.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_readme_python_snippets_run(tmp_path, monkeypatch):
    blocks = python_blocks()
    assert len(blocks) >= 3                     # the "Python" section: simulate, plots, pictures
    shutil.copytree(ROOT / "scenes", tmp_path / "scenes")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for code in blocks:
        exec(compile(code, "README.md", "exec"), namespace)      # noqa: S102
    assert (tmp_path / "askew.npz").exists() and (tmp_path / "askew_plot.png").stat().st_size > 10_000
    assert sorted(p for p in os.listdir(tmp_path) if p.startswith("askew")) == [
        "askew.gif", "askew.npz", "askew.png", "askew_plot.png"]
