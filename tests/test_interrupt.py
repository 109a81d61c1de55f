"""The stop machinery itself: deferral, library frames, a clean slate after a command."""

import os
import signal
import threading

import numpy as np
import pytest

from spinviz import interrupt


def send(sig=signal.SIGTERM):
    os.kill(os.getpid(), sig)


def test_deferred_holds_a_signal_back_even_with_other_threads_running():
    """A signal mask would cover only the main thread; with other threads alive (as OpenBLAS's
    are) the handler must still not raise inside the block: it raises when the block ends."""
    stop = threading.Event()
    helper = threading.Thread(target=stop.wait, daemon=True)
    helper.start()
    steps = []
    try:
        with interrupt.handlers():
            with pytest.raises(interrupt.Interrupted) as e:
                with interrupt.deferred():
                    send()
                    for _ in range(1000):             # the handler runs at some bytecode in here
                        np.sqrt(2.0)
                    steps.append("rest of the block ran")
            assert steps == ["rest of the block ran"] and e.value.exit_status == 143
    finally:
        stop.set()


def test_no_stale_signal_after_a_command_run_in_process():
    with interrupt.handlers():
        with pytest.raises(interrupt.Interrupted):
            send(signal.SIGINT)
            for _ in range(1000):
                np.sqrt(2.0)
    assert interrupt.received() is None
    interrupt.check()                                 # nothing to raise


def test_library_frames_are_judged_by_module_name(tmp_path):
    """A script that happens to live in a folder called pyvista is not a library frame."""
    code = compile("result = inside(frame())", str(tmp_path / "pyvista" / "run.py"), "exec")
    ns = {"inside": interrupt._inside_swallowing_library, "frame": lambda: __import__("sys")._getframe(1),
          "__name__": "__main__"}
    exec(code, ns)
    assert ns["result"] is False
    ns["__name__"] = "vtkmodules.util.something"
    exec(code, ns)
    assert ns["result"] is True


def test_a_stopped_kernel_has_returned_before_the_signal_is_reraised():
    """A signal landing while the main thread waits for a kernel: the exception reaches the
    caller only after the kernel saw its stop flag and returned.  (With Thread.join, CPython
    3.11 marks the still-running thread stopped when the handler raises inside join; the
    process could then exit under a kernel still in C++, and heyoka aborts there.)"""
    returned = []

    def kernel(stop):
        while stop[0] == 0:
            threading.Event().wait(0.005)
        threading.Event().wait(0.2)               # slow to wind down: longer than a poll interval
        returned.append(True)

    timer = threading.Timer(0.12, send)
    with interrupt.handlers():
        timer.start()
        with pytest.raises(interrupt.Interrupted):
            interrupt.call_stoppable(kernel)
        assert returned == [True]
