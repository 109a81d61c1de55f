"""
A video: the two models side by side
====================================

``spinviz.render`` writes a video (MP4 or, as here, GIF by the extension) and a PNG poster
beside it, atomically; ``spinviz render SCENE --out X.gif`` on the command line is the same
call.  The default scene (``scenes/default.toml``), shortened to 8 seconds at 640×360 and
10 frames per second so that it renders in a few seconds: the DAST cube, reduced (left)
against truncated (right), over 6 Θ.  The real crystal turns 7 billion times a second; the video shows the
spin about 10¹⁵ times slower and says so, under a time bar marked in Θ.
"""

# %%
# Render the scene: the GIF plays below, the poster (the last frame) follows it.
import spinviz

res = spinviz.render("../scenes/default.toml", out="dast_cube.gif", size=(640, 360), fps=10, duration=8.0)
print(res.frames, "frames,", f"{res.seconds:.1f} s to render")
