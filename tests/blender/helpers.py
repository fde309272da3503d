"""Scene building, export and render helpers shared by the Blender tests."""

import math
import os
import time

import bpy
import numpy as np

ADDON = None        # the enabled add-on package (set by run.py)
ADDON_NAME = None   # its module name
OUT = None          # directory for images the tests write
SOURCE_MODE = False  # the add-on was imported from the source tree (run.py --source)

BLENDER_4_1 = bpy.app.version >= (4, 1, 0)
BLENDER_4 = bpy.app.version >= (4, 0, 0)
BLENDER_5 = bpy.app.version >= (5, 0, 0)


def compat():
    """The add-on's compat module: the one home of Blender version switches (the
    compositor, File Output, EXR formats, use_nodes, sky types) for the tests too."""
    return ADDON.compat


def slow(reason):
    """Marks a test that takes over 30 s on this project's 2-core machine, saying why it
    needs that long; tests/blender/run.py lists the slowest tests with their reasons and
    names any over 30 s without one."""
    def mark(test):
        test.slow_reason = reason
        return test
    return mark


class Skip(Exception):
    """Raised by a test that cannot run here (the message says why)."""


def reset_scene(engine='GLSLPPM', size=(64, 64)):
    """An empty scene with default engine settings (faster than reloading a file,
    and keeps the add-on registered)."""
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.lights,
                       bpy.data.cameras, bpy.data.materials, bpy.data.images,
                       bpy.data.worlds, bpy.data.curves, bpy.data.collections,
                       bpy.data.node_groups):
        for item in list(collection):
            collection.remove(item)
    scene = bpy.context.scene
    scene.render.engine = engine
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.use_border = False
    scene.render.use_crop_to_border = False
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.film_transparent = False
    scene.render.use_motion_blur = False
    scene.render.use_multiview = False
    scene.frame_start = scene.frame_end = scene.frame_current = 1
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.glslppm
    for name in settings.bl_rna.properties.keys():
        if name not in ("rna_type", "name"):
            settings.property_unset(name)
    scene.world = None
    scene.camera = None
    # Both engines follow scene.cycles' Light Paths: the tests compare at 16 of every kind.
    set_light_paths(scene, 16)
    return scene


def set_light_paths(scene, total, diffuse=None, glossy=None, transmission=None):
    """Cycles' Light Paths limits, which GLSLPPM follows too (engine/light_paths.py); a kind
    left out takes the total. Without the Cycles add-on, GLSLPPM's own copies."""
    cycles = getattr(scene, "cycles", None)
    owner = cycles if cycles is not None and hasattr(cycles, "diffuse_bounces") \
        else scene.glslppm
    owner.max_bounces = total
    owner.diffuse_bounces = total if diffuse is None else diffuse
    owner.glossy_bounces = total if glossy is None else glossy
    owner.transmission_bounces = total if transmission is None else transmission


def add_mesh_object(name, vertices, faces, location=(0, 0, 0), rotation=(0, 0, 0),
                    scale=(1, 1, 1), material=None, smooth=False):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in vertices], [], [tuple(f) for f in faces])
    mesh.update()
    if smooth:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    obj = bpy.data.objects.new(name, mesh)
    obj.location, obj.rotation_euler, obj.scale = location, rotation, scale
    if material is not None:
        mesh.materials.append(material)
    bpy.context.scene.collection.objects.link(obj)
    return obj


CUBE_VERTICES = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
# Quads wound counter-clockwise seen from outside.
CUBE_FACES = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4),
              (1, 5, 7, 3)]


def add_cube(name="Cube", **kwargs):
    return add_mesh_object(name, CUBE_VERTICES, CUBE_FACES, **kwargs)


def add_quad(name, corners, material=None):
    """A one-quad mesh; corners counter-clockwise seen from the side it faces."""
    return add_mesh_object(name, corners, [(0, 1, 2, 3)], material=material)


def add_light(kind, energy, location=(0, 0, 0), rotation=(0, 0, 0), color=(1, 1, 1),
              **settings):
    light = bpy.data.lights.new(f"{kind.title()}Light", kind)
    light.energy = energy
    light.color = color
    for key, value in settings.items():
        setattr(light, key, value)
    obj = bpy.data.objects.new(light.name, light)
    obj.location, obj.rotation_euler = location, rotation
    bpy.context.scene.collection.objects.link(obj)
    return obj


