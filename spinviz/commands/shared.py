"""What every subcommand shares: the parser class, the argument types (parsing only: ranges are
the schema's), the report helpers, and the one translation of a schema error into a usage
error, with the option named from the parser itself.

Nothing here loads more than argparse and ``spinviz.errors``.
"""

from __future__ import annotations

import argparse
import errno
import os
import sys

from ..errors import SpecError, SpinvizError, UsageError, printable

EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2


class Parser(argparse.ArgumentParser):
    """argparse with its errors in the house style: one escaped line, exit status 2."""

    def error(self, message):
        """Print the one-line usage error and exit with status 2."""
        self.exit(EXIT_USAGE, f"spinviz: error: {printable(message)} (see '{printable(self.prog)} --help')\n")


def options_of(parser: argparse.ArgumentParser) -> dict:
    """{argument name (the option's ``dest``): its longest option string} of a parser: what a
    schema error about an argument is called on the command line.  (argparse lists a parser's
    actions only in ``_actions``, unchanged since Python 3.2.)"""
    return {a.dest: max(a.option_strings, key=len) for a in parser._actions if a.option_strings}


def named(e: SpecError, args, table: str | None = None) -> UsageError:
    """A schema error about an argument, in the command line's terms: the option that set the
    value (``--workers: ...``) when it was given on the command line; else, for a command that
    reads a scene, the scene's key (``SCENE: [render].fps: ...``) when ``table`` says which
    table the argument comes from; else the option or the argument's own name."""
    option = getattr(args, "options", {}).get(e.key)
    if option and getattr(args, e.key, None) is not None:
        return UsageError(f"{option}: {e.reason}")
    scene = getattr(args, "scene", None)
    if table is not None and scene is not None:
        return UsageError(f"{scene}: [{table}].{e.key}: {e.reason}")
    return UsageError(f"{option or e.key}: {e.reason}")


