"""Per-polygon albedo and emission from Blender materials, as Cycles' Diffuse bake sees them.

``polygon_colors(obj_eval, mesh)`` → ``(albedo, emission)``, two (P, 3) float64 arrays of
linear RGB, P = ``len(mesh.polygons)``, from each polygon's material (``material_index``).

What "albedo" means here: the colour Cycles' Diffuse bake multiplies the lighting by (the
COLOR pass of a DIFFUSE bake, i.e. the summed weight of the diffuse closures seen from the
surface normal, which is the direction a bake looks from). Measured with bpy 5.0.1:

* Diffuse BSDF: its Color. (Roughness > 0 makes it Oren–Nayar: a different angular shape,
  same colour; the radiosity is Lambertian regardless.)
* Principled BSDF (Blender 4.x/5.0 layering, intern/cycles/kernel/svm/closure.h):
      albedo = Base Color · (1 − Metallic) · (1 − Transmission Weight) · Alpha
               · (1 − E_spec(Roughness, F0)) · coat
  - the diffuse base sits under a dielectric specular layer which takes away its albedo
    E_spec seen from the normal. F0 = ((IOR − 1)/(IOR + 1))² · 2 · Specular IOR Level
    (0.5 is neutral). E_spec = F0 · g(Roughness, F0) with g measured from Cycles bakes
    (table below: g = 1 for a mirror-smooth layer, 0.93 at the default roughness 0.5, 0.34
    at roughness 1); Cycles gets it from its precomputed microfacet albedo tables. So the
    default Principled (0.8 base, roughness 0.5, IOR 1.5) gives 0.770, not 0.8.
  - coat = (1 − w·E_spec(Coat Roughness, F0(Coat IOR))) · (1 − w + w·Coat Tint), w = Coat
    Weight (the tint is crossed once along the normal).
  - sheen sits on top of everything and counts as diffuse colour itself:
    albedo ← (1 − s·E_sheen(Sheen Roughness)) · albedo + s·E_sheen · Sheen Tint, s = Sheen
    Weight, E_sheen measured likewise (0 for roughness ≤ 0.2, 0.019 at 0.5, 0.34 at 1).
  - Specular Tint, Subsurface Weight (subsurface counts as diffuse) and Diffuse Roughness
    do not change the colour.
* Emission shader: emission = Color · Strength (radiance, W·sr⁻¹·m⁻², what Cycles' Emit bake
  gives, and what lights other surfaces: an emissive quad lights a receiver exactly like a
  polygon light of that radiance — tested); albedo 0. Principled: emission = Emission Color ·
  Emission Strength. NOTE: Cycles' mesh emission is two-sided (tested: flipping the quad
  changes nothing); the core makes each emissive face an area light on both sides
  (`scene/emitters.rs`; tests/test_emitters_cycles.py checks it against Cycles).
* Mix Shader: (1 − Fac) · A + Fac · B; Add Shader: A + B (both for albedo and emission).
* Other BSDFs (Glossy, Glass, Refraction, Translucent, Transparent, Toon, Sheen, hair,
  Metallic): no diffuse closure → albedo 0. Subsurface Scattering: albedo = Color.
* No material, an empty slot, or a material without a usable output: Blender's default
  surface, a default Principled BSDF with base 0.8 → albedo 0.770 (measured), no emission.

Inputs: an unlinked socket gives its value; a socket linked to an Image Texture gives the mean
of the image's pixels in linear space (sRGB images are linearised per pixel before averaging;
the texture's UV mapping is not looked at: it is a per-material mean); to an RGB node its
colour; a Reroute is followed. Anything else linked (procedural textures, math, groups) falls
back to the socket's own value, and a message is appended to ``warnings`` if given.
"""
from __future__ import annotations

import numpy as np

__all__ = ["polygon_colors", "material_colors", "principled_diffuse_albedo",
           "specular_layer_albedo", "sheen_layer_albedo", "DEFAULT_ALBEDO"]

