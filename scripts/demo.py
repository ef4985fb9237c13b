"""The demo (run by scripts/demo with the venv's bpy module): builds the room of the seed
paper's Fig. 11, bakes it with the add-on's operator and writes out/demo.blend,
out/demo.glb and out/demo.png (a Cycles render of the baked objects only), then prints
the bake's statistics.
"""

import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(ROOT, "out")
sys.path[:0] = [os.path.join(ROOT, "addon"), HERE]

import bpy  # noqa: E402

import room  # noqa: E402
from bake import export_gltf  # noqa: E402


def render(scene, path, objects):
    """Cycles, CPU, few samples: the baked material is pure emission, so lights play no part
    and a handful of samples only anti-alias."""
    for o in scene.objects:
        if o.type in {"MESH", "LIGHT"} and o not in objects:
            o.hide_render = True
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    if hasattr(scene.cycles, "use_denoising"):
        scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.color = (0.0, 0.0, 0.0)
    if world.node_tree is not None:
        bg = world.node_tree.nodes.get("Background")
        if bg is not None:
            bg.inputs["Color"].default_value = (0, 0, 0, 1)
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def print_stats(stats):
    counts = [k for k in ("N_f1", "N_f2", "N_d", "N_p", "N_e", "N_v", "shots") if k in stats]
    times = [k for k in stats if k.startswith("T_")]
    print("\nPenumbra demo: bake statistics (names as in the paper's tables)")
    print("  %-22s %12s" % ("figure", "value"))
    for k in counts:
        print("  %-22s %12d" % (k, stats[k]))
    for k in times:
        print("  %-22s %12.3f s" % (k, stats[k]))
    for k in sorted(set(stats) - set(counts) - set(times)):
        v = stats[k]
        print("  %-22s %12s" % (k, ("%.4g" % v) if isinstance(v, float) else v))


def main():
    os.makedirs(OUT, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    import penumbra

    penumbra.register()
    scene = bpy.context.scene
    meshes, light = room.build_room(scene)
    room.add_camera(scene)
    room.select_only(bpy.context.view_layer, meshes + [light])

    t0 = time.perf_counter()
    try:
        bpy.ops.penumbra.bake()
    except RuntimeError as e:
        print("demo: the bake failed:", str(e).strip(), file=sys.stderr)
        return 1
    print(scene.penumbra.last_summary, "(operator: %.2f s)" % (time.perf_counter() - t0))

    baked = list(bpy.data.collections["Penumbra Bake"].objects)
    blend = os.path.join(OUT, "demo.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend, check_existing=False)
    glb = os.path.join(OUT, "demo.glb")
    export_gltf(baked, glb)
    png = os.path.join(OUT, "demo.png")
    t0 = time.perf_counter()
    render(scene, png, baked)
    print("rendered %s in %.1f s" % (png, time.perf_counter() - t0))
    print("wrote", blend, glb, png, sep="\n  ")
    print_stats(json.loads(scene.penumbra.last_stats))
    return 0


if __name__ == "__main__":
    sys.exit(main())
