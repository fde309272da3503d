"""Render presets: named sets of ``scene.glslppm`` settings, in ONE table, applied by the
operator ``glslppm.apply_preset`` (Render Properties > Sampling > Preset).

Photons per pass are not a fixed count: a count tuned on one device is wrong on another
(the Caustics preset's 262,144, the H200's best at 512x512, lost to the default 65,536 on
llvmpipe at 256x256 and equal time: caustic relative RMSE 0.49 against 0.18). A pass
has a fixed cost, its eye paths (eye trace and gather, per pixel), and SPPM's radius shrinks
once per pass, so each preset aims a pass at a target time set from that fixed cost:

    target pass seconds = (1 + photon_to_eye) x pixels / eye rays/s
    photons per pass    = photon bounces/s x (target - pixels / eye rays/s)

clamped to the preset's [lowest, highest] and rounded to a power of two, with both rates
measured on the render device (device_speed.py, once per session). photon_to_eye is
what the measured optima spend on photons against the rest of a pass: 1.0 on the H200 at
512x512 (262,144 photons, the best count at equal time, take 0.46 ms of photon trace and
hashing of a 0.93 ms pass; docs/performance.md, "NVIDIA H200"), 0.5 or less on llvmpipe,
where the fewest photons won at equal time (docs/performance.md, "Presets").
"""

import bpy
from bpy.props import EnumProperty

from .. import native_module
from .. import device_speed
from . import preferences

# key -> label, description, how photons per pass are sized, and the settings it writes
# (property name -> value). radius_scale multiplies the automatic initial radius
# (use_auto_radius stays on). Every preset chooses SPPM with light tracing: on the equal-cost
# harness's caustic scene (docs/equal_cost.md, 2026-11-27) it had the least caustic error at
# 120 CPU-s (0.130, VCM's path + light tracing 0.169, Cycles 0.271) and the least over the
# whole image (0.088, 0.105, 0.119); VCM won only at 30 CPU-s and with 16,384 light paths a
# pass (0.286 against 0.319), a setting that loses at 120.
PRESETS = {
    "PREVIEW": {
        "label": "Preview",
        "description": "Quick look at the lighting: 64 passes, each aimed at 1.5x its eye "
                       "paths' time (photons 4,096 to 65,536 from the device's measured "
                       "rates: light passes, frequent updates), stochastic hash, twice the "
                       "automatic radius (H200 512x512: 2x radius cut the RMSE at 3.2 s from "
                       "0.0150 to 0.0117)",
        "photons": {"photon_to_eye": 0.5, "lowest": 4096, "highest": 65536},
        "settings": {
            "estimator": 'SPPM', "light_tracing": True,
            "passes": 64, "time_limit": 0.0, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 2.0, "hash_mode": 'STOCHASTIC',
        },
    },
    "FINAL": {
        "label": "Final",
        "description": "Converged lighting: 4,096 passes, each aimed at 2x its eye paths' "
                       "time (H200 512x512: the best count at equal time, 262,144 photons, "
                       "spends 0.46 of its 0.93 ms on photons; it beat 65,536 and 1M), exact "
                       "hash, twice the automatic radius, alpha 0.7 (H200 Cornell box at "
                       "equal time: exact 0.0101 vs stochastic 0.0141 RMSE)",
        "photons": {"photon_to_eye": 1.0, "lowest": 4096, "highest": 1 << 20},
        "settings": {
            "estimator": 'SPPM', "light_tracing": True,
            "passes": 4096, "time_limit": 0.0, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 2.0, "hash_mode": 'EXACT',
        },
    },
    "CAUSTICS": {
        "label": "Caustics",
        "description": "Sharp caustics: 8,192 passes, each aimed at 1.5x its eye paths' "
                       "time (llvmpipe caustic scene 96x96 at equal time: 4,096 photons, "
                       "half the eye time, RMSE 0.116 at 4.8 s against 0.27 and 0.19 for "
                       "16,384 and 65,536), exact hash, half the automatic radius, since a "
                       "caustic's edge blurs by the radius (H200 caustic scene: exact 0.0285 "
                       "vs stochastic 0.0297 RMSE at equal time). SPPM with light "
                       "tracing: on llvmpipe's caustic scene at 120 CPU-s its caustic error "
                       "was 0.13 against VCM's 0.17 and Cycles' 0.27 (docs/equal_cost.md)",
        "photons": {"photon_to_eye": 0.5, "lowest": 4096, "highest": 1 << 20},
        "settings": {
            "estimator": 'SPPM', "light_tracing": True,
            "passes": 8192, "time_limit": 0.0, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 0.5, "hash_mode": 'EXACT',
        },
    },
}