# g(r, F0) = E_spec / F0: the normal-incidence albedo of Cycles' dielectric specular layer
# over F0, at Principled roughness r = 0, 0.1, ..., 1 (rows) for F0 = 0.04, 1/9, 0.25
# (IOR 1.5, 2, 3). Measured with bpy 5.0.1: DIFFUSE bake, COLOR pass only, of a white
# Principled BSDF (g = (1 − colour) / F0). Interpolated bilinearly (F0 clamped to the range).
_G_ROUGHNESS = np.linspace(0.0, 1.0, 11)
_G_F0 = np.array([0.04, 1.0 / 9.0, 0.25])
_G_TABLE = np.array([
    [1.0, 0.99995, 0.99891, 0.99383, 0.97659, 0.93462, 0.85514, 0.73798, 0.59967, 0.46284, 0.34466],
    [1.0, 0.99993, 0.99874, 0.99309, 0.97517, 0.93311, 0.85575, 0.74333, 0.61086, 0.47896, 0.36334],
    [1.0, 0.99993, 0.99878, 0.99332, 0.97665, 0.93806, 0.86768, 0.76502, 0.64220, 0.51704, 0.40388],
])

# Normal-incidence albedo of the sheen layer at Sheen Roughness 0, 0.1, ..., 1, measured
# likewise (black base, white tint, Sheen Weight 1: the colour is E_sheen itself).
_SHEEN_E = np.array([0.0, 0.0, 7.4e-05, 0.000796, 0.004892, 0.018645, 0.05043, 0.104127,
                     0.175888, 0.257708, 0.34187])


def sheen_layer_albedo(roughness: float) -> float:
    """Albedo, seen from the normal, of Cycles' Principled sheen layer (see ``_SHEEN_E``)."""
    return float(np.interp(float(np.clip(roughness, 0.0, 1.0)), _G_ROUGHNESS, _SHEEN_E))


def specular_layer_albedo(roughness: float, f0: float) -> float:
    """Albedo, seen from the normal, of Cycles' dielectric specular layer with reflectance
    ``f0`` at normal incidence and Principled ``roughness`` (see ``_G_TABLE``)."""
    r = float(np.clip(roughness, 0.0, 1.0))
    f = float(np.clip(f0, 0.0, 1.0))
    rows = np.array([np.interp(r, _G_ROUGHNESS, row) for row in _G_TABLE])
    g = float(np.interp(f, _G_F0, rows))
    return min(f * g, 1.0)


def _f0_from_ior(ior: float) -> float:
    ior = max(float(ior), 1e-6)
    return ((ior - 1.0) / (ior + 1.0)) ** 2


def principled_diffuse_albedo(base_color, metallic=0.0, transmission=0.0, roughness=0.5,
                              ior=1.5, specular_ior_level=0.5, alpha=1.0, coat_weight=0.0,
                              coat_roughness=0.03, coat_ior=1.5, coat_tint=(1.0, 1.0, 1.0),
                              sheen_weight=0.0, sheen_roughness=0.5, sheen_tint=(1.0, 1.0, 1.0)):
    """The diffuse colour Cycles bakes for a Principled BSDF (see the module docstring)."""
    base = np.asarray(base_color, dtype=np.float64)[:3]
    m = float(np.clip(metallic, 0.0, 1.0))
    t = float(np.clip(transmission, 0.0, 1.0))
    a = float(np.clip(alpha, 0.0, 1.0))
    f0 = _f0_from_ior(ior) * 2.0 * max(float(specular_ior_level), 0.0)
    albedo = base * (1.0 - m) * (1.0 - t) * a * (1.0 - specular_layer_albedo(roughness, f0))
    w = float(np.clip(coat_weight, 0.0, 1.0))
    if w > 0.0:
        e_coat = specular_layer_albedo(coat_roughness, _f0_from_ior(coat_ior))
        tint = np.asarray(coat_tint, dtype=np.float64)[:3]
        albedo = albedo * (1.0 - w * e_coat) * (1.0 - w + w * tint)
    s = float(np.clip(sheen_weight, 0.0, 1.0)) * sheen_layer_albedo(sheen_roughness)
    if s > 0.0:
        albedo = (1.0 - s) * albedo + s * np.asarray(sheen_tint, dtype=np.float64)[:3]
    return albedo


#: What Cycles bakes for a surface without material (a default Principled, base 0.8).
DEFAULT_ALBEDO = principled_diffuse_albedo((0.8, 0.8, 0.8))

