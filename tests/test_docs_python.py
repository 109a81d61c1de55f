"""The Python blocks of the manual's pages run as written, in order, from the root of a
checkout (a scratch copy of its scenes): what the pages show a reader to type works, and
prints what the pages say it prints."""

import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = ["getting_started.md", "experiment.md"]         # pages whose blocks are cheap enough to run (atlas.md's is not)

pytestmark = pytest.mark.slow                           # renders, a comparison, a receiver: ~10 s each page


def python_blocks(page: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "docs" / page).read_text(), flags=re.S)


@pytest.mark.parametrize("page", PAGES)
def test_python_blocks_run(page, tmp_path, monkeypatch, capsys):
    blocks = python_blocks(page)
    assert blocks, f"docs/{page} has no Python block"
    shutil.copytree(ROOT / "scenes", tmp_path / "scenes")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for code in blocks:
        exec(compile(code, f"docs/{page}", "exec"), namespace)      # noqa: S102
    out = capsys.readouterr().out
    if page == "getting_started.md":
        assert out.startswith("Trajectory(reduced, 'symmetric top', 400 samples, t = 0..1200 tau0, |omega| 0.3041 -> ")
        assert "askew.gif 10 frames" in out and "first time the models differ by" in out
        assert "antenna at 20 cm" in out
        assert sorted(p.name for p in tmp_path.iterdir() if p.is_file()) == [
            "askew.gif", "askew.npz", "askew.png", "askew_plot.png", "cube_compare.png", "cube_hodograph.png"]
    else:
        assert out.strip() == "1.57e-10 erg/s"
