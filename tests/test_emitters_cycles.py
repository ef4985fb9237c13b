"""An emissive panel as the only light, baked by the add-on and by Cycles (issue 14).

A floor grid under a small block, lit by nothing but a quad with an Emission material a
little above them. Cycles treats the quad as a light (both sides emit); Penumbra turns the
emissive face into two area lights (front and back), so the block's shadow on the floor has
a penumbra meshed like an area light's and the floor is lit with indirect light turned off,
where it was black before. Compared at the floor grid's interior vertices (which are vertices
of Penumbra's output too), Cycles' noise from two seeds taken out, with indirect light off
(Cycles: Diffuse bake of the direct pass) and on (direct + indirect).
"""

import bpy
import numpy as np
import pytest

import cycles_ref as cr

SAMPLES = 1024
GRID = 13
SIDE = 3.0
TOL = 0.03


def _floor():
    return cr.add_grid(GRID, SIDE, material=cr.diffuse_material("FloorMat", (0.6, 0.6, 0.6)),
                       name="Floor")


def _block():
    return cr.add_block((-0.37, -0.29, 0.0), (0.21, 0.33, 0.45), (0.5, 0.5, 0.5), material="BlockMat")


def _panel():
    """A 0.6 × 0.4 quad at height 1.2, tilted a little, with an Emission material."""
    import math

    me = bpy.data.meshes.new("Panel")
    me.from_pydata([(-0.3, -0.2, 0.0), (0.3, -0.2, 0.0), (0.3, 0.2, 0.0), (-0.3, 0.2, 0.0)],
                   [], [(0, 1, 2, 3)])
    me.update()
    # Albedo 0 plus an Emission of radiance (1, 0.9, 0.8) · 12.
    mat = cr.cycles_setup.lambert_material("Glow", (0.0, 0.0, 0.0), (12.0, 10.8, 9.6))
    me.materials.append(mat)
    ob = bpy.data.objects.new("Panel", me)
    ob.location = (0.35, 0.1, 1.2)
    ob.rotation_euler = (math.radians(12.0), 0.0, 0.0)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def _build(seed):
    cr.new_bounce_scene(SAMPLES, seed)
    objs = (_floor(), _block(), _panel())
    bpy.context.view_layer.update()
    return objs


def _ours_at(pos):
    return cr.baked_colors_at("Floor", pos)


def compare_floor(build, indirect, tag):
    """Cycles' floor (two seeds) against Penumbra's bake of the same scene, everything
    selected, at the floor grid's vertices off its border and clear of the block; returns
    the noise-free relative RMS and the reference's mean."""
    refs = []
    passes = {"DIRECT", "INDIRECT", "COLOR"} if indirect else {"DIRECT", "COLOR"}
    for seed in (1, 2):
        floor = build(seed)[0]
        refs.append(cr.bake_vertex_colors(floor, pass_filter=passes))
    (pos, a), (_, b) = refs
    for o in bpy.context.scene.objects:
        o.select_set(True)
    bpy.context.scene.penumbra.use_indirect = indirect
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    m = 1e-6
    inner = (np.abs(pos[:, 0]) < SIDE / 2 - m) & (np.abs(pos[:, 1]) < SIDE / 2 - m)
    near_block = (pos[:, 0] > -0.40) & (pos[:, 0] < 0.24) & (pos[:, 1] > -0.32) & (pos[:, 1] < 0.36)
    keep = inner & ~near_block
    ours = _ours_at(pos[keep])
    rms, noise = cr.noise_free_rel_rms(ours, a[keep], b[keep])
    ref = 0.5 * (a[keep] + b[keep])
    print(f"\n[{tag}] indirect={indirect} ours {ours.mean():.4f} Cycles {ref.mean():.4f} "
          f"rel RMS {rms:.4f} noise {noise:.4f}")
    return rms, ref


@pytest.mark.parametrize("indirect", [False, True])
def test_emissive_panel_lights_the_floor_like_cycles(indirect):
    rms, ref = compare_floor(_build, indirect, "emitters")
    assert ref.mean() > 0.01, "the panel must light the floor in Cycles"
    assert rms <= TOL
