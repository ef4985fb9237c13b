"""Selection decides what is baked, not what exists (issue 14): only the floor is selected,
yet the unselected block shadows it and the unselected wall beside it bounces light onto
it, as in Cycles. The block and the wall get no baked objects. Compared at the floor grid's
interior vertices against Cycles (direct + indirect), its noise from two seeds taken out;
with the scope "Visible" all three are baked and the floor is the same.
"""

import bpy
import numpy as np
import pytest

import cycles_ref as cr
from test_emitters_cycles import SIDE, _block, _floor, _ours_at

SAMPLES = 1024
TOL = 0.03


def _wall():
    """A 3 × 1.5 wall at y = 1.2 facing −y, bright red, beside the floor's far edge."""
    me = bpy.data.meshes.new("Wall")
    me.from_pydata([(-1.5, 1.2, 0.0), (1.5, 1.2, 0.0), (1.5, 1.2, 1.5), (-1.5, 1.2, 1.5)], [],
                   [(0, 1, 2, 3)])
    me.update()
    me.materials.append(cr.diffuse_material("WallMat", (0.9, 0.2, 0.1)))
    ob = bpy.data.objects.new("Wall", me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def _build(seed):
    cr.new_bounce_scene(SAMPLES, seed)
    floor, block, wall = _floor(), _block(), _wall()
    cr.add_light("AREA", location=(-0.2, -0.3, 1.6), name="Lamp", energy=80.0, size=0.4)
    bpy.context.view_layer.update()
    return floor, block, wall


@pytest.mark.parametrize("scope", ["SELECTED", "VISIBLE"])
def test_unselected_block_and_wall_shade_and_light_the_selected_floor(scope):
    refs = []
    for seed in (1, 2):
        floor, _, _ = _build(seed)
        refs.append(cr.bake_vertex_colors(floor))
    (pos, a), (_, b) = refs
    for o in bpy.context.scene.objects:
        o.select_set(o.name == "Floor")
    bpy.context.view_layer.objects.active = bpy.data.objects["Floor"]
    bpy.context.scene.penumbra.scope = scope
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    baked = {"Block_baked", "Wall_baked"} & set(bpy.data.objects.keys())
    assert baked == (set() if scope == "SELECTED" else {"Block_baked", "Wall_baked"})

    m = 1e-6
    inner = (np.abs(pos[:, 0]) < SIDE / 2 - m) & (np.abs(pos[:, 1]) < SIDE / 2 - m)
    under = (pos[:, 0] > -0.40) & (pos[:, 0] < 0.24) & (pos[:, 1] > -0.32) & (pos[:, 1] < 0.36)
    beyond = pos[:, 1] > 1.2 - 0.05  # behind or at the wall's foot
    keep = inner & ~under & ~beyond
    ref = 0.5 * (a[keep] + b[keep])
    ours = _ours_at(pos[keep])
    rms, noise = cr.noise_free_rel_rms(ours, a[keep], b[keep])
    print(f"\n[scope] ours {ours.mean():.4f} Cycles {ref.mean():.4f} rel RMS {rms:.4f} noise {noise:.4f}")
    assert rms <= TOL


def test_shadow_only_objects_take_part_without_output():
    _build(1)
    bpy.data.objects["Block"].penumbra_shadow_only = True
    for o in bpy.context.scene.objects:
        o.select_set(False)
    bpy.context.scene.penumbra.scope = "VISIBLE"
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    baked = {o.name for o in bpy.data.objects if o.name.endswith("_baked")}
    assert baked == {"Floor_baked", "Wall_baked"}
    # The block still shades the floor: its baked floor has vertices darker than the rim.
    col = bpy.data.objects["Floor_baked"].data.color_attributes[0].data
    c = np.empty(len(col) * 4, dtype=np.float32)
    col.foreach_get("color", c)
    c = c.reshape(-1, 4)[:, 0]
    assert c.min() < 0.3 * c.max()


def test_only_shadow_only_objects_selected_is_a_clear_error():
    _build(1)
    block = bpy.data.objects["Block"]
    block.penumbra_shadow_only = True
    for o in bpy.context.scene.objects:
        o.select_set(o is block)
    bpy.context.scene.penumbra.scope = "SELECTED"
    n = len(bpy.data.objects)
    with pytest.raises(RuntimeError, match="Shadow Only"):
        bpy.ops.penumbra.bake()
    assert len(bpy.data.objects) == n


def test_a_collection_instance_shades_like_the_object_itself():
    """Instances were skipped without a word; now they take part as scenery."""

    def floor_colours():
        col = bpy.data.objects["Floor_baked"].data.color_attributes[0].data
        c = np.empty(len(col) * 4, dtype=np.float32)
        col.foreach_get("color", c)
        return c.reshape(-1, 4)[:, :3]

    def bake_floor():
        for o in bpy.context.scene.objects:
            o.select_set(o.name == "Floor")
        assert bpy.ops.penumbra.bake() == {"FINISHED"}
        c = floor_colours()
        bpy.data.objects.remove(bpy.data.objects["Floor_baked"])
        return c

    _build(1)
    bpy.data.objects.remove(bpy.data.objects["Wall"])
    settings = bpy.context.scene.penumbra
    settings.scope, settings.use_indirect = "SELECTED", True
    direct = bake_floor()
    # The block moved into a collection outside the scene, shown by an instancing empty at
    # the same place.
    block = bpy.data.objects["Block"]
    coll = bpy.data.collections.new("Props")
    bpy.context.scene.collection.objects.unlink(block)
    coll.objects.link(block)
    empty = bpy.data.objects.new("PropsInstance", None)
    empty.instance_type = "COLLECTION"
    empty.instance_collection = coll
    bpy.context.scene.collection.objects.link(empty)
    bpy.context.view_layer.update()
    instanced = bake_floor()
    assert instanced.shape == direct.shape
    assert np.allclose(instanced, direct, rtol=1e-5, atol=1e-7)
