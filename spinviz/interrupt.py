"""Stopping cleanly: SIGINT, SIGTERM and SIGHUP become one exception, ``Interrupted``.

The command line calls ``install()``; from then on the first of these signals raises
``Interrupted`` in the main thread, so ``finally`` blocks run: temporary files are deleted,
worker processes stopped, nothing half-written is left and existing outputs stay as they
were.  Later signals are recorded but do not raise again, so the clean-up itself is not
cut short.  The exit status is 128 + the signal number (130, 143, 129).

Two places need more than a Python handler:

* a library may catch the exception (VTK swallows exceptions raised inside its calls), so
  long loops also call ``check()``, which raises if a signal arrived at any time;
* compiled (numba) loops never return to the interpreter, so ``call_stoppable`` runs them
  in a thread without the GIL and hands them a ``stop`` flag they poll; the main thread
  waits in short slices, takes the signal, sets the flag and re-raises once the kernel
  has returned.

A stop can arrive at any instant, also before a command starts its work or after it has
finished.  ``hold()`` marks the end of the work: from then on a signal is only recorded, and
``pending()`` tells the command line that one arrived which was never acted on, so that it
still ends with 128 + the signal and its one line (``spinviz.commands.entry`` keeps the
handlers installed until the process exits, so there is no instant at which a signal kills
the process unreported).
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading

SIGNALS = tuple(s for s in (getattr(signal, n, None) for n in ("SIGINT", "SIGTERM", "SIGHUP")) if s is not None)

_received: int | None = None
_raised = False           # the first signal was raised as ``Interrupted`` (so it was acted on)
_held = False             # the command's work is over: signals are only recorded (``hold``)
_outer_hook = None        # the ``sys.unraisablehook`` that ``install()`` found in place


class Interrupted(KeyboardInterrupt):
    """A stop request (SIGINT, SIGTERM or SIGHUP); ``exit_status`` is 128 + the signal number."""

    def __init__(self, signum: int = signal.SIGINT):
        self.signum = int(signum)
        super().__init__(signal.Signals(self.signum).name)

    @property
    def exit_status(self) -> int:
        """128 + the signal number: the exit status of a command stopped by it (130 for SIGINT)."""
        return 128 + self.signum


# Libraries that call back into Python and swallow what the callback raises (VTK prints an
# error block and carries on): a signal arriving inside them is only recorded, and the
# caller's loop raises it at its next ``check()`` -- between two frames.
_SWALLOWING = ("vtkmodules", "vtk", "pyvista")
# Python itself swallows what a weak reference's callback or a finalizer raises ("Exception
# ignored in ...", printed on stderr): a signal handled inside one is only recorded too.
_CALLBACK_MODULES = ("_weakrefset", "weakref")

_deferring = 0            # depth of ``deferred()`` blocks: a signal is only recorded inside one


def _inside_swallowing_library(frame) -> bool:
    """Whether the interrupted code runs in one of those libraries, or in a weak reference's
    callback or a finalizer: judged by module and function names, from the innermost frame
    out to the first of spinviz's own."""
    while frame is not None:
        name = str(frame.f_globals.get("__name__", ""))
        if name in _CALLBACK_MODULES or frame.f_code.co_name == "__del__":
            return True
        if name.split(".")[0] == "spinviz":
            return False
        if name.split(".")[0] in _SWALLOWING:
            return True
        frame = frame.f_back
    return False


def _handler(signum, frame):
    global _received, _raised
    first = _received is None
    if first:
        _received = signum                         # the first signal is the one the exit status tells
    if first and not _deferring and not _held and not _inside_swallowing_library(frame):
        _raised = True
        raise Interrupted(signum)


def _unraisable(u) -> None:
    """``sys.unraisablehook`` while the handlers are installed.  Wherever else Python cannot
    unwind -- C code that calls back into Python and reports what it raised as "Exception
    ignored in ..." -- an ``Interrupted`` raised there stays pending, silently: the next
    ``check()`` raises it, or the command line reports it as it exits.  Anything else goes
    to the hook that was in place."""
    global _raised
    if isinstance(u.exc_value, Interrupted):
        _raised = False
        return
    (_outer_hook or sys.__unraisablehook__)(u)


