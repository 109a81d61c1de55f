"""
The cellulose rod: braked alike, spun apart
===========================================

The rod of the paper's section 6.1 (L = 315 nm, L/D = 10, 4400 D along its axis) over 3 T
(T = 2.2 million years, its braking time).  Both equations brake its tumbling alike, (6.5)
and (6.6); they differ in the spin about the rod's own axis, which the reduced equation
keeps and the truncated one slows.  The rod is painted in two halves so that this spin can
be seen.
"""

# %%
# Both models from the scene, and how their ends differ (``spinviz.compare``, as
# ``spinviz compare scenes/cellulose_rod.toml`` prints it).
import matplotlib.pyplot as plt

import spinviz

sc = spinviz.load_scene("../scenes/cellulose_rod.toml")
print(spinviz.compare(sc, samples=200).table())

# %%
# The scene's poster: the middle frame of its video, at 1.5 T.  The tumbling (the dipole's
# trail about L) is alike on both sides; the rod's own spin is not, so the two rods show
# different halves: the dark one on the left (reduced), the light one on the right.
with spinviz.Renderer(sc, size=(640, 360)) as r:
    img = r.frame((r.frames - 1) // 2)
fig = plt.figure(figsize=(6.4, 3.6), dpi=100)
ax = fig.add_axes((0, 0, 1, 1))
ax.imshow(img, interpolation="none")
ax.set_axis_off()
