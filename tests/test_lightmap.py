"""Lightmaps in Blender (bpy module): images on the "Lightmap" UV map, the preview, and bad
input that changes nothing."""

import json
import os

import bpy
import numpy as np
import pytest
from conftest import Reports, snapshot

from penumbra import _core
from penumbra.blender.import_ import COLLECTION
from penumbra.blender.lightmap_preview import PREFIX
from penumbra.blender.operators import bake_blocking

RES = 32


@pytest.fixture(autouse=True, scope="module")
def _factory_scene_afterwards():
    """Later test modules start from the factory scene, not from these settings."""
    yield
    bpy.ops.wm.read_factory_settings(use_empty=True)


def _lightmap_settings(scene, output="LIGHTMAP", res=RES):
    s = scene.penumbra
    s.output = output
    s.lightmap_resolution = res
    s.lightmap_margin = 4
    s.use_indirect = False


def _pixels(image):
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[:, :, :3]


def _uv(obj):
    layer = obj.data.uv_layers["Lightmap"]
    uv = np.empty(2 * len(obj.data.loops), dtype=np.float32)
    layer.uv.foreach_get("vector", uv)
    return uv.reshape(-1, 2)


def full_snapshot():
    """``snapshot`` plus the images and every mesh's UV maps."""
    s = snapshot()
    s["images"] = sorted(i.name for i in bpy.data.images)
    s["uv_maps"] = {m.name: [u.name for u in m.uv_layers] for m in bpy.data.meshes}
    return s


def test_lightmap_output_makes_images_and_no_objects(room_scene, empty):
    meshes, _ = room_scene
    _lightmap_settings(empty.scene)
    reports = Reports()
    assert bake_blocking(empty, reports) == {"FINISHED"}, reports.items
    assert COLLECTION not in bpy.data.collections or not bpy.data.collections[COLLECTION].objects
    assert not [o for o in bpy.data.objects if o.name.endswith("_baked")]
    outputs = json.loads(empty.scene.penumbra.last_outputs)
    assert outputs["objects"] == []
    assert sorted(outputs["images"]) == sorted(m.name + "_radiosity" for m in meshes)
    for m in meshes:
        image = bpy.data.images[m.name + "_radiosity"]
        assert tuple(image.size) == (RES, RES) and image.is_float
        assert image.packed_file is not None
        assert "Lightmap" in m.data.uv_layers
        # The UV map made for the lightmap is not made the active one.
        assert m.data.uv_layers.active.name != "Lightmap" or len(m.data.uv_layers) == 1
        px = _pixels(image)
        # Direct light only: the ceiling, behind the light, is black.
        assert np.isfinite(px).all() and (px.max() > 0.0) == (m.name != "Ceiling"), m.name
    uv = _uv(bpy.data.objects["Floor"])
    assert uv.min() >= 0.0 and uv.max() <= 1.0
    assert "lightmap" in empty.scene.penumbra.last_summary


