"""The add-on inside Blender (bpy module): export, import, the operator, bad input."""

import math
import time

import bpy
import numpy as np
import pytest
from conftest import Reports, snapshot

import room
from penumbra import BakeError, _core
from penumbra.blender.export import ExportError, export_scene
from penumbra.blender.import_ import ATTRIBUTE, COLLECTION, MATERIAL, import_bake
from penumbra.blender.operators import bake_blocking

ROOM_MESHES = ["Floor", "Ceiling", "Wall Left", "Wall Right", "Wall Back", "Wall Front", "Table", "Chair"]


def _cube(name="Cube", location=(0, 0, 0)):
    mesh = bpy.data.meshes.new(name)
    v, f = room._box_parts((-1, -1, -1), (1, 1, 1))
    mesh.from_pydata(v, [], f)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _area_light(name="Lamp", z=3.0, size=1.0):
    data = bpy.data.lights.new(name, "AREA")
    data.size = size
    data.energy = 100.0
    obj = bpy.data.objects.new(name, data)
    obj.location = (0, 0, z)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _normals(m):
    """World-space normals of the exported polygons (Newell's method)."""
    p = m["positions"]
    out, at = [], 0
    for c in m["polygon_counts"]:
        idx = m["polygon_vertices"][at : at + c]
        q = p[idx]
        out.append(np.cross(q, np.roll(q, -1, axis=0)).sum(axis=0))
        at += c
    out = np.array(out)
    return out / np.linalg.norm(out, axis=1, keepdims=True)


# --- registration --------------------------------------------------------------------------


def test_operator_and_panel_are_registered():
    assert bpy.ops.penumbra.bake.get_rna_type().name == "Bake Radiosity"
    # One undo step takes a bake back (Blender pushes it when the operator finishes).
    assert {"REGISTER", "UNDO"} <= set(bpy.types.PENUMBRA_OT_bake.bl_options)
    panel = bpy.types.PENUMBRA_PT_radiosity
    assert panel.bl_label == "Radiosity" and panel.bl_context == "render"
    assert bpy.context.scene.penumbra.quality == "MEDIUM"


# --- export --------------------------------------------------------------------------------


def test_export_is_world_space_with_modifiers(empty):
    cube = _cube(location=(10, 0, 0))
    cube.modifiers.new("Subdivision", "SUBSURF").levels = 1
    cube.select_set(True)
    _area_light()
    ex = export_scene(empty, empty.scene.penumbra)
    (m,) = ex.scene["meshes"]
    assert m["name"] == "Cube"
    assert len(m["polygon_counts"]) == 24  # 6 quads subdivided once
    assert m["polygon_counts"].sum() == len(m["polygon_vertices"])
    assert abs(m["positions"][:, 0].mean() - 10.0) < 1e-6
    assert m["albedo"].shape == (24, 3) and m["emission"].shape == (24, 3)
    # Every face of the cube faces away from its centre.
    centres = np.array([m["positions"][m["polygon_vertices"][4 * i : 4 * i + 4]].mean(axis=0) for i in range(24)])
    assert (np.einsum("ij,ij->i", _normals(m), centres - [10, 0, 0]) > 0).all()
    # Exporting changed nothing in the file.
    assert [o.name for o in bpy.data.objects] == ["Cube", "Lamp"]


def test_a_mirrored_object_keeps_its_front(empty):
    cube = _cube()
    cube.scale = (-1.0, 1.0, 1.0)
    cube.select_set(True)
    _area_light()
    (m,) = export_scene(empty, empty.scene.penumbra).scene["meshes"]
    centres = np.array([m["positions"][m["polygon_vertices"][4 * i : 4 * i + 4]].mean(axis=0) for i in range(6)])
    assert (np.einsum("ij,ij->i", _normals(m), centres) > 0).all()


def test_lights_are_the_selected_ones_or_all_visible(empty):
    cube = _cube()
    a = _area_light("A")
    b = _area_light("B", z=4.0)
    hidden = _area_light("Hidden", z=5.0)
    hidden.hide_render = True
    cube.select_set(True)
    names = lambda: sorted(d["name"] for d in export_scene(empty, empty.scene.penumbra).scene["lights"])  # noqa: E731
    assert names() == ["A", "B"]
    b.select_set(True)
    assert names() == ["B"]
    assert a.name == "A"


