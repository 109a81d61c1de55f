"""Import hygiene, each in a fresh interpreter: nothing loads what it does not need."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RENDERING = ("pyvista", "vtk", "vtkmodules", "imageio", "imageio_ffmpeg", "matplotlib")


def loaded(code: str) -> set[str]:
    """Top-level modules from RENDERING + numba/scipy present after running ``code``."""
    probe = (
        code
        + "\nimport sys, json\n"
        + f"print(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}} & set({list(RENDERING) + ['numba', 'scipy']!r}))))"
    )
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    return set(json.loads(r.stdout.strip().splitlines()[-1]))


def test_import_spinviz_is_light():
    """``import spinviz`` loads no rendering stack, not even numba or scipy (PEP 562 lazy submodules)."""
    assert loaded("import spinviz") == set()


@pytest.mark.parametrize("argv", [
    ["info", "dast_cube"],
    pytest.param(["simulate", "scenes/check_6_10_cube_truncated.toml", "--out", "{tmp}/t.npz"], marks=pytest.mark.slow),
])
def test_cli_commands_never_import_rendering(argv, tmp_path):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    mods = loaded("from spinviz.commands import main\nimport contextlib, io\n"
                  f"with contextlib.redirect_stdout(io.StringIO()):\n    assert main({argv!r}) == 0")
    assert not (mods & set(RENDERING)), mods


@pytest.mark.slow
def test_check_never_imports_rendering(check_quick):
    """``spinviz check --quick``, the session's one run of it (conftest.py; its records are
    asserted in test_cli.py): the integrators were loaded, no rendering stack was."""
    assert check_quick.code == 0, check_quick.stderr
    assert {"spinviz", "numba", "heyoka"} <= check_quick.modules          # the probe saw a real run
    assert not (check_quick.modules & set(RENDERING)), check_quick.modules & set(RENDERING)


@pytest.mark.slow
def test_public_names_work_any_number_of_times():
    """No public name is shadowed by a submodule of the same name: every public name is the
    same object before and after all submodules are imported."""
    code = """
import importlib, pkgutil
import spinviz
sc = spinviz.load_scene("scenes/askew_example.toml")
first = spinviz.simulate(sc.body, "reduced", sc.omega0, t_end=10, samples=5)
second = spinviz.simulate(sc.body, "reduced", sc.omega0, t_end=10, samples=5)
names = {n: getattr(spinviz, n) for n in spinviz.__all__}
for m in pkgutil.walk_packages(spinviz.__path__, "spinviz."):
    if not m.name.startswith("spinviz.rendering.") or m.name.endswith(("spec", "timeline")):
        importlib.import_module(m.name)
assert all(getattr(spinviz, n) is v for n, v in names.items()), "a public name changed"
assert callable(spinviz.simulate) and callable(spinviz.render) and callable(spinviz.render_frame)
third = spinviz.simulate(sc.body, "reduced", sc.omega0, t_end=10, samples=5)
assert (first.omega == second.omega).all() and (second.omega == third.omega).all()
"""
    loaded(code)
