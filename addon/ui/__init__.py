"""Panels: the engine's own (render settings, light) and Blender's that apply."""

import bpy

from . import (blender_panels, light_group_panels, light_linking_panel, light_panel, render_panels,
               view_layer_panel)

_classes = (render_panels.classes + light_panel.classes + view_layer_panel.classes +
            light_group_panels.classes + light_linking_panel.classes)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    blender_panels.register()


def unregister():
    blender_panels.unregister()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