def target_pass_seconds(key, speed, pixels):
    """The time preset key aims a pass of `pixels` at, on a device of measured `speed`."""
    eye = pixels / speed["eye_rays_per_second"]
    return (1.0 + PRESETS[key]["photons"]["photon_to_eye"]) * eye


def preset_photons(key, speed, pixels):
    """Photons per pass for preset key at `pixels` on a device of measured `speed`."""
    sizing = PRESETS[key]["photons"]
    return device_speed.photons_for_pass_time(speed, pixels,
                                              target_pass_seconds(key, speed, pixels),
                                              sizing["lowest"], sizing["highest"])


def render_pixels(scene):
    """Pixels of a final render of scene (resolution x percentage, as export/frame.py)."""
    render = scene.render
    width = max(1, render.resolution_x * render.resolution_percentage // 100)
    height = max(1, render.resolution_y * render.resolution_percentage // 100)
    return width * height


def apply_preset(settings, key, speed=None, pixels=None):
    """Writes preset key's values into settings (scene.glslppm), and photons per pass sized
    from speed (device_speed.measure_device_speed) for `pixels` when given; KeyError if
    unknown."""
    for name, value in PRESETS[key]["settings"].items():
        setattr(settings, name, value)
    if speed is not None:
        settings.photons_per_pass = preset_photons(key, speed, pixels)


class GLSLPPM_OT_apply_preset(bpy.types.Operator):
    """Set passes, photons per pass (from the device's measured speed), alpha, radius and
    hash mode from a preset"""
    bl_idname = "glslppm.apply_preset"
    bl_label = "Apply GLSLPPM Preset"
    bl_options = {'REGISTER', 'UNDO'}

    __annotations__ = {
        "preset": EnumProperty(
            name="Preset",
            items=[(key, preset["label"], preset["description"])
                   for key, preset in PRESETS.items()]),
    }

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def execute(self, context):
        scene = context.scene
        settings = scene.glslppm
        label = PRESETS[self.preset]["label"]
        native, problem = native_module.load()
        speed = None
        if native is not None:
            try:
                speed = device_speed.device_speed(
                    native, preferences.render_device(settings, context))
            except Exception as error:  # noqa: BLE001 - a device that fails to render
                problem = f"measuring the device failed: {error}"
        apply_preset(settings, self.preset, speed, render_pixels(scene))
        if speed is None:
            self.report({'WARNING'}, f"GLSLPPM: {label} preset applied, photons per pass "
                        f"left at {settings.photons_per_pass:,} ({problem})")
            return {'FINISHED'}
        self.report({'INFO'}, f"GLSLPPM: {label} preset applied: "
                    f"{settings.photons_per_pass:,} photons per pass for "
                    f"{speed['photon_bounces_per_second'] / 1e6:.2f} M photon bounces/s and "
                    f"{speed['eye_rays_per_second'] / 1e6:.2f} M eye rays/s "
                    f"({speed['renderer']})")
        return {'FINISHED'}


class GLSLPPM_OT_measure_device_speed(bpy.types.Operator):
    """Render a small built-in scene for half a second on the render device and keep its
    photon and eye-ray rates for the presets"""
    bl_idname = "glslppm.measure_device_speed"
    bl_label = "Measure Device Speed"

    def execute(self, context):
        native, problem = native_module.load()
        if native is None:
            self.report({'ERROR'}, f"GLSLPPM: {problem}")
            return {'CANCELLED'}
        device = preferences.render_device(context.scene.glslppm, context)
        try:
            device_speed.forget_device_speed(device)
            device_speed.device_speed(native, device)
        except Exception as error:  # noqa: BLE001 - reported, never a crash
            self.report({'ERROR'}, f"GLSLPPM: measuring the device failed: {error}")
            return {'CANCELLED'}
        return {'FINISHED'}


classes = (GLSLPPM_OT_apply_preset, GLSLPPM_OT_measure_device_speed)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
