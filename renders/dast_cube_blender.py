"""Opens the glTF model beside this script (MODEL below) in Blender, ready to play
and render as spinviz's video shows it.

Written by spinviz beside the model.  Run it with

    blender --python THIS_SCRIPT.py

or open it in Blender's Text Editor and press Run Script.  It adds a scene of its own (the
scenes already open are left as they are), sets the video's frame rate (30 fps) before
importing the model -- Blender's glTF importer places each key at its time x the scene's
rate -- so that Blender's frame n is the video's frame n, plays frames 0-359 (the whole
video), makes the model's camera the scene's camera, sets the video's frame size, a world
that gives the video's ambient light and shows its background, and the Standard view
transform (the video's colours).  It reads the model beside it and writes nothing.
"""

import os

import bpy

MODEL = 'dast_cube.glb'           # beside this script
FPS = 30
FRAME_START, FRAME_END = 0, 359
CAMERA = "camera (the video's view)"
RESOLUTION = (1280, 720)
BACKGROUND = (1.0, 1.0, 1.0)         # linear RGB: the video's background
AMBIENT = 0.3                 # the video's ambient light (glTF has none)


def model_path():
    """The model beside this script (run from a file or from Blender's Text Editor)."""
    here = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else os.getcwd()
    path = os.path.join(here, MODEL)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"{path}: the model this script opens is not beside it")
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
