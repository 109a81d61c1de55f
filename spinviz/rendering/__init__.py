"""Off-screen rendering: from trajectories to frames to video.  Depends only on trajectories
(never on the integrators or the scene layer).

* ``spec`` -- ``RenderSpec``, the validated description of a video (pure Python);
* ``timeline`` -- frame times and what each panel shows at each frame (pure NumPy);
* ``session`` -- the pyvista windows that draw a frame; ``hud`` -- text on the frame;
* ``encode`` -- MP4/GIF/PNG writers; ``video`` -- the parallel render-and-encode pipeline.

Importing this package loads nothing heavy: pyvista, vtk, imageio and Pillow are imported
by ``session``, ``hud``, ``encode`` and ``video`` only.
"""
