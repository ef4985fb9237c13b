"""Shared helpers for tests that compare Penumbra against Cycles.

Two kinds of reference live here:

* ``bake_vertex_colors``: an actual Cycles bake (bpy module, CPU device, Diffuse bake into a
  float colour attribute on the vertices), returning per-vertex world positions and linear RGB.
* ``irradiance_*`` / ``outgoing_radiance``: pure-numpy exact direct lighting for the light
  dicts of the scene JSON (polygon lights by Lambert's formula, point / spot / sun lights in
  closed form), so a conversion from Blender lights can be checked as
  ``albedo * E / pi`` against the Cycles bake.

All scene helpers start from an empty factory scene so one test cannot leak into the next.
The bpy module is imported lazily: the numpy references work without Blender.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np

ADDON_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "addon")
SCRIPTS_DIR = os.path.join(os.path.dirname(ADDON_DIR), "scripts")
for _d in (SCRIPTS_DIR, ADDON_DIR):
    if _d not in sys.path:
        sys.path.insert(0, _d)

import cycles_setup  # noqa: E402


# --------------------------------------------------------------------------------------------
# Blender scenes and the Cycles bake
# --------------------------------------------------------------------------------------------

def new_scene(samples: int = 1024, seed: int = 0):
    """An empty factory scene set up for unbiased, reproducible Cycles bakes.

    No world (Cycles then has no background light), adaptive sampling off, no clamping,
    light tree on (the default; it is unbiased), CPU device.
    """
    return cycles_setup.reset_scene(samples, seed)


def diffuse_material(name: str = "White", color=(1.0, 1.0, 1.0)):
    """A Lambertian material: a Diffuse BSDF (roughness 0) with the given linear colour."""
    return cycles_setup.lambert_material(name, color)


def add_grid(n: int = 32, size: float = 4.0, location=(0.0, 0.0, 0.0), material=None,
             name: str = "Plane"):
    """An n×n-vertex grid in the z = location.z plane, facing +Z, ``size`` wide."""
    import bpy

    t = np.linspace(-size / 2, size / 2, n)
    xs, ys = np.meshgrid(t, t, indexing="xy")
    verts = np.stack([xs.ravel(), ys.ravel(), np.zeros(n * n)], axis=1)
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            faces.append((a, a + 1, a + 1 + n, a + n))
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts.tolist(), [], faces)
    me.update()
    ob = bpy.data.objects.new(name, me)
    ob.location = location
    bpy.context.scene.collection.objects.link(ob)
    if material is not None:
        me.materials.append(material)
    return ob


def add_light(kind: str, location=(0.0, 0.0, 2.0), rotation=(0.0, 0.0, 0.0),
              scale=(1.0, 1.0, 1.0), name: str | None = None, **props):
    """A light object of type ``kind`` with the given light-data properties set."""
    import bpy

    data = bpy.data.lights.new(name or kind.title(), kind)
    for k, v in props.items():
        setattr(data, k, v)
    ob = bpy.data.objects.new(name or kind.title(), data)
    ob.location = location
    ob.rotation_euler = rotation
    ob.scale = scale
    bpy.context.scene.collection.objects.link(ob)
    return ob


def bake_vertex_colors(obj, lighting_only: bool = False, samples: int | None = None,
                       seed: int | None = None, bake_type: str = "DIFFUSE",
                       pass_filter: set | None = None):
    """Cycles bake of ``obj`` into a float colour attribute on its vertices.

    By default a Diffuse bake with ``pass_filter`` {DIRECT, INDIRECT, COLOR}, or
    {DIRECT, INDIRECT} when ``lighting_only`` (Cycles then gives irradiance / pi); other
    ``bake_type`` / ``pass_filter`` values are passed through (e.g. {COLOR} alone gives the
    diffuse albedo, EMIT the emitted radiance). Returns (positions (V,3) in world space,
    colours (V,3) linear RGB).
    """
    import bpy

    scene = bpy.context.scene
    if samples is not None:
        scene.cycles.samples = samples
    if seed is not None:
        scene.cycles.seed = seed
    me = obj.data
    attr = me.color_attributes.get("CyclesBake")
    if attr is None:
        attr = me.color_attributes.new("CyclesBake", "FLOAT_COLOR", "POINT")
    me.color_attributes.active_color = attr
    for o in scene.objects:
        o.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    if pass_filter is None:
        pass_filter = {"DIRECT", "INDIRECT"} if lighting_only else {"DIRECT", "INDIRECT", "COLOR"}
    res = bpy.ops.object.bake(type=bake_type, pass_filter=pass_filter, target="VERTEX_COLORS",
                              use_clear=True, margin=0)
    if res != {"FINISHED"}:
        raise RuntimeError(f"Cycles bake failed: {res}")
    attr = me.color_attributes["CyclesBake"]
    nv = len(me.vertices)
    col = np.empty(nv * 4, dtype=np.float32)
    attr.data.foreach_get("color", col)
    co = np.empty(nv * 3, dtype=np.float64)
    me.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    mw = np.array(obj.matrix_world, dtype=np.float64)
    pos = co @ mw[:3, :3].T + mw[:3, 3]
    return pos, col.reshape(-1, 4)[:, :3].astype(np.float64)


# --------------------------------------------------------------------------------------------
# Exact direct lighting (numpy)
# --------------------------------------------------------------------------------------------

def irradiance_polygon(points, normal, polygon, radiance):
    """Irradiance (V,3) at ``points`` (V,3) with unit ``normal`` (3,) from a uniform polygon.

    Lambert's formula E = L/2 · Σ_i θ_i (n · Γ_i), Γ_i the unit normal of the plane through
    the point and edge i, θ_i the angle the edge subtends. The polygon emits from its front
    (the side its vertices run counter-clockwise around); points behind it get nothing. The
    polygon must lie entirely above every point's tangent plane (no horizon clipping here).
    """
    P = np.asarray(points, dtype=np.float64)
    n = np.asarray(normal, dtype=np.float64)
    V = np.asarray(polygon, dtype=np.float64)
    L = np.asarray(radiance, dtype=np.float64)
    # Light's front normal (Newell).
    ln = np.zeros(3)
    for i in range(len(V)):
        a, b = V[i], V[(i + 1) % len(V)]
        ln += np.cross(a, b)
    ln /= np.linalg.norm(ln)
    R = V[None, :, :] - P[:, None, :]                      # (N, k, 3)
    if np.any(R @ n < -1e-12):
        raise ValueError("light polygon crosses a receiver's horizon: not handled here")
    Rn = R / np.linalg.norm(R, axis=2, keepdims=True)
    R2 = np.roll(Rn, -1, axis=1)
    c = np.cross(Rn, R2)
    cn = np.linalg.norm(c, axis=2)
    theta = np.arctan2(cn, np.sum(Rn * R2, axis=2))
    gamma = c / np.maximum(cn, 1e-300)[..., None]
    s = 0.5 * np.abs(np.sum(theta * (gamma @ n), axis=1))
    front = ((P - V[0]) @ ln) > 0.0
    return (s * front)[:, None] * L[None, :]


def smoothstep01(x):
    """Cycles' smoothstepf: clamp to [0, 1], then 3x² − 2x³ (util/math_float.h)."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def spot_mask(cos_angle, angle, blend):
    """Cycles' spot cone mask (kernel/light/spot.h, spot_light_attenuation, with
    spot_smooth = 1 / ((1 − cos_half) · blend) from scene/light.cpp)."""
    cos_half = math.cos(angle * 0.5)
    if blend <= 0.0:
        return (cos_angle > cos_half).astype(np.float64)
    return smoothstep01((cos_angle - cos_half) / ((1.0 - cos_half) * blend))