def test_a_far_light_does_not_coarsen_the_preset_elements(empty):
    # The preset's sizes are fractions of the baked meshes' diagonal: a light 100 m up
    # used to count in it, and the cube's elements grew to metres.
    _cube().select_set(True)  # 2 m on a side: diagonal 2·√3
    lamp = _area_light(z=3.0)
    empty.scene.penumbra.quality = "MEDIUM"
    near = export_scene(empty, empty.scene.penumbra).scene["settings"]["element_size"]
    lamp.location = (0, 0, 100.0)
    far = export_scene(empty, empty.scene.penumbra).scene["settings"]["element_size"]
    assert near == pytest.approx(2 * math.sqrt(3) / 25, rel=1e-9)
    assert far == pytest.approx(near, rel=1e-12)


def test_exported_scene_is_valid_for_the_core(room_scene, empty):
    ex = export_scene(empty, empty.scene.penumbra)
    assert [m["name"] for m in ex.scene["meshes"]] == ROOM_MESHES
    assert [d["name"] for d in ex.scene["lights"]] == ["Ceiling Light"]
    assert isinstance(_core.validate(ex.scene), list)
    # The draft preset gives coarser elements than the medium one.
    draft = ex.scene["settings"]["element_size"]
    empty.scene.penumbra.quality = "MEDIUM"
    assert export_scene(empty, empty.scene.penumbra).scene["settings"]["element_size"] > 0 < draft
    assert export_scene(empty, empty.scene.penumbra).scene["settings"]["element_size"] < draft


def test_quality_presets_set_the_tolerance(room_scene, empty):
    # Draft 3 %, Medium 1 %, High 0.3 % relative error of the baked direct light (issue 13).
    got = {}
    for q in ("DRAFT", "MEDIUM", "HIGH"):
        empty.scene.penumbra.quality = q
        got[q] = export_scene(empty, empty.scene.penumbra).scene["settings"]["tolerance"]
    assert got == {"DRAFT": 0.03, "MEDIUM": 0.01, "HIGH": 0.003}


# --- import --------------------------------------------------------------------------------


def _fake_bake(name, n=3):
    """A bake result as the core gives it: a fan of n triangles with known colours."""
    ring = [[math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n), 0.0] for k in range(n)]
    positions = np.array([[0.0, 0.0, 0.0]] + ring)
    triangles = np.array([[0, 1 + k, 1 + (k + 1) % n] for k in range(n)], dtype=np.uint32)
    colors = np.linspace(0.1, 0.9, 3 * (n + 1), dtype=np.float32).reshape(-1, 3)
    return {
        "name": name,
        "positions": positions,
        "triangles": triangles,
        "colors": colors,
        "source_polygon": np.arange(n, dtype=np.uint32),
        "relation": np.ones((n, 1), dtype=np.uint8),
    }


def test_import_makes_objects_attribute_material_and_collection(empty):
    src = _cube("Thing")
    baked = _fake_bake("Thing", n=5)
    (obj,) = import_bake(empty, {"meshes": [baked]}, [src])
    assert obj.name == "Thing_baked"
    assert [c.name for c in obj.users_collection] == [COLLECTION]
    assert empty.scene.collection.children.get(COLLECTION) is not None
    mesh = obj.data
    assert (len(mesh.vertices), len(mesh.polygons)) == (6, 5)
    assert all(len(p.vertices) == 3 for p in mesh.polygons)
    attr = mesh.color_attributes[ATTRIBUTE]
    assert (attr.domain, attr.data_type) == ("POINT", "FLOAT_COLOR")
    assert mesh.color_attributes.active_color.name == ATTRIBUTE
    assert mesh.color_attributes[mesh.color_attributes.render_color_index].name == ATTRIBUTE
    rgba = np.empty(6 * 4, dtype=np.float32)
    attr.data.foreach_get("color", rgba)
    assert np.allclose(rgba.reshape(-1, 4)[:, :3], baked["colors"])
    tri = np.empty(15, dtype=np.int64)
    mesh.polygons.foreach_get("vertices", tri)
    assert np.array_equal(tri.reshape(-1, 3), baked["triangles"])
    # The material shows the attribute as emission, so every engine displays the bake.
    (mat,) = mesh.materials
    assert mat.name == MATERIAL
    nodes = mat.node_tree.nodes
    attr_node = next(n for n in nodes if n.type == "ATTRIBUTE")
    emission = next(n for n in nodes if n.type == "EMISSION")
    output = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    assert attr_node.attribute_name == ATTRIBUTE
    assert emission.inputs["Color"].links[0].from_node == attr_node
    assert output.inputs["Surface"].links[0].from_node == emission
    assert not src.hide_render and not src.hide_get()


