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


@pytest.mark.slow
def test_a_signal_inside_a_weakref_callback_or_finalizer_is_recorded_not_raised(monkeypatch):
    """Python swallows what a weak reference's callback or a ``__del__`` raises (it goes to
    ``sys.unraisablehook``, which prints "Exception ignored in ..." on stderr): a signal
    handled there is only recorded, and the caller's next ``check()`` raises it."""
    import gc
    import sys
    import weakref

    swallowed = []
    monkeypatch.setattr(sys, "unraisablehook", lambda u: swallowed.append(u.exc_type.__name__))

    class Thing:
        pass

    class Dying:
        def __del__(self):
            send(signal.SIGINT)
            for _ in range(1000):
                np.sqrt(2.0)

    for make in ("weakset", "finalizer"):
        with interrupt.handlers():
            if make == "weakset":
                things = weakref.WeakSet()
                t = Thing()
                things.add(t)
                weakref.finalize(t, send, signal.SIGINT)
                del t
            else:
                d = Dying()
                del d
            gc.collect()
            for _ in range(1000):
                np.sqrt(2.0)
            assert interrupt.received() == signal.SIGINT, make
            with pytest.raises(interrupt.Interrupted):
                interrupt.check()
        assert swallowed == [], make


def test_a_signal_raised_where_python_cannot_unwind_stays_pending_and_silent(monkeypatch, capsys):
    """A callback that C code calls and whose exception Python only reports ("Exception
    ignored in ..."), here a weak reference's callback of a module the handler does not
    recognise: the signal raised there is not printed, stays pending, and ``check()`` raises
    it; other unraisable exceptions still reach the hook that was in place."""
    import sys
    import weakref

    class Thing:
        pass

    def callback(_):
        send(signal.SIGINT)
        for _ in range(1000):
            np.sqrt(2.0)

    seen = []
    outer = sys.unraisablehook
    with interrupt.handlers():
        monkeypatch.setattr(interrupt, "_outer_hook", lambda u: seen.append(type(u.exc_value).__name__))
        t = Thing()
        ref = weakref.ref(t, callback)
        del t
        assert ref() is None
        assert interrupt.pending() == signal.SIGINT
        with pytest.raises(interrupt.Interrupted):
            interrupt.check()
        sys.unraisablehook(type("U", (), {"exc_value": ValueError("x")})())
    assert sys.unraisablehook is outer
    assert seen == ["ValueError"]
    assert "Exception ignored" not in capsys.readouterr().err


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


@pytest.fixture
def methods_run(monkeypatch):
    """``spinviz methods`` whose run does ``act()`` at its very end (the work done, outputs written)."""
    from spinviz.commands import methods

    real = methods.run
    box = {}

    def run(args):
        code = real(args)
        box["act"]()
        return code

    monkeypatch.setattr(methods, "run", run)
    return box


def test_a_signal_as_the_command_ends_is_its_exit_status_and_its_one_line(methods_run, capsys):
    """A signal after the work (the report being printed, the interpreter shutting down) is
    held from the end of the work on and reported, with 128 + the signal and the status the
    command would have had -- never left to its default action, which kills unreported."""
    from spinviz.commands import main

    def late():
        interrupt.hold()                          # as the dispatcher does when the run returns
        send(signal.SIGHUP)
        for _ in range(1000):
            np.sqrt(2.0)

    methods_run["act"] = late
    assert main(["methods"]) == 129
    err = capsys.readouterr().err
    assert err == "spinviz: interrupted by SIGHUP as the command ended; it had finished (exit status 0)\n"
    assert interrupt.pending() is None


def test_a_signal_while_an_error_is_reported_still_gives_its_status(monkeypatch, capsys):
    """The first signal, landing while the dispatcher reports a usage error, is said once with
    the command's stop line, never as a traceback out of the report."""
    from spinviz.commands import main, shared

    real_say = shared.say
    calls = []

    def say(prefix, message):
        calls.append(prefix)
        if len(calls) == 1:
            send(signal.SIGTERM)
            for _ in range(1000):
                np.sqrt(2.0)
        real_say(prefix, message)

    monkeypatch.setattr("spinviz.commands.say", say)
    assert main(["info", "no-such-target"]) == 143
    assert capsys.readouterr().err == "spinviz: interrupted by SIGTERM; nothing was written\n"


def test_entry_answers_signals_from_its_first_line_to_its_last(tmp_path):
    """The console script installs the handlers before anything else and never gives them back:
    a SIGTERM during the interpreter's shutdown (sent by an exit hook the command left) is
    held and reported by the last hook, with 143; the process is not killed by the signal."""
    import subprocess
    import sys

    probe = ("import os, signal, sys\n"
             "from spinviz import commands\n"
             "from spinviz.commands import methods\n"
             "real = methods.run\n"
             "import atexit\n"
             "def run(args):\n"
             "    atexit.register(lambda: os.kill(os.getpid(), signal.SIGTERM))\n"   # during the interpreter's shutdown
             "    return real(args)\n"
             "methods.run = run\n"
             "sys.argv = ['spinviz', 'methods']\n"
             "commands.entry()\n")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60,
                       env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert r.returncode == 143, (r.returncode, r.stderr)
    assert r.stderr == "spinviz: interrupted by SIGTERM as the command ended; it had finished (exit status 0)\n"
    assert "taylor" in r.stdout
