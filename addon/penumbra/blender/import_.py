"""Bake arrays → new Blender objects ``<name>_baked`` in the collection "Penumbra Bake",
with the baked colour as the FLOAT_COLOR point attribute "Radiosity" and a material that
shows it as emission, so that any engine displays the bake as it is.
"""

import bpy
import numpy as np

from .export import SOURCE_KEY

COLLECTION = "Penumbra Bake"
ATTRIBUTE = "Radiosity"
SOURCE_ATTRIBUTE = "penumbra_source_polygon"
MATERIAL = "Penumbra Radiosity"


def import_bake(context, result, sources, hide_originals=False):
    """Creates one object per baked mesh and returns them. ``sources`` are the original
    objects in the order of ``result["meshes"]``. A previous bake of the same object in the
    bake collection is replaced."""
    collection = _collection(context.scene)
    material = _material()
    created = []
    for baked, source in zip(result["meshes"], sources):
        name = source.name + "_baked"
        old = collection.objects.get(name)
        if old is not None:
            _remove(old)
        mesh = _mesh(name, baked)
        mesh.materials.append(material)
        obj = bpy.data.objects.new(name, mesh)
        obj[SOURCE_KEY] = source.name
        collection.objects.link(obj)
        created.append(obj)
    if hide_originals:
        for source in sources:
            source.hide_render = True
            try:
                source.hide_set(True)
            except RuntimeError:  # not in the current view layer: render hiding is enough
                pass
    return created


def _collection(scene):
    coll = bpy.data.collections.get(COLLECTION)
    if coll is None:
        coll = bpy.data.collections.new(COLLECTION)
    if scene.collection.children.get(coll.name) is None:
        scene.collection.children.link(coll)
    return coll


def _remove(obj):
    mesh = obj.data
    bpy.data.objects.remove(obj)
    if mesh is not None and mesh.users == 0:
        bpy.data.meshes.remove(mesh)


def _mesh(name, baked):
    positions = np.ascontiguousarray(baked["positions"], dtype=np.float32)
    triangles = np.ascontiguousarray(baked["triangles"], dtype=np.int32)
    colors = np.asarray(baked["colors"], dtype=np.float32)
    n_vert, n_tri = len(positions), len(triangles)

    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(n_vert)
    mesh.vertices.foreach_set("co", positions.ravel())
    mesh.loops.add(3 * n_tri)
    mesh.loops.foreach_set("vertex_index", triangles.ravel())
    mesh.polygons.add(n_tri)
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * n_tri, 3, dtype=np.int32))
    if not bpy.types.MeshPolygon.bl_rna.properties["loop_total"].is_readonly:
        # Blender < 4.0 keeps loop_total per polygon; later versions derive it from loop_start.
        mesh.polygons.foreach_set("loop_total", np.full(n_tri, 3, dtype=np.int32))
    mesh.update(calc_edges=True)

    rgba = np.ones((n_vert, 4), dtype=np.float32)
    rgba[:, :3] = colors
    attr = mesh.color_attributes.new(ATTRIBUTE, "FLOAT_COLOR", "POINT")
    attr.data.foreach_set("color", rgba.ravel())
    _make_active_colour(mesh, attr)

    source = mesh.attributes.new(SOURCE_ATTRIBUTE, "INT", "FACE")
    source.data.foreach_set("value", np.asarray(baked["source_polygon"], dtype=np.int32))
    return mesh


def _make_active_colour(mesh, attr):
    colors = mesh.color_attributes
    index = next(i for i, a in enumerate(colors) if a.name == attr.name)
    colors.active_color = attr
    colors.render_color_index = index
    if hasattr(colors, "active_color_name"):  # Blender >= 3.5 names them too
        colors.active_color_name = attr.name
        colors.default_color_name = attr.name
    mesh.attributes.active = attr


def _material():
    mat = bpy.data.materials.get(MATERIAL)
    if mat is not None:
        return mat
    mat = bpy.data.materials.new(MATERIAL)
    if bpy.app.version < (5, 0, 0):  # node trees are always on from Blender 5
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.clear()
    attr = tree.nodes.new("ShaderNodeAttribute")
    attr.attribute_type = "GEOMETRY"
    attr.attribute_name = ATTRIBUTE
    attr.location = (-400, 0)
    emit = tree.nodes.new("ShaderNodeEmission")
    emit.inputs["Strength"].default_value = 1.0
    emit.location = (-150, 0)
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    out.location = (100, 0)
    tree.links.new(attr.outputs["Color"], emit.inputs["Color"])
    tree.links.new(emit.outputs["Emission"], out.inputs["Surface"])
    return mat