def install() -> None:
    """Turn SIGINT, SIGTERM and SIGHUP into ``Interrupted`` (main thread only), and keep one
    that Python swallows pending (``_unraisable``)."""
    global _received, _raised, _held, _outer_hook
    _received, _raised, _held = None, False, False
    if sys.unraisablehook is not _unraisable:
        _outer_hook, sys.unraisablehook = sys.unraisablehook, _unraisable
    for s in SIGNALS:
        signal.signal(s, _handler)


def installed() -> bool:
    """Whether this module's handler is the one in place for every stop signal."""
    return all(signal.getsignal(s) is _handler for s in SIGNALS)


@contextlib.contextmanager
def handlers():
    """``install()`` for the duration of a block, then the previous handlers again (a command
    run in-process from Python leaves the caller's signal handling as it found it).  Inside a
    block that already has them (the command line's ``entry`` installs them for the life of
    the process), nothing changes: a signal held meanwhile stays pending for the outer one."""
    if threading.current_thread() is not threading.main_thread() or installed():
        yield
        return
    global _received, _raised, _held, _deferring
    old = {s: signal.getsignal(s) for s in SIGNALS}
    hook = sys.unraisablehook
    depth = _deferring
    install()
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        sys.unraisablehook = hook
        _received, _raised, _held, _deferring = None, False, False, depth   # a later run here starts clean


def hold() -> None:
    """The command's work is over: from now on a stop signal is only recorded (``pending``),
    never raised -- not inside the report, an ``atexit`` hook or the interpreter's shutdown."""
    global _held
    _held = True


def pending() -> int | None:
    """The signal that arrived and was never acted on (it came while held or deferred and no
    ``check()`` raised it), or None."""
    return None if _raised else _received


def acknowledge() -> None:
    """The pending signal has been reported: do not report it again."""
    global _raised
    _raised = True


def received() -> int | None:
    """The signal received since ``install()``, or None."""
    return _received


def check() -> None:
    """Raise ``Interrupted`` if a stop signal arrived (even if its exception was swallowed)."""
    global _raised
    if _received is not None:
        _raised = True
        raise Interrupted(_received)


@contextlib.contextmanager
def deferred():
    """Hold stop signals back for the few lines that must not be cut in two (renaming a
    group of outputs into place): inside, the handler only records a signal; it is raised
    when the block ends.  (Not a signal mask: a mask covers one thread, and a signal sent to
    the process may land on any other -- OpenBLAS's, a queue's, a kernel's -- while Python
    still runs the handler in the main thread.)"""
    global _deferring
    _deferring += 1
    try:
        yield
    finally:
        _deferring -= 1
    if not _deferring and not _held:
        check()


POLL_S = 0.05


def call_stoppable(kernel, *args):
    """``kernel(*args, stop)`` in a helper thread (the kernel releases the GIL and polls
    ``stop[0]``); a stop signal sets the flag and is re-raised once the kernel returned.

    The main thread waits on an Event, not on ``Thread.join``: a signal whose handler raises
    inside ``join`` makes CPython 3.11 mark the still-running thread as stopped (its
    bpo-45274 clean-up releases the thread's state lock), so a second ``join`` returns at
    once and the interpreter could exit under a kernel still in C++ (heyoka then aborts:
    "terminate called without an active exception")."""
    import numpy as np

    stop = np.zeros(1, dtype=np.int64)
    if threading.current_thread() is not threading.main_thread():
        return kernel(*args, stop)                 # signals only reach the main thread anyway
    box: dict = {}
    done = threading.Event()

    def run():
        try:
            box["value"] = kernel(*args, stop)
        except BaseException as e:                 # handed to the caller below
            box["error"] = e
        finally:
            done.set()

    t = threading.Thread(target=run, name="spinviz-kernel", daemon=True)
    try:
        t.start()
        while not done.wait(POLL_S):
            pass
    except BaseException:
        stop[0] = 1
        if t.ident is not None:                    # started (the signal may land inside start())
            _wait_out(done)
        raise
    if "error" in box:
        raise box["error"]
    return box["value"]


def _wait_out(done: threading.Event) -> None:
    """Wait for a stopped kernel to return (a poll interval of its loop), whatever else arrives."""
    while True:
        try:
            if done.wait(POLL_S):
                return
        except BaseException:                      # a later signal: still wait, the first one is being handled
            continue
