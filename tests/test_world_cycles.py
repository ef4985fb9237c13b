"""A grey world over a floor with a block, no lamps, baked by the add-on and by Cycles
(issue 14). Cycles lights a bake with the world; the add-on exports the world's Background
colour × strength as ``settings.world`` and the core adds the world light at every vertex
(ambient occlusion times the world's radiance), then bounces it. Compared at the floor
grid's interior vertices, with indirect light off (direct pass) and on, Cycles' noise from
two seeds taken out.
"""

import bpy
import pytest

import cycles_ref as cr
from test_emitters_cycles import _block, _floor, compare_floor

SAMPLES = 1024
TOL = 0.03


def _build(seed):
    scene = cr.new_bounce_scene(SAMPLES, seed)
    world = bpy.data.worlds.new("Grey")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    bg = next(n for n in world.node_tree.nodes if n.bl_idname == "ShaderNodeBackground")
    bg.inputs["Color"].default_value = (0.5, 0.45, 0.4, 1.0)
    bg.inputs["Strength"].default_value = 2.0
    scene.world = world
    floor, block = _floor(), _block()
    bpy.context.view_layer.update()
    return floor, block


@pytest.mark.parametrize("indirect", [False, True])
def test_grey_world_lights_the_floor_like_cycles(indirect):
    rms, ref = compare_floor(_build, indirect, "world")
    # An open floor under this world is albedo 0.6 × (0.5, 0.45, 0.4) × 2 where nothing hides it.
    assert ref.max() <= 0.6 * 1.0 * 1.02
    assert rms <= TOL
