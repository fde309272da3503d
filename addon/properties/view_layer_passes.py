"""``view_layer.glslppm``: the render passes Blender's view layer has no property for (Cycles
keeps its own in ``view_layer.cycles`` the same way). Depth, Normal, Emission and
Environment are Blender's own ``use_pass_z``, ``use_pass_normal``, ``use_pass_emit`` and
``use_pass_environment``; docs/passes.md says what each pass holds."""

import bpy


def _passes_changed(settings, context):
    # The compositor's Render Layers node shows the new sockets at once.
    for view_layer in settings.id_data.view_layers:
        view_layer.update_render_passes()


class GlslppmViewLayerSettings(bpy.types.PropertyGroup):
    __annotations__ = {
        "use_pass_denoising_data": bpy.props.BoolProperty(
            name="Denoising Data", default=False, update=_passes_changed,
            description="Denoising Normal (camera space) and Denoising Albedo of the first "
                        "diffuse-like surface (seen through mirrors and glass), as Cycles "
                        "writes them for the compositor's Denoise node"),
        "use_pass_light_split": bpy.props.BoolProperty(
            name="Light Split", default=False, update=_passes_changed,
            description="Direct, Indirect and Caustics: light from a light scattered once, "
                        "photons scattered diffusely, and photons that went through a mirror, "
                        "glass or a glossy bounce first. With Emission and Environment they "
                        "sum to Combined"),
    }


classes = (GlslppmViewLayerSettings,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.ViewLayer.glslppm = bpy.props.PointerProperty(type=GlslppmViewLayerSettings)


def unregister():
    del bpy.types.ViewLayer.glslppm
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
