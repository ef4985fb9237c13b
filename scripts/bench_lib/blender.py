"""Scene JSON and bake JSON as bpy objects (imported only inside Blender-side processes).

* `cycles_scene`: the scene for Cycles. Each scene mesh becomes one object whose polygons
  are the probe lattices (same geometry, more vertices), with a Diffuse BSDF of the
  polygon's albedo (plus an Emission of its emission radiance). Rectangular light polygons
  become RECTANGLE area lights of power P = L·π·A (Blender's convention L = P/(π·A), see
  addon/penumbra/io/lights.py); other polygons become one-sided emissive faces. Point,
  spot and sun lights become Blender lights of those types (radius, angle, cone).
* `baked_scene`: a bake JSON as meshes with an emission shader reading the colour
  attribute, for rendering what Penumbra baked.
"""
from __future__ import annotations

import math

import numpy as np

import cycles_setup


def reset(samples: int, seed: int, adaptive: bool, bounces: int, threads: int):
    return cycles_setup.reset_scene(samples, seed, adaptive, bounces, threads)


def _per_polygon(v, n):
    if v is None:
        return [None] * n
    a = np.asarray(v, dtype=np.float64)
    if a.ndim == 1:
        return [tuple(a)] * n
    return [tuple(x) for x in a]


def _object(name, verts, tris, material_index=None, materials=()):
    import bpy

    me = bpy.data.meshes.new(name)
    me.from_pydata(np.asarray(verts).tolist(), [], np.asarray(tris).tolist())
    for m in materials:
        me.materials.append(m)
    if material_index is not None:
        me.polygons.foreach_set("material_index", np.asarray(material_index, dtype=np.int32))
    me.update()
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def _light(l, index):
    import bpy

    poly = np.asarray(l["polygon"], dtype=np.float64)
    L = np.asarray(l["radiance"], dtype=np.float64)
    n = np.zeros(3)
    for i in range(len(poly)):
        n += np.cross(poly[i], poly[(i + 1) % len(poly)])
    n /= np.linalg.norm(n)
    c = poly.mean(0)
    rect = False
    if len(poly) == 4:
        e = [poly[(i + 1) % 4] - poly[i] for i in range(4)]
        rect = all(abs(np.dot(e[i], e[(i + 1) % 4])) < 1e-9 * (1 + np.dot(e[i], e[i]))
                   for i in range(4))
    if not rect:
        # One-sided emissive polygon of radiance L (emission strength 1 = radiance 1).
        mat = bpy.data.materials.new(f"LightMat{index}")
        nt = mat.node_tree
        nt.nodes.clear()
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (*L, 1.0)
        em.inputs["Strength"].default_value = 1.0
        # Back faces black: the light emits from its front only.
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        mix = nt.nodes.new("ShaderNodeMixShader")
        tr = nt.nodes.new("ShaderNodeBsdfTransparent")
        nt.links.new(geo.outputs["Backfacing"], mix.inputs[0])
        nt.links.new(em.outputs["Emission"], mix.inputs[1])
        nt.links.new(tr.outputs["BSDF"], mix.inputs[2])
        nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
        return _object(l["name"], poly, [list(range(len(poly)))], materials=[mat])
    u, w = poly[1] - poly[0], poly[3] - poly[0]
    zax = -n                        # an area light emits along its −Z
    xax = u / np.linalg.norm(u)
    yax = np.cross(zax, xax)
    area = np.linalg.norm(u) * np.linalg.norm(w)
    P = L * math.pi * area
    data = bpy.data.lights.new(l["name"], "AREA")
    data.shape = "RECTANGLE"
    data.size = float(np.linalg.norm(u))
    data.size_y = float(np.linalg.norm(w))
    data.energy = float(P.max())
    data.color = tuple(P / P.max()) if P.max() > 0 else (1, 1, 1)
    ob = bpy.data.objects.new(l["name"], data)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = xax, yax, zax, c
    import mathutils

    ob.matrix_world = mathutils.Matrix(m.tolist())
    bpy.context.scene.collection.objects.link(ob)
    return ob


def cycles_scene(scene: dict, lattices: list[dict]):
    """Builds the Cycles scene; returns the receiver objects (one per scene mesh)."""
    objs = []
    for m, lat in zip(scene["meshes"], lattices):
        npoly = len(m["polygons"])
        alb = _per_polygon(m.get("albedo") or [0.8, 0.8, 0.8], npoly)
        emi = _per_polygon(m.get("emission"), npoly)
        keys = {}
        mats = []
        pmat = []
        for a, e in zip(alb, emi):
            k = (a, e)
            if k not in keys:
                keys[k] = len(mats)
                mats.append(cycles_setup.lambert_material(f"{m['name']}.{len(mats)}", a, e))
            pmat.append(keys[k])
        tri_poly = lat["polygon"][lat["tris"][:, 0]]
        objs.append(_object(m["name"], lat["verts"], lat["tris"],
                            np.asarray(pmat)[tri_poly], mats))
    for i, l in enumerate(scene["lights"]):
        if "polygon" in l:
            _light(l, i)
        else:
            _point_or_sun(l)
    return objs


