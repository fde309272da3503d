"""Render Properties panels for scene.glslppm."""

import bpy

from .. import device_speed
from ..engine import progressive
from ..engine.light_paths import light_paths_owner
from ..properties import preferences


class GlslppmRenderPanel:
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "render"
    COMPAT_ENGINES = {'GLSLPPM'}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class RENDER_PT_glslppm_sampling(GlslppmRenderPanel, bpy.types.Panel):
    bl_label = "Sampling"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.glslppm
        layout.operator_menu_enum("glslppm.apply_preset", "preset", text="Preset",
                                  icon='PRESET')
        draw_device_speed(layout, context, settings)
        column = layout.column()
        column.prop(settings, "passes")
        column.prop(settings, "time_limit", text="Time Limit (s)")
        draw_projected_time(column, context, settings)
        column.prop(settings, "direct_light")
        column.prop(settings, "light_tracing")
        column.prop(settings, "glossy_threshold")
        column.prop(settings, "estimator")
        if settings.estimator == 'VCM':
            column.prop(settings, "vcm_techniques")
        if settings.estimator in {'PPPM', 'VCM'}:
            column.prop(settings, "first_pass")
        column.prop(settings, "seed")
        column = layout.column(heading="Viewport")
        column.prop(settings, "viewport_passes", text="Passes")
        column.prop(settings, "viewport_time_limit", text="Time Limit (s)")
        column.prop(settings, "viewport_pixel_size", text="Pixel Size")
        column.prop(settings, "viewport_photons_per_pass", text="Photons per Pass")
        column.prop(settings, "preview_passes", text="Preview Passes")


def draw_projected_time(layout, context, settings):
    """How long F12 will take, from the device's measured rates: a render of hours is
    announced before it starts (the Final preset at 1080p is about 8 hours on llvmpipe)."""
    speed = device_speed.cached_device_speed(preferences.render_device(settings, context))
    if speed is None:
        return
    render = context.scene.render
    scale = render.resolution_percentage / 100.0
    pixels = int(render.resolution_x * scale) * int(render.resolution_y * scale)
    seconds = progressive.projected_seconds(
        settings.passes, settings.time_limit,
        device_speed.pass_seconds(speed, pixels, settings.photons_per_pass))
    long = settings.time_limit <= 0.0 and seconds >= progressive.LONG_RENDER_SECONDS
    text = f"About {progressive.format_duration(seconds)} on this device"
    if settings.time_limit > 0.0 and seconds >= settings.time_limit:
        text += " (the time limit)"
    layout.label(text=text, icon='ERROR' if long else 'TIME')


def draw_device_speed(layout, context, settings):
    """The render device's measured rates, from which the presets size photons per pass."""
    speed = device_speed.cached_device_speed(preferences.render_device(settings, context))
    row = layout.row()
    if speed is None:
        row.label(text="Device speed: not measured yet", icon='INFO')
    else:
        column = row.column(align=True)
        column.label(text=f"Device: {speed['renderer']}", icon='INFO')
        column.label(text=f"{speed['photon_bounces_per_second'] / 1e6:.2f} M photon "
                     f"bounces/s, {speed['eye_rays_per_second'] / 1e6:.2f} M eye rays/s")
    row.operator("glslppm.measure_device_speed", text="", icon='FILE_REFRESH')


class RENDER_PT_glslppm_photons(GlslppmRenderPanel, bpy.types.Panel):
    bl_label = "Photons"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.glslppm
        column = layout.column()
        column.prop(settings, "photons_per_pass")
        column.prop(settings, "use_auto_radius")
        if settings.use_auto_radius:
            column.prop(settings, "radius_scale")
        else:
            column.prop(settings, "initial_radius")
        column.prop(settings, "alpha")
        column.prop(settings, "curve_triangle_limit")


class RENDER_PT_glslppm_light_paths(GlslppmRenderPanel, bpy.types.Panel):
    """Where Cycles users look for bounces, drawn as Cycles draws its Max Bounces: the same
    properties (scene.cycles', or GLSLPPM's copies without the Cycles add-on), which the
    renderer follows (engine/light_paths.py, docs/bounces.md)."""
    bl_label = "Light Paths"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        owner = light_paths_owner(context.scene)
        column = layout.column(align=True, heading="Max Bounces")
        column.prop(owner, "max_bounces", text="Total")
        column = layout.column(align=True)
        column.prop(owner, "diffuse_bounces", text="Diffuse")
        column.prop(owner, "glossy_bounces", text="Glossy")
        column.prop(owner, "transmission_bounces", text="Transmission")


class RENDER_PT_glslppm_advanced(GlslppmRenderPanel, bpy.types.Panel):
    bl_label = "Advanced"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.glslppm
        column = layout.column()
        column.prop(settings, "hash_mode")
        column.prop(settings, "rng")
        column.prop(settings, "instancing")
        if settings.device >= 0:  # set by a script or an older file
            column.prop(settings, "device")
        else:
            column.label(text="Device: Edit > Preferences > Add-ons > GLSLPPM", icon='INFO')


class RENDER_PT_glslppm_film(GlslppmRenderPanel, bpy.types.Panel):
    bl_label = "Film"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        scene = context.scene
        column = layout.column()
        column.prop(scene.render, "film_transparent", text="Transparent")
        cycles = getattr(scene, "cycles", None)
        if cycles is not None and hasattr(cycles, "film_transparent_glass"):
            row = column.row()
            row.active = scene.render.film_transparent
            row.prop(cycles, "film_transparent_glass", text="Transparent Glass")
        # Each pixel's estimate is its own (a box one pixel wide): no filter to size.
        column.label(text="Pixel Filter: 1 px box (fixed)", icon='INFO')


classes = (RENDER_PT_glslppm_sampling, RENDER_PT_glslppm_photons,
           RENDER_PT_glslppm_light_paths, RENDER_PT_glslppm_film, RENDER_PT_glslppm_advanced)
