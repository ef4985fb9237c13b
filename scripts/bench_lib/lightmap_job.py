"""Blender side of the lightmap rows, one job per process (its time is its own).

    python lightmap_job.py uv   SCENE.json OUT.json --resolution R
        the scene with a "Lightmap" UV per polygon corner (`uv`), made by Blender's
        Lightmap Pack as the add-on makes it (addon/penumbra/blender/lightmaps.py)
    python lightmap_job.py bake SCENE.json OUT.npz --resolution R --samples N --seed K
        Cycles' Diffuse bake (direct, indirect, colour) of every mesh into its own R×R float
        image on those UVs, margin 0; texels no face covers stay −1
    python lightmap_job.py read OUT.npz EXR...
        Penumbra's EXR lightmaps as arrays in the same orientation

`bake` prints one JSON line {"seconds": time of the bake call}. Arrays are saved as m0, m1, …
(one per scene mesh, R×R×3, row 0 at v = 0 as Blender stores images).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "addon"))

import numpy as np  # noqa: E402

import cycles_setup  # noqa: E402
from bench_lib import blender  # noqa: E402

LIGHTMAP_UV = "Lightmap"


def _per_polygon(v, n):
    a = np.asarray(v if v is not None else [0.8, 0.8, 0.8], dtype=np.float64)
    return [tuple(a)] * n if a.ndim == 1 else [tuple(x) for x in a]


def objects(scene: dict):
    """One object per scene mesh with its polygons as they are (so UVs run per corner in
    the JSON's order), a Lambertian material per colour, its own materials (the active
    image node of a bake is per material); polygon lights as in the vertex bench."""
    import bpy

    objs = []
    for m in scene["meshes"]:
        me = bpy.data.meshes.new(m["name"])
        me.from_pydata([tuple(p) for p in m["positions"]], [], [list(p) for p in m["polygons"]])
        keys, index = {}, []
        for a in _per_polygon(m.get("albedo"), len(m["polygons"])):
            if a not in keys:
                keys[a] = len(keys)
                me.materials.append(cycles_setup.lambert_material(f"{m['name']}.{keys[a]}", a))
            index.append(keys[a])
        me.polygons.foreach_set("material_index", np.asarray(index, dtype=np.int32))
        if m.get("uv") is not None:
            layer = me.uv_layers.new(name=LIGHTMAP_UV)
            layer.data.foreach_set("uv", np.asarray(m["uv"], dtype=np.float32).ravel())
        me.update()
        ob = bpy.data.objects.new(m["name"], me)
        bpy.context.scene.collection.objects.link(ob)
        objs.append(ob)
    for i, light in enumerate(scene["lights"]):
        blender._light(light, i)
    return objs


def make_uvs(scene: dict, resolution: int) -> dict:
    from penumbra.blender.lightmaps import ensure_uv_maps

    objs = objects(scene)
    ensure_uv_maps(objs, resolution)
    out = dict(scene)
    out["meshes"] = []
    for m, ob in zip(scene["meshes"], objs):
        uv = np.empty(len(ob.data.loops) * 2, dtype=np.float32)
        ob.data.uv_layers[LIGHTMAP_UV].data.foreach_get("uv", uv)
        out["meshes"].append({**m, "uv": uv.reshape(-1, 2).astype(np.float64).tolist()})
    return out


def bake(scene: dict, resolution: int):
    import bpy

    objs = objects(scene)
    images = []
    for ob in objs:
        img = bpy.data.images.new(f"{ob.name} cycles", resolution, resolution, alpha=False,
                                  float_buffer=True)
        img.pixels.foreach_set(np.full(resolution * resolution * 4, -1.0, dtype=np.float32))
        for mat in ob.data.materials:
            node = mat.node_tree.nodes.new("ShaderNodeTexImage")
            node.image = img
            mat.node_tree.nodes.active = node
        images.append(img)
    for o in bpy.context.scene.objects:
        o.select_set(o in objs)
    bpy.context.view_layer.objects.active = objs[0]
    t = time.perf_counter()
    res = bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT", "INDIRECT", "COLOR"},
                              target="IMAGE_TEXTURES", uv_layer=LIGHTMAP_UV, margin=0,
                              use_clear=False)
    seconds = time.perf_counter() - t
    if res != {"FINISHED"}:
        raise RuntimeError(f"Cycles bake failed: {res}")
    return seconds, [pixels(img) for img in images]


def pixels(img):
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[:, :, :3].astype(np.float64)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("kind", choices=["uv", "bake", "read"])
    ap.add_argument("inp")
    ap.add_argument("rest", nargs="*")
    ap.add_argument("--resolution", type=int, default=64)
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--bounces", type=int, default=64)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    a = ap.parse_args()
    blender.reset(a.samples, a.seed, False, a.bounces, a.threads)
    if a.kind == "read":
        import bpy

        arrays = [pixels(bpy.data.images.load(p)) for p in a.rest]
        np.savez(a.inp, **{f"m{i}": x for i, x in enumerate(arrays)})
        return
    with open(a.inp) as f:
        scene = json.load(f)
    if a.kind == "uv":
        with open(a.rest[0], "w") as f:
            json.dump(make_uvs(scene, a.resolution), f)
        return
    seconds, arrays = bake(scene, a.resolution)
    np.savez(a.rest[0], **{f"m{i}": x for i, x in enumerate(arrays)})
    print(json.dumps({"seconds": seconds}))


if __name__ == "__main__":
    main()
