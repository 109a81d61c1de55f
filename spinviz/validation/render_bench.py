"""``spinviz render SCENE --bench``: frames per second at 1280x720 and 1920x1080, encoding included.

The scene is simulated once (the frame times do not depend on the size); each size is then
rendered to a temporary MP4 and timed, start-up (worker processes importing VTK) shown
apart from the steady rate.  A benchmark is a command, not a test.
"""

from __future__ import annotations

import os
import tempfile

from ..atomic import write_json
from ..pipeline import require_render_stack, resolve_spec, scene_trajectories
from ..rendering.timeline import plan_frames

SIZES = ((1280, 720), (1920, 1080))
TARGETS_FPS = {"1280x720": 30.0, "1920x1080": 15.0}
ENCODER = "libx264 yuv420p veryfast crf 20"


def run(scene, fps=None, duration=None, frames: int = 150, workers=None) -> list[dict]:
    """One row per size: frames, workers, seconds, start-up seconds, fps, steady fps, MB.
    ``frames`` and ``workers`` are checked first (``inputs.render.RenderArguments``), the
    scene's size, fps and duration by its ``RenderSpec`` -- before the scene is simulated."""
    from ..inputs.render import RenderArguments

    RenderArguments(frames=frames, workers=workers)
    specs = {size: resolve_spec(scene, size=size, fps=fps, duration=duration)[2] for size in SIZES}
    video = require_render_stack()
    rows, trajs = [], None
    for size in SIZES:
        spec = specs[size]
        trajs = trajs or scene_trajectories(scene, spec)
        plan = plan_frames(spec, trajs)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "bench.mp4")
            res = video.render_video(plan, path, workers=workers, progress=False, poster=False, max_frames=frames)
            mb = os.path.getsize(path) / 1e6
        rows.append({"size": f"{size[0]}x{size[1]}", "frames": res.frames, "workers": res.workers,
                     "anti_aliasing": "2x2 supersampling", "encoder": ENCODER, "spin": plan.spin_mode,
                     "seconds": res.seconds, "startup_seconds": res.startup_seconds,
                     "fps": res.fps, "steady_fps": res.steady_fps, "mp4_MB": mb})
    return rows


def format_table(rows: list[dict], scene_path: str) -> str:
    """The measurements as ``spinviz render --bench`` prints them: per frame size, frames, workers,
    total and start-up seconds, frames per second overall and steady."""
    lines = [f"render benchmark: {scene_path} ({rows[0]['spin']} spin), encoding included",
             f"{'size':<10} {'frames':>6} {'workers':>7} {'total s':>8} {'start-up s':>10} {'fps':>6} {'steady fps':>10}"]
    for r in rows:
        lines.append(f"{r['size']:<10} {r['frames']:>6} {r['workers']:>7} {r['seconds']:>8.2f} "
                     f"{r['startup_seconds']:>10.2f} {r['fps']:>6.1f} {r['steady_fps']:>10.1f}")
    lines.append(f"anti-aliasing: 2x2 supersampling; encoder: {ENCODER}")
    return "\n".join(lines)


def plot(rows: list[dict], path: str) -> None:
    """Frames per second against the targets (PNG, atomic)."""
    from ..plotting import pyplot, save

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.6))
    x = range(len(rows))
    ax.bar([i - 0.2 for i in x], [r["steady_fps"] for r in rows], 0.4, label="steady (workers up)")
    ax.bar([i + 0.2 for i in x], [r["fps"] for r in rows], 0.4, label="total (with start-up)")
    for i, r in enumerate(rows):
        ax.hlines(TARGETS_FPS[r["size"]], i - 0.45, i + 0.45, colors="k", linestyles="--")
    ax.set_xticks(list(x), [r["size"] for r in rows])
    ax.set_ylabel("frames per second (encoding included)")
    ax.set_title("spinviz render --bench (dashed: targets)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, path)


def write(rows: list[dict], json_path=None, plot_path=None) -> None:
    """The rows as JSON at ``json_path`` and as a plot at ``plot_path`` (PNG), each only when
    given; both atomic."""
    if json_path:
        write_json(json_path, rows)
    if plot_path:
        plot(rows, plot_path)
