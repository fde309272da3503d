"""glslppm: a Blender render engine that renders with stochastic progressive photon
mapping on the GPU through headless OpenGL (the C++ module ``_glslppm``).

Blender 3.x reads ``bl_info``; Blender 4.2+ installs the package as an extension
described by ``blender_manifest.toml`` and ignores ``bl_info``.
"""

from . import engine, export, native_module, properties, ui  # noqa: F401 (export,
# native_module: the public submodules scripts and tests reach through the package)

bl_info = {
    "name": "GLSLPPM",
    "author": "glslppm developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > Render Engine",
    "description": "Stochastic progressive photon mapping on any GPU through OpenGL",
    "category": "Render",
}


_parts = (properties, engine, ui)


def register():
    for part in _parts:
        part.register()


def unregister():
    for part in reversed(_parts):
        part.unregister()
