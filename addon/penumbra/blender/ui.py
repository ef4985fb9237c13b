"""The "Radiosity" panel under Render Properties."""

import bpy


class PENUMBRA_PT_radiosity(bpy.types.Panel):
    bl_label = "Radiosity"
    bl_idname = "PENUMBRA_PT_radiosity"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        s = context.scene.penumbra

        layout.prop(s, "scope")
        ob = context.active_object
        if ob is not None and ob.type == "MESH":
            layout.prop(ob, "penumbra_shadow_only", text="Active: Shadow Only")
        layout.prop(s, "quality")
        layout.prop(s, "use_custom_size")
        sizes = layout.column(align=True)
        sizes.enabled = s.use_custom_size
        sizes.prop(s, "element_size")
        sizes.prop(s, "penumbra_element_size")

        layout.prop(s, "use_indirect")
        col = layout.column()
        col.enabled = s.use_indirect
        col.prop(s, "indirect_solver")
        col.prop(s, "convergence")
        layout.prop(s, "lighting_only")
        layout.prop(s, "hide_originals")
        layout.prop(s, "max_memory_gb")

        layout.prop(s, "output")
        col = layout.column()
        col.enabled = s.output != "MESH"
        col.prop(s, "lightmap_resolution")
        col.prop(s, "lightmap_margin")
        col.prop(s, "lightmap_preview")

        layout.separator()
        layout.operator("penumbra.bake", icon="LIGHT_AREA")
        if s.last_summary:
            layout.label(text=s.last_summary.replace("Penumbra: ", ""), icon="INFO")


def register():
    bpy.utils.register_class(PENUMBRA_PT_radiosity)


def unregister():
    bpy.utils.unregister_class(PENUMBRA_PT_radiosity)
