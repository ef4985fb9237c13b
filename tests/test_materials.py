"""Material → per-polygon albedo / emission, against numbers and against Cycles itself.

The Cycles checks bake a small plane's DIFFUSE COLOR pass (the colour Cycles' Diffuse bake
multiplies lighting by) or its EMIT pass, which are deterministic, so 1–4 samples suffice.
Run with ``pytest -s`` to see the measured ratios.
"""
from __future__ import annotations

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

import cycles_ref as cr  # noqa: E402  (also puts addon/ on sys.path)
from penumbra.io.materials import (  # noqa: E402
    DEFAULT_ALBEDO,
    material_colors,
    polygon_colors,
    principled_diffuse_albedo,
)

WHITE = (1.0, 1.0, 1.0, 1.0)


def _principled(name="P", **inputs):
    m = bpy.data.materials.new(name)
    p = next(n for n in m.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    for k, v in inputs.items():
        p.inputs[k].default_value = v
    return m


def _tree(name, build):
    """A material whose Surface is whatever ``build(nodes, links)`` returns (an output socket)."""
    m = bpy.data.materials.new(name)
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(build(nt.nodes, nt.links), out.inputs["Surface"])
    return m


def _diffuse(nodes, color):
    d = nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = color
    return d


def _image(name, rgba_pixels, colorspace="sRGB", float_buffer=False):
    px = np.asarray(rgba_pixels, dtype=np.float32)
    h, w = px.shape[:2]
    img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=float_buffer)
    img.colorspace_settings.name = colorspace
    img.pixels.foreach_set(px.ravel())
    img.pack()
    return img


def _plane_with(material_factory, n=4):
    cr.new_scene(samples=1)
    mat = material_factory() if material_factory else None
    plane = cr.add_grid(n, 2.0, material=mat)
    return plane


def _cycles_color(plane, emit=False):
    """Mean over vertices of Cycles' COLOR-only Diffuse bake (or the Emit bake)."""
    if emit:
        _, c = cr.bake_vertex_colors(plane, bake_type="EMIT", pass_filter=set())
    else:
        cr.add_light("SUN", energy=1.0)
        _, c = cr.bake_vertex_colors(plane, pass_filter={"COLOR"})
    return c.mean(axis=0)


def _ours(plane, warnings=None):
    dg = bpy.context.evaluated_depsgraph_get()
    ob = plane.evaluated_get(dg)
    a, e = polygon_colors(ob, ob.data, warnings)
    assert a.shape == e.shape == (len(plane.data.polygons), 3)
    return a, e


# ---- against Cycles: the diffuse colour ------------------------------------------------

def _textured(nodes, links, px, colorspace="sRGB", float_buffer=False):
    d = nodes.new("ShaderNodeBsdfDiffuse")
    t = nodes.new("ShaderNodeTexImage")
    t.image = _image("Img", px, colorspace, float_buffer)
    links.new(t.outputs["Color"], d.inputs["Color"])
    return d.outputs["BSDF"]


COLOR_CASES = [
    ("diffuse", lambda: _tree("D", lambda n, l: _diffuse(n, (0.7, 0.4, 0.2, 1)).outputs["BSDF"]), 1e-5),
    ("no_material", None, 1e-4),
    ("principled_default_0.8", lambda: _principled(**{"Base Color": (0.8, 0.8, 0.8, 1)}), 1e-4),
    ("principled_white_rough0", lambda: _principled(**{"Base Color": WHITE, "Roughness": 0.0}), 1e-4),
    ("principled_rough0.35_ior1.33", lambda: _principled(**{"Base Color": (0.9, 0.5, 0.1, 1), "Roughness": 0.35,
                                                           "IOR": 1.33}), 2e-3),
    ("principled_rough0.85_ior2.4_level0.7", lambda: _principled(**{"Base Color": WHITE, "Roughness": 0.85, "IOR": 2.4,
                                                                    "Specular IOR Level": 0.7}), 2e-3),
    ("principled_level0", lambda: _principled(**{"Base Color": (0.3, 0.6, 0.9, 1), "Specular IOR Level": 0.0}), 1e-4),
    ("principled_metallic0.3_transmission0.4_alpha0.8",
     lambda: _principled(**{"Base Color": WHITE, "Metallic": 0.3, "Transmission Weight": 0.4, "Alpha": 0.8}), 1e-3),
    ("principled_coat0.7_tint", lambda: _principled(**{"Base Color": WHITE, "Coat Weight": 0.7,
                                                      "Coat Tint": (0.9, 0.6, 0.3, 1), "Coat Roughness": 0.2}), 2e-3),
    ("principled_subsurface_sheen", lambda: _principled(**{"Base Color": (0.5, 0.5, 0.5, 1), "Subsurface Weight": 0.6,
                                                          "Sheen Weight": 0.5, "Specular Tint": (1, 0, 0, 1)}), 2e-3),
    ("principled_sheen_tinted_over_coat", lambda: _principled(**{"Base Color": (0.2, 0.7, 0.4, 1), "Sheen Weight": 0.8,
                                                                "Sheen Roughness": 0.9, "Sheen Tint": (1.0, 0.3, 0.6, 1),
                                                                "Coat Weight": 0.5, "Coat Tint": (0.5, 0.8, 1.0, 1)}), 2e-3),
    ("mix_diffuse_glossy", lambda: _tree("Mix", _mix_diffuse_glossy), 1e-4),
    ("add_two_diffuse", lambda: _tree("Add", _add_two_diffuse), 1e-4),
    ("texture_srgb_constant", lambda: _tree("Tex", lambda n, l: _textured(n, l, np.tile([0.5, 0.2, 0.9, 1.0], (4, 4, 1)))),
     1e-3),
    ("texture_float_constant", lambda: _tree("TexF", lambda n, l: _textured(n, l, np.tile([0.3, 1.5, 0.05, 1.0], (4, 4, 1)),
                                                                          "Linear Rec.709", True)), 1e-4),
    ("texture_noncolor_constant", lambda: _tree("TexN", lambda n, l: _textured(n, l, np.tile([0.5, 0.2, 0.9, 1.0], (4, 4, 1)),
                                                                             "Non-Color")), 1e-3),
]


