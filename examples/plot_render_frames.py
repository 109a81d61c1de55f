"""
Frames of the video, from Python
================================

``spinviz.render_frame`` returns the picture of a scene at a physical time as an RGB array,
and ``spinviz.Renderer`` draws any frames of one video plan, off-screen (pyvista/VTK, no
display needed).  Here the default scene (``scenes/default.toml``): the DAST cube under
the reduced equation (left) and the truncated one (right), over 6 Θ (19 days), with the
radio power of each under them.  Arrays are shown with matplotlib's ``imshow``, one
screen pixel per pixel.
"""

# %%
# The first frame: both crystals start alike, the dipole d (red) at 45° from the angular
# momentum L (green).
import matplotlib.pyplot as plt

import spinviz


def show(img):
    """An RGB array, pixel for pixel, in a figure of its own."""
    h, w, _ = img.shape
    fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(img, interpolation="none")
    ax.set_axis_off()


sc = spinviz.load_scene("../scenes/default.toml")
img = spinviz.render_frame(sc, t=0.0, size=(640, 360))
print(img.shape, img.dtype)
show(img)

# %%
# Two frames of the 12-second video, a quarter of the way in and at its end, drawn by one
# ``Renderer`` (its off-screen windows are released when the ``with`` block ends).  By the
# end the reduced crystal's dipole lies along L and its radio power has fallen by orders of
# magnitude; the truncated crystal still radiates as it slows.
with spinviz.Renderer(sc, size=(640, 360)) as r:
    print(r.frames, "frames in the video")
    for f in (r.frames // 4, r.frames - 1):
        show(r.frame(f))
