"""Shared fixtures."""

import json
import subprocess
import sys
import zlib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def rng(request):
    """A generator seeded by the test's own name: each test draws the same numbers whatever
    ran before it (a module-level generator would hand out different draws by test order)."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


@pytest.fixture(scope="session")
def check_quick(tmp_path_factory):
    """``spinviz check --quick --json`` run once for the whole session, in a fresh interpreter
    (~9 s, the suite's most expensive command): ``code`` its exit status, ``records`` its JSON,
    ``modules`` the top-level modules loaded by the end, ``stderr``.  tests/test_cli.py asserts
    the records, tests/test_imports.py the modules."""
    modules = tmp_path_factory.mktemp("check_quick") / "modules.json"
    probe = ("import json, sys\n"
             "from spinviz.commands import main\n"
             "code = main(['check', '--quick', '--json'])\n"
             f"open({str(modules)!r}, 'w').write(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}})))\n"
             "sys.exit(code)\n")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT)
    return SimpleNamespace(code=r.returncode, records=json.loads(r.stdout) if r.stdout.strip() else None,
                           modules=set(json.loads(modules.read_text())) if modules.exists() else None, stderr=r.stderr)


@pytest.fixture(scope="session")
def small_atlas_spec(tmp_path_factory):
    """The small two-model atlas spec of tests/atlasdata.py as a file."""
    from atlasdata import SPEC

    p = tmp_path_factory.mktemp("atlas") / "small.toml"
    p.write_text(SPEC)
    return p


@pytest.fixture(scope="session")
def small_atlas_reference(small_atlas_spec, tmp_path_factory):
    """That atlas computed in one go (LocalCluster, one worker thread in this process), once
    for the cluster and the fault tests, which compare their interrupted stores with it."""
    from spinviz.regimes import api

    out = tmp_path_factory.mktemp("ref") / "ref.zarr"
    res = api.atlas(small_atlas_spec, out, workers=1, processes=False, progress=False, runs_per_task=3)
    assert res.computed == 36 and res.reused == 0
    return out


def _refined(tmp_path_factory, name: str, seed: int):
    from atlasdata import refined_spec

    from spinviz.regimes import api

    d = tmp_path_factory.mktemp(name)
    spec = d / f"{name}.toml"
    spec.write_text(refined_spec(seed))
    store = d / f"{name}.zarr"
    res = api.atlas(spec, store, workers=1, processes=False, progress=False, runs_per_task=4)
    assert res.levels == 1 and res.computed == res.total
    return spec, store


@pytest.fixture(scope="session")
def refined_atlas(tmp_path_factory):
    """The small refined atlas of tests/atlasdata.py (levels 0 and 1), computed once (~3 s):
    ``spec`` its file, ``store`` the reference store; ``foreign`` (computed when first asked
    for) the same grid from another seed -- another atlas, whose level 1 is "foreign" in the
    first."""
    spec, store = _refined(tmp_path_factory, "ref", 3)

    class Refined(SimpleNamespace):
        @property
        def foreign(self):
            if "foreign" not in self.made:
                self.made["foreign"] = _refined(tmp_path_factory, "foreign", 4)[1]
            return self.made["foreign"]

    return Refined(spec=spec, store=store, made={})


# Hypothesis, deterministic and bounded: a few examples each in the README's test command
# ("quick"), 60 in .ci/run's second pass (HYPOTHESIS_PROFILE=ci, over the tests marked slow or
# fuzz); HYPOTHESIS_PROFILE=fuzz for a long random hunt.  Every test that draws its examples
# from Hypothesis is marked fuzz here, so that pass finds them all.
from hypothesis import HealthCheck, settings  # noqa: E402

_quiet = [HealthCheck.function_scoped_fixture, HealthCheck.too_slow]
settings.register_profile("quick", max_examples=8, derandomize=True, deadline=None, suppress_health_check=_quiet)
settings.register_profile("ci", max_examples=60, derandomize=True, deadline=None, suppress_health_check=_quiet)
settings.register_profile("fuzz", max_examples=3000, deadline=None, suppress_health_check=_quiet)
settings.load_profile(__import__("os").environ.get("HYPOTHESIS_PROFILE", "quick"))


def pytest_collection_modifyitems(items):
    for item in items:
        if getattr(getattr(item, "obj", None), "is_hypothesis_test", False):
            item.add_marker(pytest.mark.fuzz)


@pytest.fixture(scope="session")
def observed_cube():
    """``observe`` of scenes/dast_cube.toml (800 + 800 instants, the default receiver), once for
    the session (~3 s): tests/test_observe.py and tests/test_receiver.py assert on it."""
    from spinviz.analysis import observe as OB
    from spinviz.inputs.scene_spec import load_scene

    obs, trajs = OB.run_scene(load_scene(ROOT / "scenes" / "dast_cube.toml"), samples=800)
    obs.trajectories = trajs
    return obs


@pytest.fixture(scope="session")
def askew(tmp_path_factory):
    """The glTF and page tests' scene (``media.write_scene``: an askew top, both models, true
    spin, 180 frames), made once: ``scene`` its file, ``plan`` its frame plan, ``glb`` the model
    ``spinviz.render`` writes (with ``askew_blender.py`` beside it), ``page`` the page written
    from the plan by ``rendering.export`` (its own keyframes and model)."""
    import spinviz
    from spinviz import pipeline
    from spinviz.rendering.export import export

    from media import write_scene

    d = tmp_path_factory.mktemp("askew")
    scene = write_scene(d / "askew.toml")
    glb = d / "askew.glb"
    res = spinviz.render(str(scene), out=str(glb))
    plan = pipeline.plan(str(scene))
    page = d / "askew.html"
    export(plan, str(page))
    return SimpleNamespace(scene=scene, plan=plan, glb=glb, page=page, result=res)
