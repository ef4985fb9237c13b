"""Materials as a stock glTF viewer needs them, set up only while Blender's glTF exporter
runs and taken back afterwards (the .blend keeps its own materials).

* Baked objects (vertex colours): an unlit material (``KHR_materials_unlit``) whose base
  colour is the "Radiosity" colour attribute, exported as ``COLOR_0``. The exporter
  recognises unlit as "Light Path: Is Camera Ray" mixing into an Emission shader; the
  add-on's own material (Attribute → Emission) would export as a bare
  ``emissiveFactor [1, 1, 1]``, which viewers show white.
* Original objects with lightmaps: each material (a copy of it) shows the lightmap as
  emission on the "Lightmap" UV map, so the file carries the UV map as a ``TEXCOORD_n`` and
  the image as the ``emissiveTexture`` that uses it. glTF images are PNG or JPEG, so the
  exporter stores an 8-bit copy; the float EXR stays beside the .blend.
"""

import contextlib

import bpy

from . import lightmap_preview
from .export import LIGHTMAP_UV
from .import_ import ATTRIBUTE
from .lightmaps import IMAGE_SUFFIX

UNLIT = "Penumbra Radiosity (glTF unlit)"

__all__ = ["unlit_vertex_colours", "lightmapped", "IMAGE_SUFFIX"]


def _unlit_material():
    mat = bpy.data.materials.new(UNLIT)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.clear()
    colour = tree.nodes.new("ShaderNodeVertexColor")
    colour.layer_name = ATTRIBUTE
    emit = tree.nodes.new("ShaderNodeEmission")
    path = tree.nodes.new("ShaderNodeLightPath")
    mix = tree.nodes.new("ShaderNodeMixShader")
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(colour.outputs["Color"], emit.inputs["Color"])
    tree.links.new(path.outputs["Is Camera Ray"], mix.inputs[0])
    tree.links.new(emit.outputs["Emission"], mix.inputs[2])
    tree.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return mat


@contextlib.contextmanager
def unlit_vertex_colours(objects):
    """While active, ``objects`` (baked meshes) wear the unlit vertex-colour material."""
    mat = _unlit_material()
    saved = []
    try:
        for obj in objects:
            saved.append((obj, [s.material for s in obj.material_slots]))
            for slot in obj.material_slots:
                slot.material = mat
        yield
    finally:
        for obj, mats in saved:
            for slot, m in zip(obj.material_slots, mats):
                slot.material = m
        bpy.data.materials.remove(mat)


def _second_uv_map(mesh):
    """Makes the "Lightmap" UV map the mesh's second one, engines' lightmap channel
    (TEXCOORD_1: Godot's UV2, Unity's uv2), when it is the only one: it is renamed and a copy
    made under its name after it. Returns the undo, or None when nothing changed."""
    if len(mesh.uv_layers) != 1 or mesh.uv_layers[0].name != LIGHTMAP_UV:
        return None
    first = mesh.uv_layers[0]
    first.name = "UVMap"
    copy = mesh.uv_layers.new(name=LIGHTMAP_UV)
    data = [0.0] * (2 * len(mesh.loops))
    first.data.foreach_get("uv", data)
    copy.data.foreach_set("uv", data)

    def undo():
        mesh.uv_layers.remove(mesh.uv_layers[LIGHTMAP_UV])
        mesh.uv_layers["UVMap"].name = LIGHTMAP_UV

    return undo


@contextlib.contextmanager
def lightmapped(objects, images):
    """While active, each object's materials are copies showing its lightmap image, and
    the "Lightmap" UV map is the mesh's second one."""
    copies, saved, added, undos = [], [], [], []
    try:
        for obj, image in zip(objects, images):
            undo = _second_uv_map(obj.data)
            if undo is not None:
                undos.append(undo)
            saved.append((obj, [s.material for s in obj.material_slots]))
            if not obj.material_slots:
                mat = bpy.data.materials.new(obj.name + " (lightmap)")
                if bpy.app.version < (5, 0, 0):
                    mat.use_nodes = True
                obj.data.materials.append(mat)
                added.append(obj)
                copies.append(mat)
            for slot in obj.material_slots:
                if slot.material is None:
                    continue
                mat = slot.material.copy()
                copies.append(mat)
                slot.material = mat
            lightmap_preview.apply(obj, image, lighting_only=False)
        yield
    finally:
        for obj in added:
            obj.data.materials.pop()
        for obj, mats in saved:
            for slot, m in zip(obj.material_slots, mats):
                slot.material = m
        for mat in copies:
            bpy.data.materials.remove(mat)
        for undo in reversed(undos):
            undo()
