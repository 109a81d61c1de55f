"""Command line: a thin ``main(argv) -> int`` that parses, dispatches to library functions and
maps errors to exit codes (0 success, 1 a check or run failed, 2 bad input, 130 interrupted).
No physics and no file formats here.

Options are parsed here and checked by the library (the schema in ``spinviz.inputs``), so the
command line and Python never disagree; a library error naming an argument is shown with
the option that set it (``--workers: ...``), or with the scene's key when the value came from
the file.  Standard output and error never crash a command: a closed or full stdout gives one
line on stderr and exit status 1 (the output file is kept), a closed or full stderr is
skipped, and every echoed name is escaped (``errors.printable``).
"""

from __future__ import annotations

import argparse
import dataclasses
import errno
import json
import os
import sys
import warnings

from . import interrupt
from .errors import RenderError, SceneError, SimulationError, SpecError, SpinvizError, UsageError, printable

EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2

UserError = UsageError          # the CLI's name for bad input (exit 2)


class _Parser(argparse.ArgumentParser):
    """argparse with its errors in the house style: one escaped line, exit status 2."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"spinviz: error: {printable(message)} (see '{printable(self.prog)} --help')\n")


def _parser() -> argparse.ArgumentParser:
    """The ``spinviz`` command line: one subcommand per task, each added by its ``_add_*``."""
    p = _Parser(prog="spinviz", description="Rotation of a dipolar nanocrystal braked by radiation reaction "
                                            "(reduced (2.2)+(2.3) vs truncated (2.5) Euler equations).")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for add in (_add_check, _add_info, _add_simulate, _add_render, _add_compare, _add_observe, _add_decide, _add_listen,
                _add_bench, _add_stress, _add_report):
        add(sub)
    sub.add_parser("methods", help="list the integrators")

    from .regimes import command as atlas_command  # argparse and spinviz.errors only: light

    atlas_command.add_parser(sub)
    return p


def _add_check(sub) -> None:
    c = sub.add_parser("check", help="validate the integrators against the paper's closed forms, and secular against "
                                     "full integration at real scales (~2.5 min)")
    c.add_argument("--json", action="store_true", help="print a JSON list of records instead of a table")
    c.add_argument("--quick", action="store_true", help="secular comparisons at tau0 |Omega0| = 1e-4, 1e-5 only (~16 s)")
    c.add_argument("--sweep", action="store_true",
                   help="instead: secular against taylor on random symmetric tops, are its stated errors bounds? "
                        "(~8 s per seed of 40 runs)")
    c.add_argument("--seeds", type=_seed_list, help="with --sweep: the seeds, e.g. 1-9 or 1,4,7 (default 1-3)")
    c.add_argument("--runs", type=_positive, help="with --sweep: runs per seed (default 40)")


def _add_info(sub) -> None:
    i = sub.add_parser("info", help="derived quantities of a preset or scene, beside the paper's figures")
    i.add_argument("target", help="a preset name (cellulose_rod, dast_cube, dast_family1) or a scene file")
    i.add_argument("--json", action="store_true")


def _add_simulate(sub) -> None:
    s = sub.add_parser("simulate", help="integrate a scene and write the trajectory and its radiation observables (.npz)")
    s.add_argument("scene")
    s.add_argument("--out", required=True, help="output .npz path")
    s.add_argument("--model", help="which of the scene's models (default: the first)")
    s.add_argument("--method", help="override the scene's integrator")


def _add_render(sub) -> None:
    r = sub.add_parser("render", help="render a scene off-screen to MP4 or GIF, with a PNG poster")
    r.add_argument("scene")
    r.add_argument("--out", help="output .mp4 or .gif (default renders/<scene>.mp4)")
    r.add_argument("--size", type=_size, help="WIDTHxHEIGHT in pixels, e.g. 1280x720")
    r.add_argument("--fps", type=_whole, help="frames per second (1..240)")
    r.add_argument("--duration", type=_real, help="video length in seconds")
    r.add_argument("--workers", type=_whole, help="render processes (default: one per core, at most the cores)")
    r.add_argument("--bench", action="store_true",
                   help="measure frames per second at 1280x720 and 1920x1080, encoding included "
                        "(writes to a temporary directory)")
    r.add_argument("--frames", type=_positive, default=150, help="frames per benchmark size (with --bench)")
    r.add_argument("--json", metavar="PATH", help="with --bench: also write the results as JSON")
    r.add_argument("--plot", metavar="PATH", help="with --bench: also draw frames per second against the targets (PNG)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")


def _add_compare(sub) -> None:
    c = sub.add_parser("compare", help="reduced vs truncated for a two-model scene: angles, crossing times, final states, "
                                       "plots")
    c.add_argument("scene")
    c.add_argument("--out", help="prefix of the PNG plots (default renders/<scene>): "
                                 "<prefix>_compare.png, <prefix>_hodograph.png")
    c.add_argument("--samples", type=_positive, default=800, help="evenly spaced plus as many log-spaced output times")
    c.add_argument("--json", action="store_true", help="print the results as JSON")


def _add_observe(sub) -> None:
    o = sub.add_parser("observe", help="what a stated receiver records from both models of a scene: SNR, resolutions, "
                                       "the field at the antenna, when the models part across resolutions, the P-f "
                                       "test; plots")
    o.add_argument("scene")
    o.add_argument("--out", help="prefix of the PNG plots (default renders/<scene>): <prefix>_observe.png, "
                                 "<prefix>_detector.png and, for a physical body, <prefix>_receiver.png")
    o.add_argument("--los", type=_vector, help="line of sight X,Y,Z in the world frame (default: the scene's [observe], "
                                              "else across L(0))")
    o.add_argument("--distance-cm", type=_real, help="the antenna's distance (default: the scene's [observe], else 10)")
    o.add_argument("--integration-s", type=_real, help="the length of one estimate (default: the scene's [observe], "
                                                       "else 1)")
    for gone in ("--power-factor", "--frequency-resolution", "--polarization-deg"):
        # fixed thresholds: the resolutions are the receiver's now; say so instead of "unrecognized"
        o.add_argument(gone, type=_refused_option, help=argparse.SUPPRESS)
    o.add_argument("--samples", type=_positive, default=800, help="evenly spaced plus as many log-spaced instants")
    o.add_argument("--json", action="store_true", help="print the results as JSON")


def _refused_option(text: str):
    """The type of an option observe no longer takes: always an error, with the reason."""
    from .inputs.receiver import RESOLUTION_COMPUTED

    raise argparse.ArgumentTypeError(RESOLUTION_COMPUTED)


def _add_decide(sub) -> None:
    d = sub.add_parser("decide", help="how long to watch: a Monte Carlo over noise and unknown starts of the time a "
                                      "likelihood-ratio test needs to tell the models apart at 5 sigma in 95 %% of "
                                      "trials; or the start-free P-f test of a file of measurements")
    d.add_argument("scene")
    d.add_argument("--measurements", help="a CSV or JSON file of line frequency and power (docs: Designing an "
                                          "experiment): fit the P-f laws to it instead")
    d.add_argument("--trials", type=_whole, help="Monte Carlo trials (default 200)")
    d.add_argument("--seed", type=_whole, help="seed of the trials' random streams (default 1)")
    d.add_argument("--spin-range", type=_pair, help="LO,HI: |Omega0| log-uniform over LO..HI x the scene's (default "
                                                    "0.5,2)")
    d.add_argument("--tau0", choices=("known", "fitted"), help="the body's tau0 known (default), or fitted with the start")
    d.add_argument("--distance-cm", type=_real, help="the antenna's distance (default: the scene's [observe], else 10)")
    d.add_argument("--integration-s", type=_real, help="the length of one estimate (default: the scene's [observe], "
                                                       "else 1)")
    d.add_argument("--workers", type=_positive, help="worker processes (default: one per core)")
    d.add_argument("--scheduler", help="run the trials on a Dask cluster at this address (tcp://HOST:8786)")
    d.add_argument("--out", help="prefix of the plot (default renders/<scene>): <prefix>_decide.png")
    d.add_argument("--json", action="store_true", help="print the results as JSON")


def _pair(text: str):
    try:
        v = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LO,HI, got {text!r}") from None
    if len(v) != 2:
        raise argparse.ArgumentTypeError(f"expected two numbers LO,HI, got {text!r}")
    return v


def _add_listen(sub) -> None:
    li = sub.add_parser("listen", help="hear the crystal spin down: the detector's signal of both models as a stereo "
                                       "WAV (left one model, right the other), with its spectrogram")
    li.add_argument("scene")
    li.add_argument("--out", required=True, help="output .wav")
    li.add_argument("--png", help="spectrogram of the WAV (default: beside it, .png)")
    li.add_argument("--duration", type=_real, default=20.0, help="seconds of sound (default 20)")
    li.add_argument("--f0", type=_real, default=440.0, help="pitch of the initial rotation frequency, Hz (default 440)")
    li.add_argument("--time-map", choices=("log", "linear"), default="log", help="how sound time maps to the run's")
    li.add_argument("--pitch", choices=("auto", "linear"), default="auto",
                    help="linear: every frequency times one factor; auto: that, unless the frequency falls more than "
                         "16x, which is then compressed into 16x (default)")
    li.add_argument("--dynamic-range-db", type=_real, default=60.0,
                    help="the field's range in dB is compressed into this many dB of sound when larger (default 60)")
    li.add_argument("--los", type=_vector, help="line of sight X,Y,Z, world frame")
    li.add_argument("--distance-cm", type=_real, help=argparse.SUPPRESS)
    li.add_argument("--samples", type=_positive, default=800, help="evenly spaced plus as many log-spaced instants")


def _add_bench(sub) -> None:
    b = sub.add_parser("bench", help="work-precision benchmark: error against run time, per method and horizon")
    b.add_argument("--quick", action="store_true", help="two problems, 1e2 and 1e4 turns, fewer settings (~2 min)")
    b.add_argument("--json", metavar="PATH", help="also write rows and summary as JSON")
    b.add_argument("--plot", metavar="PATH", help="also draw error against time, log-log, one line per method (PNG)")
    b.add_argument("--process", action="store_true",
                   help="time whole processes (spinviz simulate, and the standalone heyoka and scipy scripts of "
                        "benchmarks/) instead of in-process runs, at ~400 turns (~5 min; --quick ~1 min)")
    b.add_argument("--problems", type=_names, help="only these problems, e.g. 6.10,askew (default: the plan's; "
                                                 "with --process also asym)")
    b.add_argument("--repeats", type=_positive, help="runs per point, the minimum time kept (default 3)")


def _add_stress(sub) -> None:
    st = sub.add_parser("stress", help="stiff and extreme cases: pass/fail, error, time, and the method the driver picked")
    st.add_argument("--json", action="store_true", help="print a JSON list of records instead of a table")


def _add_report(sub) -> None:
    rp = sub.add_parser("report", help="regenerate docs/accuracy.md: bench plot and tables, stress table")
    rp.add_argument("--quick", action="store_true", help="the quick benchmark plan")
    rp.add_argument("--out", default="docs/accuracy.md", help="the Markdown file to write")
    rp.add_argument("--out-dir", default="renders", help="where the plot and JSON go")


# --- argument types: parsing only; ranges are checked by the library -----------------------
def _typed(cast, what):
    def parse(text: str):
        try:
            return cast(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
    return parse


_whole = _typed(int, "a whole number")
_real = _typed(float, "a number")


def _positive(text: str) -> int:
    v = _whole(text)
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {v}")
    return v


def _seed_list(text: str) -> list[int]:
    try:
        if "-" in text:
            lo, hi = (int(x) for x in text.split("-"))
            seeds = list(range(lo, hi + 1))
        else:
            seeds = [int(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seeds A-B or A,B,C, got {text!r}") from None
    if not seeds:
        raise argparse.ArgumentTypeError(f"no seeds in {text!r}")
    return seeds


def _names(text: str) -> tuple[str, ...]:
    names = tuple(x.strip() for x in text.split(",") if x.strip())
    if not names:
        raise argparse.ArgumentTypeError(f"expected NAME[,NAME...], got {text!r}")
    return names


def _vector(text: str):
    try:
        v = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z, got {text!r}") from None
    if len(v) != 3:
        raise argparse.ArgumentTypeError(f"expected three numbers X,Y,Z, got {text!r}")
    return v


def _size(text: str):
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    return (w, h)


# --- dispatch ---------------------------------------------------------------------------
class _Stream:
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
        self._do(lambda t: self.stream.write(t), text)
        return len(text)

    def flush(self) -> None:
        self._do(lambda: self.stream.flush())

    def isatty(self) -> bool:
        try:
            return self.error is None and self.stream.isatty()
        except (OSError, ValueError, AttributeError):
            return False

    def fileno(self) -> int:
        if self.stream is None:
            import io

            raise io.UnsupportedOperation("the stream was closed before the command started")
        return self.stream.fileno()

    def __getattr__(self, name):
        return getattr(self.stream, name)


def main(argv: list[str] | None = None) -> int:
    """Run one ``spinviz`` command in-process and return its exit status.

    argv : the arguments after ``spinviz`` (default ``sys.argv[1:]``), e.g. ``["check", "--quick"]``.
    Returns 0 on success, 1 when a check or run failed or an output could not be written, 2 for
    bad input (one line on stderr), 128 + the signal number when stopped by SIGINT, SIGTERM or
    SIGHUP.  Standard output and error are guarded for the call (a closed or full stream never
    raises into the command); ``entry`` is the console script around it.
    """
    args = _parser().parse_args(argv)
    out, err = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _Stream(out, pipe_ends=True), _Stream(err, pipe_ends=False)
    try:
        with interrupt.handlers(), warnings.catch_warnings():
            # NumPy's overflow warnings are not for the user: every result is checked for finite
            # values and a run that leaves them fails with one line (driver._check_finite)
            warnings.simplefilter("ignore", RuntimeWarning)
            code = _run(args)
        sys.stdout.flush()
        if sys.stdout.error is not None:
            # the report is lost; whatever the command wrote to files stays (it was written first)
            e = sys.stdout.error
            _say("", f"cannot write to standard output: {getattr(e, 'strerror', None) or e}")
            code = code or EXIT_FAIL
        return code
    finally:
        sys.stdout, sys.stderr = out, err


def _say(prefix: str, message) -> None:
    """One line on stderr, control characters escaped and cut: nothing from a file or a key
    name can colour, clear or split the terminal."""
    print(f"spinviz: {prefix}{printable(message)}", file=sys.stderr)


def _p(name) -> str:
    """A path or name for a report line: escaped (it may hold any byte a file system allows)."""
    return printable(name, 300)


def _out(text: str) -> None:
    """Print a report for people, each of its lines escaped (names in it are escaped by
    ``_p`` where they are put in, so that a newline in a name cannot split a line)."""
    print("\n".join(printable(line, 2000) for line in str(text).split("\n")))


def _run(args) -> int:
    try:
        return _COMMANDS[args.command](args)
    except WriteFailed as e:
        _say("error: ", e)
        return EXIT_FAIL
    except (UsageError, SceneError, SpecError) as e:
        _say("error: ", e)
        return EXIT_USAGE
    except (SimulationError, RenderError) as e:
        _say("run failed: ", e)
        return EXIT_FAIL
    except interrupt.Interrupted as e:
        _say("interrupted by ", f"{e}; nothing was written")
        return e.exit_status
    except KeyboardInterrupt:
        _say("interrupted", "; nothing was written")
        return 130
    except BrokenPipeError:
        raise                                           # the reader left: entry() ends quietly
    except (SpinvizError, ValueError, OSError, ImportError, ArithmeticError, RuntimeError, RecursionError,
            MemoryError) as e:
        # the safety net: whatever input slipped past the specific checks still gets one
        # line, not a traceback (SPINVIZ_DEBUG=1 shows the traceback)
        if os.environ.get("SPINVIZ_DEBUG"):
            raise
        what = getattr(e, "filename", None) if isinstance(e, OSError) else None
        if isinstance(e, OSError) and what is None and getattr(args, "out", None):
            what = args.out                                 # e.g. a full disk while writing the output
        if isinstance(e, OSError) and e.strerror:
            _say("error: ", f"{what}: {e.strerror}" if what else e.strerror)
            return EXIT_FAIL if e.errno in (errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG) else EXIT_USAGE
        _say("error: ", str(e) or type(e).__name__)
        return EXIT_USAGE


def _progress(msg: str) -> None:
    sys.stderr.write(f"  {msg}\n")
    sys.stderr.flush()


def _cmd_check(args) -> int:
    from .validation import checks

    if args.sweep:
        return _secular_sweep(args)
    for given, option in ((args.seeds, "--seeds"), (args.runs, "--runs")):
        if given is not None:
            raise UsageError(f"{option}: only with --sweep")
    results = checks.run_all(quick=args.quick)
    if args.json:
        print(json.dumps([r.record() for r in results], indent=2, default=float))
    else:
        _out(checks.format_table(results))
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


def _secular_sweep(args) -> int:
    import time

    from .validation import secular_sweep as SW

    if args.quick:
        raise UsageError("--quick: not with --sweep (give fewer --seeds or --runs)")
    start = time.perf_counter()
    rows = SW.run(args.seeds or [1, 2, 3], args.runs or 40, progress=lambda r: _progress(SW.row_line(r)))
    if args.json:
        print(json.dumps(rows, indent=2, default=float))
    else:
        _out(SW.format_table(rows, time.perf_counter() - start))
    return EXIT_OK if SW.passed(rows) else EXIT_FAIL


def _cmd_info(args) -> int:
    from .analysis import info
    from .physics.presets import PRESETS

    target = args.target
    if target in PRESETS:
        body = PRESETS[target]()
        title, omega = f"{body.name}  (preset {target})", None
    elif os.path.exists(target) or target.endswith(".toml"):
        from .scene import load_scene

        sc = load_scene(target)
        body, title, omega = sc.body, f"{sc.title}  ({_p(target)}): {sc.body.name}", sc.omega0
    else:
        raise UsageError(f"{_p(target)}: not a preset ({', '.join(PRESETS)}) nor a scene file")
    if args.json:
        print(json.dumps(info.rows(body, omega), indent=2, default=float))
    else:
        _out(info.format_info(body, title, omega))
    return EXIT_OK


def _cmd_simulate(args) -> int:
    from .atomic import check_outputs
    from .driver import simulate_request
    from .scene import load_scene

    if os.path.splitext(args.out)[1].lower() != ".npz":
        raise UsageError(f"--out: {args.out}: a trajectory is written as .npz; give a path ending in .npz")
    check_outputs([args.out], [args.scene])
    sc = load_scene(args.scene)
    model = args.model or sc.model
    if model not in sc.models:
        raise UsageError(f"{args.scene}: --model {model!r} is not one of the scene's models ({', '.join(sc.models)})")
    request = sc.request(model)
    if args.method:                                 # the option replaces the scene's method, checked the same way
        try:
            request = dataclasses.replace(request, method=args.method)
        except SpecError as e:
            raise UsageError(f"--method: {e.reason}" if e.key == "method" else f"--method: {e.key}: {e.reason}") from None
    try:
        traj = simulate_request(request)
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    try:
        traj.save(args.out, radiation=True)
    except OSError as e:
        raise _cannot_write(args.out, e) from None
    st = traj.stats
    cost = f"{st['nsteps']} steps" if "nsteps" in st else f"{st.get('nfev', '?')} rhs evaluations"
    _out(f"{_p(args.out)}: {traj.t.size} samples, model {model}, method {st['method']}, {cost}, {st['runtime_s']:.3f} s")
    for note in st.get("accuracy_notes", ()):
        _say("note: ", note)
    return EXIT_OK


class WriteFailed(SpinvizError, OSError):
    """An output could not be written (a full disk, an I/O error): exit status 1, the path named."""


def _cannot_write(path, e: OSError) -> SpinvizError:
    """One line naming the output that could not be written, and why."""
    return WriteFailed(f"{path}: cannot write: {e.strerror or e}")


def _named(e: SpecError, args, flags: dict, scene_keys: dict | None = None) -> UsageError:
    """A library error about an argument, in the command line's terms: the option that set the
    value (``--workers: ...``) when it was given on the command line, else the scene's key
    (``SCENE: [render].fps: ...``), else the argument's own name."""
    option = flags.get(e.key)
    if option and getattr(args, option.lstrip("-").replace("-", "_"), None) is not None:
        return UsageError(f"{option}: {e.reason}")
    scene = getattr(args, "scene", None)
    if scene_keys is not None and scene is not None:
        return UsageError(f"{scene}: {scene_keys.get(e.key, e.key)}: {e.reason}")
    return UsageError(f"{option or e.key}: {e.reason}")


