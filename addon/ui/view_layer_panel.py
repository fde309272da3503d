"""View Layer Properties > Passes for GLSLPPM, laid out as Cycles' (docs/passes.md)."""

import bpy


class VIEWLAYER_PT_glslppm_passes(bpy.types.Panel):
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "view_layer"
    bl_label = "Passes"
    COMPAT_ENGINES = {'GLSLPPM'}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        view_layer = context.view_layer
        own = view_layer.glslppm
        column = layout.column(heading="Data", align=True)
        column.prop(view_layer, "use_pass_combined")
        column.prop(view_layer, "use_pass_z")
        column.prop(view_layer, "use_pass_normal")
        column.prop(own, "use_pass_denoising_data")
        column = layout.column(heading="Light", align=True)
        column.prop(view_layer, "use_pass_emit", text="Emission")
        column.prop(view_layer, "use_pass_environment")
        column.prop(own, "use_pass_light_split", text="Direct, Indirect, Caustics")


classes = (VIEWLAYER_PT_glslppm_passes,)