def _mix_diffuse_glossy(nodes, links):
    mix = nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.3
    g = nodes.new("ShaderNodeBsdfGlossy")
    links.new(_diffuse(nodes, (0.2, 0.9, 0.5, 1)).outputs["BSDF"], mix.inputs[1])
    links.new(g.outputs["BSDF"], mix.inputs[2])
    return mix.outputs["Shader"]


def _add_two_diffuse(nodes, links):
    add = nodes.new("ShaderNodeAddShader")
    links.new(_diffuse(nodes, (0.2, 0.3, 0.1, 1)).outputs["BSDF"], add.inputs[0])
    links.new(_diffuse(nodes, (0.1, 0.4, 0.5, 1)).outputs["BSDF"], add.inputs[1])
    return add.outputs["Shader"]


@pytest.mark.parametrize("case,factory,tol", COLOR_CASES, ids=[c[0] for c in COLOR_CASES])
def test_albedo_matches_cycles_color_pass(case, factory, tol):
    plane = _plane_with(factory)
    warnings = []
    ours, _ = _ours(plane, warnings)
    assert not warnings, warnings
    assert np.ptp(ours, axis=0).max() == 0.0  # one material: one colour
    cyc = _cycles_color(plane)
    print(f"\n[materials] {case:48s} ours {np.round(ours[0], 5)}  Cycles {np.round(cyc, 5)}  "
          f"ratio {np.round(ours[0] / np.maximum(cyc, 1e-12), 5)}")
    assert np.abs(ours[0] - cyc).max() <= tol


def test_emission_matches_cycles_emit_bake():
    def mat():
        m = bpy.data.materials.new("Lamp")
        nt = m.node_tree
        nt.nodes.clear()
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        mix = nt.nodes.new("ShaderNodeMixShader")
        mix.inputs["Fac"].default_value = 0.25
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (1.0, 0.5, 0.25, 1)
        em.inputs["Strength"].default_value = 4.0
        p = nt.nodes.new("ShaderNodeBsdfPrincipled")
        p.inputs["Emission Color"].default_value = (0.2, 0.4, 0.8, 1)
        p.inputs["Emission Strength"].default_value = 3.0
        nt.links.new(em.outputs["Emission"], mix.inputs[1])
        nt.links.new(p.outputs["BSDF"], mix.inputs[2])
        nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
        return m

    plane = _plane_with(mat)
    _, e = _ours(plane)
    cyc = _cycles_color(plane, emit=True)
    expect = 0.75 * np.array([4.0, 2.0, 1.0]) + 0.25 * np.array([0.6, 1.2, 2.4])
    print(f"\n[materials] emission mix: ours {e[0]}  Cycles {cyc}")
    assert e[0] == pytest.approx(expect, rel=1e-6)
    assert np.abs(e[0] - cyc).max() <= 1e-4 * expect.max()


# ---- numbers, no bake ------------------------------------------------------------------

def test_texture_mean_is_linear_mean_of_srgb_pixels():
    cr.new_scene(samples=1)
    px = np.array([[[1.0, 0.0, 0.5, 1.0], [0.0, 1.0, 0.5, 1.0]],
                   [[0.2, 0.2, 0.2, 1.0], [0.8, 0.8, 0.8, 1.0]]])
    m = _tree("Tex", lambda n, l: _textured(n, l, px))
    a, e = material_colors(m)
    byte = np.round(px[..., :3] * 255) / 255  # stored as 8-bit

    def lin(c):
        return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    assert a == pytest.approx(lin(byte).reshape(-1, 3).mean(axis=0), abs=1e-6)
    assert not e.any()