def _cmd_methods(args) -> int:
    from .integrators import get, names

    for n in names():
        m = get(n)
        order = f"order {m.order}" if m.order else "variable order"
        print(f"{n:<14} {order:<15} {'fixed step' if m.fixed_step else 'adaptive':<10} {m.description}")
    return EXIT_OK


RENDER_FLAGS = {"size": "--size", "fps": "--fps", "duration": "--duration", "out": "--out", "workers": "--workers",
                "frames": "--frames"}


def _option(e: SpecError, args) -> UsageError:
    """A SpecError from ``render``, named by its option, or by the scene's ``[render]`` key."""
    return _named(e, args, RENDER_FLAGS, _RenderKeys())


class _RenderKeys(dict):
    def __missing__(self, key):
        return f"[render].{key}"


def _cmd_render(args) -> int:
    from . import pipeline
    from .scene import load_scene

    sc = load_scene(args.scene)
    if args.bench:
        return _render_bench(sc, args)
    out = args.out or pipeline.default_output(sc)
    try:
        res = pipeline.render(sc, out, size=args.size, fps=args.fps, duration=args.duration, workers=args.workers,
                              progress=not args.quiet)
    except SpecError as e:
        raise _option(e, args) from None
    except OSError as e:
        raise _cannot_write(out, e) from None
    except SpinvizError:
        raise                                           # says what it is about (an output, the scene)
    except ValueError as e:
        raise UsageError(f"{args.scene}: {e}") from None
    _out(f"{_p(res.path)}: {res.frames} frames {res.size[0]}x{res.size[1]}, "
          f"rendered in {res.seconds:.1f} s ({res.fps:.1f} fps, {res.workers} workers)")
    if res.poster:
        _out(f"{_p(res.poster)}: poster frame")
    for note in res.notes:
        _out(note)
    return EXIT_OK


