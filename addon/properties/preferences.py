"""Add-on preferences: the GPU to render on, listed by name from the module's
list_devices() (EGL devices), for every scene of this Blender."""

import bpy
from bpy.props import EnumProperty

from .. import native_module

# The add-on's own package ("glslppm", or "bl_ext.<repository>.glslppm" as an extension):
# Blender finds preferences by it.
ADDON_PACKAGE = __package__.rpartition(".")[0]

AUTOMATIC = "AUTO"

# Blender keeps only the strings of dynamic enum items that Python holds on to.
_items = []


def device_items(self, context):
    """("AUTO", "Automatic", ...) then one item per EGL device: ("0", "0: <name>", ...)."""
    items = [(AUTOMATIC, "Automatic", "$GLSLPPM_DEVICE if set, else the first GPU, else "
              "the software renderer", 0)]
    native, problem = native_module.load()
    names = []
    if native is not None:
        try:
            names = list(native.list_devices())
        except Exception:  # noqa: BLE001 - a broken driver must not break the preferences
            names = []
    for index, name in enumerate(names):
        items.append((str(index), f"{index}: {name}", f"EGL device {index} ({name})",
                      index + 1))
    _items[:] = items
    return _items


class GlslppmPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_PACKAGE

    __annotations__ = {
        "device": EnumProperty(
            name="Device", items=device_items,
            description="The GPU (EGL device) GLSLPPM renders on"),
    }

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(self, "device")
        if len(_items) <= 1:
            native, problem = native_module.load()
            layout.label(text=problem or "EGL lists no devices; rendering uses the "
                         "surfaceless platform", icon='INFO')


def preferred_device(context=None):
    """The device index chosen in the preferences, or -1 (automatic, or no preferences:
    the add-on imported without being enabled)."""
    context = context or bpy.context
    addon = context.preferences.addons.get(ADDON_PACKAGE)
    if addon is None or addon.preferences is None:
        return -1
    value = addon.preferences.device
    return int(value) if value and value != AUTOMATIC else -1


def render_device(settings, context=None):
    """The EGL device a render uses: the scene's own override (settings.device, kept for
    scripts and older files) when set, else the preferences' choice."""
    return settings.device if settings.device >= 0 else preferred_device(context)


classes = (GlslppmPreferences,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