def add_camera(location, rotation, lens=50.0, sensor_fit='AUTO', **settings):
    camera = bpy.data.cameras.new("Camera")
    camera.lens = lens
    camera.sensor_fit = sensor_fit
    for key, value in settings.items():
        setattr(camera, key, value)
    obj = bpy.data.objects.new("Camera", camera)
    obj.location, obj.rotation_euler = location, rotation
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    return obj


def node_material(name, node_type, **inputs):
    """A material whose output's Surface is one shader node with the given inputs
    (names as Blender spells them; a missing name is an error)."""
    material = bpy.data.materials.new(name)
    tree = compat().use_nodes(material)
    for node in list(tree.nodes):
        if node.type != 'OUTPUT_MATERIAL':
            tree.nodes.remove(node)
    link_to_output(tree, node_type, "Surface", **inputs)
    return material


def link_to_output(tree, node_type, socket, **inputs):
    """A new node of node_type with the given inputs, its first output linked to the
    Material Output's `socket` ("Surface", "Volume"); returns the node."""
    node = tree.nodes.new(node_type)
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(node.outputs[0], output.inputs[socket])
    return node


def diffuse_material(name, color):
    return node_material(name, "ShaderNodeBsdfDiffuse", Color=tuple(color) + (1.0,))


def color_attribute_material(name, attribute="", multiply=None, factor=1.0):
    """A Diffuse BSDF (white) whose Color is a mesh colour attribute: a Color Attribute
    node for the default one (attribute ""), an Attribute node naming another; with
    `multiply` (rgb) through a Mix set to Multiply (factor `factor`) with that constant,
    the 4.x Mix node or 3.x's MixRGB."""
    material = node_material(name, "ShaderNodeBsdfDiffuse", Color=(1.0, 1.0, 1.0, 1.0))
    tree = material.node_tree
    diffuse = next(node for node in tree.nodes if node.type == 'BSDF_DIFFUSE')
    if attribute:
        source = tree.nodes.new("ShaderNodeAttribute")
        source.attribute_name = attribute
    else:
        source = tree.nodes.new("ShaderNodeVertexColor")
    color = source.outputs["Color"]
    if multiply is not None:
        if BLENDER_4:
            mix = tree.nodes.new("ShaderNodeMix")
            mix.data_type = 'RGBA'
            sockets = {s.identifier: s for s in mix.inputs}
            factor_in, a, b = sockets["Factor_Float"], sockets["A_Color"], sockets["B_Color"]
        else:
            mix = tree.nodes.new("ShaderNodeMixRGB")
            factor_in, a, b = mix.inputs["Fac"], mix.inputs["Color1"], mix.inputs["Color2"]
        mix.blend_type = 'MULTIPLY'
        factor_in.default_value = factor
        a.default_value = tuple(multiply) + (1.0,)
        tree.links.new(color, b)
        color = next(o for o in mix.outputs if o.enabled and o.type == 'RGBA')
    tree.links.new(color, diffuse.inputs["Color"])
    return material


def set_corner_colors(obj, name, colors, domain='CORNER', data_type='BYTE_COLOR', srgb=False):
    """A colour attribute on obj's mesh: one rgb per corner (loop) or point; byte colours
    given as sRGB values when srgb (Blender stores those bytes exactly)."""
    attribute = obj.data.color_attributes.new(name, data_type, domain)
    rgba = np.concatenate([np.asarray(colors, np.float32),
                           np.ones((len(colors), 1), np.float32)], axis=1)
    attribute.data.foreach_set("color_srgb" if srgb else "color", rgba.ravel())
    return attribute


def emission_material(name, color, strength):
    return node_material(name, "ShaderNodeEmission", Color=tuple(color) + (1.0,),
                         Strength=strength)


def set_world(color, strength=1.0):
    world = bpy.data.worlds.new("World")
    compat().use_nodes(world)
    background = next(node for node in world.node_tree.nodes if node.type == 'BACKGROUND')
    background.inputs["Color"].default_value = tuple(color) + (1.0,)
    background.inputs["Strength"].default_value = strength
    bpy.context.scene.world = world
    return world


def export(size=None):
    """Exports the current scene as the engine would: SceneData."""
    scene = bpy.context.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    width, height = size or (scene.render.resolution_x, scene.render.resolution_y)
    return ADDON.export.export_scene(depsgraph, scene.camera, width, height)