def _render_bench(sc, args) -> int:
    from .validation import render_bench

    try:
        rows = render_bench.run(sc, fps=args.fps, duration=args.duration, frames=args.frames, workers=args.workers)
    except SpecError as e:
        raise _option(e, args) from None
    _out(render_bench.format_table(rows, args.scene))
    render_bench.write(rows, args.json, args.plot)
    return EXIT_OK


def _cmd_compare(args) -> int:
    from .analysis import compare
    from .atomic import Outputs
    from .driver import simulate_request
    from .scene import load_scene

    sc = load_scene(args.scene)
    if len(sc.models) != 2:
        raise UsageError(f"{args.scene}: [simulation].models: compare needs two models, "
                         f"e.g. models = [\"reduced\", \"truncated\"]")
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UsageError("compare's plots need matplotlib: pip install 'spinviz[render]'") from None
    if args.samples > compare.MAX_SAMPLES:
        raise UsageError(f"--samples: at most {compare.MAX_SAMPLES} (each model is stored at 2 x samples instants), "
                         f"got {args.samples}")
    prefix = args.out or os.path.join("renders", os.path.splitext(os.path.basename(args.scene))[0])
    paths = [f"{prefix}_compare.png", f"{prefix}_hodograph.png"]
    group = Outputs(paths, [args.scene])                # checked before the runs, landed together after
    times = compare.compare_times(sc.t_end, max(2, args.samples))
    try:
        trajs = [simulate_request(sc.request(m, t_eval=times)) for m in sc.models]
    except SpecError as e:
        raise _named(e, args, {"t_eval": "--samples"}) from None
    c = compare.compare(trajs)
    try:
        with group as tmps:
            compare.plot(c, tmps[0], sc.title)
            compare.plot_hodograph(c, tmps[1], sc.title)
    except OSError as e:
        raise _cannot_write(prefix, e) from None
    if args.json:
        print(json.dumps({**c.record(), "plots": list(paths)}, indent=2, default=float))
    else:
        _out(compare.format_table(c, sc.title))
        _out(f"\nplots: {_p(paths[0])}, {_p(paths[1])}")
    return EXIT_OK


