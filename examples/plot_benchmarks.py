"""
Work-precision and rendering speed
==================================

Two measurements too long for a documentation build, redrawn here from the results
committed with the repository: ``renders/bench.json``, written by ``spinviz report`` on
2026-11-24 (42 minutes on this project's 2-core x86_64 machine, nothing else running;
``spinviz bench`` alone: error against time for every method on the paper's closed-form
cases and an askew top, over 10², 10⁴ and 10⁶ turns), and ``renders/render_bench.json``,
written by ``spinviz render scenes/default.toml --bench`` on 2026-11-21 on the same machine
(frames per second of the default scene's video, encoding included, software OpenGL).  The
files are plain JSON: this example reads them with the standard library and draws them with
matplotlib.  The tables are in the :doc:`accuracy report <../accuracy>`.
"""

# %%
# The benchmark's summary as ``spinviz bench`` wrote it: per problem and horizon, the
# fastest method to reach 1e-8 rad of orientation error, and its time.
import json
import math

import matplotlib.pyplot as plt

saved = json.load(open("../renders/bench.json"))
rows = saved["rows"]
print(len(rows), "measurements")
for s in saved["summary"]:
    best = f"{s['best_method']} {s['best_seconds']:.3g} s" if s["best_method"] else "not reached"
    print(f"({s['problem']}) {s['turns']:.0e} turns: fastest to 1e-8 rad: {best}")

# %%
# Orientation error against wall time, one line per method, one panel per problem and
# horizon; the dotted line is 1e-8 rad.
STYLES = {"baseline": ("k", "o"), "dop853": ("tab:gray", "s"), "radau": ("tab:brown", "v"),
          "taylor": ("tab:blue", "D"), "split8": ("tab:red", "*"), "split6": ("tab:orange", "X"),
          "secular": ("tab:green", "P")}
panels = [(s["problem"], s["turns"]) for s in saved["summary"]]        # one per problem and horizon
fig, axes = plt.subplots(len(panels) // 3, 3, figsize=(15, 3.8 * (len(panels) // 3)))
for ax, (problem, turns) in zip(axes.flat, panels):
    for method, (color, marker) in STYLES.items():
        pts = sorted((r["seconds"], max(r["orientation_error"], 1e-16)) for r in rows
                     if (r["problem"], r["turns"], r["method"]) == (problem, turns, method)
                     and r["repeats"] and math.isfinite(r["orientation_error"]))
        if pts:
            ax.loglog(*zip(*pts), color=color, marker=marker, label=method)
    ax.axhline(1e-8, color="grey", lw=0.8, ls=":")
    ax.set(title=f"({problem}), {turns:.0e} turns", xlabel="wall time [s]", ylabel="max orientation error [rad]")
    ax.legend(fontsize=7)
fig.tight_layout()

# %%
# Frames per second of the default scene's video at 1280×720 and 1920×1080: steady (the
# render workers up) and overall (start-up included).
speed = json.load(open("../renders/render_bench.json"))
for r in speed:
    print(f"{r['size']:>9}: {r['frames']} frames on {r['workers']} workers in {r['seconds']:.1f} s, "
          f"{r['fps']:.1f} fps overall, {r['steady_fps']:.1f} fps steady")
fig, ax = plt.subplots(figsize=(6, 3.6))
x = range(len(speed))
ax.bar([i - 0.2 for i in x], [r["steady_fps"] for r in speed], 0.4, label="steady (workers up)")
ax.bar([i + 0.2 for i in x], [r["fps"] for r in speed], 0.4, label="overall (with start-up)")
ax.set_xticks(list(x), [r["size"] for r in speed])
ax.set(ylabel="frames per second (encoding included)", title="spinviz render --bench")
ax.legend(fontsize=8)
fig.tight_layout()
