"""Settings: ``scene.glslppm`` and ``view_layer.glslppm`` (stored in .blend files) and
the add-on preferences (stored with Blender's: the device)."""

from . import preferences, presets, render_settings, view_layer_passes

_modules = (preferences, render_settings, presets, view_layer_passes)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