_NO_DIFFUSE = {
    "ShaderNodeBsdfGlossy", "ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction",
    "ShaderNodeBsdfTranslucent", "ShaderNodeBsdfTransparent", "ShaderNodeBsdfToon",
    "ShaderNodeBsdfSheen", "ShaderNodeBsdfHair", "ShaderNodeBsdfHairPrincipled",
    "ShaderNodeBsdfAnisotropic", "ShaderNodeBsdfMetallic", "ShaderNodeBsdfRayPortal",
    "ShaderNodeHoldout", "ShaderNodeVolumeAbsorption", "ShaderNodeVolumeScatter",
    "ShaderNodeVolumePrincipled",
}


def _srgb_to_linear(c):
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


_LINEAR_SPACES = {"Non-Color", "Linear Rec.709", "Linear", "Linear CIE-XYZ E", "Raw",
                  "Linear Rec.2020", "Linear FilmLight E-Gamut", "ACEScg", "ACES2065-1"}


def _image_mean(image, warn) -> np.ndarray:
    """Mean RGB of an image's pixels in linear space."""
    n = len(image.pixels)
    if n == 0:
        warn(f"image '{image.name}' has no pixels; using black")
        return np.zeros(3)
    px = np.empty(n, dtype=np.float32)
    image.pixels.foreach_get(px)
    ch = max(int(image.channels), 1)
    rgb = px.reshape(-1, ch)[:, :3].astype(np.float64)
    if rgb.shape[1] < 3:
        rgb = np.repeat(rgb[:, :1], 3, axis=1)
    space = image.colorspace_settings.name
    if not image.is_float:
        if space == "sRGB":
            rgb = _srgb_to_linear(rgb)
        elif space not in _LINEAR_SPACES:
            warn(f"image '{image.name}': colour space '{space}' treated as sRGB")
            rgb = _srgb_to_linear(rgb)
    return rgb.mean(axis=0)


def _follow(sock):
    """The (node, output socket) feeding ``sock``, through reroutes; None if unlinked."""
    seen = 0
    while sock.is_linked and seen < 64:
        link = sock.links[0]
        if not link.is_valid or getattr(link, "is_muted", False):
            return None
        node = link.from_node
        if node.bl_idname == "NodeReroute":
            sock = node.inputs[0]
            seen += 1
            continue
        return node, link.from_socket
    return None


def _rgb(sock, warn, where) -> np.ndarray:
    src = _follow(sock)
    if src is None:
        v = sock.default_value
        try:
            return np.array(v[:3], dtype=np.float64)
        except TypeError:
            return np.full(3, float(v))
    node, out = src
    if node.bl_idname == "ShaderNodeTexImage" and node.image is not None:
        if out.name == "Alpha":
            warn(f"{where}: '{sock.name}' uses an image's alpha; using its socket value")
        else:
            return _image_mean(node.image, warn)
    elif node.bl_idname == "ShaderNodeRGB":
        return np.array(node.outputs[0].default_value[:3], dtype=np.float64)
    warn(f"{where}: '{sock.name}' is driven by '{node.name}' ({node.bl_idname}); using the socket's own value")
    v = sock.default_value
    try:
        return np.array(v[:3], dtype=np.float64)
    except TypeError:
        return np.full(3, float(v))


def _float(sock, warn, where) -> float:
    src = _follow(sock)
    if src is not None:
        node, _ = src
        if node.bl_idname == "ShaderNodeValue":
            return float(node.outputs[0].default_value)
        warn(f"{where}: '{sock.name}' is driven by '{node.name}' ({node.bl_idname}); using the socket's own value")
    v = sock.default_value
    try:
        return float(v)
    except TypeError:
        return float(np.mean(v[:3]))