# --- argument types: parsing only; ranges are checked by the schema ------------------------
def typed(cast, what):
    """An argparse type that parses with ``cast`` and says ``expected WHAT`` otherwise."""
    def parse(text: str):
        try:
            return cast(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
    parse.__doc__ = f"Parse {what} (``argparse.ArgumentTypeError`` otherwise)."
    return parse


whole = typed(int, "a whole number")
real = typed(float, "a number")


def positive(text: str) -> int:
    """A whole number of at least 1."""
    v = whole(text)
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {v}")
    return v


def reals(text: str) -> tuple[float, ...]:
    """A comma-separated list of numbers (their ranges are the schema's)."""
    try:
        out = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas, got {text!r}") from None
    if not out:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas, got {text!r}")
    return out


def names(text: str) -> tuple[str, ...]:
    """A comma-separated list of names."""
    out = tuple(x.strip() for x in text.split(",") if x.strip())
    if not out:
        raise argparse.ArgumentTypeError(f"expected NAME[,NAME...], got {text!r}")
    return out


def numbers(form: str):
    """The type of an option given as a fixed count of comma-separated numbers, named ``form``
    (``"X,Y,Z"``, ``"LO,HI"``) in its messages; their ranges are the schema's."""
    count = form.count(",") + 1
    words = {2: "two", 3: "three"}[count]

    def parse(text: str) -> tuple[float, ...]:
        try:
            v = tuple(float(x) for x in text.split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {form}, got {text!r}") from None
        if len(v) != count:
            raise argparse.ArgumentTypeError(f"expected {words} numbers {form}, got {text!r}")
        return v

    parse.__name__ = form
    parse.__doc__ = f"{words.capitalize()} comma-separated numbers {form}."
    return parse


vector = numbers("X,Y,Z")              # a direction or a point


def size(text: str):
    """A frame size WIDTHxHEIGHT in pixels."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    return (w, h)


# --- the detector's options (observe, decide, listen) ----------------------------------------
# The receiver keys (``inputs.receiver.ReceiverSpec``) that observe, decide and listen take as
# options, each overriding the scene's [observe] key of its name: a key named here is an option
# of the three commands, --key-with-dashes, checked by the receiver's schema.
RECEIVER_OPTIONS = {
    "distance_cm": "the antenna's distance, cm (default: the scene's [observe], else 10)",
    "integration_s": "the length of one estimate, s (default: the scene's [observe], else 1)",
    "antenna_gain_dbi": "the antenna's gain, dBi, flat over the band (default: the scene's [observe], else 5)",
    "noise_temperature_k": "the system noise temperature, K (default: the scene's [observe], else 5)",
}


def add_detector_options(parser, line_of_sight: bool = True, hidden: tuple = ()) -> None:
    """The detector's options of a scene command: ``--los`` (unless ``line_of_sight`` is False)
    and one per ``RECEIVER_OPTIONS`` key (those in ``hidden`` not listed in --help)."""
    if line_of_sight:
        parser.add_argument("--los", dest="line_of_sight", type=vector, metavar="X,Y,Z",
                            help="line of sight X,Y,Z in the world frame (default: the scene's [observe], else "
                                 "across L(0))")
    for key, text in RECEIVER_OPTIONS.items():
        parser.add_argument("--" + key.replace("_", "-"), dest=key, type=real,
                            help=argparse.SUPPRESS if key in hidden else text)


def receiver_options(args) -> dict:
    """The receiver options given on the command line (``RECEIVER_OPTIONS``'s keys, None: not given)."""
    return {k: getattr(args, k, None) for k in RECEIVER_OPTIONS}


# The [environment] keys (``inputs.environment.EnvironmentSpec``) that observe and decide take as
# options, each in place of the scene's key of its name, checked by the environment's schema.
ENVIRONMENT_OPTIONS = {
    "pressure_mbar": (real, "PRESSURE", "the residual gas's pressure, mbar (default: the scene's [environment], else 0: "
                                        "no gas)"),
    "gas": (str, "NAME", "the gas: H2, He, Ne, N2, O2, Ar, CO2 or Xe (default: the scene's, else N2)"),
    "gas_temperature_k": (real, "K", "the gas's temperature (default: the scene's, else 300)"),
    "accommodation": (real, "SHARE", "the share of molecules re-emitted diffusely (default: the scene's, else 1)"),
    "body_temperature_k": (real, "K", "the crystal's surface temperature (default: the scene's, else the gas's)"),
    "field_v_per_m": (vector, "X,Y,Z", "a static field, V/m, world frame (default: the scene's, else none)"),
}


def add_environment_options(parser) -> None:
    """One option per ``ENVIRONMENT_OPTIONS`` key, --key-with-dashes."""
    for key, (kind, metavar, text) in ENVIRONMENT_OPTIONS.items():
        parser.add_argument("--" + key.replace("_", "-"), dest=key, type=kind, metavar=metavar, help=text)


def environment_options(args) -> dict:
    """The environment options given on the command line (None: not given)."""
    return {k: getattr(args, k, None) for k in ENVIRONMENT_OPTIONS}


# --- reports ------------------------------------------------------------------------------
def say(prefix: str, message) -> None:
    """One line on stderr, control characters escaped and cut: nothing from a file or a key
    name can colour, clear or split the terminal.  Nothing when stderr was closed before the
    command started (``print`` would otherwise write the line to stdout)."""
    if sys.stderr is None:
        return
    print(f"spinviz: {prefix}{printable(message)}", file=sys.stderr)


def p(name) -> str:
    """A path or name for a report line: escaped (it may hold any byte a file system allows)."""
    return printable(name, 300)


def out(text: str) -> None:
    """Print a report for people, each of its lines escaped (names in it are escaped by ``p``
    where they are put in, so that a newline in a name cannot split a line)."""
    print("\n".join(printable(line, 2000) for line in str(text).split("\n")))


def progress(msg: str) -> None:
    """One progress line on stderr, indented, escaped as every echoed text is (a name in it
    cannot split the line or colour the terminal)."""
    sys.stderr.write(f"  {printable(msg, 2000)}\n")
    sys.stderr.flush()


def prefix_of(args, default_dir: str = "renders") -> str:
    """The plots' prefix: ``--out``, else ``renders/<scene stem>``."""
    return args.out or os.path.join(default_dir, os.path.splitext(os.path.basename(args.scene))[0])


def need_matplotlib(what: str) -> None:
    """``UsageError`` saying how to install matplotlib when it is missing (``what`` need it)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UsageError(f"{what} need matplotlib: pip install 'spinviz[render]'") from None


class WriteFailed(SpinvizError, OSError):
    """An output could not be written (a full disk, an I/O error): exit status 1, the path named."""


def cannot_write(path, e: OSError) -> SpinvizError:
    """One line naming the output that could not be written, and why."""
    return WriteFailed(f"{path}: cannot write: {e.strerror or e}")


# --- standard streams ---------------------------------------------------------------------
class Stream:
    """A standard stream that never raises into a command: the first failure (a closed or full
    stream) is kept in ``error`` and later writes are dropped; text the stream cannot encode
    is written escaped.  A reader that left stdout (EPIPE) still ends the command quietly."""

    def __init__(self, stream, pipe_ends: bool):
        self.stream, self.pipe_ends = stream, pipe_ends
        self.error = None if stream is not None else OSError(errno.EBADF, os.strerror(errno.EBADF))

    def _do(self, op, *a):
        if self.error is not None:
            return
        try:
            op(*a)
        except BrokenPipeError as e:
            if self.pipe_ends:
                raise
            self.error = e
        except UnicodeEncodeError as e:
            if not a:
                self.error = e
                return
            enc = getattr(self.stream, "encoding", None) or "utf-8"
            self._do(op, a[0].encode(enc, "backslashreplace").decode(enc))
        except (OSError, ValueError) as e:               # ValueError: a closed file object
            self.error = e

    def write(self, text: str) -> int:
        """Write ``text`` unless the stream has failed; never raises (but EPIPE on stdout)."""
        self._do(lambda t: self.stream.write(t), text)
        return len(text)

    def flush(self) -> None:
        """Flush unless the stream has failed."""
        self._do(lambda: self.stream.flush())

    def isatty(self) -> bool:
        """Whether the stream is a working terminal."""
        try:
            return self.error is None and self.stream.isatty()
        except (OSError, ValueError, AttributeError):
            return False

    def fileno(self) -> int:
        """The descriptor of the stream (``io.UnsupportedOperation`` when it was closed)."""
        if self.stream is None:
            import io

            raise io.UnsupportedOperation("the stream was closed before the command started")
        return self.stream.fileno()

    def __getattr__(self, name):
        return getattr(self.stream, name)