def test_material_index_picks_slots_and_clamps():
    cr.new_scene(samples=1)
    plane = cr.add_grid(3, 2.0)  # 4 quads
    me = plane.data
    red = _tree("Red", lambda n, l: _diffuse(n, (1, 0, 0, 1)).outputs["BSDF"])
    me.materials.append(red)
    me.materials.append(None)  # empty slot → default surface
    me.materials.append(_principled("Glow", **{"Base Color": (0, 0, 1, 1), "Emission Color": (1, 1, 0, 1),
                                               "Emission Strength": 2.0, "Roughness": 0.0}))
    me.polygons.foreach_set("material_index", np.array([0, 1, 2, 7], dtype=np.int32))
    a, e = polygon_colors(plane, me)
    assert a[0] == pytest.approx([1, 0, 0])
    assert a[1] == pytest.approx(DEFAULT_ALBEDO)
    assert a[2] == pytest.approx([0, 0, 0.96])  # 1 − F0(1.5) for a smooth dielectric layer
    assert a[3] == pytest.approx(a[2])          # index 7 clamps to the last slot
    assert e[2] == pytest.approx([2, 2, 0]) and not e[:2].any()


def test_no_material_at_all_is_default_surface():
    cr.new_scene(samples=1)
    plane = cr.add_grid(3, 2.0)
    a, e = polygon_colors(plane, plane.data)
    assert a == pytest.approx(np.tile(DEFAULT_ALBEDO, (4, 1)))
    assert DEFAULT_ALBEDO == pytest.approx([0.770, 0.770, 0.770], abs=5e-4)
    assert not e.any()


def test_unknown_inputs_fall_back_with_a_warning():
    cr.new_scene(samples=1)

    def build(nodes, links):
        d = _diffuse(nodes, (0.25, 0.5, 0.75, 1))
        noise = nodes.new("ShaderNodeTexNoise")
        links.new(noise.outputs["Color"], d.inputs["Color"])
        return d.outputs["BSDF"]
    m = _tree("Noisy", build)
    warnings = []
    a, _ = material_colors(m, warnings)
    assert a == pytest.approx([0.25, 0.5, 0.75])
    assert len(warnings) == 1 and "Noise" in warnings[0]


def test_principled_formula_pieces():
    # Smooth layer: exactly 1 − F0; no specular: the base colour; metallic removes diffuse.
    assert principled_diffuse_albedo((1, 1, 1), roughness=0.0) == pytest.approx([0.96] * 3)
    assert principled_diffuse_albedo((0.3, 0.2, 0.1), specular_ior_level=0.0) == pytest.approx([0.3, 0.2, 0.1])
    assert principled_diffuse_albedo((1, 1, 1), metallic=1.0) == pytest.approx([0, 0, 0])


def test_large_mesh_is_vectorised():
    """200k polygons, 3 materials: must not loop in Python per polygon."""
    import time
    cr.new_scene(samples=1)
    plane = cr.add_grid(450, 10.0)  # 449² ≈ 201k quads
    me = plane.data
    for name, col in (("A", (1, 0, 0, 1)), ("B", (0, 1, 0, 1)), ("C", (0, 0, 1, 1))):
        me.materials.append(_tree(name, lambda n, l, c=col: _diffuse(n, c).outputs["BSDF"]))
    idx = np.arange(len(me.polygons), dtype=np.int32) % 3
    me.polygons.foreach_set("material_index", idx)
    t = time.perf_counter()
    a, _ = polygon_colors(plane, me)
    dt = time.perf_counter() - t
    assert np.array_equal(np.argmax(a, axis=1), idx)
    assert dt < 1.0, f"{dt:.2f} s for {len(me.polygons)} polygons"


@pytest.mark.parametrize("facing", ["down", "up"])
def test_emissive_mesh_lights_like_a_polygon_of_that_radiance(facing):
    """An emissive quad of emission colour·strength C lights a receiver exactly like a
    polygon light of radiance C (Lambert's formula) — so ``emission`` is the radiance the
    radiosity must shoot. Cycles' mesh emission is two-sided: flipping the quad (facing up,
    away from the receiver) changes nothing."""
    cr.new_scene(samples=1024)
    plane = cr.add_grid(24, 4.0, material=cr.diffuse_material())
    m = bpy.data.materials.new("Glow")
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (1.0, 0.6, 0.3, 1.0)
    em.inputs["Strength"].default_value = 5.0
    nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
    quad = [(-0.5, -0.5, 0.0), (0.5, -0.5, 0.0), (0.5, 0.5, 0.0), (-0.5, 0.5, 0.0)]
    face = [(0, 3, 2, 1)] if facing == "down" else [(0, 1, 2, 3)]
    me = bpy.data.meshes.new("Lamp")
    me.from_pydata(quad, [], face)
    me.materials.append(m)
    lamp = bpy.data.objects.new("Lamp", me)
    lamp.location = (0.3, -0.2, 1.5)
    bpy.context.scene.collection.objects.link(lamp)
    bpy.context.view_layer.update()
    _, e = polygon_colors(lamp, me)
    pos, baked = cr.bake_vertex_colors(plane)
    poly = (np.array(quad) + np.array(lamp.location))[[0, 3, 2, 1]]  # front facing down
    ours = cr.outgoing_radiance(pos, (0, 0, 1), [{"polygon": poly, "radiance": e[0]}])
    r, err = cr.ratio(ours, baked), cr.relative_rms(ours, baked)
    print(f"\n[materials] emissive quad facing {facing}: ours/Cycles = {r:.5f}  relative RMS = {err:.5f}")
    assert err <= 0.01
