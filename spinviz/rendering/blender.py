"""The short Blender script spinviz writes beside a glTF model (``X.glb`` -> ``X_blender.py``):
what the file cannot tell Blender's importer.

Blender's glTF importer places a key at (its time) x (the scene's frame rate) and leaves the
scene's rate (24 fps), frame range (1-250), camera and world as they were; the file's clock
is the MP4's (frame f at f / fps s).  The script opens a new scene (the scenes already open
are left as they are), sets the video's rate before importing, so that Blender's frame n is
the video's frame n, then the frame range 0..F-1, the file's camera as the scene's camera,
the video's frame size, a world that gives the video's ambient light and shows its background
colour, and the Standard view transform (the video's colours).

Safe to run: the script is text from this module with numbers and the model's file name (once,
as a Python literal: ``repr``), nothing from a scene's title or captions; it reads the model
beside it and writes nothing.  Pure Python (no drawing library).
"""

from __future__ import annotations

import os

from .framing import AMBIENT_STRENGTH
from .gltf import BLENDER_SCRIPT_SUFFIX, CAMERA_NAME, linear_from_srgb
from .style import COLORS

__all__ = ["script", "script_path"]

TEMPLATE = '''"""Opens the glTF model beside this script (MODEL below) in Blender, ready to play
and render as spinviz's video shows it.

Written by spinviz beside the model.  Run it with

    blender --python THIS_SCRIPT.py

or open it in Blender's Text Editor and press Run Script.  It adds a scene of its own (the
scenes already open are left as they are), sets the video's frame rate ({fps} fps) before
importing the model -- Blender's glTF importer places each key at its time x the scene's
rate -- so that Blender's frame n is the video's frame n, plays frames {first}-{last} (the whole
video), makes the model's camera the scene's camera, sets the video's frame size, a world
that gives the video's ambient light and shows its background, and the Standard view
transform (the video's colours).  It reads the model beside it and writes nothing.
"""

import os

import bpy

MODEL = {model!r}           # beside this script
FPS = {fps}
FRAME_START, FRAME_END = {first}, {last}
CAMERA = {camera!r}
RESOLUTION = {resolution!r}
BACKGROUND = {background!r}         # linear RGB: the video's background
AMBIENT = {ambient!r}                 # the video's ambient light (glTF has none)


def model_path():
    """The model beside this script (run from a file or from Blender's Text Editor)."""
    here = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else os.getcwd()
    path = os.path.join(here, MODEL)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"{{path}}: the model this script opens is not beside it")
    return path


def world():
    """The video's ambient light on the crystals, its background colour behind them."""
    w = bpy.data.worlds.new("spinviz world")
    w.use_nodes = True
    nodes, links = w.node_tree.nodes, w.node_tree.links
    light = nodes["Background"]
    light.inputs["Color"].default_value = (AMBIENT, AMBIENT, AMBIENT, 1.0)
    seen = nodes.new("ShaderNodeBackground")
    seen.inputs["Color"].default_value = (*BACKGROUND, 1.0)
    path = nodes.new("ShaderNodeLightPath")
    mix = nodes.new("ShaderNodeMixShader")
    links.new(path.outputs["Is Camera Ray"], mix.inputs[0])
    links.new(light.outputs[0], mix.inputs[1])
    links.new(seen.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], nodes["World Output"].inputs["Surface"])
    return w


def main():
    path = model_path()
    scene = bpy.data.scenes.new(os.path.splitext(MODEL)[0])
    if bpy.context.window is not None:
        bpy.context.window.scene = scene
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    with bpy.context.temp_override(scene=scene, view_layer=scene.view_layers[0]):
        bpy.ops.import_scene.gltf(filepath=path)
    scene.frame_start, scene.frame_end = FRAME_START, FRAME_END
    scene.frame_set(FRAME_START)
    scene.camera = next(o for o in scene.objects if o.type == "CAMERA" and o.name.startswith(CAMERA))
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.world = world()
    scene.view_settings.view_transform = "Standard"
    return scene


if __name__ == "__main__":
    main()
'''


def script_path(model_path: str) -> str:
    """Where the script of the model ``model_path`` goes: X.glb -> X_blender.py beside it."""
    return os.path.splitext(os.fspath(model_path))[0] + BLENDER_SCRIPT_SUFFIX


def script(plan, model_path: str) -> str:
    """The Blender script for ``plan``'s model written at ``model_path`` (its file name only
    goes into the script, as a Python literal).

    Parameters
    ----------
    plan : FramePlan
        fps, the number of frames, the frame size and the background.
    model_path : str
        The .glb or .gltf the script opens (beside it).

    Returns
    -------
    str
        Python source for Blender (``bpy``).
    """
    spec = plan.spec
    name = os.path.basename(os.fspath(model_path))
    return TEMPLATE.format(model=name, fps=int(spec.fps), first=0,
                           last=int(plan.frames - 1), camera=CAMERA_NAME, resolution=tuple(int(x) for x in spec.size),
                           background=tuple(round(x, 6) for x in linear_from_srgb(COLORS[spec.background]["bg_rgb"])),
                           ambient=float(AMBIENT_STRENGTH))
