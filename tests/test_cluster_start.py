"""The embedded cluster under load: it waits for its workers in proportion to the machine's
load (a spawned interpreter that imports Dask and the integrators takes seconds on an idle
machine and many times that at a load of 30 on 2 cores, where a fixed 120 s is too short), keeps
waiting while workers keep arriving, and when it does give up says so in one line, with the
load, and leaves no process behind."""

import multiprocessing
import os

import pytest

from spinviz.errors import SpinvizError
from spinviz.executors import cluster as CL


def test_the_wait_grows_with_the_load(monkeypatch):
    monkeypatch.setattr(CL, "usable_cores", lambda: 2)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.5, 0.5, 0.5))
    assert CL.start_timeout() == CL.START_TIMEOUT_S                    # an idle machine: the measured wait
    monkeypatch.setattr(os, "getloadavg", lambda: (30.0, 20.0, 10.0))
    assert CL.start_timeout() == pytest.approx(15.0 * CL.START_TIMEOUT_S)
    monkeypatch.setattr(os, "getloadavg", lambda: (1e6, 1e6, 1e6))
    assert CL.start_timeout() == CL.MAX_START_S                         # bounded: a day's wait is no answer either


@pytest.mark.slow
def test_a_cluster_that_does_not_start_in_time_says_so_in_one_line_and_leaves_nothing(monkeypatch):
    """The wait shrunk to nothing: the refusal is one line naming the load and what to do,
    exit status 75 (try again later), and the workers being started are killed."""
    monkeypatch.setattr(CL, "START_TIMEOUT_S", 1e-3)
    before = {p.pid for p in multiprocessing.active_children()}
    with pytest.raises(SpinvizError) as e:
        with CL.Cluster(None, 2):
            pass
    msg = str(e.value)
    assert "\n" not in msg and "load average" in msg and "did not start" in msg, msg
    assert getattr(e.value, "exit_status", None) == 75
    assert [p.pid for p in multiprocessing.active_children() if p.pid not in before] == []