def irradiance_point(points, normal, light):
    """Irradiance (V,3) from a scene-JSON point light dict (``point``, ``intensity``,
    optional ``spot``): E = I · mask · max(cos, 0) / r²."""
    P = np.asarray(points, dtype=np.float64)
    n = np.asarray(normal, dtype=np.float64)
    c = np.asarray(light["point"], dtype=np.float64)
    d = c[None, :] - P
    r2 = np.sum(d * d, axis=1)
    r = np.sqrt(r2)
    cos_r = np.maximum(d @ n / r, 0.0)
    # With a radius: Blender's soft falloff, a disk facing the receiver; a sphere
    # (``"sphere": true``) lights like a point at its centre.
    soft = 0.0 if light.get("sphere", False) else float(light.get("radius", 0.0))
    f = cos_r / (r2 + soft ** 2)
    spot = light.get("spot")
    if spot is not None:
        sd = np.asarray(spot["direction"], dtype=np.float64)
        sd = sd / np.linalg.norm(sd)
        cos_a = (-d / r[:, None]) @ sd
        f = f * spot_mask(cos_a, spot["angle"], spot.get("blend", 0.0))
    return f[:, None] * np.asarray(light["intensity"], dtype=np.float64)[None, :]


def irradiance_sun(points, normal, light):
    """Irradiance (V,3) from a scene-JSON sun dict: E = E⊥ · max(−n·d, 0)."""
    n = np.asarray(normal, dtype=np.float64)
    d = np.asarray(light["direction"], dtype=np.float64)
    d = d / np.linalg.norm(d)
    cos = max(-float(n @ d), 0.0)
    return np.tile(np.asarray(light["irradiance"], dtype=np.float64) * cos, (len(points), 1))