def test_import_replaces_an_earlier_bake_and_hides_originals(empty):
    src = _cube("Thing")
    import_bake(empty, {"meshes": [_fake_bake("Thing")]}, [src])
    import_bake(empty, {"meshes": [_fake_bake("Thing", n=7)]}, [src], hide_originals=True)
    baked = [o for o in bpy.data.objects if o.name.startswith("Thing_baked")]
    assert [o.name for o in baked] == ["Thing_baked"]
    assert len(baked[0].data.polygons) == 7
    assert len([m for m in bpy.data.meshes if m.name.startswith("Thing_baked")]) == 1
    assert src.hide_render and src.hide_get()


# --- bad input: a report naming the culprit, and the scene untouched -------------------------


def _refused(context, must_name):
    """Runs the bake both ways (our reporter, then bpy.ops) and checks the refusal."""
    before = snapshot()
    reports = Reports()
    assert bake_blocking(context, reports) == {"CANCELLED"}
    (message,) = reports.errors()
    for word in must_name:
        assert word in message, message
    assert "\n" not in message
    with pytest.raises(RuntimeError, match=must_name[0]):
        bpy.ops.penumbra.bake()
    assert snapshot() == before
    return message


def test_nothing_selected(room_scene, empty):
    room.select_only(empty.view_layer, [])
    _refused(empty, ["Nothing selected"])


def test_no_lights(room_scene, empty):
    _, light = room_scene
    bpy.data.objects.remove(light)
    _refused(empty, ["No lights"])


def test_zero_size_light(room_scene, empty):
    _, light = room_scene
    light.data.size = 0.0
    _refused(empty, ["Ceiling Light", "size"])


def test_nan_coordinates_set_from_a_script(room_scene, empty):
    meshes, _ = room_scene
    table = meshes[ROOM_MESHES.index("Table")]
    co = np.empty(len(table.data.vertices) * 3, dtype=np.float32)
    table.data.vertices.foreach_get("co", co)
    co[4] = np.nan
    table.data.vertices.foreach_set("co", co)
    _refused(empty, ["Table", "vertex positions"])


def test_a_bad_setting_caught_by_the_core(room_scene, empty):
    s = empty.scene.penumbra
    s.use_custom_size = True
    s.element_size = s.penumbra_element_size = 1e-5  # far too many elements
    _refused(empty, ["element_size"])


def test_a_bake_over_the_memory_limit_is_refused_before_it_starts(room_scene, empty):
    s = empty.scene.penumbra
    s.use_custom_size = True
    s.element_size = s.penumbra_element_size = 0.01  # millions of elements, under max_elements
    s.max_memory_gb = 0.25
    message = _refused(empty, ["element_size", "max_memory", "256.0 MiB"])
    assert message.count("settings.") == 1, message


def test_cancel_leaves_the_scene_untouched(room_scene, empty):
    empty.scene.penumbra.quality = "HIGH"
    before = snapshot()
    ex = export_scene(empty, empty.scene.penumbra)
    job = _core.start_bake(ex.scene)
    job.cancel()
    with pytest.raises(BakeError) as info:
        job.result()
    assert info.value.kind == "cancelled"
    assert snapshot() == before


# --- real bakes (need the core pipeline) -----------------------------------------------------


def _colors(obj):
    rgba = np.empty(len(obj.data.vertices) * 4, dtype=np.float32)
    obj.data.color_attributes[ATTRIBUTE].data.foreach_get("color", rgba)
    co = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3), rgba.reshape(-1, 4)[:, :3]


