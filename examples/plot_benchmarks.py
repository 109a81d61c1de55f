"""
Work-precision and rendering speed
==================================

Two measurements too long for a documentation build, redrawn here from the results
committed with the repository: ``renders/bench.json``, written by ``spinviz report`` (42
minutes; ``spinviz bench`` alone: error against time for every method on the paper's
closed-form cases and an askew top, over 10², 10⁴ and 10⁶ turns), and
``renders/render_bench.json``, written by ``spinviz render scenes/default.toml --bench``
(frames per second of the README's video, encoding included).  The numbers are this
machine's (2 cores, software OpenGL); the tables are in the accuracy report.
"""

# %%
# The benchmark's rows as ``spinviz bench`` measured them, and the time each problem takes
# to reach 1e-8 rad of orientation error.
import json

from spinviz.validation import bench, render_bench

saved = json.load(open("../renders/bench.json"))
rows = [bench.Row(**r) for r in saved["rows"]]
print(len(rows), "measurements")
for s in bench.summary(rows):
    best = f"{s['best_method']} {s['best_seconds']:.3g} s" if s["best_method"] else "not reached"
    print(f"({s['problem']}) {s['turns']:.0e} turns: fastest to 1e-8 rad: {best}")

# %%
# Orientation error against wall time, one line per method, one panel per problem and
# horizon; the dotted line is 1e-8 rad.
bench.plot(rows, "work_precision.png")

# %%
# Frames per second of the README's video at 1280×720 and 1920×1080 against the targets.
speed = json.load(open("../renders/render_bench.json"))
for r in speed:
    print(f"{r['size']:>9}: {r['frames']} frames on {r['workers']} workers in {r['seconds']:.1f} s, "
          f"{r['fps']:.1f} fps overall, {r['steady_fps']:.1f} fps steady")
render_bench.plot(speed, "render_bench.png")