OBSERVE_FLAGS = {"line_of_sight": "--los", "distance_cm": "--distance-cm", "integration_s": "--integration-s"}


def _observe_args(args):
    """The observe/listen overrides, checked by the ``[observe]`` table's own schema (so an
    option and the key it overrides take the same values): (line of sight, distance)."""
    from .inputs.scene import ObserveTable

    given = {k: getattr(args, opt.lstrip("-").replace("-", "_"), None) for k, opt in OBSERVE_FLAGS.items()
             if k != "line_of_sight"}
    given["line_of_sight"] = args.los
    try:
        ObserveTable(**{k: v for k, v in given.items() if v is not None})
    except SpecError as e:
        raise UsageError(f"{OBSERVE_FLAGS.get(e.key, e.key)}: {e.reason}") from None
    return args.los, args.distance_cm


def _cmd_observe(args) -> int:
    from .analysis import observe as OB
    from .atomic import Outputs
    from .scene import load_scene

    los, dist = _observe_args(args)
    sc = load_scene(args.scene)
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UsageError("observe's plots need matplotlib: pip install 'spinviz[render]'") from None
    if args.samples > OB_MAX_SAMPLES:
        raise UsageError(f"--samples: at most {OB_MAX_SAMPLES}, got {args.samples}")
    prefix = args.out or os.path.join("renders", os.path.splitext(os.path.basename(args.scene))[0])
    paths = [f"{prefix}_observe.png", f"{prefix}_detector.png"] + ([f"{prefix}_receiver.png"] if sc.units == "cgs" else [])
    group = Outputs(paths, [args.scene])
    try:
        obs, _ = OB.run_scene(sc, args.samples, los, dist, integration_s=args.integration_s)
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    except ValueError as e:
        raise UsageError(f"{args.scene}: {e}") from None
    try:
        with group as tmps:
            OB.plot(obs, tmps[0])
            OB.plot_detector(obs, tmps[1])
            if len(tmps) > 2:
                from .analysis.experiment_plots import plot_receiver

                plot_receiver(obs, tmps[2])
    except OSError as e:
        raise _cannot_write(prefix, e) from None
    if args.json:
        print(json.dumps({**obs.record(), "plots": list(paths)}, indent=2, default=float))
    else:
        _out(OB.format_table(obs))
        _out(f"\nplots: {', '.join(_p(x) for x in paths)}")
    return EXIT_OK


