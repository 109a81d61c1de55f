"""
Turn the crystal yourself
=========================

``spinviz.render`` writes a scene as a glTF model (``.glb``) or as one self-contained web
page (``.html``) instead of a video: both models side by side, turnable in the browser, with
a Play button and a slider on the video's clock (marked in Θ, with the video's captions and
its honesty line).  The poses are the video's: the model holds the video's own frames as
keyframes, and between them its interpolation stays within 0.25° of every frame.  The page
has its viewer (three.js) inside and loads nothing from the network.

Below, the default scene (``scenes/default.toml``): the DAST cube, reduced (left) and
truncated (right), over 6 Θ.  Drag to turn both crystals, scroll to zoom.
"""

# %%
# The page, shown in a frame; and the model, which imports into Blender, three.js or any
# glTF viewer (both crystals with the dipole and L arrows, animated on the video's clock,
# the physical time of every keyframe in its ``extras``).
import matplotlib.pyplot as plt

import spinviz

sc = spinviz.load_scene("../scenes/default.toml")
page = spinviz.render(sc, out="dast_cube_turnable.html")
print(page.describe())
model = spinviz.render(sc, out="dast_cube.glb")
print(model.describe())

# %%
# What a drag on the page shows: the same crystals from above (elevation 60° instead of
# the video's 22°), here drawn by ``spinviz.render_frame`` with the camera keys of the
# scene's ``[render]`` table, halfway through the run (9.4 days, 3 Θ).  The reduced
# crystal's dipole (red) has nearly joined L (green, the world's z axis); the truncated
# one's still stands 45° from it.  (The page draws with three.js, the video and
# this frame with VTK; the poses are the same.)
img = spinviz.render_frame(sc, t=sc.t_end / 2, size=(640, 360), azimuth_deg=20.0, elevation_deg=60.0)
fig = plt.figure(figsize=(6.4, 3.6), dpi=100)
ax = fig.add_axes((0, 0, 1, 1))
ax.imshow(img, interpolation="none")
ax.set_axis_off()