def load_native():
    """The add-on's native module. A test that needs it fails when it cannot load: the
    module is built and installed for every Blender this suite runs in."""
    module, problem = ADDON.native_module.load()
    if module is None:
        raise RuntimeError(f"the native module did not load in Blender: {problem}")
    return module


def render_image(name, engine='GLSLPPM'):
    """Renders the current scene with engine into OUT/name.exr; returns linear RGBA
    (H, W, 4) with row 0 at the top."""
    scene = bpy.context.scene
    scene.render.engine = engine
    settings = scene.render.image_settings
    compat().set_exr_format(settings)  # single-layer (5.x: media type Image)
    settings.exr_codec = 'ZIP'
    path = os.path.join(OUT, f"{name}.exr")
    scene.render.filepath = path
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    return load_image(path)


def linear_image(name, pixels):
    """A float image of (H, W, 4) pixels saved as EXR in OUT and loaded back Linear, so that
    both engines read it from a file (row 0 at the bottom)."""
    height, width = pixels.shape[:2]
    image = bpy.data.images.new(name, width, height, float_buffer=True)
    image.pixels.foreach_set(np.ascontiguousarray(pixels, dtype=np.float32).ravel())
    path = os.path.join(OUT, f"{name}.exr")
    image.filepath_raw = path
    image.file_format = 'OPEN_EXR'
    image.save()
    bpy.data.images.remove(image)
    image = bpy.data.images.load(path, check_existing=False)
    image.colorspace_settings.name = "Linear" if not BLENDER_4 else "Linear Rec.709"
    return image


def load_image(path):
    image = bpy.data.images.load(path, check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)[::-1]


def setup_cycles(samples=64, bounces=16):
    """Cycles on the CPU, unbiased and unclamped, so it is a fair reference."""
    scene = bpy.context.scene
    scene.render.engine = 'CYCLES'
    cycles = scene.cycles
    cycles.device = 'CPU'
    cycles.samples = samples
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    set_light_paths(scene, bounces)
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.light_sampling_threshold = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    cycles.blur_glossy = 0.0
    cycles.seed = 1
    scene.render.threads_mode = 'AUTO'


def region_means(image, grid):
    """Mean RGB of each cell of a grid x grid split of the image: (grid, grid, 3);
    NaN pixels (masked out) are left out of the means."""
    height, width = image.shape[:2]
    rows = np.array_split(np.arange(height), grid)
    cols = np.array_split(np.arange(width), grid)
    return np.array([[np.nanmean(image[r[0]:r[-1] + 1, c[0]:c[-1] + 1, :3].reshape(-1, 3),
                                 axis=0)
                      for c in cols] for r in rows])


