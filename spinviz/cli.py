"""Command line: a thin ``main(argv) -> int`` that parses, delegates and maps errors to
exit codes (0 success, 1 a check or run failed, 2 bad input).  No physics here."""

from __future__ import annotations

import argparse
import json
import os
import sys

EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2


class UserError(Exception):
    """Bad input: printed as one line, exit status 2."""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="spinviz", description="Rotation of a dipolar nanocrystal braked by radiation reaction "
                                "(reduced (2.2)+(2.3) vs truncated (2.5) Euler equations).")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    c = sub.add_parser("check", help="validate the integrators against the paper's closed forms")
    c.add_argument("--json", action="store_true", help="print a JSON list of records instead of a table")

    i = sub.add_parser("info", help="derived quantities of a preset or scene, beside the paper's figures")
    i.add_argument("target", help="a preset name (cellulose_rod, dast_cube, dast_family1) or a scene file")
    i.add_argument("--json", action="store_true")

    s = sub.add_parser("simulate", help="integrate a scene and write the trajectory (.npz)")
    s.add_argument("scene")
    s.add_argument("--out", required=True, help="output .npz path")
    s.add_argument("--model", help="which of the scene's models (default: the first)")
    s.add_argument("--method", help="override the scene's integrator")

    r = sub.add_parser("render", help="render a scene off-screen to MP4 or GIF, with a PNG poster")
    r.add_argument("scene")
    r.add_argument("--out", help="output .mp4 or .gif (default renders/<scene>.mp4)")
    r.add_argument("--size", type=_size, help="WIDTHxHEIGHT in pixels, e.g. 1280x720")
    r.add_argument("--fps", type=_fps, help="frames per second (1..240)")
    r.add_argument("--duration", type=_duration, help="video length in seconds")
    r.add_argument("--workers", type=_positive_int, help="render processes (default: one per core)")
    r.add_argument("--bench", action="store_true",
                   help="measure frames per second at 1280x720 and 1920x1080, encoding included (writes to a temporary directory)")
    r.add_argument("--frames", type=_positive_int, default=150, help="frames per benchmark size (with --bench)")
    r.add_argument("--json", metavar="PATH", help="with --bench: also write the results as JSON")
    r.add_argument("--plot", metavar="PATH", help="with --bench: also draw frames per second against the targets (PNG)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")

    c2 = sub.add_parser("compare", help="reduced vs truncated for a two-model scene: angles, crossing times, final states, plots")
    c2.add_argument("scene")
    c2.add_argument("--out", help="prefix of the PNG plots (default renders/<scene>): <prefix>_compare.png, <prefix>_hodograph.png")
    c2.add_argument("--samples", type=_positive_int, default=800, help="evenly spaced plus as many log-spaced output times")
    c2.add_argument("--json", action="store_true", help="print the results as JSON")

    b = sub.add_parser("bench", help="work-precision benchmark: error against run time, per method and horizon")
    b.add_argument("--quick", action="store_true", help="two problems, 1e2 and 1e4 turns, fewer settings (~2 min)")
    b.add_argument("--json", metavar="PATH", help="also write rows and summary as JSON")
    b.add_argument("--plot", metavar="PATH", help="also draw error against time, log-log, one line per method (PNG)")

    st = sub.add_parser("stress", help="stiff and extreme cases: pass/fail, error, time, and the method the driver picked")
    st.add_argument("--json", action="store_true", help="print a JSON list of records instead of a table")

    rp = sub.add_parser("report", help="regenerate the README's 'Accuracy and speed' section: bench plot and tables, stress table")
    rp.add_argument("--quick", action="store_true", help="the quick benchmark plan")
    rp.add_argument("--readme", default="README.md", help="README to update between its report markers")
    rp.add_argument("--out-dir", default="renders", help="where the plot and JSON go")

    sub.add_parser("methods", help="list the integrators")
    return p


