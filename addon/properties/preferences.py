"""Add-on preferences: the GPUs to render on, for every scene of this Blender. As Cycles'
Render Devices: one row per EGL device (name, vendor, a checkbox), filled by Detect Devices;
the software renderer (llvmpipe) is listed and off by default where a GPU exists. Several
devices checked run one worker each with the PPPM estimator."""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, IntProperty,
                       StringProperty)

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


class GlslppmDevice(bpy.types.PropertyGroup):
    __annotations__ = {
        "index": IntProperty(name="Index", default=0, min=0),
        "vendor": StringProperty(name="Vendor"),
        "software": BoolProperty(name="Software", default=False),
        "use": BoolProperty(name="Use", default=True,
                            description="Render on this device (one worker per device)"),
    }


def default_use(devices):
    """Which listed devices start checked: every GPU, and the software renderer only where
    there is no GPU. devices: dicts with "software"."""
    has_gpu = any(not d["software"] for d in devices)
    return [not d["software"] or not has_gpu for d in devices]


def detect_devices(preferences, native):
    """Fills preferences.devices from the module: name and vendor of each EGL device (the
    vendor from a context opened once; blank where it cannot be opened)."""
    listed = list(native.describe_devices())
    preferences.devices.clear()
    for device, use in zip(listed, default_use(listed)):
        entry = preferences.devices.add()
        entry.name = device["name"]
        entry.index = device["index"]
        entry.software = device["software"]
        entry.use = use
        try:
            limits = native.device_limits(device["index"])
            entry.vendor = limits.get("vendor", "")
            entry.name = f"{limits['renderer']} ({device['name']})"
        except Exception:  # noqa: BLE001 - a device that will not open stays listed, blank
            entry.vendor = ""


class GLSLPPM_OT_detect_devices(bpy.types.Operator):
    bl_idname = "glslppm.detect_devices"
    bl_label = "Detect Devices"
    bl_description = "List the EGL devices (GPUs and the software renderer) to render on"

    def execute(self, context):
        native, problem = native_module.load()
        if native is None:
            self.report({'ERROR'}, problem)
            return {'CANCELLED'}
        detect_devices(context.preferences.addons[ADDON_PACKAGE].preferences, native)
        return {'FINISHED'}


class GlslppmPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_PACKAGE

    __annotations__ = {
        "device": EnumProperty(
            name="Device", items=device_items,
            description="The GPU (EGL device) GLSLPPM renders on, until devices are detected"),
        "devices": CollectionProperty(type=GlslppmDevice, name="Render Devices"),
    }

    def draw(self, context):
        layout = self.layout
        layout.label(text="Render Devices:")
        if len(self.devices) == 0:
            layout.use_property_split = True
            layout.prop(self, "device")
            if len(_items) <= 1:
                native, problem = native_module.load()
                layout.label(text=problem or "EGL lists no devices; rendering uses the "
                             "surfaceless platform", icon='INFO')
        for entry in self.devices:
            row = layout.row()
            row.prop(entry, "use", text=entry.name)
            row.label(text=entry.vendor or "?")
        layout.operator(GLSLPPM_OT_detect_devices.bl_idname, icon='FILE_REFRESH')
        if sum(entry.use for entry in self.devices) > 1:
            layout.label(text="Several devices: scenes render with them when their "
                         "estimator is PPPM", icon='INFO')


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
    return render_devices(settings, context)[0]


def render_devices(settings, context=None):
    """The EGL devices a render uses, one worker each: the scene's override when set, else
    the devices checked in the preferences (the first alone unless the estimator is PPPM,
    whose passes can be split), else the preferences' single choice ([-1]: automatic)."""
    if settings.device >= 0:
        return [settings.device]
    context = context or bpy.context
    addon = context.preferences.addons.get(ADDON_PACKAGE)
    checked = []
    if addon is not None and addon.preferences is not None:
        checked = [entry.index for entry in addon.preferences.devices if entry.use]
    if not checked:
        return [preferred_device(context)]
    return checked if settings.estimator == 'PPPM' else checked[:1]


classes = (GlslppmDevice, GLSLPPM_OT_detect_devices, GlslppmPreferences)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
