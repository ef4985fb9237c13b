"""Blender lights → scene-JSON light dicts, in the units Cycles uses.

``lights_to_scene(obj, depsgraph)`` turns one Blender light object into the light dicts of the
scene JSON (world space, see DESIGN.md), such that an unoccluded Lambertian receiver gets the
irradiance Cycles gives it. Every formula below is taken from Cycles' source (Blender 5.0) and
checked against an actual Cycles bake in ``tests/test_cycles_lights.py``.

Strength (all types), ``S`` in the formulas below
    S = color · energy · 2^exposure · temperature_color (when ``use_temperature``; ``color``
    is then the tint) · light-node Emission colour·strength (when the light uses nodes).
    Blender's sync gives Cycles ``strength = color · energy`` (intern/cycles/blender/light.cpp,
    ``BlenderSync::sync_light``); exposure and the blackbody colour multiply it as the UI
    labels say ("Tint" when temperature is on). ``Light.temperature_color`` is the blackbody
    colour Blender computes for ``temperature``, so we read it rather than recompute it.

Conversion of S (intern/cycles/scene/light.cpp, ``LightManager::device_update_lights`` and
``Light::area``; the kernel side in intern/cycles/kernel/light/{area,point,spot,distant}.h)
    AREA   radiance  L = S / (π · A)   (normalize on), L = S / π (normalize off)
           A = |X|·|Y|·size_x·size_y of the world matrix columns X, Y, times π/4 for
           DISK/ELLIPSE (``Light::area``). "Convert radiant flux to radiance": eval_fac = 1/(π A).
    POINT  intensity I = S / (4π)   (normalize on; ``Light::area`` is 4πr², or 4 for r = 0,
           and eval_fac = invarea / π; for r = 0 eval_fac is used as intensity, for r > 0 as
           the radiance of a sphere of projected area πr²: both give S/(4π)).
           normalize off: I = S/π for r = 0, I = S · r² for r > 0.
    SPOT   as POINT, times Cycles' cone mask (kernel/light/spot.h, spot_light_attenuation):
           mask = smoothstep(clamp((cos θ − cos(angle/2)) / ((1 − cos(angle/2)) · blend), 0, 1))
           with smoothstep(x) = 3x² − 2x³ and θ the angle between the spot axis and the
           direction from the light to the receiver; blend = 0 is a hard cone.
    SUN    irradiance on a surface facing the sun E⊥ = S (normalize on: eval_fac = 1/area with
           area = π sin²(angle/2), the projected solid angle of the sun disk);
           normalize off and angle > 0: E⊥ = S · π · sin²(angle/2).

Shapes and orientation
    An area light spans the world-matrix columns X, Y around the object origin (so object
    scale, rotation and parents apply) and emits along −Z of its world matrix. SQUARE and
    RECTANGLE become a 4-gon; DISK and ELLIPSE a regular ``disk_segments``-gon (affinely
    stretched for ellipses) scaled so its AREA EQUALS the ellipse's (πab): the flux and the
    far field are exact, the near field differs by O(1/N²). Vertices run counter-clockwise
    seen from the emitting side (Blender's and the scene JSON's front rule), also for
    mirrored (negative-determinant) matrices.

Approximations (documented, not errors)
    * POINT/SPOT ``shadow_soft_size`` (radius) r > 0: exported with the scene JSON's
      ``radius``, a round light with soft shadows. With soft falloff (the default) Cycles
      uses a disk of radius r facing the receiver (kernel/light/point.h), which gives
      exactly I·cos/(d² + r²) unoccluded (tested); with ``use_soft_falloff`` off a sphere
      (``"sphere": true``), whose irradiance on a receiver that sees the whole sphere is
      exactly I·cos/d² (tested). The core clips the disc facing each point against the
      occluders (a 48-gon). A spot's cone is applied from the light's centre.
    * SUN ``angle``: exported as the scene JSON's ``angle``, a disc of that angular diameter
      with soft shadows. Unoccluded receivers get exactly E⊥·cos while the sun disk is
      entirely above their horizon.
    * ``diffuse_factor`` (and the other influence factors) are EEVEE-only: Cycles ignores them
      (Blender's UI shows them for EEVEE only; the test proves Cycles ignores it), so do we.
    * ``cycles.max_bounces`` of a light only limits indirect light; ignored.
    * Spot ``use_square`` is not supported by Cycles (circular cone), so it is ignored.

Contributes nothing (returns [])
    ``visible_diffuse`` off on the light object (Cycles excludes the light from diffuse
    surfaces: SHADER_EXCLUDE_DIFFUSE in scene/light.cpp ``light_object_shader_flags``),
    portals, zero strength, zero-area area lights, a node tree whose output has no emission.

Unsupported (raises ``UnsupportedLightError``, a ValueError naming the light and the field)
    * AREA ``spread`` < 180°: Cycles then weights emission by direction
      (kernel/light/area.h, area_light_spread_attenuation: max((tan(spread/2) − tan α) ·
      normalize_spread, 0), a soft-box grid), so the light is no longer a uniform-radiance
      polygon. It narrows the beam: receivers far off the light's axis get less, or nothing.
    * ``use_shadow`` off (the scene JSON has no shadowless lights).
    * SPOT with non-uniform world scale (Cycles then makes an elliptical cone).
    * light-node trees other than one Emission node with unlinked inputs into the output.
    * light linking / shadow linking collections on the light object.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["lights_to_scene", "UnsupportedLightError", "light_strength", "DEFAULT_DISK_SEGMENTS"]

#: Sides of the polygon standing in for a disk or ellipse area light.
DEFAULT_DISK_SEGMENTS = 32

_FULL_SPREAD = math.pi
_SCALE_TOL = 1e-5


class UnsupportedLightError(ValueError):
    """A light uses a feature the scene JSON cannot represent exactly."""

    def __init__(self, light_name: str, field: str, why: str):
        self.light_name = light_name
        self.field = field
        super().__init__(f"light '{light_name}': unsupported {field}: {why}")


def _node_factor(name: str, light) -> np.ndarray | None:
    """Colour·strength of a light's node tree, 1 without nodes, None if it emits nothing.

    Only the simplest tree is supported: an Emission node with unlinked Color and Strength
    linked into the active Light Output. Cycles multiplies the light's strength by the
    emission closure's weight (the default light shader is an Emission of strength 1).
    """
    if not getattr(light, "use_nodes", False) or light.node_tree is None:
        return np.ones(3)
    nt = light.node_tree
    outs = [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputLight"
            and getattr(n, "target", "ALL") in {"ALL", "CYCLES"}]
    active = [n for n in outs if getattr(n, "is_active_output", False)] or outs
    if not active:
        return None
    surf = active[0].inputs["Surface"]
    if not surf.is_linked:
        return None
    src = surf.links[0].from_node
    if src.bl_idname != "ShaderNodeEmission":
        raise UnsupportedLightError(name, "node_tree",
                                    f"'{src.name}' feeds the light output (only Emission is supported)")
    col, strength = src.inputs["Color"], src.inputs["Strength"]
    for sock in (col, strength):
        if sock.is_linked:
            raise UnsupportedLightError(name, "node_tree",
                                        f"Emission input '{sock.name}' is linked (only constants are supported)")
    return np.array(col.default_value[:3], dtype=np.float64) * float(strength.default_value)


def light_strength(name: str, light) -> np.ndarray | None:
    """S = color · energy · 2^exposure · temperature colour · node factor, RGB; None if the
    node tree emits nothing."""
    node = _node_factor(name, light)
    if node is None:
        return None
    s = np.array(light.color[:3], dtype=np.float64) * float(light.energy)
    s *= 2.0 ** float(getattr(light, "exposure", 0.0))
    if getattr(light, "use_temperature", False):
        s *= np.array(light.temperature_color[:3], dtype=np.float64)
    return s * node


def _regular_polygon_unit(n: int) -> np.ndarray:
    """(n, 2) vertices of a regular n-gon with the area of the unit-diameter disk (π/4),
    running clockwise in (u, v) so that, spanned by +X, +Y, its front faces −Z."""
    # Area of a regular n-gon of circumradius R: n/2 · R² · sin(2π/n). Match π r², r = 1/2.
    R = 0.5 * math.sqrt(2.0 * math.pi / (n * math.sin(2.0 * math.pi / n)))
    a = -2.0 * math.pi * np.arange(n) / n
    return R * np.stack([np.cos(a), np.sin(a)], axis=1)


def _check_linking(name: str, obj) -> None:
    ll = getattr(obj, "light_linking", None)
    if ll is None:
        return
    if getattr(ll, "receiver_collection", None) is not None:
        raise UnsupportedLightError(name, "light_linking.receiver_collection",
                                    "light linking is not supported")
    if getattr(ll, "blocker_collection", None) is not None:
        raise UnsupportedLightError(name, "light_linking.blocker_collection",
                                    "shadow linking is not supported")


def lights_to_scene(obj, depsgraph=None, *, disk_segments: int = DEFAULT_DISK_SEGMENTS) -> list[dict]:
    """Scene-JSON light dicts (world space) for the Blender light object ``obj``.

    Uses the evaluated object (``obj.evaluated_get(depsgraph)``) when a depsgraph is given,
    so animation, drivers and parenting are as rendered. Returns [] for a light that adds
    nothing to diffuse surfaces in Cycles; raises ``UnsupportedLightError`` (a ValueError)
    for a light the scene JSON cannot represent. See the module docstring for the formulas.
    """
    ob = obj.evaluated_get(depsgraph) if depsgraph is not None else obj
    light = ob.data
    name = obj.name
    if getattr(ob, "type", "LIGHT") != "LIGHT":
        raise ValueError(f"object '{name}' is not a light")
    if not getattr(ob, "visible_diffuse", True):
        return []
    if light.type == "AREA" and light.cycles.is_portal:
        return []
    _check_linking(name, ob)
    if not light.use_shadow:
        raise UnsupportedLightError(name, "use_shadow",
                                    "shadowless lights cannot be represented (lights always cast shadows)")
    S = light_strength(name, light)
    if S is None or not np.any(S != 0.0):
        return []
    M = np.array(ob.matrix_world, dtype=np.float64)
    X, Y, Z, co = M[:3, 0], M[:3, 1], M[:3, 2], M[:3, 3]
    lz = np.linalg.norm(Z)
    if lz == 0.0:
        return []
    emit = -Z / lz  # Cycles: dir = −(third column) of the object transform

    if light.type == "AREA":
        return _area(name, light, S, X, Y, co, emit, disk_segments)
    if light.type in {"POINT", "SPOT"}:
        r = float(light.shadow_soft_size)
        if getattr(light, "normalize", True):
            I = S / (4.0 * math.pi)
        else:
            I = S * r * r if r > 0.0 else S / math.pi
        d = {"name": name, "point": co.tolist(), "intensity": I.tolist()}
        if r > 0.0:
            # Soft falloff: a disk of radius r facing the receiver, I·cos/(d² + r²); without
            # it a sphere, I·cos/d². Both cast soft shadows.
            d["radius"] = r
            if not getattr(light, "use_soft_falloff", True):
                d["sphere"] = True
        if light.type == "SPOT":
            lens = np.array([np.linalg.norm(X), np.linalg.norm(Y), lz])
            if np.ptp(lens) > _SCALE_TOL * lens.max():
                raise UnsupportedLightError(name, "scale",
                                            f"non-uniform scale {lens.round(6).tolist()} makes Cycles' spot cone elliptical")
            d["spot"] = {"direction": emit.tolist(), "angle": float(light.spot_size),
                         "blend": float(light.spot_blend)}
        return [d]
    if light.type == "SUN":
        half = 0.5 * float(light.angle)
        E = S if (getattr(light, "normalize", True) or half <= 0.0) else S * math.pi * math.sin(half) ** 2
        d = {"name": name, "direction": emit.tolist(), "irradiance": E.tolist()}
        if half > 0.0:
            d["angle"] = 2.0 * half
        return [d]
    raise UnsupportedLightError(name, "type", f"unknown light type {light.type!r}")


def _area(name, light, S, X, Y, co, emit, disk_segments):
    if getattr(light, "spread", _FULL_SPREAD) < _FULL_SPREAD - 1e-6:
        raise UnsupportedLightError(
            name, "spread",
            f"{math.degrees(light.spread):.1f}° < 180°: Cycles narrows the emission by direction "
            "(not a uniform-radiance polygon)")
    su = float(light.size)
    sv = su if light.shape in {"SQUARE", "DISK"} else float(light.size_y)
    ellipse = light.shape in {"DISK", "ELLIPSE"}
    area = np.linalg.norm(X) * su * np.linalg.norm(Y) * sv
    if ellipse:
        area *= math.pi / 4.0
    if area <= 0.0:
        return []
    L = S / (math.pi * area) if getattr(light, "normalize", True) else S / math.pi
    if ellipse:
        if disk_segments < 3:
            raise ValueError("disk_segments must be at least 3")
        uv = _regular_polygon_unit(disk_segments)
    else:
        uv = 0.5 * np.array([[1.0, 1.0], [1.0, -1.0], [-1.0, -1.0], [-1.0, 1.0]])
    pts = co[None, :] + np.outer(uv[:, 0] * su, X) + np.outer(uv[:, 1] * sv, Y)
    # Front = counter-clockwise side = the emitting side −Z (fix mirrored matrices).
    newell = np.sum(np.cross(pts, np.roll(pts, -1, axis=0)), axis=0)
    if newell @ emit < 0.0:
        pts = pts[::-1]
    return [{"name": name, "polygon": pts.tolist(), "radiance": L.tolist()}]
