"""The demo room's floor lightmap against Cycles' own bake to an image on the same "Lightmap"
UV map at the same resolution (direct + indirect + colour).

Materials are Lambertian (Diffuse BSDF) in the room's colours: Penumbra's radiosity is
Lambertian, and a Principled BSDF's glossy layer would bring light into Cycles' Diffuse bake
that no radiosity method carries.

Noise: Cycles is run with two seeds. Their mean is the reference; for each texel
(a − b)²/4 estimates the variance of that mean (E[(a − b)²] = 2σ², the mean of two has σ²/2),
and its sum over the texels is taken out of the summed squared error before the relative
RMS is formed. With thousands of texels the estimate is tight, so a modest sample count
gives an unbiased figure and the test stays quick.

Only texels whose whole 3×3 neighbourhood Cycles baked are compared: a texel on an island's
edge is partly off the surface, where our value is the mean over the covered part and
Cycles' is whatever its samples inside the surface saw.
"""

import bpy
import numpy as np

import cycles_ref as cr
import room
from conftest import Reports
from penumbra.blender.operators import bake_blocking

RES = 64
SAMPLES = 256
TOL = 0.03


def _build():
    return cr.cycles_setup.lambertian_room(SAMPLES, seed=1)


def _cycles_image(floor, seed):
    """Cycles' Diffuse bake of ``floor`` into a new float image on the "Lightmap" UVs;
    texels it does not bake keep −1."""
    scene = bpy.context.scene
    scene.cycles.seed = seed
    image = bpy.data.images.new("Cycles %d" % seed, RES, RES, alpha=False, float_buffer=True)
    image.pixels.foreach_set(np.full(RES * RES * 4, -1.0, dtype=np.float32))
    mat = floor.material_slots[0].material.copy()
    floor.material_slots[0].material = mat
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node
    room.select_only(bpy.context.view_layer, [floor])
    res = bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT", "INDIRECT", "COLOR"},
                              target="IMAGE_TEXTURES", uv_layer="Lightmap", margin=0, use_clear=False)
    assert res == {"FINISHED"}
    px = np.empty(RES * RES * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(RES, RES, 4)[:, :, :3].astype(np.float64)


def test_floor_lightmap_matches_cycles_bake_to_image():
    scene, meshes, light = _build()
    room.select_only(bpy.context.view_layer, meshes + [light])
    s = scene.penumbra
    s.quality = "MEDIUM"
    s.output = "LIGHTMAP"
    s.lightmap_resolution = RES
    s.lightmap_margin = 0
    reports = Reports()
    assert bake_blocking(bpy.context, reports) == {"FINISHED"}, reports.items
    image = bpy.data.images["Floor_radiosity"]
    ours = np.empty(RES * RES * 4, dtype=np.float32)
    image.pixels.foreach_get(ours)
    ours = ours.reshape(RES, RES, 4)[:, :, :3].astype(np.float64)

    floor = bpy.data.objects["Floor"]
    a, b = _cycles_image(floor, 1), _cycles_image(floor, 2)
    baked = (a[:, :, 0] >= 0.0) & (b[:, :, 0] >= 0.0)
    keep = baked.copy()
    for dj in (-1, 0, 1):
        for di in (-1, 0, 1):
            keep[1:-1, 1:-1] &= baked[1 + dj : RES - 1 + dj, 1 + di : RES - 1 + di]
    keep[0, :] = keep[-1, :] = keep[:, 0] = keep[:, -1] = False
    assert keep.sum() > 0.5 * RES * RES, "the floor should fill most of its lightmap"

    ref = 0.5 * (a + b)
    e = ours[keep] - ref[keep]
    sq_noise = float(np.sum((a[keep] - b[keep]) ** 2)) / 4.0
    mean_ref = float(ref[keep].mean())
    rms = np.sqrt(max(float(np.sum(e * e)) - sq_noise, 0.0) / e.size) / mean_ref
    noise = np.sqrt(sq_noise / e.size) / mean_ref
    print(f"\n[lightmap-cycles] {keep.sum()} texels, ours {ours[keep].mean():.4f}  Cycles {mean_ref:.4f}"
          f"  relative RMS {rms:.4f} (Cycles noise {noise:.4f} taken out)")
    assert noise < 0.15, "the reference is too noisy for the noise estimate to be tight"
    assert rms <= TOL
