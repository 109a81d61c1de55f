"""Shared fixtures."""

import zlib

import numpy as np
import pytest


@pytest.fixture
def rng(request):
    """A generator seeded by the test's own name: each test draws the same numbers whatever
    ran before it (a module-level generator would hand out different draws by test order)."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))
