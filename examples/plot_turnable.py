"""
Turn the crystal yourself
=========================

``spinviz.render`` writes a scene as a glTF model (``.glb``) or as one self-contained web
page (``.html``) instead of a video.  The page is for people: one sentence on what the two
crystals are, each turnable under its heading (one above the other on a phone), Play and a
slider in days, labels on the arrows, full screen, the captions in plain words -- and its
viewer (three.js, MIT licence, printed at its foot) inside it, so it loads nothing from the
network.  The model is for Blender and the web: the video's camera and lights, its clock,
and beside it a Blender script that plays it whole at the video's rate.  Both show the
video's own frames: between the kept ones a viewer's interpolation stays within 0.25° of
every frame.

Below, the default scene (``scenes/default.toml``): the DAST cube, reduced (left) and
truncated (right), over 6 Θ.  Drag to turn both crystals, scroll to zoom.
"""

# %%
# The page, shown in a frame; and the model, which imports into Blender (``blender --python
# dast_cube_blender.py`` opens it at 30 fps, frames 0-359, through its camera), three.js or
# any glTF viewer -- both crystals with the dipole and L arrows, the physical time of every
# keyframe in its ``extras``.
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