def test_an_existing_lightmap_uv_map_is_used_as_it_is(room_scene, empty):
    floor = bpy.data.objects["Floor"]
    layer = floor.data.uv_layers.new(name="Lightmap")
    # Only the middle of the image: the rest stays dark beyond the margin.
    uv = np.array([[0.25, 0.25], [0.75, 0.25], [0.75, 0.75], [0.25, 0.75]], dtype=np.float32)
    layer.uv.foreach_set("vector", uv.ravel())
    _lightmap_settings(empty.scene)
    assert bake_blocking(empty, Reports()) == {"FINISHED"}
    assert np.array_equal(_uv(floor), uv)
    px = _pixels(bpy.data.images["Floor_radiosity"])
    assert px[RES // 4 : 3 * RES // 4, RES // 4 : 3 * RES // 4].max() > 0.0
    assert px[0, 0].max() == 0.0 and px[RES - 1, RES - 1].max() == 0.0


def test_both_with_preview_leaves_the_users_materials_alone(room_scene, empty):
    _lightmap_settings(empty.scene, output="BOTH")
    empty.scene.penumbra.lightmap_preview = True
    mat = bpy.data.materials["Room White"]
    links_before = {(l.from_node.name, l.to_node.name) for l in mat.node_tree.links}
    nodes_before = sorted(n.name for n in mat.node_tree.nodes)
    assert bake_blocking(empty, Reports()) == {"FINISHED"}
    assert bpy.data.objects.get("Floor_baked") is not None
    floor = bpy.data.objects["Floor"]
    shown = floor.material_slots[0].material
    assert shown != mat and floor.material_slots[0].link == "OBJECT"
    assert floor.data.materials[0] == mat
    names = [n.name for n in shown.node_tree.nodes if n.name.startswith(PREFIX)]
    assert len(names) == 2  # UV map + image; emission shows the lightmap without Lighting Only
    assert sorted(n.name for n in mat.node_tree.nodes) == nodes_before
    assert {(l.from_node.name, l.to_node.name) for l in mat.node_tree.links} == links_before
    # Previewing again replaces, never stacks.
    empty.scene.penumbra.lighting_only = True
    assert bake_blocking(empty, Reports()) == {"FINISHED"}
    shown = floor.material_slots[0].material
    names = [n.name for n in shown.node_tree.nodes if n.name.startswith(PREFIX)]
    assert len(names) == 3  # UV map, image, multiply
    assert not [m for m in bpy.data.materials if m.name.startswith("Room White (") and m.users == 0]


def test_images_are_saved_beside_a_saved_blend(room_scene, empty, tmp_path):
    path = str(tmp_path / "room.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    _lightmap_settings(bpy.context.scene)
    assert bake_blocking(bpy.context, Reports()) == {"FINISHED"}
    exr = tmp_path / "lightmaps" / "Floor_radiosity.exr"
    assert exr.is_file() and exr.stat().st_size > 0


def _overlapping(obj):
    layer = obj.data.uv_layers.new(name="Lightmap")
    uv = np.tile(np.array([[0.1, 0.1], [0.4, 0.1], [0.4, 0.4], [0.1, 0.4]], dtype=np.float32),
                 (len(obj.data.loops) // 4, 1))
    layer.uv.foreach_set("vector", uv.ravel())


def _zero_area(obj):
    layer = obj.data.uv_layers.new(name="Lightmap")
    layer.uv.foreach_set("vector", np.full(2 * len(obj.data.loops), 0.5, dtype=np.float32))


@pytest.mark.parametrize(
    "case, expect",
    [
        ("resolution 0", "lightmap_resolution"),
        ("resolution 1e6", "lightmap_resolution"),
        ("overlapping", "overlap"),
        ("zero area", "no area"),
    ],
)
def test_bad_lightmap_input_is_one_report_and_changes_nothing(room_scene, empty, case, expect):
    _lightmap_settings(empty.scene)
    table = bpy.data.objects["Table"]
    if case == "resolution 0":
        empty.scene.penumbra.lightmap_resolution = 0
    elif case == "resolution 1e6":
        empty.scene.penumbra.lightmap_resolution = 1_000_000
    elif case == "overlapping":
        _overlapping(table)
    else:
        _zero_area(table)
    before = full_snapshot()
    reports = Reports()
    assert bake_blocking(empty, reports) == {"CANCELLED"}
    (error,) = reports.errors()
    assert expect in error and "\n" not in error, error
    if case in ("overlapping", "zero area"):
        assert "Table" in error
    assert full_snapshot() == before


def test_core_lightmap_binding_matches_a_hand_made_field():
    # A unit quad, baked mesh = the quad itself with colour = x: texel means are exact.
    source = {
        "name": "Quad",
        "positions": np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64),
        "polygon_vertices": np.array([0, 1, 2, 3]),
        "polygon_counts": np.array([4]),
        "uv": np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64),
    }
    baked = {
        "positions": source["positions"],
        "triangles": np.array([[0, 1, 2], [0, 2, 3]]),
        "colors": np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0]], dtype=np.float32),
        "source_polygon": np.array([0, 0], dtype=np.uint32),
    }
    rgb, cov = _core.lightmap(source, baked, 4, 0)
    assert rgb.shape == (4, 4, 3) and rgb.dtype == np.float32 and cov.shape == (4, 4)
    np.testing.assert_allclose(rgb[:, :, 0], np.tile((np.arange(4) + 0.5) / 4, (4, 1)), atol=1e-6)
    assert np.all(cov == 1.0)
    with pytest.raises(_core.BakeError, match="lightmap_resolution"):
        _core.lightmap(source, baked, 0, 0)
    source["uv"] = source["uv"][:3]
    with pytest.raises(_core.BakeError, match='mesh "Quad": uv'):
        _core.check_lightmap_uv(source, 16, 4)


def test_escape_during_a_lightmap_bake_takes_the_new_uv_maps_back(room_scene, empty, monkeypatch):
    from test_addon import _Context, _Event, _modal_op

    import penumbra.blender.operators as ops

    _lightmap_settings(empty.scene)
    empty.scene.penumbra.quality = "HIGH"
    before = full_snapshot()
    op, ctx = _modal_op(), _Context()
    monkeypatch.setattr(ops, "has_ui", lambda context: True)
    assert op.invoke(ctx, _Event("NONE")) == {"RUNNING_MODAL"}
    # The UV maps exist while the bake runs (the export read them) ...
    assert "Lightmap" in bpy.data.objects["Floor"].data.uv_layers
    assert op.modal(ctx, _Event("ESC", "PRESS")) == {"CANCELLED"}
    # ... and are gone once it is cancelled.
    assert full_snapshot() == before


@pytest.mark.parametrize("mirrored", [False, True])
def test_exported_uvs_follow_the_exported_corners(empty, mirrored):
    # Each exported UV must belong to the corner it stands beside in polygon_vertices, also
    # when a mirroring transform reverses every polygon's corners.
    from test_addon import _area_light, _cube

    from penumbra.blender.export import export_scene

    cube = _cube(location=(0, 0, 3))
    if mirrored:
        cube.scale = (-1.0, 1.0, 1.0)
    _area_light(z=6.0)
    me = cube.data
    layer = me.uv_layers.new(name="Lightmap")
    loop_vert = np.empty(len(me.loops), dtype=np.int64)
    me.loops.foreach_get("vertex_index", loop_vert)
    co = np.empty(3 * len(me.vertices))
    me.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    # UV = a function of the corner's vertex (not a valid unwrap; only the pairing matters).
    uv_of_vertex = 0.5 + 0.2 * co[:, :2] + 0.05 * co[:, 2:3]
    layer.uv.foreach_set("vector", uv_of_vertex[loop_vert].astype(np.float32).ravel())
    cube.select_set(True)
    empty.scene.penumbra.output = "LIGHTMAP"
    ex = export_scene(empty, empty.scene.penumbra)
    (m,) = ex.scene["meshes"]
    np.testing.assert_allclose(m["uv"], uv_of_vertex[m["polygon_vertices"]], atol=1e-6)
