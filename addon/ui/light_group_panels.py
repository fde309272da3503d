"""Light groups in the Properties editor for GLSLPPM (docs/light_groups.md): the view layer's
list of groups, and the Light Group field of objects (lights and emissive meshes) and of the
World. Blender draws these in Cycles' own panels (View Layer > Light Groups, Object >
Shading > Light Group, World > Settings > Light Group), which show only while Cycles is
the engine; these panels draw the same properties and operators for GLSLPPM. Blender 3.2+
(where `ViewLayer.lightgroups` exists)."""

import bpy


class GlslppmLightGroupPanel:
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    COMPAT_ENGINES = {'GLSLPPM'}

    @classmethod
    def poll(cls, context):
        return (context.engine in cls.COMPAT_ENGINES and
                hasattr(context.view_layer, "lightgroups"))


class VIEWLAYER_PT_glslppm_light_groups(GlslppmLightGroupPanel, bpy.types.Panel):
    """Each group a Combined-like pass of its own, named as Cycles names them."""
    bl_context = "view_layer"
    bl_label = "Light Groups"

    def draw(self, context):
        view_layer = context.view_layer
        row = self.layout.row()
        row.template_list("UI_UL_list", "lightgroups", view_layer, "lightgroups", view_layer,
                          "active_lightgroup_index", rows=3)
        column = row.column(align=True)
        column.operator("scene.view_layer_add_lightgroup", icon='ADD', text="")
        column.operator("scene.view_layer_remove_lightgroup", icon='REMOVE', text="")


def draw_light_group_field(layout, owner, view_layer):
    row = layout.row(align=True)
    row.use_property_split = True
    row.prop_search(owner, "lightgroup", view_layer, "lightgroups", text="Light Group",
                    results_are_suggestions=True)
    # The field may name a group the view layer does not have yet: a button adds it.
    sub = row.column(align=True)
    sub.enabled = bool(owner.lightgroup) and not any(
        group.name == owner.lightgroup for group in view_layer.lightgroups)
    sub.operator("scene.view_layer_add_lightgroup", icon='ADD', text="").name = owner.lightgroup


class GlslppmLightGroupField(GlslppmLightGroupPanel):
    """The Light Group field of the context's `owner` (an object, the World)."""
    bl_label = "Light Group"
    owner = ""

    @classmethod
    def poll(cls, context):
        return super().poll(context) and getattr(context, cls.owner, None) is not None

    def draw(self, context):
        draw_light_group_field(self.layout, getattr(context, self.owner), context.view_layer)


class OBJECT_PT_glslppm_light_group(GlslppmLightGroupField, bpy.types.Panel):
    bl_context = "object"
    owner = "object"


class WORLD_PT_glslppm_light_group(GlslppmLightGroupField, bpy.types.Panel):
    bl_context = "world"
    owner = "world"


classes = (VIEWLAYER_PT_glslppm_light_groups, OBJECT_PT_glslppm_light_group,
           WORLD_PT_glslppm_light_group)
