"""The lightmap preview on originals that share a material: each object shows its own
lightmap through object-linked copies, the shared material itself never changes, and turning
the preview off gives every slot back as it was."""

import bpy
import numpy as np
import pytest
from conftest import Reports

from penumbra.blender.lightmap_preview import PREFIX
from penumbra.blender.operators import bake_blocking


@pytest.fixture(autouse=True, scope="module")
def _factory_scene_afterwards():
    yield
    bpy.ops.wm.read_factory_settings(use_empty=True)


def _principled(name):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    return mat


def _quad(name, x0, mat):
    me = bpy.data.meshes.new(name)
    me.from_pydata([(x0, 0, 0), (x0 + 1, 0, 0), (x0 + 1, 1, 0), (x0, 1, 0)], [], [[0, 1, 2, 3]])
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


@pytest.fixture
def two_quads_one_material(empty):
    """Two floor tiles side by side sharing the material "Shared"; a third object, "Own",
    links its material at object level already. A small area light above the left tile, so
    the two lightmaps differ."""
    shared = _principled("Shared")
    left, right = _quad("Left", 0.0, shared), _quad("Right", 1.5, shared)
    own = _quad("Own", 3.0, _principled("Data"))
    own.material_slots[0].link = "OBJECT"
    own.material_slots[0].material = _principled("Object level")
    light = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "AREA"))
    light.data.energy = 50.0
    light.data.size = 0.5
    light.location = (0.5, 0.5, 1.0)
    empty.scene.collection.objects.link(light)
    for o in empty.scene.objects:
        o.select_set(True)
    empty.view_layer.objects.active = left
    s = empty.scene.penumbra
    s.quality = "DRAFT"
    s.output = "LIGHTMAP"
    s.lightmap_resolution = 16
    s.lightmap_margin = 2
    s.use_indirect = False
    return left, right, own, shared


def _image_shown(obj):
    mat = obj.material_slots[0].material
    nodes = [n for n in mat.node_tree.nodes if n.name == PREFIX + " Image"]
    assert len(nodes) == 1, obj.name
    return mat, nodes[0].image


def test_objects_sharing_a_material_each_show_their_own_lightmap(two_quads_one_material, empty):
    left, right, own, shared = two_quads_one_material
    shared_nodes = sorted(n.name for n in shared.node_tree.nodes)
    empty.scene.penumbra.lightmap_preview = True
    assert bake_blocking(empty, Reports()) == {"FINISHED"}

    (ml, il), (mr, ir) = _image_shown(left), _image_shown(right)
    assert il.name == "Left_radiosity" and ir.name == "Right_radiosity"
    assert ml != mr and shared not in (ml, mr)
    # The two images really differ: the light is over the left tile.
    px = [np.empty(16 * 16 * 4, dtype=np.float32) for _ in range(2)]
    il.pixels.foreach_get(px[0])
    ir.pixels.foreach_get(px[1])
    assert px[0].max() > 2 * px[1].max() > 0.0
    # The user's shared material and the meshes' own slots are untouched.
    assert sorted(n.name for n in shared.node_tree.nodes) == shared_nodes
    assert left.data.materials[0] == shared and right.data.materials[0] == shared
    assert [s.link for s in (left.material_slots[0], right.material_slots[0])] == ["OBJECT"] * 2
    mo, io = _image_shown(own)
    assert io.name == "Own_radiosity" and mo.name.startswith("Object level (")

    # Off: every slot as it was, the copies gone.
    copies = {ml.name, mr.name, mo.name}
    empty.scene.penumbra.lightmap_preview = False
    assert left.material_slots[0].link == "DATA" and left.material_slots[0].material == shared
    assert right.material_slots[0].link == "DATA" and right.material_slots[0].material == shared
    assert own.material_slots[0].link == "OBJECT"
    assert own.material_slots[0].material == bpy.data.materials["Object level"]
    assert not copies & {m.name for m in bpy.data.materials}

    # On again: the existing lightmaps are shown without a new bake.
    empty.scene.penumbra.lightmap_preview = True
    assert _image_shown(left)[1].name == "Left_radiosity"
    assert _image_shown(right)[1].name == "Right_radiosity"
