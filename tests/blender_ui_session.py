"""Run inside Debian's Blender with a real window (under Xvfb) by test_ui.py: invokes
"Bake Radiosity" as a click would (modal, on the Rust thread), waits for the bake, then
undoes once. Writes what it saw as JSON to the path after "--".

Blender 3.4 lacks the light settings io/lights.py reads (Light.normalize is Blender 4), so
this session converts its one area light itself and leaves the meshes without materials:
what is under test here is the operator's modal path and its undo step.
"""

import json
import os
import sys
import time
import traceback

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "addon"), os.path.join(ROOT, "scripts")]

import bpy  # noqa: E402
from mathutils import Vector  # noqa: E402

import penumbra  # noqa: E402
import penumbra.blender.export  # noqa: E402
import room  # noqa: E402

OUT = sys.argv[sys.argv.index("--") + 1]
seen = {}
state = {"polls": 0}


def square_light(obj, depsgraph):
    m, s = obj.matrix_world, obj.data.size / 2
    corners = [(-s, s, 0), (s, s, 0), (s, -s, 0), (-s, -s, 0)]  # counter-clockwise seen from −Z
    return [{"name": obj.name, "polygon": [list(m @ Vector(c)) for c in corners], "radiance": [50.0] * 3}]


def window_override():
    win = bpy.context.window_manager.windows[0]
    return bpy.context.temp_override(window=win, area=win.screen.areas[0])


def finish():
    with open(OUT, "w") as f:
        json.dump(seen, f)
    bpy.ops.wm.quit_blender()


def start():
    try:
        penumbra.register()
        penumbra.blender.export.lights_to_scene = square_light
        for o in list(bpy.data.objects):
            bpy.data.objects.remove(o)
        meshes, light = room.build_room()
        for m in meshes:
            m.data.materials.clear()
        room.select_only(bpy.context.view_layer, meshes + [light])
        bpy.context.scene.penumbra.quality = "MEDIUM"  # the default a user clicks; HIGH takes minutes under Xvfb
        bpy.ops.ed.undo_push(message="room")
        seen["meshes_before"] = len(bpy.data.meshes)
        with window_override():
            seen["invoke"] = sorted(bpy.ops.penumbra.bake("INVOKE_DEFAULT"))
        state["t0"] = time.time()
        bpy.app.timers.register(poll, first_interval=0.05)
    except Exception:
        seen["error"] = traceback.format_exc()
        finish()


def poll():
    try:
        state["polls"] += 1
        coll = bpy.data.collections.get("Penumbra Bake")
        if coll is None or not coll.objects:
            if time.time() - state["t0"] > 300:
                seen["error"] = "no bake after 300 s"
                finish()
                return None
            return 0.05
        seen["baked"] = sorted(o.name for o in coll.objects)
        seen["summary"] = bpy.context.scene.penumbra.last_summary
        seen["polls"] = state["polls"]
        seen["seconds"] = time.time() - state["t0"]
        with window_override():
            bpy.ops.ed.undo()
        coll = bpy.data.collections.get("Penumbra Bake")
        seen["baked_after_undo"] = 0 if coll is None else len(coll.objects)
        seen["meshes_after_undo"] = len(bpy.data.meshes)
        seen["room_after_undo"] = sorted(o.name for o in bpy.data.objects if o.type == "MESH")
    except Exception:
        seen["error"] = traceback.format_exc()
    finish()
    return None


bpy.app.timers.register(start, first_interval=0.5)