def irradiance(points, normal, lights):
    """Total irradiance (V,3) from a list of scene-JSON light dicts, no occlusion."""
    E = np.zeros((len(points), 3))
    for l in lights:
        if "polygon" in l:
            E += irradiance_polygon(points, normal, l["polygon"], l["radiance"])
        elif "point" in l:
            E += irradiance_point(points, normal, l)
        elif "direction" in l:
            E += irradiance_sun(points, normal, l)
        else:
            raise ValueError(f"unknown light dict {sorted(l)}")
    return E


def outgoing_radiance(points, normal, lights, albedo=1.0, emission=0.0):
    """What Cycles' Diffuse bake (direct + indirect + colour) gives an unoccluded Lambertian
    receiver that sees nothing but the lights: albedo · E / π + emission."""
    return np.asarray(albedo) * irradiance(points, normal, lights) / math.pi + emission


def relative_rms(ours, ref, mask=None):
    """RMS of (ours − ref) over the mean of ref (all channels), optionally on a mask."""
    ours = np.asarray(ours, dtype=np.float64)
    ref = np.asarray(ref, dtype=np.float64)
    if mask is not None:
        ours, ref = ours[mask], ref[mask]
    return float(np.sqrt(np.mean((ours - ref) ** 2)) / np.mean(ref))


def ratio(ours, ref, mask=None):
    """Sum of ours over sum of ref: the overall scale factor (1 when conventions agree)."""
    ours = np.asarray(ours, dtype=np.float64)
    ref = np.asarray(ref, dtype=np.float64)
    if mask is not None:
        ours, ref = ours[mask], ref[mask]
    return float(ours.sum() / ref.sum())


def new_bounce_scene(samples: int, seed: int):
    """``new_scene`` with 64 diffuse bounces and no other kind: what a whole-scene comparison
    with indirect light needs."""
    scene = new_scene(samples=samples, seed=seed)
    cy = scene.cycles
    cy.max_bounces = cy.diffuse_bounces = 64
    cy.glossy_bounces = cy.transmission_bounces = cy.volume_bounces = cy.transparent_max_bounces = 0
    return scene


def baked_mesh(name: str):
    """The baked object ``<name>_baked``: world vertex positions (V,3), Penumbra's colours
    (V,3) and its triangles (T,3) as vertex indices."""
    import bpy

    from penumbra.blender.import_ import ATTRIBUTE

    ob = bpy.data.objects[name + "_baked"]
    me = ob.data
    n = len(me.vertices)
    co = np.empty(n * 3)
    me.vertices.foreach_get("co", co)
    mw = np.array(ob.matrix_world)
    co = co.reshape(-1, 3) @ mw[:3, :3].T + mw[:3, 3]
    col = np.empty(n * 4, dtype=np.float32)
    me.color_attributes[ATTRIBUTE].data.foreach_get("color", col)
    col = col.reshape(-1, 4)[:, :3].astype(np.float64)
    me.calc_loop_triangles()
    tri = np.empty(len(me.loop_triangles) * 3, dtype=np.int64)
    me.loop_triangles.foreach_get("vertices", tri)
    return co, col, tri.reshape(-1, 3)


def baked_colors_at(name: str, pos):
    """Penumbra's colours of the baked object ``<name>_baked`` at the world points ``pos``
    (each must be one of its vertices: its triangles conform to every input polygon)."""
    co, col, _ = baked_mesh(name)
    d = np.linalg.norm(pos[:, None, :] - co[None, :, :], axis=2)
    nearest = d.argmin(axis=1)
    assert np.all(d[np.arange(len(pos)), nearest] < 1e-5), f"{name}: a grid vertex is not in the bake"
    return col[nearest]


def noise_free_rel_rms(ours, a, b):
    """Relative RMS of ``ours`` against the mean of two Cycles bakes ``a`` and ``b`` (other
    seeds), with the variance of that mean, (a − b)²/4, taken out of the squared error; and
    the reference's own noise on the same scale."""
    ref = 0.5 * (a + b)
    e = ours - ref
    noise = float(np.sum((a - b) ** 2)) / 4.0
    rms = np.sqrt(max(float(np.sum(e * e)) - noise, 0.0) / e.size) / ref.mean()
    return rms, np.sqrt(noise / e.size) / ref.mean()


def add_block(lo, hi, color, name: str = "Block", material: str = "Block"):
    """An axis-aligned box from ``lo`` to ``hi`` with outward faces and a Lambertian material."""
    import bpy

    (x0, y0, z0), (x1, y1, z1) = lo, hi
    verts = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
             (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    me.materials.append(diffuse_material(material, color))
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob
