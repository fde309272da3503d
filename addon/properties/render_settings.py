"""``scene.glslppm``: the SPPM render settings shown in Render Properties."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

INT_MAX = 2**31 - 1


class GlslppmRenderSettings(bpy.types.PropertyGroup):
    # Blender reads properties from the class annotations; a dict keeps flake8 from
    # parsing the property calls as type hints.
    __annotations__ = {
        "passes": IntProperty(
            name="Passes", default=64, min=1, max=INT_MAX, soft_max=100000,
            description="SPPM passes to render (each pass traces one eye ray per pixel "
                        "and one batch of photons)"),
        "time_limit": FloatProperty(
            name="Time Limit", default=0.0, min=0.0, soft_max=3600.0, precision=1,
            description="Stop after this many seconds even if passes remain (0 = no limit)"),
        "viewport_passes": IntProperty(
            name="Viewport Passes", default=1024, min=1, max=INT_MAX, soft_max=100000,
            description="Passes the rendered viewport refines the image for, then stops"),
        "viewport_time_limit": FloatProperty(
            name="Viewport Time Limit", default=0.0, min=0.0, soft_max=3600.0, precision=1,
            description="Stop refining the viewport after this many seconds (0 = no limit)"),
        "viewport_pixel_size": IntProperty(
            name="Viewport Pixel Size", default=1, min=1, max=16,
            description="Render the viewport at 1/N of the region's width and height "
                        "(faster restarts on slow devices)"),
        "viewport_photons_per_pass": IntProperty(
            name="Viewport Photons", default=16384, min=1, max=INT_MAX, soft_max=1 << 22,
            description="Photon paths per pass in the viewport and in material previews "
                        "(fewer: faster passes while editing)"),
        "preview_passes": IntProperty(
            name="Preview Passes", default=32, min=1, max=100000,
            description="Passes a material or light preview renders"),
        "photons_per_pass": IntProperty(
            name="Photons per Pass", default=65536, min=1, max=INT_MAX, soft_max=1 << 24,
            description="Photon paths advanced by one bounce in each pass"),
        "use_auto_radius": BoolProperty(
            name="Automatic Radius", default=True,
            description="Choose the initial gather radius from the scene size and resolution"),
        "radius_scale": FloatProperty(
            name="Radius Scale", default=1.0, min=1e-3, soft_min=0.1, soft_max=10.0,
            max=1000.0, precision=3,
            description="Initial gather radius as a multiple of the automatic one "
                        "(smaller: sharper caustics, more noise at first)"),
        "initial_radius": FloatProperty(
            name="Initial Radius", default=0.01, min=0.0, soft_max=1.0, precision=4,
            subtype='DISTANCE', unit='LENGTH',
            description="Initial photon gather radius in scene units"),
        "alpha": FloatProperty(
            name="Alpha", default=0.7, min=0.01, max=1.0,
            description="Fraction of new photons kept per pass: lower shrinks the radius "
                        "faster (less blur, more noise)"),
        # Cycles' Light Paths under its names and defaults, read only where the Cycles
        # add-on is off (engine/light_paths.py); with it on, scene.cycles' own are.
        "max_bounces": IntProperty(
            name="Total", default=12, min=0, max=1024,
            description="Maximum number of light bounces, as Cycles' Light Paths Total (used "
                        "when the Cycles add-on is disabled; otherwise Cycles' own)"),
        "diffuse_bounces": IntProperty(
            name="Diffuse", default=4, min=0, max=1024,
            description="Maximum number of diffuse reflection bounces, as Cycles'"),
        "glossy_bounces": IntProperty(
            name="Glossy", default=4, min=0, max=1024,
            description="Maximum number of glossy reflection bounces, as Cycles'"),
        "transmission_bounces": IntProperty(
            name="Transmission", default=12, min=0, max=1024,
            description="Maximum number of transmission bounces, as Cycles'"),
        "direct_light": EnumProperty(
            name="Direct Light", default='SAMPLED',
            items=(('SAMPLED', "Light Sampling", "One light sample and shadow ray per pixel and "
                    "pass: sharp shadows, less noise; photons carry only scattered light "
                    "(docs/direct_light.md)"),
                   ('PHOTONS', "Photons", "All light from photons, as in the paper: shadows "
                    "blurred by the gather radius"))),
        "light_tracing": BoolProperty(
            name="Light Tracing", default=True,
            description="Caustics seen directly (light through mirrors and glass onto a "
                        "diffuse surface) by connecting photons to the camera instead of "
                        "gathering them: sharp and less noisy (docs/light_tracing.md). Used "
                        "with mirrors and smooth glass on diffuse surfaces, pinhole or "
                        "orthographic cameras"),
        "estimator": EnumProperty(
            name="Estimator", default='SPPM',
            items=(('SPPM', "SPPM", "Stochastic progressive photon mapping: each pixel's "
                    "radius shrinks with its own photons (passes run in order)"),
                   ('PPPM', "PPPM", "Probabilistic progressive photon mapping: a radius per "
                    "pass index, so passes run on several GPUs and farm machines and merge "
                    "exactly (glslppm-merge)"),
                   ('VCM', "VCM (in progress)", "Vertex connection and merging, being built "
                    "(docs/vcm.md): today path tracing from the camera with light sampling, "
                    "light tracing of caustics seen directly and merging of caustics seen "
                    "through glass, weighted together (VCM Techniques); passes are "
                    "independent as PPPM's. Renders Combined, the render passes but the light "
                    "split, light groups, a transparent film and tiles; not yet light "
                    "linking"))),
        "vcm_techniques": EnumProperty(
            name="VCM Techniques", default='PT_LT_VM',
            items=(('PT_LT', "Path + Light Tracing", "Caustics seen directly (light through "
                    "glass or mirrors onto a diffuse surface) from both the camera's paths and "
                    "the lights' paths, weighted by multiple importance sampling; everything "
                    "else by path tracing (docs/vcm.md)"),
                   ('PT', "Path Tracing", "Paths from the camera alone, with light sampling: "
                    "caustics only where a camera path happens to reach the light"),
                   ('PT_LT_VM', "Path + Light Tracing + Merging", "As Path + Light Tracing, "
                    "and caustics seen through glass or a mirror (a pool's floor through "
                    "its water) merged from the lights' paths at the camera paths' first "
                    "rough surface behind the glass, weighted against path tracing "
                    "(docs/vcm.md)"))),
        "first_pass": IntProperty(
            name="First Pass", default=0, min=0, max=INT_MAX,
            description="PPPM and VCM: the pass offset, the index of the first pass this render "
                        "runs; farm job k of n passes each sets k * n (glslppm-merge joins "
                        "the files)"),
        "glossy_threshold": FloatProperty(
            name="Glossy Threshold", default=0.5, min=0.0, max=1.0, precision=2,
            description="Glossy and glass lobes smoother than this roughness are followed "
                        "by the eye paths; rougher ones gather photons (0.5 measured the "
                        "least error on the glossy Cornell box, docs/materials.md)"),
        "hash_mode": EnumProperty(
            name="Photon Hash", default='STOCHASTIC',
            items=(('STOCHASTIC', "Stochastic", "Keep one random photon per hash cell and "
                    "scale it by the cell's count (fast)"),
                   ('EXACT', "Exact", "Keep every photon (slower, less noise)"))),
        "rng": EnumProperty(
            name="Random Numbers", default='PCG',
            items=(('PCG', "PCG", "Integer PCG generator: passes dieharder at 24 bits and "
                    "draws 2.5-4.4x faster (docs/rng.md)"),
                   ('PAPER', "Float (paper)", "The float-only generator of Hachisuka's GLSL "
                    "rendering system, as printed (fails dieharder's bit tests at 24 bits)"))),
        "instancing": EnumProperty(
            name="Instancing", default='AUTO',
            items=(('AUTO', "Automatic", "Two-level MTBVH or flattened copy, whichever was "
                    "measured faster for the scene's size (docs/instancing.md)"),
                   ('TWO_LEVEL', "Two-Level", "Each instanced mesh once, a tree over the "
                    "instances: memory for the meshes, not for every copy"),
                   ('FLATTENED', "Flattened", "Every instance's triangles in world space"))),
        "device": IntProperty(
            name="Device Override", default=-1, min=-1, max=64,
            description="EGL device index for this scene only; -1 uses the device chosen "
                        "in the add-on preferences"),
        "curve_triangle_limit": IntProperty(
            name="Curve Triangle Limit", default=4_000_000, min=0, max=INT_MAX,
            description="Most triangles that hair, Curves objects and point clouds may "
                        "become (12 per curve segment, 20 per point); past it the rest "
                        "are left out with a warning"),
        "seed": IntProperty(
            name="Seed", default=0, min=0, max=INT_MAX,
            description="Random seed; renders with the same seed and settings repeat"),
        "max_block_bytes": IntProperty(
            name="Largest Pixel Buffer", default=0, min=0, max=INT_MAX,
            description="Caps the per-pixel GPU buffers below the GPU's largest storage "
                        "buffer (0: the GPU's own limit); a frame past it renders as image "
                        "tiles. For tests: forces tiles on small images"),
    }

    def radius(self):
        """The module's initial_radius: 0 means automatic."""
        return 0.0 if self.use_auto_radius else self.initial_radius


def register():
    bpy.utils.register_class(GlslppmRenderSettings)
    bpy.types.Scene.glslppm = PointerProperty(type=GlslppmRenderSettings, name="GLSLPPM")


def unregister():
    del bpy.types.Scene.glslppm
    bpy.utils.unregister_class(GlslppmRenderSettings)
