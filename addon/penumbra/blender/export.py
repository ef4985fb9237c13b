"""Blender → scene arrays for ``penumbra._core``: the selected meshes evaluated with their
modifiers, in world space, and the lights in scene-JSON form. Only numpy and
``foreach_get`` touch mesh data; nothing here changes the Blender scene.
"""

import bpy
import numpy as np

from ..io.lights import UnsupportedLightError, lights_to_scene
from ..io.materials import polygon_colors
from ..io.world import world_radiance
from ..io.scene import LIGHTMAP_UV, MESH_TYPES, SOURCE_KEY, ExportError, loop_order, polygon_area, settings_dict

__all__ = ["LIGHTMAP_UV", "SOURCE_KEY", "ExportError", "Export", "export_scene"]

class Export:
    """What a bake needs: the scene for the core and the source objects, in mesh order."""

    def __init__(self, scene, sources, lights, warnings):
        self.scene = scene
        self.sources = sources
        self.lights = lights
        # Material features approximated on the way out (from materials.polygon_colors).
        self.warnings = warnings


def export_scene(context, settings, objects=None):
    """Builds the scene dict from the selection of ``context`` (or from ``objects``).

    Lights are the selected lights, or every visible light when none is selected.
    Raises ``ExportError`` on bad input.
    """
    if objects is None:
        objects = list(context.selected_objects)
    # Every visible mesh takes part (shadows, bounces, emission); the scope and the Shadow
    # Only property decide which get outputs. Earlier bakes never take part: they would lie
    # on top of their sources.
    visible = [
        o
        for o in context.view_layer.objects
        if o.type in MESH_TYPES and o.visible_get() and not o.hide_render and SOURCE_KEY not in o.keys()
    ]
    scope = getattr(settings, "scope", "SELECTED")
    sources = _sources(visible if scope == "VISIBLE" else objects)
    shadow_only = [o for o in sources if getattr(o, "penumbra_shadow_only", False)]
    sources = [o for o in sources if o not in shadow_only]
    if not sources:
        if shadow_only:
            raise ExportError('Nothing to bake: "%s" is set to Shadow Only' % shadow_only[0].name)
        raise ExportError("Nothing selected: select the meshes to bake")
    scenery = [o for o in visible if o not in sources]
    scenery += [o for o in shadow_only if o not in scenery]
    lights = [o for o in objects if o.type == "LIGHT"]
    if not lights:
        lights = [
            o
            for o in context.view_layer.objects
            if o.type == "LIGHT" and o.visible_get() and not o.hide_render
        ]
    depsgraph = context.evaluated_depsgraph_get()

    warnings = []
    want_uv = getattr(settings, "output", "MESH") != "MESH"
    meshes = [_mesh(o, depsgraph, warnings, want_uv) for o in sources]
    # Outputs first: the bake's meshes and ``sources`` are zipped, and the scenery after
    # them has no output.
    for o in scenery:
        m = _mesh(o, depsgraph, warnings, False)
        m["output"] = False
        meshes.append(m)
    meshes.extend(_instances(depsgraph, warnings))
    light_dicts = []
    for o in lights:
        light_dicts.extend(_light(o, depsgraph, warnings))
    emissive = any(np.any(np.asarray(m["emission"]) > 0.0) for m in meshes)
    world = world_radiance(getattr(context.scene, "world", None), warnings)
    if not light_dicts and not emissive and world is None:
        skipped = [w for w in warnings if w.endswith("left out of this bake")]
        if skipped:
            raise ExportError("No usable lights: %s" % skipped[0])
        raise ExportError("No lights: add a light or select one (or give a material emission, or the world a colour)")

    outputs = [m for m in meshes if m.get("output", True)]
    scene = {"meshes": meshes, "lights": light_dicts, "settings": settings_dict(settings, outputs)}
    if world is not None:
        scene["settings"]["world"] = world
    return Export(scene, sources, lights, warnings)


# Instances past this many are left out (one warning): each is a mesh of its own in the bake.
MAX_INSTANCES = 10000


def _instances(depsgraph, warnings):
    """Meshes that exist only as instances (collection instances, Geometry Nodes instances,
    particles), realised in world space as scenery: they cast shadows and reflect light but
    get no output. An instance's object is valid only while the iteration is on it, so each
    mesh is read at once."""
    out = []
    for inst in depsgraph.object_instances:
        if not inst.is_instance or inst.object is None or inst.object.type not in MESH_TYPES:
            continue
        if not inst.show_self:
            continue
        if len(out) >= MAX_INSTANCES:
            warnings.append("more than %d instances: the rest are left out of this bake" % MAX_INSTANCES)
            break
        ob = inst.object
        parent = inst.parent.name if inst.parent is not None else "?"
        m = _mesh(ob, depsgraph, warnings, False, matrix=inst.matrix_world.copy(),
                  name="%s (instance %d in %s)" % (ob.name, len(out), parent))
        m["output"] = False
        out.append(m)
    return out


