"""``spinviz render SCENE [--out PATH] [--size WxH] [--fps N] [--duration S] [--workers N]``:
off-screen video (MP4 or GIF by the extension) with a PNG poster, or an animated glTF model
(.glb, .gltf) or a self-contained page where the crystal can be turned (.html); ``--bench``: frames per
second.  A value refused by the schema is named by its option when given here, else by the
scene's ``[render]`` key."""

from __future__ import annotations

from ..errors import SpinvizError, UsageError
from .shared import EXIT_OK, cannot_write, out, p, positive, real, size, whole

SCENE_TABLE = "render"          # where a refused value came from when no option gave it


def add_parser(sub) -> None:
    """Add ``spinviz render`` (the video (or --bench)) and its options to ``sub``."""
    r = sub.add_parser("render", help="render a scene off-screen to MP4 or GIF, with a PNG poster; or write it as an "
                                      "animated glTF model (.glb, .gltf) or a page where the crystal can be turned (.html)")
    r.add_argument("scene")
    r.add_argument("--out", help="output .mp4 or .gif, .glb or .gltf (3-D model), .html (self-contained page) "
                                 "(default renders/<scene>.mp4)")
    r.add_argument("--size", type=size, help="WIDTHxHEIGHT in pixels, e.g. 1280x720")
    r.add_argument("--fps", type=whole, help="frames per second (1..240)")
    r.add_argument("--duration", type=real, help="video length in seconds")
    r.add_argument("--workers", type=whole, help="render processes (default: one per core, at most the cores)")
    r.add_argument("--bench", action="store_true",
                   help="measure frames per second at 1280x720 and 1920x1080, encoding included "
                        "(writes to a temporary directory)")
    r.add_argument("--frames", type=positive, default=150, help="frames per benchmark size (with --bench)")
    r.add_argument("--json", metavar="PATH", help="with --bench: also write the results as JSON")
    r.add_argument("--plot", metavar="PATH", help="with --bench: also draw frames per second against the targets (PNG)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args) -> int:
    """Carry out ``spinviz render`` with the parsed ``args``; return its exit status."""
    from .. import pipeline
    from ..inputs.scene_spec import load_scene

    sc = load_scene(args.scene)
    if args.bench:
        return _bench(sc, args)
    path = args.out or pipeline.default_output(sc)
    try:
        res = pipeline.render(sc, path, size=args.size, fps=args.fps, duration=args.duration, workers=args.workers,
                              progress=not args.quiet)
    except OSError as e:
        raise cannot_write(path, e) from None
    except SpinvizError:
        raise                                           # says what it is about (an output, the scene, an option)
    except ValueError as e:
        raise UsageError(f"{args.scene}: {e}") from None
    if hasattr(res, "describe"):                        # a glTF model or a page
        out(res.describe())
        for note in res.notes:
            out(note)
        return EXIT_OK
    out(f"{p(res.path)}: {res.frames} frames {res.size[0]}x{res.size[1]}, "
        f"rendered in {res.seconds:.1f} s ({res.fps:.1f} fps, {res.workers} workers)")
    if res.poster:
        out(f"{p(res.poster)}: poster frame")
    for note in res.notes:
        out(note)
    return EXIT_OK


def _bench(sc, args) -> int:
    from ..validation import render_bench

    rows = render_bench.run(sc, fps=args.fps, duration=args.duration, frames=args.frames, workers=args.workers)
    out(render_bench.format_table(rows, args.scene))
    render_bench.write(rows, args.json, args.plot)
    return EXIT_OK
