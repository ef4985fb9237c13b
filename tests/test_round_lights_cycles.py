"""Soft shadows of round lights, baked by the add-on and by Cycles (issue 14).

A floor grid under a block, lit by one light with a size: a point light of radius 0.2 (soft
falloff, Blender's default: a disc facing each point; and a sphere), a spot of radius 0.15
whose cone edge crosses the floor, and a sun of angle 5°.
Cycles shadows them with a penumbra; Penumbra clips the disc facing each point against the
block and meshes the penumbra. Compared with the direct pass (indirect light off) at the
floor grid's interior vertices (vertices of Penumbra's output too), Cycles' noise from two
seeds taken out; the grid is fine enough that some probes lie inside the penumbra (Cycles
between 10 % and 90 % of the unshadowed light there), and those are scored on their own too.
"""

import math

import bpy
import numpy as np
import pytest

import cycles_ref as cr
from penumbra.io.lights import lights_to_scene

SAMPLES = 1024
GRID = 41
SIDE = 3.0
TOL = 0.03
BLOCK = ((-0.37, -0.29, 0.0), (0.21, 0.33, 0.7))


def _floor():
    return cr.add_grid(GRID, SIDE, material=cr.diffuse_material("FloorMat", (0.6, 0.6, 0.6)),
                       name="Floor")


LIGHTS = {
    "point_r0.2": ("POINT", dict(location=(0.3, -0.2, 1.6)), dict(energy=60.0, shadow_soft_size=0.2)),
    "sphere_r0.2": ("POINT", dict(location=(0.3, -0.2, 1.6)),
                    dict(energy=60.0, shadow_soft_size=0.2, use_soft_falloff=False)),
    # A spot of radius 0.15: Cycles applies the cone mask per point of the disc, so the disc
    # blurs the cone's edge (which crosses the floor inside the grid).
    "spot_r0.15": ("SPOT", dict(location=(0.3, -0.2, 1.6)),
                   dict(energy=60.0, shadow_soft_size=0.15, spot_size=math.radians(70.0), spot_blend=0.1)),
    "sun_5deg": ("SUN", dict(rotation=(0.55, -0.35, 0.0)), dict(energy=3.0, angle=math.radians(5.0))),
}


def _build(case, seed):
    cr.new_bounce_scene(SAMPLES, seed)
    floor = _floor()
    cr.add_block(*BLOCK, (0.5, 0.5, 0.5), material="BlockMat")
    kind, obj_kw, props = LIGHTS[case]
    light = cr.add_light(kind, **obj_kw, **props)
    bpy.context.view_layer.update()
    return floor, light


@pytest.mark.parametrize("case", sorted(LIGHTS))
def test_round_light_penumbra_like_cycles(case):
    refs = []
    for seed in (1, 2):
        floor, light = _build(case, seed)
        refs.append(cr.bake_vertex_colors(floor, pass_filter={"DIRECT", "COLOR"}))
    (pos, a), (_, b) = refs
    exported = lights_to_scene(light, bpy.context.evaluated_depsgraph_get())
    assert ("angle" in exported[0]) == (case == "sun_5deg")
    assert ("radius" in exported[0]) == (case != "sun_5deg")
    for o in bpy.context.scene.objects:
        o.select_set(True)
    bpy.context.scene.penumbra.use_indirect = False
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    m = 1e-6
    inner = (np.abs(pos[:, 0]) < SIDE / 2 - m) & (np.abs(pos[:, 1]) < SIDE / 2 - m)
    (x0, y0, _), (x1, y1, _) = BLOCK
    near_block = (pos[:, 0] > x0 - 0.03) & (pos[:, 0] < x1 + 0.03) & (pos[:, 1] > y0 - 0.03) & (pos[:, 1] < y1 + 0.03)
    keep = inner & ~near_block
    ours = cr.baked_colors_at("Floor", pos[keep])
    rms, noise = cr.noise_free_rel_rms(ours, a[keep], b[keep])
    ref = 0.5 * (a[keep] + b[keep])
    # The penumbra: Cycles between 10 % and 90 % of the light with no block.
    open_floor = cr.outgoing_radiance(pos[keep], (0.0, 0.0, 1.0), exported, albedo=0.6)
    frac = ref[:, 0] / np.maximum(open_floor[:, 0], 1e-12)
    pen = (frac > 0.1) & (frac < 0.9)
    rms_pen, _ = cr.noise_free_rel_rms(ours[pen], a[keep][pen], b[keep][pen])
    print(f"\n[round-lights] {case}: ours {ours.mean():.4f} Cycles {ref.mean():.4f} rel RMS {rms:.4f} "
          f"noise {noise:.4f}; {pen.sum()} penumbra probes, rel RMS there {rms_pen:.4f}")
    assert pen.sum() >= 10, "the grid must probe the penumbra"
    assert rms <= TOL
    assert rms_pen <= 2 * TOL
