"""Light linking and shadow linking need Blender 4.0+ (Object.light_linking; Blender draws
them in Object > Shading > Light Linking / Shadow Linking, and GLSLPPM renders them:
docs/light_linking.md). On an older Blender the Object tab says so where they would be, for
a user who reads of them, or who opened a 4.x file, whose links that Blender dropped."""

import bpy

MESSAGE = "Light and shadow linking need Blender 4.0 or newer"


class OBJECT_PT_glslppm_light_linking(bpy.types.Panel):
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "object"
    bl_label = "Light Linking"
    COMPAT_ENGINES = {'GLSLPPM'}

    @classmethod
    def poll(cls, context):
        obj = getattr(context, "object", None)
        return (context.engine in cls.COMPAT_ENGINES and obj is not None and
                not hasattr(obj, "light_linking"))

    def draw(self, context):
        self.layout.label(text=MESSAGE, icon='INFO')


# Registered only where Blender has no light linking of its own.
classes = () if bpy.app.version >= (4, 0, 0) else (OBJECT_PT_glslppm_light_linking,)
