"""The ``spinviz`` command line: a thin ``main(argv) -> int`` that parses, dispatches to one
module per subcommand and maps errors to exit statuses (0 success, 1 a check or run failed,
2 bad input, 128 + the signal when stopped).  No physics and no file formats here.

Each subcommand is a module of this package with ``add_parser(subparsers)`` (its options,
declared once), ``run(args) -> int`` and, where it has one, ``shorthand(argv) -> argv`` (how
its own arguments are spelt shorter: ``atlas SPEC`` for ``atlas run SPEC``); ``COMMANDS``
lists them in the order ``--help`` shows.  Options are parsed here and checked by the schema (``spinviz.inputs``), so the
command line and Python never disagree; a schema error naming an argument is shown with the
option that set it, its name read from the parser (``--workers: ...``), or with the scene's
key when the value came from the file (``shared.named``: the one translation).  Standard
output and error never crash a command: a closed or full stdout gives one line on stderr and
exit status 1 (the output file is kept), a closed or full stderr is skipped, and every echoed
name is escaped (``errors.printable``).
"""

from __future__ import annotations

import argparse
import errno
import importlib
import os
import sys
import warnings

from .. import interrupt
from ..errors import RenderError, SceneError, SimulationError, SpecError, SpinvizError, UsageError, printable
from .shared import EXIT_FAIL, EXIT_USAGE, Parser, Stream, WriteFailed, named, options_of, say

COMMANDS = ("check", "info", "simulate", "render", "compare", "observe", "decide", "listen", "bench", "stress",
            "report", "methods", "atlas")


def command(name: str):
    """The module of subcommand ``name``."""
    return importlib.import_module(f".{name}", __name__)


def parser() -> argparse.ArgumentParser:
    """The ``spinviz`` command line: one subcommand per module of this package."""
    p = Parser(prog="spinviz", description="Rotation of a dipolar nanocrystal braked by radiation reaction "
                                           "(reduced (2.2)+(2.3) vs truncated (2.5) Euler equations).")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True
    for name in COMMANDS:
        command(name).add_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run one ``spinviz`` command in-process and return its exit status.

    argv : the arguments after ``spinviz`` (default ``sys.argv[1:]``), e.g. ``["check", "--quick"]``.
    Returns 0 on success, 1 when a check or run failed or an output could not be written, 2 for
    bad input (one line on stderr), 128 + the signal number when stopped by SIGINT, SIGTERM or
    SIGHUP -- whenever the signal arrives, before the work, during it, or as the command ends.
    Standard output and error are guarded for the call (a closed or full stream never raises
    into the command); ``entry`` is the console script around it.
    """
    top = parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in COMMANDS and hasattr(command(argv[0]), "shorthand"):
        try:
            argv = [argv[0], *command(argv[0]).shorthand(argv[1:])]
        except UsageError as e:
            top.error(str(e))
    args = top.parse_args(argv)
    args.options = options_of(_subparser(top, args))
    out, err = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = Stream(out, pipe_ends=True), Stream(err, pipe_ends=False)
    try:
        with interrupt.handlers(), warnings.catch_warnings():
            # NumPy's overflow warnings are not for the user: every result is checked for finite
            # values and a run that leaves them fails with one line (driver._check_finite)
            warnings.simplefilter("ignore", RuntimeWarning)
            code = _run(args)                          # from its end on, a signal is only recorded
            code = ended(code)
        sys.stdout.flush()
        if sys.stdout.error is not None:
            # the report is lost; whatever the command wrote to files stays (it was written first)
            e = sys.stdout.error
            say("", f"cannot write to standard output: {getattr(e, 'strerror', None) or e}")
            code = code or EXIT_FAIL
        return code
    finally:
        sys.stdout, sys.stderr = out, err


def ended(code: int) -> int:
    """A stop signal that arrived after the command's work (held, never acted on): its one line,
    and 128 + the signal instead of ``code``."""
    late = interrupt.pending()
    if late is None:
        return code
    interrupt.acknowledge()
    import signal

    say("interrupted by ", f"{signal.Signals(late).name} as the command ended; it had finished (exit status {code})")
    return 128 + late


def _subparser(top: argparse.ArgumentParser, args) -> argparse.ArgumentParser:
    """The parser that read the innermost sub-command of ``args`` (``atlas evidence KIND``'s)."""
    p = top
    while True:
        sub = next((a for a in p._actions if isinstance(a, argparse._SubParsersAction)), None)
        if sub is None:
            return p
        p = sub.choices[getattr(args, sub.dest)]


def _run(args) -> int:
    """The command's exit status; a stop signal at any point of it -- its error reports
    included -- ends it with 128 + the signal and the command's own line (``stopped``)."""
    from ..atomic import forget_written

    mod = command(args.command)
    code = None
    forget_written()
    try:
        code = _dispatch(mod, args)
        interrupt.hold()                               # the work is over: a signal now is only recorded
        return code
    except interrupt.Interrupted as e:
        interrupt.hold()
        if code is not None:                           # it came between the end of the work and the hold
            interrupt.acknowledge()
            say("interrupted by ", f"{e} as the command ended; it had finished (exit status {code})")
        else:
            line = getattr(mod, "stopped", None)
            say("", line(args, e) if line is not None else _stopped(e))
        return e.exit_status
    except KeyboardInterrupt:                          # a library's own Ctrl-C handling
        interrupt.hold()
        say("interrupted", "; nothing was written")
        return 130


def _stopped(e) -> str:
    """The line of a command stopped by a signal: what it had written before (outputs land
    whole or not at all, ``atomic``), or that it wrote nothing."""
    from ..atomic import written

    done = written()
    if not done:
        return f"interrupted by {e}; nothing was written"
    names = ", ".join(printable(x, 200) for x in done)
    return f"interrupted by {e} after writing {names}; nothing else was written"


def _dispatch(mod, args) -> int:
    try:
        try:
            return mod.run(args)
        except SpecError as e:                           # the schema's, about an argument: said with its option
            raise named(e, args, getattr(mod, "SCENE_TABLE", None)) from None
    except WriteFailed as e:
        say("error: ", e)
        return EXIT_FAIL
    except (UsageError, SceneError) as e:
        say("error: ", e)
        return EXIT_USAGE
    except (SimulationError, RenderError) as e:
        say("run failed: ", e)
        return EXIT_FAIL
    except interrupt.Interrupted:
        raise                                           # said by _run, with the command's own line
    except KeyboardInterrupt:
        raise
    except BrokenPipeError:
        raise                                           # the reader left: entry() ends quietly
    except (SpinvizError, ValueError, OSError, ImportError, ArithmeticError, RuntimeError, RecursionError,
            MemoryError) as e:
        # the safety net: whatever input slipped past the specific checks still gets one
        # line, not a traceback (SPINVIZ_DEBUG=1 shows the traceback)
        if os.environ.get("SPINVIZ_DEBUG"):
            raise
        status = getattr(e, "exit_status", None)
        if isinstance(status, int):                     # a failure with its own status (a busy store: 75)
            say("error: ", e)
            return status
        what = getattr(e, "filename", None) if isinstance(e, OSError) else None
        if isinstance(e, OSError) and what is None and getattr(args, "out", None):
            what = args.out                                 # e.g. a full disk while writing the output
        if isinstance(e, OSError) and e.strerror:
            say("error: ", f"{what}: {e.strerror}" if what else e.strerror)
            return EXIT_FAIL if e.errno in (errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG) else EXIT_USAGE
        say("error: ", str(e) or type(e).__name__)
        return EXIT_USAGE


def _occupy_closed_std_fds() -> None:
    """A standard descriptor (0, 1, 2) closed by the caller (``>&-``) is opened on /dev/null,
    as careful Unix tools do: otherwise the next file opened -- the output itself -- would
    take its number, and anything written to "stdout" (by us or a child process) would land
    in it.  Python has already set ``sys.stdout`` (or ``stderr``) to None for it, so the
    command still knows the stream is gone."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            nul = os.open(os.devnull, os.O_RDWR)
            if nul != fd:
                os.dup2(nul, fd)
                os.close(nul)


def _settle(stream) -> None:
    """Text a standard stream could not take stays in its buffer and would fail again (with
    a complaint and exit status 120) at the interpreter's last flush: send it to /dev/null."""
    if stream is None:
        return
    try:
        stream.flush()
    except (OSError, ValueError):
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), stream.fileno())
            stream.flush()
        except (OSError, ValueError):
            pass


