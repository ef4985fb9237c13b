"""Blender light → scene-JSON conversion, proved against actual Cycles bakes.

Each case puts one light over an unoccluded 24×24-vertex plane with a Lambertian (Diffuse
BSDF, roughness 0) material, bakes it with Cycles (Diffuse: direct + indirect + colour,
adaptive sampling off) into vertex colours, and compares with albedo · E / π computed exactly
(numpy, tests/cycles_ref.py) from what ``lights_to_scene`` exports. The plane sees nothing but
the light, so indirect light is zero and the comparison is exact up to Cycles' noise.

Run with ``pytest -s`` to see the measured ratio (ours / Cycles) and relative RMS per case.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

import cycles_ref as cr  # noqa: E402  (also puts addon/ on sys.path)
from penumbra.io.lights import (  # noqa: E402
    DEFAULT_DISK_SEGMENTS,
    UnsupportedLightError,
    lights_to_scene,
)

SAMPLES = 1024
GRID = 24  # vertices a side: 576 probe points, ~3 s a bake at 1024 samples on 2 cores
TOL = 0.01  # relative RMS

# (id, light type, object kwargs, light-data properties, albedo, lighting_only)
CASES = [
    ("area_square", "AREA", {}, dict(energy=100.0, size=1.0), 1.0, False),
    ("area_rectangle", "AREA", {}, dict(energy=80.0, shape="RECTANGLE", size=1.6, size_y=0.4), 0.8, False),
    ("area_disk", "AREA", {}, dict(energy=100.0, shape="DISK", size=1.5), 1.0, False),
    ("area_ellipse", "AREA", {}, dict(energy=100.0, shape="ELLIPSE", size=1.5, size_y=0.5), 1.0, False),
    ("area_rotated_scaled", "AREA", dict(rotation=(0.4, 0.3, 0.5), scale=(1.3, 0.7, 2.0)),
     dict(energy=100.0, shape="RECTANGLE", size=1.5, size_y=0.5), 1.0, False),
    ("area_ellipse_rotated_scaled", "AREA", dict(rotation=(-0.3, 0.5, 1.0), scale=(0.6, 1.4, 1.0)),
     dict(energy=60.0, shape="ELLIPSE", size=1.2, size_y=0.8), 1.0, False),
    ("area_mirrored", "AREA", dict(scale=(-1.0, 1.0, 1.0)),
     dict(energy=100.0, shape="RECTANGLE", size=1.0, size_y=0.5), 1.0, False),
    ("area_normalize_off", "AREA", {}, dict(energy=10.0, size=1.5, normalize=False), 1.0, False),
    ("area_color_exposure", "AREA", {}, dict(energy=100.0, size=1.0, color=(1.0, 0.5, 0.2), exposure=1.5), 1.0, False),
    ("area_exposure_negative", "AREA", {}, dict(energy=100.0, size=1.0, exposure=-2.0), 1.0, False),
    ("area_temperature_3000K", "AREA", {}, dict(energy=100.0, size=1.0, use_temperature=True, temperature=3000.0,
                                                color=(0.9, 1.0, 0.8)), 1.0, False),
    ("area_lighting_only", "AREA", {}, dict(energy=100.0, size=1.0), 0.5, True),
    ("area_diffuse_factor_ignored", "AREA", {}, dict(energy=100.0, size=1.0, diffuse_factor=0.3), 1.0, False),
    ("point", "POINT", {}, dict(energy=100.0), 1.0, False),
    ("point_color_temperature", "POINT", {}, dict(energy=200.0, color=(0.3, 0.6, 1.0), use_temperature=True,
                                                  temperature=9000.0), 0.8, False),
    ("point_normalize_off", "POINT", {}, dict(energy=20.0, normalize=False), 1.0, False),
    ("point_sphere_r0.3", "POINT", {}, dict(energy=100.0, shadow_soft_size=0.3, use_soft_falloff=False), 1.0, False),
    ("point_sphere_r0.3_normalize_off", "POINT", {}, dict(energy=100.0, shadow_soft_size=0.3,
                                                          use_soft_falloff=False, normalize=False), 1.0, False),
    ("point_soft_falloff_r0.1", "POINT", {}, dict(energy=100.0, shadow_soft_size=0.1), 1.0, False),
    ("spot_blend0.3", "SPOT", {}, dict(energy=100.0, spot_size=1.0, spot_blend=0.3), 1.0, False),
    ("spot_hard", "SPOT", dict(rotation=(0.2, 0.0, 0.0)), dict(energy=100.0, spot_size=1.0, spot_blend=0.0), 1.0, False),
    ("spot_blend1_tilted_scaled", "SPOT", dict(rotation=(0.3, 0.1, 0.0), scale=(2.0, 2.0, 2.0)),
     dict(energy=150.0, spot_size=1.2, spot_blend=1.0), 1.0, False),
    ("sun", "SUN", dict(rotation=(0.3, 0.2, 0.0)), dict(energy=2.0), 1.0, False),
    ("sun_angle", "SUN", dict(rotation=(0.5, -0.3, 0.0)), dict(energy=3.0, angle=0.3, color=(1.0, 0.9, 0.7)), 0.8, False),
    ("sun_angle_normalize_off", "SUN", dict(rotation=(0.3, 0.2, 0.0)), dict(energy=50.0, angle=0.3, normalize=False),
     1.0, False),
]

LIGHT_LOCATION = (0.3, -0.2, 2.0)


def _bake_case(kind, obj_kw, props, albedo, lighting_only, samples=SAMPLES):
    cr.new_scene(samples=samples)
    plane = cr.add_grid(GRID, 4.0, material=cr.diffuse_material(color=(albedo,) * 3))
    kw = dict(location=LIGHT_LOCATION)
    kw.update(obj_kw)
    lo = cr.add_light(kind, **kw, **props)
    bpy.context.view_layer.update()
    pos, baked = cr.bake_vertex_colors(plane, lighting_only=lighting_only)
    return plane, lo, pos, baked


def _report(case, ours, baked, mask=None):
    r = cr.ratio(ours, baked, mask)
    e = cr.relative_rms(ours, baked, mask)
    print(f"\n[cycles-lights] {case:32s} ours/Cycles = {r:.5f}  relative RMS = {e:.5f}")
    return r, e


@pytest.mark.parametrize("case,kind,obj_kw,props,albedo,lighting_only", CASES, ids=[c[0] for c in CASES])
def test_light_matches_cycles(case, kind, obj_kw, props, albedo, lighting_only):
    _, lo, pos, baked = _bake_case(kind, obj_kw, props, albedo, lighting_only)
    lights = lights_to_scene(lo, bpy.context.evaluated_depsgraph_get())
    assert len(lights) == 1
    ours = cr.outgoing_radiance(pos, (0.0, 0.0, 1.0), lights, albedo=1.0 if lighting_only else albedo)
    assert baked.mean() > 1e-3, "Cycles baked (almost) nothing: the case tests nothing"
    r, e = _report(case, ours, baked)
    assert e <= TOL, f"{case}: relative RMS {e:.4f} > {TOL} (ratio {r:.4f})"
    assert abs(r - 1.0) <= TOL


def test_soft_falloff_point_is_a_disk_facing_the_receiver():
    """Cycles' default point light with a radius (use_soft_falloff on) gives I·cos/(d² + r²),
    not I·cos/d²: we export the radius, and the light it gives matches; a bare point would
    over-estimate by ≈ r²/d² (beyond 1 % for r = 0.3 at d ≈ 2): this test pins both facts."""
    r0 = 0.3
    _, lo, pos, baked = _bake_case("POINT", {}, dict(energy=100.0, shadow_soft_size=r0), 1.0, False)
    lights = lights_to_scene(lo)
    assert lights[0]["radius"] == pytest.approx(r0)
    ours = cr.outgoing_radiance(pos, (0.0, 0.0, 1.0), lights)
    bare = cr.outgoing_radiance(pos, (0.0, 0.0, 1.0), [dict(lights[0], radius=0.0)])
    r, e = _report("point_soft_falloff_r0.3 (radius)", ours, baked)
    rb, _ = _report("point_soft_falloff_r0.3 (bare point)", bare, baked)
    assert e <= TOL and abs(r - 1.0) <= TOL
    d2 = np.sum((pos - np.array(LIGHT_LOCATION)) ** 2, axis=1)
    assert 0.0 < rb - 1.0 <= r0 * r0 / d2.min()


def test_invisible_to_diffuse_light_exports_nothing():
    """``visible_diffuse`` off: Cycles gives diffuse surfaces nothing, and we export nothing."""
    _, lo, pos, baked = _bake_case("AREA", {}, dict(energy=100.0, size=1.0), 1.0, False, samples=64)
    lo.visible_diffuse = False
    bpy.context.view_layer.update()
    plane = bpy.data.objects["Plane"]
    _, baked = cr.bake_vertex_colors(plane)
    assert np.abs(baked).max() == 0.0
    assert lights_to_scene(lo) == []


def test_parented_light_through_depsgraph():
    """World transform from parents (a scaled, rotated empty) is what Cycles uses."""
    cr.new_scene(samples=SAMPLES)
    plane = cr.add_grid(GRID, 4.0, material=cr.diffuse_material())
    empty = bpy.data.objects.new("Rig", None)
    bpy.context.scene.collection.objects.link(empty)
    empty.location = (0.2, 0.1, 1.0)
    empty.rotation_euler = (0.0, 0.0, 0.7)
    empty.scale = (1.5, 0.8, 1.0)
    lo = cr.add_light("AREA", location=(0.0, 0.0, 1.2), energy=120.0, shape="RECTANGLE", size=1.0, size_y=0.6)
    lo.parent = empty
    dg = bpy.context.evaluated_depsgraph_get()
    dg.update()
    pos, baked = cr.bake_vertex_colors(plane)
    lights = lights_to_scene(lo, bpy.context.evaluated_depsgraph_get())
    ours = cr.outgoing_radiance(pos, (0, 0, 1), lights)
    r, e = _report("area_parented_depsgraph", ours, baked)
    assert e <= TOL


def test_light_node_emission_strength_and_color():
    """A light node tree with one Emission node multiplies the strength by colour·strength."""
    cr.new_scene(samples=SAMPLES)
    plane = cr.add_grid(GRID, 4.0, material=cr.diffuse_material())
    lo = cr.add_light("AREA", location=LIGHT_LOCATION, energy=100.0, size=1.0)
    lo.data.use_nodes = True
    em = next(n for n in lo.data.node_tree.nodes if n.bl_idname == "ShaderNodeEmission")
    em.inputs["Strength"].default_value = 2.5
    em.inputs["Color"].default_value = (0.2, 0.5, 1.0, 1.0)
    pos, baked = cr.bake_vertex_colors(plane)
    ours = cr.outgoing_radiance(pos, (0, 0, 1), lights_to_scene(lo))
    r, e = _report("area_light_nodes", ours, baked)
    assert e <= TOL


def test_two_lights_add_up():
    cr.new_scene(samples=SAMPLES)
    plane = cr.add_grid(GRID, 4.0, material=cr.diffuse_material(color=(0.8, 0.6, 0.4)))
    a = cr.add_light("AREA", location=(-0.8, 0.0, 1.5), rotation=(0.0, -0.4, 0.0), energy=60.0,
                     shape="DISK", size=0.8, color=(1.0, 0.8, 0.6))
    s = cr.add_light("SPOT", location=(1.0, 0.5, 2.5), rotation=(0.2, 0.3, 0.0), energy=300.0,
                     spot_size=0.8, spot_blend=0.5)
    pos, baked = cr.bake_vertex_colors(plane)
    lights = lights_to_scene(a) + lights_to_scene(s)
    ours = cr.outgoing_radiance(pos, (0, 0, 1), lights, albedo=np.array([0.8, 0.6, 0.4]))
    r, e = _report("disk+spot, coloured albedo", ours, baked)
    assert e <= TOL


# ---- geometry of the exported polygons (no bake) ----------------------------------------

def _polygon_area_normal(poly):
    p = np.asarray(poly)
    v = 0.5 * np.sum(np.cross(p, np.roll(p, -1, axis=0)), axis=0)
    a = np.linalg.norm(v)
    return a, v / a


@pytest.mark.parametrize("shape,size,size_y,scale", [
    ("SQUARE", 2.0, 1.0, (1.0, 1.0, 1.0)),
    ("RECTANGLE", 2.0, 0.5, (1.5, 2.0, 3.0)),
    ("DISK", 1.0, 1.0, (1.0, 1.0, 1.0)),
    ("ELLIPSE", 2.0, 0.5, (0.5, -2.0, 1.0)),
])
def test_area_polygon_area_and_front(shape, size, size_y, scale):
    cr.new_scene(samples=1)
    lo = cr.add_light("AREA", location=(1.0, 2.0, 3.0), rotation=(0.3, -0.2, 0.9), scale=scale,
                      energy=10.0, shape=shape, size=size, size_y=size_y)
    bpy.context.view_layer.update()
    (l,) = lights_to_scene(lo)
    area, normal = _polygon_area_normal(l["polygon"])
    expect = abs(scale[0] * scale[1]) * size * (size if shape in {"SQUARE", "DISK"} else size_y)
    if shape in {"DISK", "ELLIPSE"}:
        expect *= math.pi / 4.0
        assert len(l["polygon"]) == DEFAULT_DISK_SEGMENTS
    assert area == pytest.approx(expect, rel=1e-6)  # matrix_world is float32
    mw = np.array(lo.matrix_world)
    emit = -mw[:3, 2] / np.linalg.norm(mw[:3, 2])
    assert normal @ emit == pytest.approx(1.0, abs=1e-9)
    # Power conservation: flux π·L·A equals the strength when normalized.
    assert math.pi * l["radiance"][0] * area == pytest.approx(10.0, rel=1e-6)


# ---- unsupported features: clear errors, and proof they matter ----------------------------

def test_spread_is_unsupported_and_changes_cycles():
    _, lo, pos, full = _bake_case("AREA", {}, dict(energy=100.0, size=1.0), 1.0, False, samples=128)
    lo.data.spread = math.radians(60.0)
    _, narrow = cr.bake_vertex_colors(bpy.data.objects["Plane"])
    # Spread narrows the emission (same power, pushed towards the light's axis): Cycles'
    # result changes a lot, so the field cannot be ignored.
    far = np.linalg.norm(pos[:, :2] - np.array(LIGHT_LOCATION[:2]), axis=1) > 1.5
    print(f"\n[cycles-lights] spread 60°: far-field ratio {narrow[far].sum() / full[far].sum():.3f}, "
          f"near-axis ratio {narrow[~far].sum() / full[~far].sum():.3f}")
    assert cr.relative_rms(narrow, full) > 0.1
    assert narrow[far].sum() < 0.5 * full[far].sum()
    with pytest.raises(UnsupportedLightError) as ei:
        lights_to_scene(lo)
    assert ei.value.field == "spread" and "Area" in str(ei.value)


def test_shadowless_light_is_unsupported():
    cr.new_scene(samples=1)
    lo = cr.add_light("POINT", energy=10.0, use_shadow=False)
    with pytest.raises(UnsupportedLightError, match="use_shadow"):
        lights_to_scene(lo)


def test_non_uniform_spot_scale_is_unsupported():
    cr.new_scene(samples=1)
    lo = cr.add_light("SPOT", scale=(1.0, 2.0, 1.0), energy=10.0)
    bpy.context.view_layer.update()
    with pytest.raises(UnsupportedLightError, match="scale"):
        lights_to_scene(lo)


def test_textured_light_nodes_are_unsupported():
    cr.new_scene(samples=1)
    lo = cr.add_light("AREA", energy=10.0)
    lo.data.use_nodes = True
    nt = lo.data.node_tree
    em = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeEmission")
    tex = nt.nodes.new("ShaderNodeTexChecker")
    nt.links.new(tex.outputs["Color"], em.inputs["Color"])
    with pytest.raises(UnsupportedLightError, match="node_tree"):
        lights_to_scene(lo)


def test_portal_and_zero_energy_export_nothing():
    cr.new_scene(samples=1)
    p = cr.add_light("AREA", energy=10.0)
    p.data.cycles.is_portal = True
    z = cr.add_light("POINT", energy=0.0)
    assert lights_to_scene(p) == [] and lights_to_scene(z) == []


def test_light_linking_is_unsupported():
    cr.new_scene(samples=1)
    lo = cr.add_light("AREA", energy=10.0)
    coll = bpy.data.collections.new("Receivers")
    bpy.context.scene.collection.children.link(coll)
    lo.light_linking.receiver_collection = coll
    with pytest.raises(UnsupportedLightError, match="light_linking"):
        lights_to_scene(lo)
