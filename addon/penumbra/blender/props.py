"""Bake settings, stored on the scene (``scene.penumbra``)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty


def _preview_changed(settings, context):
    """Turning the preview on shows each object's existing lightmap; off restores every
    previewed object's materials."""
    from . import lightmap_preview
    from .lightmaps import IMAGE_SUFFIX

    objects = [o for o in context.scene.objects if o.type == "MESH"]
    if not settings.lightmap_preview:
        lightmap_preview.hide_all(objects)
        return
    for obj in objects:
        image = bpy.data.images.get(obj.name + IMAGE_SUFFIX)
        if image is not None:
            lightmap_preview.show(obj, image, settings.lighting_only)


class PenumbraSettings(bpy.types.PropertyGroup):
    scope: EnumProperty(
        name="Bake",
        description="Which meshes get baked outputs; every visible mesh takes part either way",
        items=(
            ("SELECTED", "Selected", "Bake the selected meshes; every other visible mesh still casts shadows and reflects light"),
            ("VISIBLE", "Visible", "Bake every visible mesh"),
        ),
        default="SELECTED",
    )
    quality: EnumProperty(
        name="Quality",
        description="Error of the baked direct light the elements are refined to",
        items=(
            ("DRAFT", "Draft", "Direct light within 3 %: a quick look"),
            ("MEDIUM", "Medium", "Direct light within 1 %"),
            ("HIGH", "High", "Direct light within 0.3 %, sharp penumbrae; slower"),
        ),
        default="MEDIUM",
    )
    use_custom_size: BoolProperty(
        name="Custom Element Size",
        description="Set element edge lengths in scene units instead of from the quality preset",
        default=False,
    )
    element_size: FloatProperty(
        name="Element Size",
        description="Element edge length outside penumbrae",
        default=0.2,
        min=1e-6,
        soft_max=10.0,
        subtype="DISTANCE",
        unit="LENGTH",
    )
    penumbra_element_size: FloatProperty(
        name="Penumbra Element Size",
        description="Element edge length inside penumbrae, where light changes fast",
        default=0.04,
        min=1e-6,
        soft_max=10.0,
        subtype="DISTANCE",
        unit="LENGTH",
    )
    use_indirect: BoolProperty(
        name="Indirect Light",
        description="Add light bounced between surfaces (radiosity)",
        default=True,
    )
    indirect_solver: EnumProperty(
        name="Solver",
        description="How bounced light is computed",
        items=(
            ("HIERARCHICAL", "Hierarchical", "Hierarchical radiosity with clusters on the discontinuity mesh: follows every shadow, and scales to rooms"),
            ("PROGRESSIVE", "Progressive", "Progressive refinement over grid patches (the round-1 solver): fast on a few dozen faces, slow on rooms"),
        ),
        default="HIERARCHICAL",
    )
    convergence: FloatProperty(
        name="Convergence",
        description="Stop shooting when the unshot power falls below this fraction of the emitted power",
        default=1e-3,
        min=1e-6,
        max=0.5,
        precision=4,
    )
    max_memory_gb: FloatProperty(
        name="Memory Limit (GB)",
        description=(
            "Refuse a bake that would need more memory than this, before it starts "
            "(0: half of this machine's memory)"
        ),
        default=0.0,
        min=0.0,
        soft_max=256.0,
        precision=1,
    )
    lighting_only: BoolProperty(
        name="Lighting Only",
        description="Bake irradiance/π without surface colour (a lightmap to multiply by albedo later)",
        default=False,
    )
    hide_originals: BoolProperty(
        name="Hide Originals",
        description="Hide the source objects after the bake, in the viewport and in renders",
        default=False,
    )
    output: EnumProperty(
        name="Output",
        description="What a bake makes",
        items=(
            ("MESH", "Mesh", "New objects whose meshes follow the shadow boundaries, with the light as colours"),
            ("LIGHTMAP", "Lightmap", "An image per object on its \"Lightmap\" UV map (for game engines); no new objects"),
            ("BOTH", "Both", "The new objects and the lightmap images"),
        ),
        default="MESH",
    )
    # No hard limits: a value out of range reaches the core, which reports it in one line
    # and changes nothing (a hard limit would silently clamp it).
    lightmap_resolution: IntProperty(
        name="Resolution",
        description="Texels on a side of each object's lightmap (1 to 16384)",
        default=512,
        soft_min=16,
        soft_max=8192,
    )
    lightmap_margin: IntProperty(
        name="Margin",
        description="Rings of texels filled around the UV islands, so filtering does not bleed in black",
        default=16,
        soft_min=0,
        soft_max=64,
    )
    lightmap_preview: BoolProperty(
        name="Preview on Originals",
        description=(
            "Show the lightmap on the original objects' materials: base colour × lightmap with "
            "Lighting Only, else the lightmap as emission (each object through its own copies "
            "of its materials; off restores them)"
        ),
        default=False,
        update=_preview_changed,
    )
    # Written by the last successful bake, read by the panel and by scripts.
    last_summary: StringProperty(name="Last Bake", default="")
    last_stats: StringProperty(name="Last Bake Stats (JSON)", default="")
    # What the last successful bake made: {"objects": [names], "images": [names]} (JSON).
    last_outputs: StringProperty(name="Last Bake Outputs (JSON)", default="")


def register():
    bpy.utils.register_class(PenumbraSettings)
    bpy.types.Scene.penumbra = PointerProperty(type=PenumbraSettings)
    bpy.types.Object.penumbra_shadow_only = BoolProperty(
        name="Penumbra: Shadow Only",
        description="Take part in Penumbra bakes (cast shadows, reflect and emit light) but never get a baked output",
        default=False,
    )


def unregister():
    del bpy.types.Object.penumbra_shadow_only
    del bpy.types.Scene.penumbra
    bpy.utils.unregister_class(PenumbraSettings)