DECIDE_FLAGS = {"trials": "--trials", "seed": "--seed", "spin_range": "--spin-range", "tau0": "--tau0"}
DASK_TRIALS = 2000            # from this many trials (or with --scheduler) the Monte Carlo runs on Dask


def _cmd_decide(args) -> int:
    from .analysis import decide as DC
    from .inputs.decide import DecideArguments
    from .scene import load_scene

    given = {k: getattr(args, k) for k in DECIDE_FLAGS if getattr(args, k) is not None}
    try:
        spec = DecideArguments(**given)
    except SpecError as e:
        raise UsageError(f"{DECIDE_FLAGS.get(e.key, e.key)}: {e.reason}") from None
    sc = load_scene(args.scene)
    receiver = sc.observe.receiver
    for key, flag in (("distance_cm", "--distance-cm"), ("integration_s", "--integration-s")):
        if getattr(args, key) is not None:
            try:
                receiver = dataclasses.replace(receiver, **{key: getattr(args, key)})
            except SpecError as e:
                raise UsageError(f"{flag}: {e.reason}") from None
    if args.measurements is not None:
        return _decide_measurements(args, sc)
    try:
        setup = DC.setup_from_scene(sc, receiver, sc.observe.t_end or sc.t_end, spec.spin_range, spec.tau0)
    except ValueError as e:
        raise UsageError(f"{args.scene}: {e}") from None
    prefix = args.out or os.path.join("renders", os.path.splitext(os.path.basename(args.scene))[0])
    from .atomic import Outputs

    group = Outputs([f"{prefix}_decide.png"], [args.scene])
    out = _run_trials(DC, setup, spec, args)
    try:
        with group as tmps:
            from .analysis.experiment_plots import plot_decide

            plot_decide(out, sc.title, tmps[0])
    except OSError as e:
        raise _cannot_write(prefix, e) from None
    if args.json:
        print(json.dumps({**out.record(), "receiver": receiver.record(), "plots": [f"{prefix}_decide.png"]}, indent=2))
    else:
        _out(DC.format_outcome(out, sc.title, receiver))
        _out(f"\nplot: {_p(prefix + '_decide.png')}")
    return EXIT_OK


