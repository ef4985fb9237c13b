"""Lightmaps on the original objects: the "Lightmap" UV map (used as it is, or made with
Blender's Lightmap Pack), the rasterised bake as a float image ``<object>_radiosity``
packed into the .blend (and saved as ``<blend dir>/lightmaps/<object>_radiosity.exr`` when
the file has a path). The texel values come from ``_core.lightmap``: exact means of the
baked field over each texel, margins dilated; nothing here loops over texels.

Order of work, so that a failed or cancelled bake leaves the scene as it was:
``ensure_uv_maps`` before the export (remembering what it created), ``check_uvs`` before
the bake, ``compute`` after it (may raise, changes nothing), and only then ``store``.
``UvMaps.undo`` removes the UV maps made for a bake that did not finish.
"""

import os

import bpy
import numpy as np

from .. import _core
from .export import LIGHTMAP_UV, ExportError

IMAGE_SUFFIX = "_radiosity"
FOLDER = "lightmaps"


class UvMaps:
    """UV maps this bake created, to be removed again if it does not finish."""

    def __init__(self):
        self.created = []  # (mesh datablock, previous active UV name, previous render UV name)

    def undo(self):
        for mesh, active, render in reversed(self.created):
            try:
                layer = mesh.uv_layers.get(LIGHTMAP_UV)
                if layer is not None:
                    mesh.uv_layers.remove(layer)
                _set_active(mesh, active, render)
            except ReferenceError:  # the mesh was deleted meanwhile
                pass
        self.created = []


def ensure_uv_maps(objects, resolution):
    """Gives every object in ``objects`` a "Lightmap" UV map: an existing one is used as it
    is, otherwise one is made with Lightmap Pack (each object its own texture space, a margin
    of about one texel so no texel straddles two faces). Returns the ``UvMaps`` made."""
    made = UvMaps()
    try:
        for obj in objects:
            if obj.type != "MESH":
                raise ExportError(
                    'Object "%s": lightmaps need a mesh object with UVs (convert the %s to a mesh)'
                    % (obj.name, obj.type.lower())
                )
            mesh = obj.data
            if mesh.uv_layers.get(LIGHTMAP_UV) is not None:
                continue
            if mesh.library is not None:
                raise ExportError('Object "%s": UV map "%s": missing, and the mesh is linked from a library'
                                  % (obj.name, LIGHTMAP_UV))
            active = mesh.uv_layers.active.name if mesh.uv_layers.active else None
            render = next((u.name for u in mesh.uv_layers if u.active_render), None)
            layer = mesh.uv_layers.new(name=LIGHTMAP_UV, do_init=False)
            if layer is None:
                raise ExportError('Object "%s": UV map "%s": the mesh has no room for another UV map'
                                  % (obj.name, LIGHTMAP_UV))
            made.created.append((mesh, active, render))
            mesh.uv_layers.active = layer
            _lightmap_pack(mesh, resolution)
            _set_active(mesh, active, render)
            mesh.update()
    except Exception:
        made.undo()
        raise
    return made


def _lightmap_pack(mesh, resolution):
    # Blender's own Lightmap Pack, called as a function: the operator would need the
    # object selected, active and in object mode.
    from bl_operators.uvcalc_lightmap import lightmap_uvpack

    lightmap_uvpack(
        [mesh],
        PREF_SEL_ONLY=False,
        PREF_NEW_UVLAYER=False,
        PREF_PACK_IN_ONE=False,
        PREF_BOX_DIV=12,
        # Each face is inset by 1/PREF_MARGIN_DIV of the square: one texel at this resolution.
        PREF_MARGIN_DIV=max(8, int(resolution)),
    )


def _set_active(mesh, active, render):
    if active is not None and mesh.uv_layers.get(active) is not None:
        mesh.uv_layers.active = mesh.uv_layers[active]
    if render is not None and mesh.uv_layers.get(render) is not None:
        mesh.uv_layers[render].active_render = True


def check_uvs(meshes, resolution, margin):
    """Raises ``_core.BakeError`` (naming the object) for bad lightmap settings or UVs:
    zero-area or overlapping UV faces, before any time is spent baking."""
    for m in meshes:
        _core.check_lightmap_uv(m, int(resolution), int(margin))


def compute(sources, baked_meshes, resolution, margin):
    """``[(name, rgb)]``: the lightmap of each source mesh dict (with "uv") from its baked
    mesh, rgb of shape (R, R, 3). Raises ``_core.BakeError``; changes nothing."""
    return [
        (src["name"], _core.lightmap(src, baked, int(resolution), int(margin))[0])
        for src, baked in zip(sources, baked_meshes)
    ]


def store(maps):
    """Writes each ``(object name, rgb)`` into the float image ``<name>_radiosity``
    (replacing its pixels), packs it, and saves it beside the .blend when there is one.
    Returns the images."""
    images = []
    for name, rgb in maps:
        h, w = rgb.shape[:2]
        image_name = name + IMAGE_SUFFIX
        image = bpy.data.images.get(image_name)
        if image is not None and (tuple(image.size) != (w, h) or not image.is_float or image.source != "GENERATED"):
            bpy.data.images.remove(image)
            image = None
        if image is None:
            image = bpy.data.images.new(image_name, w, h, alpha=False, float_buffer=True)
        rgba = np.ones((h * w, 4), dtype=np.float32)
        rgba[:, :3] = rgb.reshape(-1, 3)
        image.pixels.foreach_set(rgba.ravel())
        image.file_format = "OPEN_EXR"
        # Nothing need use the image (the preview is optional): keep it in the saved file.
        image.use_fake_user = True
        if bpy.data.filepath:
            folder = os.path.join(os.path.dirname(bpy.data.filepath), FOLDER)
            os.makedirs(folder, exist_ok=True)
            image.filepath_raw = os.path.join(folder, image_name + ".exr")
            image.save()
        image.pack()
        images.append(image)
    return images
