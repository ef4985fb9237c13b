"""Lightmap speed against error on the demo room's floor: Penumbra's exact lightmap and
Cycles' bake to an image at 16–1024 samples per texel, on the same "Lightmap" UVs and
resolution, both against a reference of two Cycles bakes at --ref-samples with different
seeds, whose own noise is taken out of the error (as tests/test_lightmap_cycles.py explains).

    .venv/bin/python scripts/bench_lightmap.py [--resolution 64] [--ref-samples 1024] [--ladder 16,64,256,1024]

Materials are Lambertian in the room's colours (see the test for why). Penumbra's time is
the whole bake (every object's light is needed for the indirect light) plus the
rasterisation of every object's lightmap; Cycles' time is the bake of the floor alone.
Prints a Markdown table; takes minutes (the reference dominates).
"""

import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path[:0] = [os.path.join(ROOT, "addon"), HERE]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import penumbra  # noqa: E402
import room  # noqa: E402
import cycles_setup  # noqa: E402


def build():
    # Samples and seed are set per bake (cycles_bake).
    return cycles_setup.lambertian_room(samples=1, seed=0)


def cycles_bake(floor, res, samples, seed):
    scene = bpy.context.scene
    scene.cycles.samples = samples
    scene.cycles.seed = seed
    image = bpy.data.images.new("Cycles %d %d" % (samples, seed), res, res, alpha=False, float_buffer=True)
    image.pixels.foreach_set(np.full(res * res * 4, -1.0, dtype=np.float32))
    mat = floor.material_slots[0].material
    if not mat.name.startswith("Floor bake"):
        mat = mat.copy()
        mat.name = "Floor bake"
        floor.material_slots[0].material = mat
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node
    room.select_only(bpy.context.view_layer, [floor])
    t0 = time.perf_counter()
    assert bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT", "INDIRECT", "COLOR"}, target="IMAGE_TEXTURES",
                               uv_layer="Lightmap", margin=0, use_clear=False) == {"FINISHED"}
    seconds = time.perf_counter() - t0
    px = np.empty(res * res * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(res, res, 4)[:, :, :3].astype(np.float64), seconds


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--resolution", type=int, default=64)
    p.add_argument("--ref-samples", type=int, default=1024)
    p.add_argument("--ladder", default="16,64,256,1024")
    p.add_argument("--quality", default="MEDIUM")
    args = p.parse_args()
    res = args.resolution

    penumbra.register()
    scene, meshes, light = build()
    room.select_only(bpy.context.view_layer, meshes + [light])
    s = scene.penumbra
    s.quality = args.quality
    s.output = "LIGHTMAP"
    s.lightmap_resolution = res
    s.lightmap_margin = 0
    t0 = time.perf_counter()
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    ours_seconds = time.perf_counter() - t0
    ours = np.empty(res * res * 4, dtype=np.float32)
    bpy.data.images["Floor_radiosity"].pixels.foreach_get(ours)
    ours = ours.reshape(res, res, 4)[:, :, :3].astype(np.float64)

    floor = bpy.data.objects["Floor"]
    a, ta = cycles_bake(floor, res, args.ref_samples, 1)
    b, tb = cycles_bake(floor, res, args.ref_samples, 2)
    baked = (a[:, :, 0] >= 0) & (b[:, :, 0] >= 0)
    keep = baked.copy()
    for dj in (-1, 0, 1):
        for di in (-1, 0, 1):
            keep[1:-1, 1:-1] &= baked[1 + dj : res - 1 + dj, 1 + di : res - 1 + di]
    keep[0, :] = keep[-1, :] = keep[:, 0] = keep[:, -1] = False
    ref = 0.5 * (a + b)
    noise2 = float(np.mean((a[keep] - b[keep]) ** 2)) / 4.0
    mean_ref = float(ref[keep].mean())

    def rel_rms(x):
        return np.sqrt(max(float(np.mean((x[keep] - ref[keep]) ** 2)) - noise2, 0.0)) / mean_ref

    rows = [("Penumbra (%s, whole scene)" % args.quality.lower(), ours_seconds, rel_rms(ours))]
    for n in [int(x) for x in args.ladder.split(",") if x]:
        c, t = cycles_bake(floor, res, n, 3)
        rows.append(("Cycles %d spp (floor only)" % n, t, rel_rms(c)))
    print("\nFloor of the demo room, %d×%d lightmap, %d texels compared; reference: Cycles %d spp × 2 seeds "
          "(%.1f + %.1f s), its noise %.4f taken out\n" % (res, res, int(keep.sum()), args.ref_samples, ta, tb,
                                                             np.sqrt(noise2) / mean_ref))
    print("| bake | time (s) | relative RMS error |")
    print("|---|---:|---:|")
    for name, t, e in rows:
        print("| %s | %.2f | %.4f |" % (name, t, e))


if __name__ == "__main__":
    main()
