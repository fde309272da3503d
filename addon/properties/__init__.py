"""Settings: ``scene.glslppm`` (stored in .blend files) and the add-on preferences
(stored with Blender's: the device)."""

from . import preferences, presets, render_settings

_modules = (preferences, render_settings, presets)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
