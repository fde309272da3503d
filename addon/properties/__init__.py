"""Settings stored in .blend files: ``scene.glslppm``."""

from . import render_settings

_modules = (render_settings,)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