def _closure(sock, warn, where, depth=0):
    """(albedo, emission) of the shader plugged into ``sock``."""
    zero = np.zeros(3)
    src = _follow(sock)
    if src is None:
        return zero, zero
    node, _ = src
    if depth > 32:
        warn(f"{where}: shader tree too deep")
        return zero, zero
    t = node.bl_idname
    inp = node.inputs
    if t == "ShaderNodeBsdfDiffuse":
        return _rgb(inp["Color"], warn, where), zero
    if t == "ShaderNodeSubsurfaceScattering":
        return _rgb(inp["Color"], warn, where), zero
    if t == "ShaderNodeEmission":
        return zero, _rgb(inp["Color"], warn, where) * _float(inp["Strength"], warn, where)
    if t == "ShaderNodeBsdfPrincipled" and "Transmission Weight" not in inp:
        # Blender < 4.0 (Principled v1, e.g. Debian's 3.4): its diffuse lobe is the base
        # colour times (1 − metallic)(1 − transmission), with no specular energy taken off.
        f = lambda name: _float(inp[name], warn, where)  # noqa: E731
        albedo = (_rgb(inp["Base Color"], warn, where) * (1.0 - f("Metallic"))
                  * (1.0 - f("Transmission")) * f("Alpha"))
        emission = _rgb(inp["Emission"], warn, where) * f("Emission Strength")
        return np.clip(albedo, 0.0, 1.0), emission
    if t == "ShaderNodeBsdfPrincipled":
        f = lambda name: _float(inp[name], warn, where)  # noqa: E731
        albedo = principled_diffuse_albedo(
            _rgb(inp["Base Color"], warn, where), metallic=f("Metallic"),
            transmission=f("Transmission Weight"), roughness=f("Roughness"), ior=f("IOR"),
            specular_ior_level=f("Specular IOR Level"), alpha=f("Alpha"),
            coat_weight=f("Coat Weight"), coat_roughness=f("Coat Roughness"),
            coat_ior=f("Coat IOR"), coat_tint=_rgb(inp["Coat Tint"], warn, where),
            sheen_weight=f("Sheen Weight"), sheen_roughness=f("Sheen Roughness"),
            sheen_tint=_rgb(inp["Sheen Tint"], warn, where))
        emission = _rgb(inp["Emission Color"], warn, where) * f("Emission Strength")
        return albedo, emission
    if t == "ShaderNodeMixShader":
        fac = float(np.clip(_float(inp[0], warn, where), 0.0, 1.0))
        a0, e0 = _closure(inp[1], warn, where, depth + 1)
        a1, e1 = _closure(inp[2], warn, where, depth + 1)
        return (1.0 - fac) * a0 + fac * a1, (1.0 - fac) * e0 + fac * e1
    if t == "ShaderNodeAddShader":
        a0, e0 = _closure(inp[0], warn, where, depth + 1)
        a1, e1 = _closure(inp[1], warn, where, depth + 1)
        return a0 + a1, e0 + e1
    if t in _NO_DIFFUSE:
        return zero, zero
    warn(f"{where}: shader node '{node.name}' ({t}) is not understood; using the default surface")
    return DEFAULT_ALBEDO.copy(), zero


def material_colors(material, warnings: list | None = None):
    """(albedo (3,), emission (3,)) of one material as Cycles' Diffuse bake sees it."""
    def warn(msg):
        if warnings is not None:
            warnings.append(msg)

    if material is None:
        return DEFAULT_ALBEDO.copy(), np.zeros(3)
    where = f"material '{material.name}'"
    nt = material.node_tree
    if nt is None:
        # No node tree: Cycles renders a Diffuse BSDF of the viewport colour
        # (intern/cycles/blender/shader.cpp, BlenderSync::sync_materials). Blender 5.0 ignores
        # use_nodes = False (measured: the node tree is still used), so we ignore it too.
        return np.array(material.diffuse_color[:3], dtype=np.float64), np.zeros(3)
    outs = [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputMaterial"
            and getattr(n, "target", "ALL") in {"ALL", "CYCLES"}]
    active = [n for n in outs if getattr(n, "is_active_output", False)] or outs
    if not active:
        warn(f"{where}: no material output; using the default surface")
        return DEFAULT_ALBEDO.copy(), np.zeros(3)
    return _closure(active[0].inputs["Surface"], warn, where)


def polygon_colors(obj_eval, mesh, warnings: list | None = None):
    """(albedo (P,3), emission (P,3)) linear RGB per polygon of ``mesh``, from the material
    each polygon's ``material_index`` picks on ``obj_eval`` (clamped to the last slot, as
    Blender does). One evaluation per material, then numpy indexing: no per-polygon Python."""
    P = len(mesh.polygons)
    slots = [s.material for s in getattr(obj_eval, "material_slots", [])]
    if not slots:
        slots = list(getattr(mesh, "materials", []))
    if not slots:
        slots = [None]
    table_a = np.empty((len(slots), 3))
    table_e = np.empty((len(slots), 3))
    for i, mat in enumerate(slots):
        table_a[i], table_e[i] = material_colors(mat, warnings)
    if P == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    idx = np.zeros(P, dtype=np.int32)
    mesh.polygons.foreach_get("material_index", idx)
    np.clip(idx, 0, len(slots) - 1, out=idx)
    return table_a[idx], table_e[idx]