def assert_close(actual, expected, tolerance=1e-5, what="value"):
    actual = np.asarray(actual, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    if actual.shape != expected.shape or not np.allclose(actual, expected, atol=tolerance,
                                                         rtol=0.0):
        raise AssertionError(f"{what}: expected {expected.tolist()}, got {actual.tolist()}")


def recording_engine_class():
    """A subclass of the add-on's engine that records its reports and can stop after
    a number of passes (standing in for the user pressing Esc)."""
    mixin = ADDON.engine.render_engine.GlslppmEngineMixin

    class GlslppmRecordingEngine(mixin, bpy.types.RenderEngine):
        bl_idname = "GLSLPPM_RECORDING"
        bl_label = "GLSLPPM (test recorder)"
        reports = []
        break_after_passes = None
        break_in_stage = None       # (stage, seconds in it): cancel there, as Esc would
        break_requested_at = None   # perf_counter() of the first cancel answered
        break_stage = None          # the stage it was answered in
        render_returned_at = None
        last_passes = 0
        last_stats = {}
        tiles_seen = []             # (tile, tiles) of the engine's image tiles, in order

        def render(self, depsgraph):
            super().render(depsgraph)
            GlslppmRecordingEngine.render_returned_at = time.perf_counter()

        def report_to_user(self, level, message):
            GlslppmRecordingEngine.reports.append((level, message))
            super().report_to_user(level, message)

        def should_stop(self):
            limit = GlslppmRecordingEngine.break_after_passes
            GlslppmRecordingEngine.last_passes = self.passes_done
            GlslppmRecordingEngine.last_stats = self.last_stats
            seen = GlslppmRecordingEngine.tiles_seen
            if self.tile_progress is not None and self.tile_progress not in seen:
                seen.append(self.tile_progress)
            if limit is not None and self.passes_done >= limit:
                return True
            stage = GlslppmRecordingEngine.break_in_stage
            clock = self.stage_clock
            if stage is not None and clock is not None and clock.stage == stage[0] and \
                    time.perf_counter() - clock.since >= stage[1]:
                if GlslppmRecordingEngine.break_requested_at is None:
                    GlslppmRecordingEngine.break_requested_at = time.perf_counter()
                    GlslppmRecordingEngine.break_stage = clock.stage
                return True
            return super().should_stop()

    return GlslppmRecordingEngine


_recording = []


def recording_engine():
    """The recording engine, registered once per session; its records cleared."""
    if not _recording:
        cls = recording_engine_class()
        bpy.utils.register_class(cls)
        _recording.append(cls)
    cls = _recording[0]
    cls.reports.clear()
    cls.break_after_passes = None
    cls.break_in_stage = None
    cls.break_requested_at = None
    cls.break_stage = None
    cls.render_returned_at = None
    cls.last_passes = 0
    cls.last_stats = {}
    cls.tiles_seen = []
    return cls


def look_at_rotation(location, target):
    """Euler rotation of a camera at location looking at target with +Z up."""
    from mathutils import Vector
    direction = Vector(target) - Vector(location)
    return direction.to_track_quat('-Z', 'Y').to_euler()


def degrees(value):
    return math.radians(value)


def add_bumpy_grid(quads_per_side, name="Grid"):
    """A grid of 2 * n^2 triangles over [-1, 1]^2 with random heights (so a BVH build does
    real work), built with foreach_set: a million quads take about a second."""
    n = quads_per_side
    xs, ys = np.meshgrid(np.linspace(-1, 1, n + 1), np.linspace(-1, 1, n + 1))
    heights = 0.05 * np.random.default_rng(1).random(xs.size)
    vertices = np.stack([xs.ravel(), ys.ravel(), heights], 1)
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    base = (j * (n + 1) + i).ravel()
    quads = np.stack([base, base + 1, base + n + 2, base + n + 1], 1)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", vertices.astype(np.float32).ravel())
    mesh.loops.add(quads.size)
    mesh.loops.foreach_set("vertex_index", quads.astype(np.int32).ravel())
    mesh.polygons.add(len(quads))
    mesh.polygons.foreach_set("loop_start", np.arange(0, quads.size, 4, dtype=np.int32))
    if not BLENDER_4:
        mesh.polygons.foreach_set("loop_total", np.full(len(quads), 4, dtype=np.int32))
    mesh.update(calc_edges=True)
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def render_recorded(name, engine=None):
    """(image or None, error or None, the recording engine) for the current scene."""
    load_native()
    engine = engine or recording_engine()
    try:
        return render_image(name, engine.bl_idname), None, engine
    except RuntimeError as error:
        path = os.path.join(OUT, f"{name}.exr")
        image = load_image(path) if os.path.exists(path) else None
        return image, str(error), engine


def last_render_stats():
    """renderer.stats() of the recording engine's last render (its variant, radii...)."""
    return _recording[0].last_stats if _recording else {}


# The warning of a render projected past 10 minutes (engine/progressive.py) speaks of the
# machine's speed, not of the scene: on a loaded machine it comes with scenes of a few
# hundred passes, so the tests of a scene's warnings leave it out (test_render tests it).
LONG_RENDER_WARNING = "this render will take about"


def warnings_of(engine):
    return [message for level, message in engine.reports
            if level == 'WARNING' and LONG_RENDER_WARNING not in message]


def render_cycles_box_filter(name, samples=64):
    """Cycles with a 1-pixel box filter (as GLSLPPM's jittered samples), then back to
    GLSLPPM."""
    setup_cycles(samples=samples)
    cycles = bpy.context.scene.cycles
    cycles.pixel_filter_type = 'BOX'
    cycles.filter_width = 1.0
    image = render_image(f"{name}_cycles", 'CYCLES')
    bpy.context.scene.render.engine = 'GLSLPPM'
    return image


def region_comparison(ours, reference, grid=3):
    """Region means (grey) of both images, the worst region's difference relative to the
    brightest reference region, and the image means' relative difference."""
    a, b = (region_means(image, grid).mean(axis=2).astype(np.float64)
            for image in (ours, reference))
    region_error = float(np.abs(a - b).max() / b.max())
    mean_error = float(abs(a.mean() - b.mean()) / b.mean())
    return a, b, region_error, mean_error
