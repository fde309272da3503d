"""The RenderEngine (``render_engine``), its pass loop (``progressive``) and the
bridge from exported data to the native module (``native_scene``)."""

import bpy

from .render_engine import GlslppmRenderEngine


def register():
    bpy.utils.register_class(GlslppmRenderEngine)


def unregister():
    bpy.utils.unregister_class(GlslppmRenderEngine)
