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


# Hypothesis: deterministic and bounded in CI; HYPOTHESIS_PROFILE=fuzz for a long random hunt.
from hypothesis import HealthCheck, settings  # noqa: E402

_quiet = [HealthCheck.function_scoped_fixture, HealthCheck.too_slow]
settings.register_profile("ci", max_examples=60, derandomize=True, deadline=None, suppress_health_check=_quiet)
settings.register_profile("fuzz", max_examples=3000, deadline=None, suppress_health_check=_quiet)
settings.load_profile(__import__("os").environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture(scope="session")
def observed_cube():
    """``observe`` of scenes/dast_cube.toml (800 + 800 instants, the default receiver), once for
    the session (~3 s): tests/test_observe.py and tests/test_receiver.py assert on it."""
    from spinviz.analysis import observe as OB
    from spinviz.inputs.scene_spec import load_scene

    obs, trajs = OB.run_scene(load_scene(ROOT / "scenes" / "dast_cube.toml"), samples=800)
    obs.trajectories = trajs
    return obs
