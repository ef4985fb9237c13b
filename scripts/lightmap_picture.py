"""The README's lightmap picture: the demo room's floor lightmap beside the low-poly room
rendered with nothing but its lightmaps (each original object shows its own image as
emission, the light is off, no bounces: what a game engine would draw).

    .venv/bin/python scripts/lightmap_picture.py [--resolution 256] [--output docs/lightmap.png]
"""

import argparse
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path[:0] = [os.path.join(ROOT, "addon"), HERE]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import penumbra  # noqa: E402
import room  # noqa: E402


def srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def bake_room(resolution):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    meshes, light = room.build_room()
    room.add_camera()
    room.select_only(bpy.context.view_layer, meshes + [light])
    s = bpy.context.scene.penumbra
    s.output = "LIGHTMAP"
    s.lightmap_resolution = resolution
    s.quality = "MEDIUM"
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    print(s.last_summary)
    return meshes, light


def lightmap_only(obj):
    """Replaces ``obj``'s materials by its lightmap as emission, on the Lightmap UVs."""
    mat = bpy.data.materials.new(obj.name + " lightmap only")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.clear()
    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = "Lightmap"
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image = bpy.data.images[obj.name + "_radiosity"]
    tex.interpolation = "Linear"
    emit = tree.nodes.new("ShaderNodeEmission")
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(uv.outputs["UV"], tex.inputs["Vector"])
    tree.links.new(tex.outputs["Color"], emit.inputs["Color"])
    tree.links.new(emit.outputs["Emission"], out.inputs["Surface"])
    obj.data.materials.clear()
    obj.data.materials.append(mat)


def render(width, height, exposure):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 16
    scene.cycles.max_bounces = 0
    scene.cycles.use_denoising = False
    scene.world = None
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.exposure = float(np.log2(exposure))
    path = os.path.join(tempfile.mkdtemp(), "room.png")
    scene.render.filepath = path
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    px = np.empty(width * height * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(height, width, 4)[:, :, :3]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--resolution", type=int, default=256)
    p.add_argument("--output", default=os.path.join(ROOT, "docs", "lightmap.png"))
    args = p.parse_args()

    penumbra.register()
    meshes, light = bake_room(args.resolution)
    floor = bpy.data.images["Floor_radiosity"]
    r = args.resolution
    lm = np.empty(r * r * 4, dtype=np.float32)
    floor.pixels.foreach_get(lm)
    lm = lm.reshape(r, r, 4)[:, :, :3]
    exposure = 0.9 / float(np.percentile(lm, 99.5))

    for o in meshes:
        lightmap_only(o)
    light.hide_render = True
    height = 400
    shot = render(600, height, exposure)

    # The lightmap as stored (bottom row first), scaled to the render's height, same exposure.
    idx = (np.arange(height) * r // height)
    panel = srgb(lm[idx][:, idx] * exposure)
    gap = np.ones((height, 8, 3), dtype=np.float32)
    picture = np.concatenate([panel, gap, shot], axis=1)
    h, w = picture.shape[:2]
    out = bpy.data.images.new("lightmap picture", w, h, alpha=False)
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[:, :, :3] = picture
    out.pixels.foreach_set(rgba.ravel())
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    out.filepath_raw = os.path.abspath(args.output)
    out.file_format = "PNG"
    out.save()
    print("wrote", args.output)


if __name__ == "__main__":
    main()
