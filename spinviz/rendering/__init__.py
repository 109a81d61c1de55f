"""Off-screen rendering: from trajectories to frames to video, in two layers.  Depends only
on trajectories (never on the integrators or the scene layer).

Planning -- what each frame shows and where; plain data and NumPy, tested without GL
(no drawing library is imported; ``pyproject.toml`` has the contract):

* ``spec`` -- ``RenderSpec``, the validated description of a video, and the time map;
* ``timeline`` -- frame times, spin mode and each panel's arrays, sampled from trajectories
  (``FramePlan``, ``Panel``: plain data in ``frameplan``);
* ``picture`` -- ``plan_picture`` lays a frame plan out on its frame, in one pass down:
  ``captions`` (every word, per frame too), ``style`` (colours and sizes), ``layout``
  (bands and type sizes), ``stage`` (3-D content, poses at every frame, the ``camera``
  fitted to all of them, axis labels), ``overlay`` (text items and marks, per frame too).

Drawing -- a ``Picture`` into pixels; decides nothing:

* ``video`` -- the front door: plans the picture, hands the frames to ``workers`` (this
  process, or a pool of render processes that each encode a segment), writes atomically;
* ``session`` -- one frame: ``views`` (VTK windows; ``meshes`` builds the solids) and
  ``hud`` (Pillow; ``fonts`` measures text for the layout and draws it); ``encode`` --
  MP4/GIF/PNG writers.

Media -- the same plan as a glTF model or a page, without the drawing stack: ``export``
writes the model (``keyframes``, ``framing``: its camera and lights, ``gltf``) with the
Blender script beside it (``blender``), or the page (``webpage``: its words ``pagetext``, its
poster ``poster``, its viewer ``web/``).

Importing this package loads nothing heavy: pyvista, vtk, imageio and Pillow are imported
by the drawing modules only.
"""