_EXIT = {"code": 0}


def _last_words() -> None:
    """The process's last act (the first ``atexit`` hook registered, so the last to run): a stop
    signal that arrived during the interpreter's shutdown (held: the handlers stay installed)
    gets its line and 128 + the signal; then the process exits at once, before the interpreter
    would give the signals back their default action (which kills unreported)."""
    code = _EXIT["code"]
    late = interrupt.pending()
    if late is not None:
        import signal

        interrupt.acknowledge()
        say("interrupted by ", f"{signal.Signals(late).name} as the command ended; it had finished (exit status {code})")
        code = 128 + late
    for stream in (sys.stdout, sys.stderr):
        _settle(stream)
    os._exit(code)


def entry() -> None:
    """Console-script entry point (``spinviz``, and ``python -m spinviz``).

    The stop signals are answered from the first instant to the last: the handlers are
    installed before anything else and never given back, a signal after the command's work
    is held and reported (``ended``, ``_last_words``), and library logging (Dask's reconnect
    attempts, asyncio's complaints about futures a stopped cluster left) is silenced: one
    line on stderr per outcome (SPINVIZ_DEBUG=1 keeps the logs)."""
    import atexit
    import logging

    interrupt.install()
    _EXIT["code"] = 1                                # until the command says otherwise (an uncaught bug: 1)
    atexit.register(_last_words)
    if not os.environ.get("SPINVIZ_DEBUG"):
        logging.disable(logging.CRITICAL)
    _occupy_closed_std_fds()
    try:
        code = main()
        if sys.stdout is not None:
            sys.stdout.flush()
    except interrupt.Interrupted as e:              # before the command ran (its arguments being read)
        interrupt.hold()
        say("interrupted by ", f"{e}; nothing was written")
        code = e.exit_status
    except SystemExit as e:                         # argparse: --help (0) or a usage error (2)
        interrupt.hold()
        code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    except BrokenPipeError:
        # the reader went away (spinviz methods | head -1): end quietly, as a Unix tool does
        interrupt.hold()
        code = 128 + 13
    interrupt.hold()
    _settle(sys.stdout)
    _settle(sys.stderr)
    _EXIT["code"] = code
    sys.exit(code)
