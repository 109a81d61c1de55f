"""Run by Blender's Python (bpy) for tests/test_blender.py: open a spinviz model with the script
spinviz wrote beside it, play it, render one frame, and report what Blender holds as JSON.

Usage: python blender_drive.py REQUEST.json   (REQUEST: script, frames to read, render frame,
size, samples, out.png); prints one JSON object."""

import json
import runpy
import sys

import bpy


def main():
    req = json.loads(open(sys.argv[1]).read())
    scene = runpy.run_path(req["script"], run_name="spinviz_test")["main"]()
    report = {"scene": scene.name, "fps": scene.render.fps, "fps_base": scene.render.fps_base,
              "frame_start": scene.frame_start, "frame_end": scene.frame_end,
              "camera": scene.camera.name if scene.camera else None,
              "camera_type": scene.camera.data.type if scene.camera else None,
              "resolution": [scene.render.resolution_x, scene.render.resolution_y],
              "view_transform": scene.view_settings.view_transform,
              "lights": sorted([o.name, o.data.type, o.data.energy] for o in scene.objects if o.type == "LIGHT"),
              "scenes": sorted(s.name for s in bpy.data.scenes)}
    # the last key of every animated object, in frames
    keys = [kp.co[0] for o in scene.objects if o.animation_data and o.animation_data.action
            for fc in _fcurves(o.animation_data) for kp in fc.keyframe_points]
    report["key_range"] = [min(keys), max(keys)]
    bodies = {}
    for f in req["frames"]:
        scene.frame_set(f)
        for o in scene.objects:
            if o.name.endswith(" body") and o.type == "MESH":
                q = o.matrix_world.to_quaternion()
                bodies.setdefault(o.name, []).append([q.w, q.x, q.y, q.z])
    report["bodies"] = bodies
    scene.frame_set(req["render_frame"])
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = req["samples"]
    scene.render.resolution_x, scene.render.resolution_y = req["size"]
    scene.render.filepath = req["out"]
    bpy.ops.render.render(write_still=True, scene=scene.name)
    print("SPINVIZ-REPORT " + json.dumps(report))


def _fcurves(anim):
    """The F-curves of an object's action (Blender 4.4+ keeps them in the action's slots' channel bags)."""
    action = anim.action
    if hasattr(action, "fcurves") and len(action.fcurves):
        return list(action.fcurves)
    out = []
    for layer in getattr(action, "layers", []):
        for strip in layer.strips:
            for bag in strip.channelbags:
                if bag.slot == anim.action_slot:
                    out += list(bag.fcurves)
    return out


main()