def _bounded(cast, lo, hi, what):
    """An argparse type: ``cast(text)`` within [lo, hi] (lo exclusive for floats)."""
    def parse(text: str):
        try:
            v = cast(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
        if cast is int and v < lo:
            raise argparse.ArgumentTypeError(f"must be at least {lo}, got {v}")
        if cast is int and hi is not None and v > hi:
            raise argparse.ArgumentTypeError(f"must be at most {hi}, got {v}")
        if cast is float and not (lo < v < hi):
            raise argparse.ArgumentTypeError(f"must be between {lo:g} and {hi:g} s, got {text}")
        return v

    return parse


_positive_int = _bounded(int, 1, None, "a whole number")
_fps = _bounded(int, 1, 240, "a whole number")
_duration = _bounded(float, 0.0, 3600.0, "seconds")


def _size(text: str):
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    if not (16 <= w <= 7680 and 16 <= h <= 7680):
        raise argparse.ArgumentTypeError(f"size must be within 16..7680 px, got {text!r}")
    return (w, h)


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from .scene import SceneError
    from .simulate import SimulationError

    try:
        return _COMMANDS[args.command](args)
    except (UserError, SceneError) as e:
        print(f"spinviz: error: {e}", file=sys.stderr)
        return EXIT_USAGE
    except SimulationError as e:
        print(f"spinviz: run failed: {e}", file=sys.stderr)
        return EXIT_FAIL
    except KeyboardInterrupt:
        print("spinviz: interrupted", file=sys.stderr)
        return 130
    except (ValueError, OSError, ImportError, ArithmeticError, RuntimeError) as e:
        # the safety net: whatever input slipped past the specific checks still gets one
        # line, not a traceback (SPINVIZ_DEBUG=1 shows the traceback)
        if os.environ.get("SPINVIZ_DEBUG"):
            raise
        what = getattr(e, "filename", None)
        msg = f"{what}: {e.strerror}" if isinstance(e, OSError) and what and e.strerror else str(e)
        print(f"spinviz: error: {msg}", file=sys.stderr)
        return EXIT_USAGE


def _cmd_check(args) -> int:
    from . import checks

    results = checks.run_all()
    if args.json:
        print(json.dumps([r.record() for r in results], indent=2, default=float))
    else:
        print(checks.format_table(results))
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


def _cmd_info(args) -> int:
    from . import info
    from .physics.bodies import PRESETS

    target = args.target
    if target in PRESETS:
        body = PRESETS[target]()
        title, omega = f"{body.name}  (preset {target})", None
    elif os.path.exists(target) or target.endswith(".toml"):
        from .scene import load_scene

        sc = load_scene(target)
        body, title, omega = sc.body, f"{sc.title}  ({target}): {sc.body.name}", sc.omega0
    else:
        raise UserError(f"{target}: not a preset ({', '.join(PRESETS)}) nor a scene file")
    if args.json:
        print(json.dumps(info.rows(body, omega), indent=2, default=float))
    else:
        print(info.format_info(body, title, omega))
    return EXIT_OK


def _cmd_simulate(args) -> int:
    from .scene import load_scene
    from .simulate import SimulationError, simulate

    sc = load_scene(args.scene)
    model = args.model or sc.model
    if model not in sc.models:
        raise UserError(f"{args.scene}: --model {model!r} is not one of the scene's models ({', '.join(sc.models)})")
    kw = sc.simulation_kwargs()
    if args.method:
        from .integrators import get

        if args.method.lower() != "auto":
            try:
                get(args.method)
            except ValueError as e:
                raise UserError(f"--method: {e}") from None
        kw["method"] = args.method.lower()
    try:
        traj = simulate(sc.body, model, **kw)
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    except ValueError as e:
        raise UserError(f"{args.scene}: {e}") from None
    try:
        traj.save_npz(args.out)
    except OSError as e:
        raise UserError(f"{args.out}: cannot write: {e.strerror or e}") from None
    st = traj.stats
    print(f"{args.out}: {traj.t.size} samples, model {model}, method {st['method']}, "
          f"{st.get('nfev', '?')} rhs evaluations, {st['runtime_s']:.3f} s")
    return EXIT_OK


def _cmd_methods(args) -> int:
    from .integrators import get, names

    for n in names():
        m = get(n)
        order = f"order {m.order}" if m.order else "variable order"
        print(f"{n:<14} {order:<15} {'fixed step' if m.fixed_step else 'adaptive':<10} {m.description}")
    return EXIT_OK


def _cmd_render(args) -> int:
    from . import video
    from .simulate import SimulationError
    from .scene import load_scene

    sc = load_scene(args.scene)
    out = args.out or video.default_output(sc)
    ext = os.path.splitext(out)[1].lower()
    if ext not in (".mp4", ".gif"):
        raise UserError(f"{out}: unknown video format {ext or '(none)'!r}; use .mp4 or .gif")
    spec = video.spec_with(sc, size=args.size, fps=args.fps, duration=args.duration)
    if ext == ".mp4" and (spec.size[0] % 2 or spec.size[1] % 2):
        raise UserError(f"{out}: MP4 (H.264, yuv420p) needs an even width and height, got {spec.size[0]}x{spec.size[1]}")
    if spec.size[0] % len(sc.models):
        raise UserError(f"{args.scene}: {len(sc.models)} panels side by side need a width divisible by "
                        f"{len(sc.models)}, got {spec.size[0]}")
    try:
        render = video.require_render_stack()
    except video.MissingRenderStack as e:
        raise UserError(str(e)) from None
    try:
        if args.bench:
            return _render_bench(sc, args, render, video)
        plan = video.plan_scene(sc, spec)
    except ValueError as e:
        raise UserError(f"{args.scene}: {e}") from None
    except render.RenderError as e:
        raise SimulationError(str(e)) from None
    try:
        res = render.render_video(plan, out, workers=args.workers, progress=not args.quiet)
    except render.RenderError as e:
        raise SimulationError(str(e)) from None
    except OSError as e:
        raise UserError(f"{out}: cannot write: {e.strerror or e}") from None
    print(f"{res.path}: {res.frames} frames {res.size[0]}x{res.size[1]} at {spec.fps} fps, "
          f"rendered in {res.seconds:.1f} s ({res.fps:.1f} fps, {res.workers} workers)")
    if res.poster:
        print(f"{res.poster}: poster frame")
    for note in plan.notes:
        print(note)
    return EXIT_OK


def _render_bench(sc, args, render, video) -> int:
    import tempfile

    rows = []
    trajs = None
    for size in ((1280, 720), (1920, 1080)):
        spec = video.spec_with(sc, size=size, fps=args.fps, duration=args.duration)
        trajs = trajs or video.scene_trajectories(sc, spec)      # the frame times do not depend on the size
        plan = video.plan_frames(spec, trajs)
        with tempfile.TemporaryDirectory() as d:
            res = render.render_video(plan, os.path.join(d, "bench.mp4"), workers=args.workers, progress=False,
                                      poster=False, max_frames=args.frames)
            mb = os.path.getsize(os.path.join(d, "bench.mp4")) / 1e6
        rows.append({"size": f"{size[0]}x{size[1]}", "frames": res.frames, "workers": res.workers,
                     "anti_aliasing": "2x2 supersampling", "encoder": "libx264 yuv420p veryfast crf 20",
                     "seconds": res.seconds, "startup_seconds": res.startup_seconds,
                     "fps": res.fps, "steady_fps": res.steady_fps, "mp4_MB": mb})
    print(f"render benchmark: {args.scene} ({plan.spin_mode} spin), encoding included")
    print(f"{'size':<10} {'frames':>6} {'workers':>7} {'total s':>8} {'start-up s':>10} {'fps':>6} {'steady fps':>10}")
    for r in rows:
        print(f"{r['size']:<10} {r['frames']:>6} {r['workers']:>7} {r['seconds']:>8.2f} {r['startup_seconds']:>10.2f} "
              f"{r['fps']:>6.1f} {r['steady_fps']:>10.1f}")
    print("anti-aliasing: 2x2 supersampling; encoder: libx264 yuv420p (veryfast, crf 20)")
    if args.json:
        _write_json(args.json, rows)
    if args.plot:
        _plot_render_bench(args.plot, rows)
    return EXIT_OK


RENDER_TARGETS_FPS = {"1280x720": 30.0, "1920x1080": 15.0}


def _plot_render_bench(path: str, rows) -> None:
    from .plotting import pyplot, save

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.6))
    x = range(len(rows))
    ax.bar([i - 0.2 for i in x], [r["steady_fps"] for r in rows], 0.4, label="steady (workers up)")
    ax.bar([i + 0.2 for i in x], [r["fps"] for r in rows], 0.4, label="total (with start-up)")
    for i, r in enumerate(rows):
        ax.hlines(RENDER_TARGETS_FPS[r["size"]], i - 0.45, i + 0.45, colors="k", linestyles="--")
    ax.set_xticks(list(x), [r["size"] for r in rows])
    ax.set_ylabel("frames per second (encoding included)")
    ax.set_title("spinviz render --bench (dashed: targets)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, path)


def _write_json(path: str, data) -> None:
    """JSON written atomically (temporary file, then rename)."""
    from .atomic import atomic_path

    with atomic_path(path) as tmp, open(tmp, "w") as fh:
        json.dump(data, fh, indent=2, default=float)


def _cmd_compare(args) -> int:
    from . import compare
    from .scene import load_scene
    from .simulate import simulate

    sc = load_scene(args.scene)
    if len(sc.models) != 2:
        raise UserError(f"{args.scene}: [simulation].models: compare needs two models, e.g. models = [\"reduced\", \"truncated\"]")
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UserError("compare's plots need matplotlib: pip install 'spinviz[render]'") from None
    kw = sc.simulation_kwargs(t_eval=compare.compare_times(sc.t_end, max(2, args.samples)))
    try:
        trajs = [simulate(sc.body, m, **kw) for m in sc.models]
    except ValueError as e:
        raise UserError(f"{args.scene}: {e}") from None
    c = compare.compare(trajs)
    prefix = args.out or os.path.join("renders", os.path.splitext(os.path.basename(args.scene))[0])
    paths = (f"{prefix}_compare.png", f"{prefix}_hodograph.png")
    try:
        compare.plot(c, paths[0], sc.title)
        compare.plot_hodograph(c, paths[1], sc.title)
    except OSError as e:
        raise UserError(f"{prefix}: cannot write the plots: {e.strerror or e}") from None
    if args.json:
        print(json.dumps({**c.record(), "plots": list(paths)}, indent=2, default=float))
    else:
        print(compare.format_table(c, sc.title))
        print(f"\nplots: {paths[0]}, {paths[1]}")
    return EXIT_OK


def _progress(msg: str) -> None:
    sys.stderr.write(f"  {msg}\n")
    sys.stderr.flush()


def _run_bench(quick: bool):
    from . import bench

    plan = bench.quick_plan() if quick else bench.Plan()
    rows = bench.run(plan, progress=_progress)
    return bench, plan, rows, bench.summary(rows)


def _cmd_bench(args) -> int:
    bench, plan, rows, summ = _run_bench(args.quick)
    print(bench.format_table(rows, summ, plan.notes))
    if args.json:
        _write_json(args.json, {"rows": [r.record() for r in rows], "summary": summ, "notes": plan.notes})
    if args.plot:
        bench.plot(rows, args.plot)
    return EXIT_OK


def _cmd_stress(args) -> int:
    from . import stress

    results = stress.run_all(progress=lambda r: _progress(f"{r.case}: {'pass' if r.passed else 'FAIL'}"))
    if args.json:
        print(json.dumps([r.record() for r in results], indent=2, default=float))
    else:
        print(stress.format_table(results))
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


REPORT_BEGIN = "<!-- spinviz report: begin (regenerated by `spinviz report`; do not edit by hand) -->"
REPORT_END = "<!-- spinviz report: end -->"


def _cmd_report(args) -> int:
    from . import stress
    from .atomic import atomic_path

    try:
        with open(args.readme) as fh:
            readme = fh.read()
    except OSError as e:
        raise UserError(f"{args.readme}: {e.strerror or e}") from None
    if REPORT_BEGIN not in readme or REPORT_END not in readme:
        raise UserError(f"{args.readme}: no report markers (the begin and end comments of the 'Accuracy and speed' section)")
    bench, plan, rows, summ = _run_bench(args.quick)
    plot_path = os.path.join(args.out_dir, "work_precision.png")
    bench.plot(rows, plot_path)
    _write_json(os.path.join(args.out_dir, "bench.json"), {"rows": [r.record() for r in rows], "summary": summ,
                                                            "notes": plan.notes})
    results = stress.run_all(progress=lambda r: _progress(f"{r.case}: {'pass' if r.passed else 'FAIL'}"))
    _write_json(os.path.join(args.out_dir, "stress.json"), [r.record() for r in results])
    body = "\n".join([
        REPORT_BEGIN, "",
        f"![work-precision]({plot_path})", "",
        "Time to reach 1e-8 rad of orientation error (interpolated along each method's sweep):", "",
        "```", *bench.format_table([], summ, []).splitlines()[3:], "```", "",
        "<details><summary>all benchmark rows</summary>", "", "```", bench.format_table(rows, [], plan.notes), "```",
        "", "</details>", "",
        "`spinviz stress`:", "", "```", stress.format_table(results), "```", "",
        REPORT_END,
    ])
    new = readme[:readme.index(REPORT_BEGIN)] + body + readme[readme.index(REPORT_END) + len(REPORT_END):]
    with atomic_path(args.readme) as tmp, open(tmp, "w") as fh:
        fh.write(new)
    print(f"{args.readme}: 'Accuracy and speed' regenerated; {plot_path}")
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


_COMMANDS = {"check": _cmd_check, "info": _cmd_info, "simulate": _cmd_simulate, "methods": _cmd_methods,
             "render": _cmd_render, "compare": _cmd_compare, "bench": _cmd_bench, "stress": _cmd_stress,
             "report": _cmd_report}


def entry() -> None:
    """Console-script entry point."""
    sys.exit(main())
