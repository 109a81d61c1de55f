"""Shared fixtures."""

import zlib

import numpy as np
import pytest


@pytest.fixture
def rng(request):
    """A generator seeded by the test's own name: each test draws the same numbers whatever
    ran before it (a module-level generator would hand out different draws by test order)."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


# Hypothesis: deterministic and bounded in CI; HYPOTHESIS_PROFILE=fuzz for a long random hunt.
from hypothesis import HealthCheck, settings  # noqa: E402

_quiet = [HealthCheck.function_scoped_fixture, HealthCheck.too_slow]
settings.register_profile("ci", max_examples=60, derandomize=True, deadline=None, suppress_health_check=_quiet)
settings.register_profile("fuzz", max_examples=3000, deadline=None, suppress_health_check=_quiet)
settings.load_profile(__import__("os").environ.get("HYPOTHESIS_PROFILE", "ci"))