def _point_or_sun(l):
    """A point, spot or sun light dict as the Blender light the add-on would export it from
    (addon/penumbra/io/lights.py, normalize on): power 4π·I, radius and soft falloff (off for
    a sphere), spot cone and blend, sun strength E and angle; Blender's lights emit along −Z."""
    import bpy
    import mathutils

    if "point" in l:
        kind = "SPOT" if "spot" in l else "POINT"
        S = 4.0 * math.pi * np.asarray(l["intensity"], dtype=np.float64)
        emit = np.asarray(l["spot"]["direction"], dtype=np.float64) if "spot" in l else np.array([0, 0, -1.0])
        at = np.asarray(l["point"], dtype=np.float64)
    else:
        kind = "SUN"
        S = np.asarray(l["irradiance"], dtype=np.float64)
        emit = np.asarray(l["direction"], dtype=np.float64)
        at = np.zeros(3)
    data = bpy.data.lights.new(l["name"], kind)
    data.energy = float(S.max())
    data.color = tuple(S / S.max()) if S.max() > 0 else (1, 1, 1)
    if kind == "SUN":
        data.angle = float(l.get("angle", 0.0))
    else:
        data.shadow_soft_size = float(l.get("radius", 0.0))
        data.use_soft_falloff = not l.get("sphere", False)
    if kind == "SPOT":
        data.spot_size = float(l["spot"]["angle"])
        data.spot_blend = float(l["spot"].get("blend", 0.0))
    ob = bpy.data.objects.new(l["name"], data)
    z = -emit / np.linalg.norm(emit)
    x = np.cross([0.0, 1.0, 0.0] if abs(z[1]) < 0.9 else [1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, np.cross(z, x), z, at
    ob.matrix_world = mathutils.Matrix(m.tolist())
    bpy.context.scene.collection.objects.link(ob)
    return ob


def baked_scene(bake: dict):
    """The bake JSON as meshes shaded by an emission of their colour attribute."""
    import bpy

    mat = bpy.data.materials.new("Baked")
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em = nt.nodes.new("ShaderNodeEmission")
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "Penumbra"
    nt.links.new(attr.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
    for m in bake["meshes"]:
        if not m["triangles"]:
            continue
        ob = _object(m["name"], m["positions"], m["triangles"], materials=[mat])
        col = np.ones((len(m["positions"]), 4), dtype=np.float32)
        col[:, :3] = np.asarray(m["colors"], dtype=np.float32)
        a = ob.data.color_attributes.new("Penumbra", "FLOAT_COLOR", "POINT")
        a.data.foreach_set("color", col.ravel())


def camera(location, target, lens=35.0):
    import bpy
    import mathutils

    cam = bpy.data.cameras.new("Camera")
    cam.lens = lens
    ob = bpy.data.objects.new("Camera", cam)
    ob.location = location
    d = mathutils.Vector(target) - mathutils.Vector(location)
    ob.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.collection.objects.link(ob)
    bpy.context.scene.camera = ob


def bake_vertex_colors(objs, pass_filter):
    """One Cycles Diffuse bake of all `objs` into a float vertex attribute; returns the
    seconds of the bake call and per object the (V,3) colours."""
    import time

    import bpy

    for o in bpy.context.scene.objects:
        o.select_set(False)
    for o in objs:
        a = o.data.color_attributes.new("CyclesBake", "FLOAT_COLOR", "POINT")
        o.data.color_attributes.active_color = a
        o.select_set(True)
    bpy.context.view_layer.objects.active = objs[0]
    t = time.perf_counter()
    res = bpy.ops.object.bake(type="DIFFUSE", pass_filter=set(pass_filter),
                              target="VERTEX_COLORS", use_clear=True, margin=0)
    dt = time.perf_counter() - t
    if res != {"FINISHED"}:
        raise RuntimeError(f"Cycles bake failed: {res}")
    cols = []
    for o in objs:
        nv = len(o.data.vertices)
        c = np.empty(nv * 4, dtype=np.float32)
        o.data.color_attributes["CyclesBake"].data.foreach_get("color", c)
        cols.append(c.reshape(-1, 4)[:, :3].astype(np.float64))
    return dt, cols