def test_bake_the_room_with_default_settings(room_scene, empty):
    empty.scene.penumbra.quality = "MEDIUM"
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    coll = bpy.data.collections[COLLECTION]
    assert sorted(o.name for o in coll.objects) == sorted(n + "_baked" for n in ROOM_MESHES)
    for name in ROOM_MESHES:
        obj = bpy.data.objects[name + "_baked"]
        assert obj.data.color_attributes.active_color.name == ATTRIBUTE
        assert obj.data.materials[0].name == MATERIAL
        co, rgb = _colors(obj)
        assert np.isfinite(rgb).all() and (rgb >= 0).all()
        assert not bpy.data.objects[name].hide_render  # not asked to hide
    summary = empty.scene.penumbra.last_summary
    assert "elements" in summary and "8 objects" in summary
    # The floor under the table lies in its shadow: darker than the open floor.
    co, rgb = _colors(bpy.data.objects["Floor_baked"])
    under = (np.abs(co[:, 0]) < 0.5) & (np.abs(co[:, 1]) < 0.3)
    open_floor = (np.abs(co[:, 0]) > 1.2) | (np.abs(co[:, 1]) > 1.2)
    assert under.any() and open_floor.any()
    assert rgb[under].mean() < rgb[open_floor].mean()
    # The baked floor covers the original floor (same plane, same extent).
    assert np.allclose(co[:, 2], 0.0, atol=1e-6)
    assert np.allclose(co[:, :2].min(axis=0), [-2, -2]) and np.allclose(co[:, :2].max(axis=0), [2, 2])


def test_the_hierarchical_solver_is_chosen_from_the_panel(room_scene, empty):
    # The setting reaches the core (which refuses a solver it does not know), and both
    # solvers bake the room: the ceiling gets only bounced light, and the two agree on it
    # as a whole (each is checked against closed forms and Cycles in the core's tests).
    empty.scene.penumbra.quality = "DRAFT"
    means = {}
    for solver in ("PROGRESSIVE", "HIERARCHICAL"):
        empty.scene.penumbra.indirect_solver = solver
        ex = export_scene(empty, empty.scene.penumbra)
        assert ex.scene["settings"]["indirect_solver"] == solver.lower()
        assert bpy.ops.penumbra.bake() == {"FINISHED"}
        _, rgb = _colors(bpy.data.objects["Ceiling_baked"])
        means[solver] = rgb.mean()
    assert abs(means["HIERARCHICAL"] / means["PROGRESSIVE"] - 1) < 0.05, means


def test_hide_originals_and_rebake(room_scene, empty):
    empty.scene.penumbra.hide_originals = True
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    assert bpy.data.objects["Floor"].hide_render and bpy.data.objects["Floor"].hide_get()
    # The originals are hidden now: selecting the baked objects stands for them.
    baked = list(bpy.data.collections[COLLECTION].objects)
    room.select_only(empty.view_layer, baked)
    ex = export_scene(empty, empty.scene.penumbra)
    assert sorted(m["name"] for m in ex.scene["meshes"]) == sorted(ROOM_MESHES)
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    assert len([o for o in bpy.data.objects if o.name.startswith("Floor_baked")]) == 1
    assert len(bpy.data.collections[COLLECTION].objects) == len(ROOM_MESHES)
    assert len(bpy.data.objects["Floor_baked"].data.polygons) > 0


def test_lighting_only_is_brighter_than_albedo_times_light(room_scene, empty):
    # Colour = albedo·E/π (+ indirect); lighting only = E/π: with albedo < 1 the latter is larger.
    empty.scene.penumbra.use_indirect = False
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    _, with_albedo = _colors(bpy.data.objects["Floor_baked"])
    empty.scene.penumbra.lighting_only = True
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    _, light_only = _colors(bpy.data.objects["Floor_baked"])
    assert light_only.sum() > with_albedo.sum() > 0


# --- the modal path, driven by hand (there is no window in the bpy module) -------------------


class _WindowManager:
    def __init__(self):
        self.calls = []

    def event_timer_add(self, step, window=None):
        self.calls.append("timer_add")
        return "timer"

    def event_timer_remove(self, timer):
        self.calls.append("timer_remove")

    def progress_begin(self, lo, hi):
        self.calls.append("progress_begin")

    def progress_update(self, value):
        self.calls.append(("progress", value))

    def progress_end(self):
        self.calls.append("progress_end")

    def modal_handler_add(self, op):
        self.calls.append("modal")


