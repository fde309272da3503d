"""Shows Blender's own panels that apply to GLSLPPM (output, dimensions, colour
management, camera, light shape, material slots and surface, world surface) by
adding the engine to their COMPAT_ENGINES, as Blender's RenderEngine template does."""

import bpy

ENGINE = 'GLSLPPM'

# Panels meant for 'BLENDER_RENDER' that do not apply to this engine.
EXCLUDED = {
    'VIEWLAYER_PT_filter',
    'VIEWLAYER_PT_layer_passes',
    'RENDER_PT_freestyle',
    'DATA_PT_area',           # 3.x only; the engine's light panel draws the shape
}
# Whole families that do not apply: light probes (EEVEE's baked lighting), Volume objects
# (not rendered: export warns) and Freestyle's line settings (not drawn).
EXCLUDED_PREFIXES = (
    'DATA_PT_lightprobe', 'DATA_PT_context_lightprobe',
    'DATA_PT_volume', 'DATA_PT_context_volume', 'DATA_PT_custom_props_volume',
    'VIEWLAYER_PT_freestyle',
)

# EEVEE's and Cycles' panels that draw nothing specific to those engines.
EXTRA = (
    'EEVEE_MATERIAL_PT_context_material',
    'EEVEE_MATERIAL_PT_surface',
    'EEVEE_WORLD_PT_surface',
    'DATA_PT_camera_dof',
    'DATA_PT_camera_dof_aperture',
)

_added = []


def compatible_panels():
    panels = []
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines is None or excluded(panel.__name__):
            continue
        if 'BLENDER_RENDER' in engines or panel.__name__ in EXTRA:
            panels.append(panel)
    return panels


def excluded(name):
    return name in EXCLUDED or name.startswith(EXCLUDED_PREFIXES)


def register():
    for panel in compatible_panels():
        if ENGINE not in panel.COMPAT_ENGINES:
            panel.COMPAT_ENGINES.add(ENGINE)
            _added.append(panel)


def unregister():
    for panel in _added:
        panel.COMPAT_ENGINES.discard(ENGINE)
    _added.clear()