def _sources(objects):
    """The meshes to bake. A baked object stands for its source, so that selecting a bake
    and baking again re-bakes the (possibly hidden) original; baked objects themselves are
    never baked, they would lie on top of their sources."""
    out = []
    for o in objects:
        if o.type not in MESH_TYPES:
            continue
        if SOURCE_KEY in o.keys():
            o = bpy.data.objects.get(o[SOURCE_KEY])
            if o is None or o.type not in MESH_TYPES:
                continue
        if o not in out:
            out.append(o)
    return out


def _mesh(obj, depsgraph, warnings, want_uv=False, matrix=None, name=None):
    """The mesh dict of ``obj`` as evaluated (modifiers applied), in world space; for an
    instance, ``obj`` is the instance's evaluated object, placed by ``matrix``."""
    obj_eval = obj if matrix is not None else obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        n_vert = len(mesh.vertices)
        co = np.empty(n_vert * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
        local = co.reshape(-1, 3).astype(np.float64)
        m = np.array(obj_eval.matrix_world if matrix is None else matrix, dtype=np.float64)
        positions = local @ m[:3, :3].T + m[:3, 3]
        bad = ~np.isfinite(positions).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ExportError(
                'Object "%s": vertex positions: vertex %d is %s (not a finite number)'
                % (obj.name, i, tuple(float(x) for x in local[i]))
            )

        n_poly = len(mesh.polygons)
        starts = np.empty(n_poly, dtype=np.int64)
        counts = np.empty(n_poly, dtype=np.int64)
        mesh.polygons.foreach_get("loop_start", starts)
        mesh.polygons.foreach_get("loop_total", counts)
        loop_vert = np.empty(len(mesh.loops), dtype=np.int64)
        mesh.loops.foreach_get("vertex_index", loop_vert)
        order = loop_order(starts, counts, np.linalg.det(m[:3, :3]) < 0.0)
        polygon_vertices = loop_vert[order]

        albedo, emission = polygon_colors(obj_eval, mesh, warnings)
        out = {
            "name": name or obj.name,
            "positions": positions,
            "polygon_vertices": polygon_vertices,
            "polygon_counts": counts,
            "albedo": np.asarray(albedo, dtype=np.float64).reshape(-1, 3),
            "emission": np.asarray(emission, dtype=np.float64).reshape(-1, 3),
        }
        if want_uv:
            out["uv"] = _lightmap_uv(obj, mesh, order)
        return out
    finally:
        obj_eval.to_mesh_clear()


def _lightmap_uv(obj, mesh, order):
    """The "Lightmap" UV of each polygon corner, in the order of ``polygon_vertices``."""
    layer = mesh.uv_layers.get(LIGHTMAP_UV)
    if layer is None:
        raise ExportError('Object "%s": UV map "%s": missing (a modifier removed it?)' % (obj.name, LIGHTMAP_UV))
    uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    if hasattr(layer, "uv"):  # Blender >= 3.5
        layer.uv.foreach_get("vector", uv)
    else:
        layer.data.foreach_get("uv", uv)
    return uv.reshape(-1, 2).astype(np.float64)[order]


def _light(obj, depsgraph, warnings):
    light = obj.data
    if light.type == "AREA":
        sizes = [("size", light.size)]
        if light.shape in {"RECTANGLE", "ELLIPSE"}:
            sizes.append(("size_y", light.size_y))
        for field, value in sizes:
            if not value > 0.0:
                raise ExportError('Light "%s": %s is %g: an area light needs a size above 0' % (obj.name, field, value))
        scale = obj.matrix_world.to_scale()
        if abs(scale.x * scale.y) <= 0.0:
            raise ExportError('Light "%s": scale: the area light is scaled to zero size' % obj.name)
    try:
        dicts = lights_to_scene(obj, depsgraph)
    except UnsupportedLightError as e:
        # A feature the bake cannot model (spread, shadowless, light linking, a textured
        # light): the light is left out with one warning, and the rest of the bake goes on.
        warnings.append("%s; the light is left out of this bake" % e)
        return []
    except ValueError as e:  # bad light data; names light and field
        raise ExportError(str(e))
    for d in dicts:
        polygon = d.get("polygon")
        if polygon is not None and polygon_area(np.asarray(polygon, dtype=np.float64)) <= 0.0:
            raise ExportError('Light "%s": size: the light polygon has no area' % obj.name)
    return dicts
