"""Light Properties: the light settings GLSLPPM uses. Blender's own panels cover the
type and the spot cone; colour, power and shape live in engine-specific panels."""

import bpy


class DATA_PT_glslppm_light(bpy.types.Panel):
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "data"
    bl_label = "Light Settings"
    COMPAT_ENGINES = {'GLSLPPM'}

    @classmethod
    def poll(cls, context):
        return context.light is not None and context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        light = context.light
        column = layout.column()
        column.prop(light, "color")
        column.prop(light, "energy", text="Strength" if light.type == 'SUN' else "Power")
        if light.type in {'POINT', 'SPOT'}:
            column.prop(light, "shadow_soft_size", text="Radius")
        elif light.type == 'SUN':
            column.prop(light, "angle")
        elif light.type == 'AREA':
            column.prop(light, "shape")
            sizes = column.column(align=True)
            if light.shape in {'SQUARE', 'DISK'}:
                sizes.prop(light, "size")
            else:
                sizes.prop(light, "size", text="Size X")
                sizes.prop(light, "size_y", text="Y")


classes = (DATA_PT_glslppm_light,)