class _Workspace:
    def __init__(self):
        self.status = []

    def status_text_set(self, text):
        self.status.append(text)


class _Context:
    """bpy.context with a window: the operator's modal path runs as under the UI."""

    def __init__(self):
        self.window_manager = _WindowManager()
        self.workspace = _Workspace()
        self.window = object()

    def __getattr__(self, name):
        return getattr(bpy.context, name)


class _Event:
    def __init__(self, type, value="NOTHING"):
        self.type, self.value = type, value


class _Operator:
    """Stands in for the operator instance: its methods are plain functions on the class."""

    def __init__(self):
        self.reports = Reports()

    def report(self, level, message):
        self.reports(level, message)


def _modal_op():
    op = _Operator()
    cls = bpy.types.PENUMBRA_OT_bake
    op.modal = lambda ctx, ev: cls.modal(op, ctx, ev)
    op._end = lambda ctx: cls._end(op, ctx)
    op.invoke = lambda ctx, ev: cls.invoke(op, ctx, ev)
    op.execute = lambda ctx: cls.execute(op, ctx)
    return op


def test_modal_escape_cancels_and_changes_nothing(room_scene, empty, monkeypatch):
    empty.scene.penumbra.quality = "HIGH"
    before = snapshot()
    op, ctx = _modal_op(), _Context()
    import penumbra.blender.operators as ops

    monkeypatch.setattr(ops, "has_ui", lambda context: True)
    assert op.invoke(ctx, _Event("NONE")) == {"RUNNING_MODAL"}
    assert op.modal(ctx, _Event("MOUSEMOVE")) == {"PASS_THROUGH"}  # the UI stays usable
    assert op.modal(ctx, _Event("ESC", "PRESS")) == {"CANCELLED"}
    assert op._job.cancelled()
    assert ctx.window_manager.calls[-2:] == ["timer_remove", "progress_end"]
    assert ctx.workspace.status[-1] is None
    assert snapshot() == before


def test_modal_timer_polls_until_the_bake_is_imported(room_scene, empty, monkeypatch):
    import penumbra.blender.operators as ops

    monkeypatch.setattr(ops, "has_ui", lambda context: True)
    op, ctx = _modal_op(), _Context()
    assert op.invoke(ctx, _Event("NONE")) == {"RUNNING_MODAL"}
    outcome = {"RUNNING_MODAL"}
    for _ in range(6000):
        outcome = op.modal(ctx, _Event("TIMER"))
        if outcome != {"RUNNING_MODAL"}:
            break
        time.sleep(0.01)
    assert outcome == {"FINISHED"}, op.reports.items
    assert any(isinstance(c, tuple) and c[0] == "progress" for c in ctx.window_manager.calls)
    assert any(s and s.startswith("Penumbra: ") for s in ctx.workspace.status)
    assert len(bpy.data.collections[COLLECTION].objects) == len(ROOM_MESHES)
    assert "elements" in op.reports.items[-1][1]


def test_overall_progress_follows_the_pipeline():
    from penumbra.blender.operators import overall_fraction

    names = ["validate", "shadow volumes", "discontinuity loops", "meshing", "direct light", "indirect light"]
    values = [overall_fraction(n, 0.5) for n in names]
    assert values == sorted(values) and 0 < values[0] and values[-1] < 1
    assert overall_fraction("something new", 0.5) == 0.0


def test_a_light_the_scene_json_cannot_hold_is_refused(room_scene, empty):
    _, light = room_scene
    light.data.use_shadow = False
    _refused(empty, ["Ceiling Light", "use_shadow"])


def test_a_light_that_gives_nothing_is_counted_in_the_report(empty):
    """A light facing away from everything bakes (it is a valid scene), but the report says so."""
    _cube().select_set(True)
    _area_light("Lamp")
    away = _area_light("Away", z=4.0)
    away.rotation_euler = (math.pi, 0.0, 0.0)  # emits upwards, away from the cube
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    summary = empty.scene.penumbra.last_summary
    assert "(1 warning, see console)" in summary, summary