def _run_trials(DC, setup, spec, args):
    """The Monte Carlo where it belongs: a Dask cluster when large or asked for (the atlas's
    ``Cluster``, imported here and nowhere else in the command), worker processes otherwise."""
    from .inputs.render import usable_cores

    if args.scheduler is not None or spec.trials >= DASK_TRIALS:
        from .regimes.cluster import Cluster, check_workers, polled

        check_workers(args.workers, args.scheduler)
        with Cluster(args.scheduler, args.workers) as cl:
            _progress(f"decide: {spec.trials} trials on {cl.describe}")

            def mapper(fn, items):
                return polled(cl.client.gather, cl.client.map(fn, items, pure=False))

            return DC.run(setup, spec.trials, spec.seed, mapper)
    workers = min(args.workers or usable_cores(), max(1, spec.trials // 8))
    if workers == 1:
        return DC.run(setup, spec.trials, spec.seed)
    with DC.ProcessMapper(workers) as mapper:
        return DC.run(setup, spec.trials, spec.seed, mapper)


def _decide_measurements(args, sc) -> int:
    """``decide --measurements FILE``: the start-free P-f test of measured data."""
    from .analysis import pftest as PF
    from .inputs.measurements import read_measurements

    law, reason = PF.line_law(sc.body)
    data, unit = read_measurements(args.measurements)
    if law is None:
        result = {"measurements": args.measurements, "law": None, "reason": reason}
        if args.json:
            print(json.dumps(result, indent=2))
        else:
            _out(f"{_p(args.measurements)}: no test: {reason}")
        return EXIT_OK
    test = PF.fit(PF.from_measurements(data, unit, args.measurements))
    if args.json:
        print(json.dumps({"measurements": args.measurements, "law": law, **test.record()}, indent=2, default=float))
    else:
        _out("\n".join([f"{_p(args.measurements)} ({sc.title}): line: {law}"] + [f"  {x}" for x in test.summary()]))
    return EXIT_OK


OB_MAX_SAMPLES = 100_000


def _cmd_listen(args) -> int:
    from .analysis import sonify
    from .atomic import Outputs
    from .scene import load_scene

    los, dist = _observe_args(args)
    if os.path.splitext(args.out)[1].lower() != ".wav":
        raise UsageError(f"--out: {args.out}: the sound is written as WAV; give a path ending in .wav")
    png = args.png or os.path.splitext(args.out)[0] + ".png"
    if os.path.splitext(png)[1].lower() != ".png":
        raise UsageError(f"--png: {png}: give a path ending in .png")
    if not 0.5 <= args.duration <= sonify.MAX_SECONDS:
        raise UsageError(f"--duration: must lie in [0.5, {sonify.MAX_SECONDS:g}] s, got {args.duration:g}")
    if not 20.0 <= args.f0 <= 5000.0:
        raise UsageError(f"--f0: must lie in [20, 5000] Hz (audible, well under the Nyquist frequency), got {args.f0:g}")
    if not 1.0 <= args.dynamic_range_db <= 120.0:
        raise UsageError(f"--dynamic-range-db: must lie in [1, 120], got {args.dynamic_range_db:g}")
    if args.samples > OB_MAX_SAMPLES:
        raise UsageError(f"--samples: at most {OB_MAX_SAMPLES}, got {args.samples}")
    sc = load_scene(args.scene)
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UsageError("listen's spectrogram needs matplotlib: pip install 'spinviz[render]'") from None
    group = Outputs([args.out, png], [args.scene])
    try:
        with group as (tmp_wav, tmp_png):
            mapping = sonify.listen_scene(sc, tmp_wav, tmp_png, args.duration, args.f0, args.time_map, args.samples,
                                          los, dist, args.dynamic_range_db, args.pitch)
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    except ValueError as e:
        raise UsageError(f"{args.scene}: {e}") from None
    except OSError as e:
        raise _cannot_write(args.out, e) from None
    _out(f"{_p(args.out)}: {mapping.duration_s:g} s, {mapping.rate} Hz, 16-bit stereo")
    _out(mapping.statement())
    if mapping.dropped_above_nyquist:
        _out(f"note: {mapping.dropped_above_nyquist} line(s) above {sonify.NYQUIST_SHARE * mapping.rate:.0f} Hz left "
             f"out (lower --f0 to hear them)")
    if mapping.below_audible_s > 0.0:
        _out(f"note: for {mapping.below_audible_s:.1f} s the strongest line is below 20 Hz (raise --f0)")
    _out(f"{_p(png)}: spectrogram of the WAV")
    return EXIT_OK


def _cmd_bench(args) -> int:
    from .atomic import write_json
    from .validation import bench

    if args.process:
        from .validation import process_bench as PB

        _known_problems(args.problems, PB.PROBLEMS)
        pts = PB.run(args.problems or PB.PROBLEMS, repeats=args.repeats or 3, quick=args.quick, progress=_progress)
        print(PB.format_table(pts))
        if args.json:
            write_json(args.json, {"points": [p.record() for p in pts], "headline": PB.headline(pts)})
        if args.plot:
            PB.plot(pts, args.plot)
        return EXIT_OK
    plan = bench.quick_plan() if args.quick else bench.Plan()
    _known_problems(args.problems, bench.PROBLEMS)
    plan = dataclasses.replace(plan, **{k: v for k, v in (("problems", args.problems), ("repeats", args.repeats))
                                        if v is not None})
    rows = bench.run(plan, progress=_progress)
    summ = bench.summary(rows)
    print(bench.format_table(rows, summ, plan.notes))
    if args.json:
        write_json(args.json, {"rows": [r.record() for r in rows], "summary": summ, "notes": plan.notes})
    if args.plot:
        bench.plot(rows, args.plot)
    return EXIT_OK


def _known_problems(names, valid) -> None:
    unknown = [n for n in names or () if n not in valid]
    if unknown:
        raise UsageError(f"--problems: unknown {', '.join(map(_p, unknown))}; valid: {', '.join(valid)}")


def _cmd_stress(args) -> int:
    from .validation import stress

    results = stress.run_all(progress=lambda r: _progress(f"{r.case}: {'pass' if r.passed else 'FAIL'}"))
    if args.json:
        print(json.dumps([r.record() for r in results], indent=2, default=float))
    else:
        print(stress.format_table(results))
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


def _cmd_report(args) -> int:
    from .validation import report

    results, plot_path = report.generate(args.out, args.out_dir, args.quick, progress=_progress)
    _out(f"{_p(args.out)}: regenerated; {_p(plot_path)}")
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


ATLAS_FLAGS = {"out": "--out", "scheduler": "--scheduler", "workers": "--workers", "plot": "--plot",
               "runs_per_task": "--runs-per-task"}


def _cmd_atlas(args) -> int:
    from .regimes import command

    try:
        return command.run(args)
    except SpecError as e:
        raise _named(e, args, ATLAS_FLAGS) from None


_COMMANDS = {"check": _cmd_check, "info": _cmd_info, "simulate": _cmd_simulate, "methods": _cmd_methods,
             "render": _cmd_render, "compare": _cmd_compare, "bench": _cmd_bench, "stress": _cmd_stress,
             "report": _cmd_report, "atlas": _cmd_atlas, "observe": _cmd_observe, "decide": _cmd_decide,
             "listen": _cmd_listen}


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


def entry() -> None:
    """Console-script entry point."""
    _occupy_closed_std_fds()
    try:
        code = main()
        if sys.stdout is not None:
            sys.stdout.flush()
    except BrokenPipeError:
        # the reader went away (spinviz methods | head -1): end quietly, as a Unix tool does
        code = 128 + 13
    _settle(sys.stdout)
    _settle(sys.stderr)
    sys.exit(code)
