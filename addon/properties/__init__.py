"""Settings stored in .blend files: ``scene.glslppm``."""

from . import presets, render_settings

_modules = (render_settings, presets)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
