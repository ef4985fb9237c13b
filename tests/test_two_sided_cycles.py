"""A single plane lit from its back, baked by the add-on and by Cycles (issue 14).

A floor grid under a ceiling that is one plane facing up, and between them an area light
facing up: it lights only the ceiling's back, never the floor. Cycles' diffuse surfaces
reflect from both sides, so all the floor's light is what the ceiling's back reflects down
(and what goes round between them). Cycles bakes a face's front only, so the ceiling's own
bake is black in both. The same scene with a closed slab in place of the plane: the light
falls on the slab's underside, a front, and its inside stays dark. And plates over the floor
lit from above: their backs get only the floor's light, and send part of it back.

Compared at the floor grid's interior vertices (vertices of Penumbra's output too), with
Cycles' noise from two seeds taken out.
"""

import math

import bpy
import numpy as np
import pytest

import cycles_ref as cr

SAMPLES = 1024
GRID = 13
SIDE = 3.0
HEIGHT = 1.2
TOL = 0.03


def _light():
    # Blender's area lights face −Z; turned over, this one faces up.
    return cr.add_light("AREA", location=(0.3, -0.2, 0.7), rotation=(math.pi, 0.0, 0.0),
                        name="Lamp", energy=150.0, size=0.6)


def _plane(seed):
    cr.new_bounce_scene(SAMPLES, seed)
    floor = cr.add_grid(GRID, SIDE, material=cr.diffuse_material("FloorMat", (0.6, 0.6, 0.6)),
                        name="Floor")
    cr.add_grid(2, SIDE, location=(0.0, 0.0, HEIGHT),
                material=cr.diffuse_material("CeilingMat", (0.8, 0.75, 0.7)), name="Ceiling")
    _light()
    bpy.context.view_layer.update()
    return floor


def _slab(seed):
    cr.new_bounce_scene(SAMPLES, seed)
    floor = cr.add_grid(GRID, SIDE, material=cr.diffuse_material("FloorMat", (0.6, 0.6, 0.6)),
                        name="Floor")
    h = SIDE / 2
    cr.add_block((-h, -h, HEIGHT), (h, h, HEIGHT + 0.2), (0.8, 0.75, 0.7), name="Ceiling",
                 material="CeilingMat")
    _light()
    bpy.context.view_layer.update()
    return floor


def _plates(seed):
    """Nine single plates facing up at different heights over the floor, lit from above:
    their backs get no direct light, only what the floor reflects, and send it back down."""
    cr.new_bounce_scene(SAMPLES, seed)
    floor = cr.add_grid(GRID, SIDE, material=cr.diffuse_material("FloorMat", (0.6, 0.6, 0.6)),
                        name="Floor")
    mat = cr.diffuse_material("PlateMat", (0.8, 0.75, 0.7))
    for k in range(9):
        x, y = -0.8 + 0.8 * (k % 3), -0.8 + 0.8 * (k // 3)
        cr.add_grid(2, 0.5, location=(x, y, 0.5 + 0.1 * ((k * 5) % 4)), material=mat,
                    name=f"Plate{k}")
    cr.add_light("AREA", location=(0.2, 0.1, 2.5), name="Lamp", energy=300.0, size=1.0)
    bpy.context.view_layer.update()
    return floor


@pytest.mark.parametrize("build", [_plane, _slab, _plates], ids=["plane", "slab", "plates"])
def test_light_behind_a_thin_ceiling_reaches_the_floor_like_cycles(build):
    refs = [cr.bake_vertex_colors(build(seed)) for seed in (1, 2)]
    (pos, a), (_, b) = refs
    for o in bpy.context.scene.objects:
        o.select_set(True)
    bpy.context.scene.penumbra.use_indirect = True
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    m = 1e-6
    inner = (np.abs(pos[:, 0]) < SIDE / 2 - m) & (np.abs(pos[:, 1]) < SIDE / 2 - m)
    ours = cr.baked_colors_at("Floor", pos[inner])
    rms, noise = cr.noise_free_rel_rms(ours, a[inner], b[inner])
    ref = 0.5 * (a[inner] + b[inner])
    print(f"\n[two-sided {build.__name__}] ours {ours.mean():.4f} Cycles {ref.mean():.4f} "
          f"rel RMS {rms:.4f} noise {noise:.4f}")
    assert ref.mean() > 0.05, "the ceiling must light the floor in Cycles"
    assert rms <= TOL
    # The ceiling's outside is lit by nothing: black in its own bake, as in Cycles'.
    if build is _plane:
        h = SIDE / 2
        corners = np.array([[x, y, HEIGHT] for x in (-h, h) for y in (-h, h)])
        top = cr.baked_colors_at("Ceiling", corners)
        assert np.all(top == 0.0)
