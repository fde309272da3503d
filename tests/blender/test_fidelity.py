"""What a new user meets in Blender's own settings: render region, pixel aspect, broken
light numbers, light node trees, transparent film, volumes, motion blur, UDIM images,
oversized renders, multi-view and two-sided mesh emission. Each either matches Cycles
(or a closed form) within a stated tolerance, or warns in words the test checks exactly
while the image is still written.

Cycles renders with a 1-pixel box filter here, as GLSLPPM's pixels are, so that edges
compare pixel by pixel.
"""

import math
import os
import time

import bpy
import numpy as np

import helpers
from helpers import add_camera, add_light, add_mesh_object, diffuse_material

REFERENCE_SAMPLES = 64


def _pixel_error(ours, reference):
    """Mean absolute difference of the RGB pixels over the reference's mean: a pixel
    misplaced across the test pattern's edges shows as tens of percent."""
    return float(np.abs(ours[..., :3] - reference[..., :3]).mean() /
                 max(reference[..., :3].mean(), 1e-9))


def _emissive_grid(size=(64, 48)):
    """Sixteen emissive squares of distinct strengths (1..16) on a black plane, seen from
    straight above: only emission seen directly, so both renderers converge in a few
    passes and every pixel's value says where it is."""
    scene = helpers.reset_scene(size=size)
    scene.glslppm.passes = 64
    scene.glslppm.photons_per_pass = 1024
    for i in range(4):
        for j in range(4):
            lamp = helpers.emission_material(f"Lamp{i}{j}", (1, 1, 1), 1.0 + i + 4 * j)
            x, y = -2.0 + i, -2.0 + j
            add_mesh_object(f"Square{i}{j}", [(x + .1, y + .1, 0), (x + .9, y + .1, 0),
                                              (x + .9, y + .9, 0), (x + .1, y + .9, 0)],
                            [(0, 1, 2, 3)], material=lamp)
    add_camera((0.3, -0.2, 6), (0, 0, 0.1), lens=35.0)
    return scene


# Render region

def _region_scene(crop):
    scene = _emissive_grid()
    render = scene.render
    render.use_border = True
    render.use_crop_to_border = crop
    render.border_min_x, render.border_max_x = 0.3, 0.8
    render.border_min_y, render.border_max_y = 0.25, 0.7
    return scene


def test_render_region_with_crop_matches_cycles():
    """Region 0.3-0.8 x 0.25-0.7 of 64x48, cropped: a 32x21 image (Blender's pixels:
    19..50 by 12..32 from the bottom), pixel error against Cycles below 5% (one pixel's
    shift measures 24-25%)."""
    _region_scene(crop=True)
    ours, error, engine = helpers.render_recorded("region_crop")
    assert error is None, error
    reference = helpers.render_cycles_box_filter("region_crop", REFERENCE_SAMPLES)
    assert ours.shape == reference.shape == (21, 32, 4), (ours.shape, reference.shape)
    measured = _pixel_error(ours, reference)
    print(f"  region with crop: pixel error {measured:.4f} (tolerance 0.05)")
    assert measured < 0.05, measured
    assert np.isfinite(ours).all()


def test_render_region_without_crop_matches_cycles():
    """The same region in the full 64x48 frame: pixel error below 5% against Cycles and
    nothing outside the region (Blender leaves it transparent black)."""
    _region_scene(crop=False)
    ours, error, engine = helpers.render_recorded("region_full")
    assert error is None, error
    reference = helpers.render_cycles_box_filter("region_full", REFERENCE_SAMPLES)
    assert ours.shape == reference.shape == (48, 64, 4), (ours.shape, reference.shape)
    measured = _pixel_error(ours, reference)
    print(f"  region without crop: pixel error {measured:.4f} (tolerance 0.05)")
    assert measured < 0.05, measured
    outside = np.ones((48, 64), dtype=bool)
    outside[48 - 33:48 - 12, 19:51] = False  # rows counted from the top here
    assert ours[outside].max() == 0.0 and ours[~outside, :3].mean() > 0.5


# Pixel aspect

def test_pixel_aspect_matches_cycles():
    """Pixel aspect 2:1 (and 1:2 with a vertical sensor fit): image mean within 2% of
    Cycles', pixel error below 5%."""
    for aspect, fit in (((2.0, 1.0), 'AUTO'), ((1.0, 2.0), 'VERTICAL')):
        scene = _emissive_grid()
        scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = aspect
        scene.camera.data.sensor_fit = fit
        ours, error, engine = helpers.render_recorded("pixel_aspect")
        assert error is None, error
        reference = helpers.render_cycles_box_filter("pixel_aspect", REFERENCE_SAMPLES)
        means = float(ours[..., :3].mean()), float(reference[..., :3].mean())
        measured = _pixel_error(ours, reference)
        print(f"  pixel aspect {aspect} {fit}: mean GLSLPPM {means[0]:.4f} Cycles "
              f"{means[1]:.4f}; pixel error {measured:.4f} (tolerances 0.02, 0.05)")
        assert abs(means[0] - means[1]) < 0.02 * means[1], means
        assert measured < 0.05, measured


# Light numbers that are not finite

def _floor_and_light(size=(32, 32)):
    """A white diffuse floor (albedo 0.8) under a 300 W point light 3 m above it."""
    scene = helpers.reset_scene(size=size)
    scene.glslppm.passes = 16
    scene.glslppm.photons_per_pass = 8192
    white = diffuse_material("White", (0.8, 0.8, 0.8))
    add_mesh_object("Floor", [(-10, -10, 0), (10, -10, 0), (10, 10, 0), (-10, 10, 0)],
                    [(0, 1, 2, 3)], material=white)
    light = add_light('POINT', 300.0, location=(0, 0, 3), shadow_soft_size=0.0)
    location = (0, -4, 2)
    add_camera(location, helpers.look_at_rotation(location, (0, 0, 0)), lens=35.0)
    return scene, light


def test_infinite_or_nan_light_is_off_with_a_warning():
    """A light whose power is inf, or whose colour is NaN, is left out (as Cycles leaves
    it dark) with a warning naming it: the image is finite and equals the render without
    that light to 1e-5 relative."""
    _floor_and_light()
    clean, error, engine = helpers.render_recorded("light_clean")
    assert error is None, error
    cases = ((dict(energy=math.inf), "light 'Bad': power is inf; the light is off"),
             (dict(color=(1.0, math.nan, 1.0)),
              "light 'Bad': colour G is nan; the light is off"),
             (dict(energy=math.nan), "light 'Bad': power is nan; the light is off"))
    for settings, expected in cases:
        bad = add_light('POINT', 100.0, location=(1, 1, 2))
        bad.name = bad.data.name = "Bad"
        for key, value in settings.items():
            setattr(bad.data, key, value)
        if not all(math.isfinite(v) for v in (bad.data.energy, *bad.data.color)):
            image, error, engine = helpers.render_recorded("light_bad")
            assert error is None, error
            assert expected in helpers.warnings_of(engine), (expected, engine.reports)
            assert np.isfinite(image).all()
            difference = float(np.abs(image - clean).max() / clean[..., :3].max())
            print(f"  {expected}: largest difference from the clean render {difference:.2e}")
            assert difference < 1e-5, difference
        else:
            print(f"  Blender stored {settings} as finite numbers; nothing to check")
        bpy.data.objects.remove(bad)
        bpy.data.lights.remove(bpy.data.lights["Bad"])


# Light node trees

def _emission_node(light):
    tree = helpers.compat().use_nodes(light)
    return tree, next(node for node in tree.nodes if node.type == 'EMISSION')


def test_light_node_emission_matches_cycles():
    """The Emission node of a light's node tree (strength 3, colour (1, 0.5, 0.25))
    scales the light as in Cycles: the floor's centre within 5% per channel."""
    scene, light = _floor_and_light()
    scene.glslppm.passes = 64
    tree, emission = _emission_node(light.data)
    emission.inputs["Strength"].default_value = 3.0
    emission.inputs["Color"].default_value = (1.0, 0.5, 0.25, 1.0)
    ours, error, engine = helpers.render_recorded("light_nodes")
    assert error is None, error
    reference = helpers.render_cycles_box_filter("light_nodes", REFERENCE_SAMPLES)
    a = ours[8:24, 8:24, :3].mean(axis=(0, 1))
    b = reference[8:24, 8:24, :3].mean(axis=(0, 1))
    errors = np.abs(a - b) / b
    print(f"  light node tree: centre GLSLPPM {[round(float(x), 4) for x in a]} Cycles "
          f"{[round(float(x), 4) for x in b]}; errors "
          f"{[round(float(x), 4) for x in errors]} (tolerance 0.05)")
    assert errors.max() < 0.05, (a, b)


def test_light_ies_texture_warns():
    """An IES Texture in a light's node tree is named in a warning; the light still
    lights the floor and the image is written."""
    scene, light = _floor_and_light()
    tree, emission = _emission_node(light.data)
    ies = tree.nodes.new("ShaderNodeTexIES")
    tree.links.new(ies.outputs[0], emission.inputs["Strength"])
    image, error, engine = helpers.render_recorded("light_ies")
    assert error is None, error
    expected = f"light '{light.data.name}': IES textures are not supported; the light emits " \
               "evenly"
    assert expected in helpers.warnings_of(engine), engine.reports
    assert np.isfinite(image).all() and image[..., :3].mean() > 1e-3


# Transparent film

def _object_in_the_world(make_material):
    scene = helpers.reset_scene(size=(48, 48))
    material = make_material()
    scene.glslppm.passes = 64
    scene.glslppm.photons_per_pass = 4096
    helpers.set_world((0.4, 0.6, 0.9), strength=1.0)
    helpers.add_cube(location=(0, 0, 0), rotation=(0.3, 0.2, 0.5), scale=(0.8, 0.8, 0.8),
                     material=material)
    location = (0, -5, 1.5)
    add_camera(location, helpers.look_at_rotation(location, (0, 0, 0)), lens=40.0)
    scene.render.film_transparent = True
    return scene


def _alpha_error(name):
    ours, error, engine = helpers.render_recorded(name)
    assert error is None, error
    reference = helpers.render_cycles_box_filter(name, REFERENCE_SAMPLES)
    difference = float(np.abs(ours[..., 3] - reference[..., 3]).mean())
    return ours, reference, difference


def test_transparent_film_alpha_matches_cycles():
    """Film > Transparent: alpha 0 where camera rays leave the scene, 1 on the cube,
    partial on its edges: mean per-pixel alpha difference from Cycles below 0.01; where
    Cycles is fully transparent the image is exactly 0 (no world)."""
    _transparent_grey_cube_against_cycles('SPPM', "transparent")


def test_transparent_film_under_vcm_matches_cycles():
    """Film > Transparent under the VCM estimator (its eye paths leave the world out as
    SPPM's do): the same bounds against Cycles as above. Measured: mean alpha 0.1977
    against Cycles' 0.1975-0.1977, mean pixel difference 0.0016 (bound 0.01) on 3.4.1,
    4.3.2 and 5.2.2. The bound catches a film that shows the world or loses the cube; a 1%
    bias of the transparency itself is the module's test_camera::
    test_transparent_glass_film_sees_through_a_slab_as_often_as_it_transmits[vcm] (0.28%)."""
    _transparent_grey_cube_against_cycles('VCM', "transparent_vcm")


def _transparent_grey_cube_against_cycles(estimator, name):
    scene = _object_in_the_world(lambda: diffuse_material("Grey", (0.5, 0.5, 0.5)))
    scene.glslppm.estimator = estimator
    ours, reference, difference = _alpha_error(name)
    assert helpers.last_render_stats()["estimator"] == estimator.lower()
    print(f"  transparent film, {estimator}: mean alpha GLSLPPM {ours[..., 3].mean():.4f} "
          f"Cycles {reference[..., 3].mean():.4f}; mean pixel difference {difference:.4f} "
          "(tolerance 0.01)")
    assert difference < 0.01, difference
    empty = reference[..., 3] == 0.0
    assert empty.sum() > 1000 and np.abs(ours[empty]).max() == 0.0
    assert ours[..., 3].max() == 1.0


def test_transparent_glass_alpha_matches_cycles():
    """With Cycles' Transparent Glass on, camera rays that leave through smooth glass are
    transparent by what the glass transmits: the glass cube's mean alpha within 0.03 of
    Cycles', the mean per-pixel difference below 0.03."""
    scene = _object_in_the_world(lambda: helpers.node_material(
        "Glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.0))
    scene.cycles.film_transparent_glass = True
    ours, reference, difference = _alpha_error("transparent_glass")
    cube = reference[..., 3] > 0.0
    means = float(ours[cube, 3].mean()), float(reference[cube, 3].mean())
    print(f"  transparent glass: cube alpha GLSLPPM {means[0]:.4f} Cycles {means[1]:.4f}; "
          f"mean pixel difference {difference:.4f} (tolerances 0.03, 0.03)")
    assert abs(means[0] - means[1]) < 0.03, means
    assert difference < 0.03, difference
    assert 0.05 < means[1] < 0.9, "the glass should be partly transparent"


# Volumes, motion blur, UDIM: warnings, and the image still written

def _volume_material(name):
    material = bpy.data.materials.new(name)
    tree = helpers.compat().use_nodes(material)
    for node in list(tree.nodes):
        if node.type != 'OUTPUT_MATERIAL':
            tree.nodes.remove(node)
    output = next(node for node in tree.nodes if node.type == 'OUTPUT_MATERIAL')
    volume = tree.nodes.new("ShaderNodeVolumePrincipled")
    tree.links.new(volume.outputs[0], output.inputs["Volume"])
    return material


def test_volume_object_is_left_out_with_a_warning():
    """A cube whose material has only a Volume output is left out (not an opaque black
    cube): the exact warning, and the image equals the scene without it."""
    scene, light = _floor_and_light()
    clean, error, engine = helpers.render_recorded("volume_clean")
    assert error is None, error
    helpers.add_cube("Smoke", location=(0, 0, 1), scale=(0.6, 0.6, 0.6),
                     material=_volume_material("Smoke"))
    image, error, engine = helpers.render_recorded("volume_object")
    assert error is None, error
    expected = "object 'Smoke': its material 'Smoke' has only a Volume output; volumes " \
               "are not supported, so the object is left out"
    assert expected in helpers.warnings_of(engine), engine.reports
    difference = float(np.abs(image - clean).max())
    print(f"  volume object: largest difference from the scene without it {difference:.2e}")
    assert difference == 0.0, difference


def test_world_volume_warns():
    scene, light = _floor_and_light()
    world = helpers.set_world((0.05, 0.05, 0.05))
    output = next(node for node in world.node_tree.nodes if node.type == 'OUTPUT_WORLD')
    volume = world.node_tree.nodes.new("ShaderNodeVolumeScatter")
    world.node_tree.links.new(volume.outputs[0], output.inputs["Volume"])
    image, error, engine = helpers.render_recorded("world_volume")
    assert error is None, error
    expected = "world 'World': world volumes are not supported; rendering without it"
    assert expected in helpers.warnings_of(engine), engine.reports
    assert np.isfinite(image).all() and image[..., :3].mean() > 1e-3


def test_udim_image_warns():
    """A UDIM image of two tiles as a base colour: the warning names it and the tile
    used; the render is written."""
    scene, light = _floor_and_light()
    image = bpy.data.images.new("Tiles", 8, 8, tiled=True)
    image.generated_color = (0.8, 0.6, 0.4, 1.0)
    image.tiles.new(tile_number=1002)
    floor = bpy.data.objects["Floor"]
    floor.data.uv_layers.new().data.foreach_set("uv", [0, 0, 2, 0, 2, 1, 0, 1])
    material = floor.data.materials[0]
    texture = material.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    diffuse = next(node for node in material.node_tree.nodes if node.type == 'BSDF_DIFFUSE')
    material.node_tree.links.new(texture.outputs["Color"], diffuse.inputs["Color"])
    result, error, engine = helpers.render_recorded("udim")
    assert error is None, error
    expected = "material 'White': image 'Tiles' is a UDIM image of 2 tiles; only tile 1001 " \
               "is used, for every UV"
    assert expected in helpers.warnings_of(engine), engine.reports
    assert np.isfinite(result).all() and result[..., :3].mean() > 1e-3


# Two-sided mesh emission

def test_mesh_emission_is_two_sided_as_in_cycles():
    """An emissive quad facing up, 1 m above a white floor: its back lights the floor
    and shows its radiance to a camera below it, as in Cycles. The quad's back seen
    directly equals its strength (closed form, 1e-4 relative); the 2x2 region means are
    within 6% of Cycles' and the image mean within 4%."""
    scene = helpers.reset_scene(size=(48, 48))
    scene.glslppm.passes = 64
    scene.glslppm.photons_per_pass = 16384
    white = diffuse_material("White", (0.8, 0.8, 0.8))
    add_mesh_object("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)],
                    [(0, 1, 2, 3)], material=white)
    lamp = helpers.emission_material("Lamp", (1, 1, 1), 5.0)
    helpers.add_quad("Panel", [(-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)],
                     material=lamp)  # counter-clockwise from above: facing +Z
    location = (0, -3.5, 0.3)
    add_camera(location, helpers.look_at_rotation(location, (0, 0, 0.7)), lens=30.0)
    ours, error, engine = helpers.render_recorded("two_sided")
    assert error is None, error
    reference = helpers.render_cycles_box_filter("two_sided", REFERENCE_SAMPLES)
    errors = np.abs(helpers.region_means(ours, 2) - helpers.region_means(reference, 2))
    errors = (errors / np.maximum(helpers.region_means(reference, 2), 1e-6)).mean(axis=2)
    means = float(ours[..., :3].mean()), float(reference[..., :3].mean())
    panel = reference[..., :3].min(axis=2) > 4.99
    seen = float(ours[panel, :3].mean()) if panel.any() else float("nan")
    print(f"  two-sided emission: mean GLSLPPM {means[0]:.4f} Cycles {means[1]:.4f}; "
          f"quadrant errors {[round(float(e), 3) for e in errors.ravel()]}; panel back "
          f"{seen:.5f} over {int(panel.sum())} pixels (expected 5)")
    assert panel.sum() > 20, int(panel.sum())
    assert abs(seen - 5.0) < 5e-4, seen
    assert abs(means[0] - means[1]) < 0.04 * means[1], means
    assert errors.max() < 0.06, errors.round(3).tolist()


# Renders too large to fit

def test_oversized_render_is_refused_at_once():
    """16384 x 16384 is refused before anything is allocated: an error naming the
    memory needed and the limit it exceeds, within 10 s and without growing the process
    by more than 1 GiB (the full render needs tens of GiB)."""
    import resource
    scene, light = _floor_and_light()
    scene.render.resolution_x = scene.render.resolution_y = 16384
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    began = time.perf_counter()
    image, error, engine = helpers.render_recorded("oversized")
    seconds = time.perf_counter() - began
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - before
    errors = [message for level, message in engine.reports if level == 'ERROR']
    print(f"  oversized: refused in {seconds:.2f} s, peak memory grew {grown / 2**20:.0f} MiB: "
          f"{errors}")
    assert errors and errors[0].startswith("the render does not fit: "), engine.reports
    assert "GiB" in errors[0] and errors[0].endswith(
        "Lower the resolution (or use a render region) or the photons per pass"), errors
    assert error is not None and "does not fit" in error, error
    assert seconds < 10.0, seconds
    assert grown < 2**30, grown
    # A small render is never refused for a GPU memory figure a driver got wrong (Mesa's
    # llvmpipe answers the NVX memory query with a negative number).
    memory = helpers.ADDON.engine.memory
    native = helpers.load_native()
    settings = native.Settings(width=64, height=64, photons_per_pass=65536)
    for limits in ({"software": True, "memory_bytes": -1507758825472,
                    "max_storage_buffer_bytes": 1 << 27},
                   {"software": False, "memory_bytes": -1, "max_storage_buffer_bytes": 0}):
        small = memory.estimate(native, settings, 1, limits)
        # The GPU's bytes are the module's (memory_estimate), not a copy of its sizes.
        assert small["gpu"] == native.memory_estimate(
            settings, largest_block=limits["max_storage_buffer_bytes"])["gpu"]
        assert memory.refusal(small, limits, 1 << 30) is None, limits


# Stereo 3D

def _render_views(name, engine):
    """Renders the current scene with engine; Blender writes one file per eye
    (name_L.exr, name_R.exr): {"left": image, "right": image}."""
    helpers.load_native()
    scene = bpy.context.scene
    scene.render.engine = engine
    settings = scene.render.image_settings
    settings.file_format = 'OPEN_EXR'
    settings.color_depth = '32'
    scene.render.filepath = os.path.join(helpers.OUT, f"{name}.exr")
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    scene.render.engine = 'GLSLPPM'
    # Read by the module: Blender's loader takes name_L.exr for a two-view image.
    native = helpers.load_native()
    return {eye: native.read_exr(os.path.join(helpers.OUT, f"{name}{suffix}.exr"))[0]
            for eye, suffix in (("left", "_L"), ("right", "_R"))}


def test_stereo_views_match_cycles():
    """Stereo 3D (off-axis, 0.3 m between the eyes): both eyes rendered, each through its
    own camera: pixel error against Cycles' same eye below 5% (an eye swapped or missing
    measures tens of percent), opaque, and the two eyes differ."""
    scene = _emissive_grid()
    scene.render.use_multiview = True
    scene.render.views_format = 'STEREO_3D'
    scene.render.image_settings.views_format = 'INDIVIDUAL'
    stereo = scene.camera.data.stereo
    stereo.convergence_mode = 'OFFAXIS'
    stereo.interocular_distance = 0.3
    stereo.convergence_distance = 4.0
    engine = helpers.recording_engine()
    ours = _render_views("stereo", engine.bl_idname)
    helpers.setup_cycles(samples=REFERENCE_SAMPLES)
    scene.cycles.pixel_filter_type = 'BOX'
    scene.cycles.filter_width = 1.0
    reference = _render_views("stereo_cycles", 'CYCLES')
    assert not [m for level, m in engine.reports if level == 'ERROR'], engine.reports
    for eye in ("left", "right"):
        measured = _pixel_error(ours[eye], reference[eye])
        swapped = _pixel_error(ours[eye], reference["right" if eye == "left" else "left"])
        print(f"  stereo {eye} eye: pixel error {measured:.4f} (tolerance 0.05; against the "
              f"other eye {swapped:.4f})")
        assert measured < 0.05, measured
        assert ours[eye][..., 3].min() == 1.0
    assert _pixel_error(ours["left"], ours["right"]) > 0.2


# The device, by name, in the add-on preferences

def test_device_preferences_list_devices_by_name():
    """The preferences list "Automatic" and every EGL device the module lists, by index
    and name; the device chosen there is the one renders use (unless a scene overrides
    it), and a render on it finishes."""
    native = helpers.load_native()
    preferences = helpers.ADDON.properties.preferences
    names = list(native.list_devices())
    items = preferences.device_items(None, bpy.context)
    assert items[0][:2] == ("AUTO", "Automatic"), items
    assert [item[:2] for item in items[1:]] == \
        [(str(i), f"{i}: {name}") for i, name in enumerate(names)], (items, names)
    print(f"  devices: {[item[1] for item in items]}")
    if helpers.SOURCE_MODE:
        raise helpers.Skip("the add-on's preferences exist only when it is enabled")
    if not names:
        raise helpers.Skip("EGL lists no devices here")
    addon_preferences = bpy.context.preferences.addons[helpers.ADDON_NAME].preferences
    scene, light = _floor_and_light()
    addon_preferences.device = str(len(names) - 1)
    try:
        assert preferences.render_device(scene.glslppm) == len(names) - 1
        scene.glslppm.device = 0
        assert preferences.render_device(scene.glslppm) == 0
        scene.glslppm.device = -1
        image, error, engine = helpers.render_recorded("preferred_device")
        assert error is None, error
        assert image[..., :3].mean() > 1e-3
    finally:
        addon_preferences.device = "AUTO"
    assert preferences.render_device(scene.glslppm) == -1


def test_multiview_cameras_match_cycles():
    """Output > Views as Multi-View with a camera per view ("Cam_L" and "Cam_R", another
    place and lens): each view through its own camera, pixel error against Cycles' same
    view below 5%."""
    scene = _emissive_grid()
    scene.camera.name = "Cam_L"
    right = add_camera((-0.5, 0.4, 7), (0.05, -0.08, -0.1), lens=50.0)
    right.name = "Cam_R"
    scene.camera = bpy.data.objects["Cam_L"]
    scene.render.use_multiview = True
    scene.render.views_format = 'MULTIVIEW'
    scene.render.image_settings.views_format = 'INDIVIDUAL'
    engine = helpers.recording_engine()
    ours = _render_views("multiview", engine.bl_idname)
    helpers.setup_cycles(samples=REFERENCE_SAMPLES)
    scene.cycles.pixel_filter_type = 'BOX'
    scene.cycles.filter_width = 1.0
    reference = _render_views("multiview_cycles", 'CYCLES')
    assert not [m for level, m in engine.reports if level == 'ERROR'], engine.reports
    for eye in ("left", "right"):
        measured = _pixel_error(ours[eye], reference[eye])
        print(f"  multi-view {eye}: pixel error {measured:.4f} (tolerance 0.05)")
        assert measured < 0.05, measured
    assert _pixel_error(reference["left"], reference["right"]) > 0.2


# A surface that both emits and reflects (Principled BSDF's Emission)

def _emissive_principled(name, strength):
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    node = next(n for n in material.node_tree.nodes if n.type == 'BSDF_PRINCIPLED')
    color = node.inputs["Emission Color" if "Emission Color" in node.inputs else "Emission"]
    color.default_value = (1.0, 1.0, 1.0, 1.0)
    node.inputs["Emission Strength"].default_value = strength
    return material


def test_emissive_principled_cube_is_its_emission_alone():
    """A grey Principled cube emitting 2 W/m^2 sr, no lamp, a black world: a convex surface
    sees nothing but the black world, so every pixel wholly on it is exactly 2 (closed form;
    the emission seen is noiseless and nothing else may add to it: 0.1% on the mean, 1% on
    any pixel). Its back faces light its closed inside, whose photons the gather took up near
    the edges outside: measured before the fix 14.3x on the mean and 3,019 at worst (64
    passes); after, 1.0000 and 1.0000."""
    scene = helpers.reset_scene(size=(64, 64))
    scene.glslppm.passes = 64
    scene.glslppm.photons_per_pass = 16384
    helpers.add_cube(material=_emissive_principled("Glow", 2.0))
    location = (4, -5, 3)
    add_camera(location, helpers.look_at_rotation(location, (0, 0, 0)), lens=35.0)
    ours, error, engine = helpers.render_recorded("emissive_principled_cube")
    assert error is None, error
    value = ours[..., :3].mean(axis=2)
    lit = value > 1.0
    # Pixels wholly on the cube: lit, with their 8 neighbours lit.
    inner = lit.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            inner &= np.roll(np.roll(lit, dy, axis=0), dx, axis=1)
    print(f"  emissive Principled cube: {int(inner.sum())} pixels, mean "
          f"{value[inner].mean():.5f} max {value.max():.4f} (expected 2)")
    assert inner.sum() > 300, int(inner.sum())
    assert abs(value[inner].mean() - 2.0) < 2e-3, value[inner].mean()
    assert np.abs(value[inner] - 2.0).max() < 0.02, np.abs(value[inner] - 2.0).max()
    assert value.max() < 2.02, value.max()


def _emissive_text():
    """The word "Text" (extruded 0.1: a mesh of 696 triangles) emitting 1 W/m^2 sr from
    a grey Principled BSDF, seen from the front and above: its strokes light each other."""
    scene = helpers.reset_scene(size=(96, 48))
    scene.glslppm.passes = 128
    scene.glslppm.photons_per_pass = 16384
    bpy.ops.object.text_add(location=(-1.0, 0.0, -0.3), rotation=(math.pi / 2, 0.0, 0.0))
    text = bpy.context.object
    text.data.extrude = 0.1
    text.data.materials.append(_emissive_principled("TextGlow", 1.0))
    location = (0.2, -2.5, 1.2)
    add_camera(location, helpers.look_at_rotation(location, (0.0, 0.0, 0.0)), lens=35.0)
    return text


def test_text_object_is_exported_once():
    """A text object is listed by the depsgraph itself and then its evaluated mesh as an
    instance of it; Cycles reads only the mesh. Exported: exactly the mesh's triangles, once
    (before: 696 as world triangles and 696 again as an instance)."""
    text = _emissive_text()
    mesh = text.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    mesh.calc_loop_triangles()
    expected = len(mesh.loop_triangles)
    text.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()
    data = helpers.export()
    exported = data.triangle_count + sum(len(m["indices"]) for m in data.instance_meshes)
    print(f"  text: {data.triangle_count} triangles and {data.instance_count} instances of "
          f"{len(data.instance_meshes)} meshes exported; its mesh has {expected}")
    assert expected > 100, expected
    assert exported == expected, (exported, expected)
    assert data.instance_count <= 1, data.instance_count


def test_emissive_principled_text_matches_cycles():
    """The emissive text against Cycles (box filter, 64 samples), 128 passes. Measured
    before (text drawn twice, photons from the letters' lit insides gathered outside, a
    mix doubling photon flux): image mean 2.35x Cycles', one pixel 211 where Cycles has
    at most 2.3. Then 1.365x, brightest 50.9 against 2.6, an excess that did not shrink
    with passes (1.38x at 128, 1.34x at 512, 1.58x at 2048: fireflies, 50 pixels held 96% of
    it). Its cause: the light inside the closed letters. 98% of the stored photons are
    there, carrying 99.9% of the flux (a furnace of albedo near 1, fluxes up to 10^4 times
    an outside photon's), and the gather's side test let it out: it read shading normals,
    and its exception for normals within 26 degrees (a tessellated sphere's facets) kept the
    inside of every stroke's far wall. It now reads the true surfaces' normals
    (tests/python/test_photon_sides.py, exact): 1.090x, brightest 21.5 against 2.65, and it
    did not converge (other seeds, against Cycles at 256 samples: 1.075x, 1.117x, 1.496x;
    1.072x at 512 passes, 1.113x at 2048; 4.3: 1.003x). Its cause: Principled v1's specular
    is a Fresnel-weighted mix whose index was inverted on back faces, as a Fresnel node's
    is, so inside the closed letters it reflected totally beyond 42 degrees, an albedo near
    1.8 (the letters' meshes are the same in 3.4 and 4.3, whose Principled has no such mix;
    Specular 0 measured 1.004x-1.010x, photons stopped at the specular 0.99x-1.01x). Cycles
    never inverts the specular's index (tests/python/test_layer_fresnel.py); now 1.017x,
    brightest 9.9 against 2.65 (seeds 0-3 against Cycles at 256 samples: 1.018x, 1.008x,
    1.014x, 0.998x, brightest 4.5 to 10.3; 1.006x at 512 and 2048 passes, brightest 3.3, 2.9).
    That pixel is light sampled on the specular seen edge-on (with photons for direct light the
    brightest is 3.6; 0.99x): no BSDF sample is weighed against area lights yet. Bounds: the
    mean within 5% (before 1.07x at best), the brightest pixel within 6x Cycles' (after at
    most 4.1x; before 8.1x with this seed); the cube test above holds the closed form to
    0.1%."""
    _emissive_text()
    ours, error, engine = helpers.render_recorded("emissive_text")
    assert error is None, error
    reference = helpers.render_cycles_box_filter("emissive_text", REFERENCE_SAMPLES)
    mean_ratio = float(ours[..., :3].mean() / reference[..., :3].mean())
    worst = float(ours[..., :3].mean(axis=2).max())
    brightest = float(reference[..., :3].mean(axis=2).max())
    print(f"  emissive text: mean ratio {mean_ratio:.4f}; brightest pixel GLSLPPM {worst:.3f} "
          f"Cycles {brightest:.3f}")
    assert 0.97 < mean_ratio < 1.05, mean_ratio
    assert worst < 6.0 * brightest, (worst, brightest)


# What Cycles shows where something is wrong

def test_missing_image_renders_magenta_as_in_cycles():
    """An emissive panel whose colour is an Image Texture of a file that is gone: Cycles
    shows magenta (1, 0, 1); so does GLSLPPM (before: the socket's own colour, white here),
    with a warning naming the image. Emission seen directly: exact (1e-4)."""
    scene = helpers.reset_scene(size=(16, 16))
    scene.glslppm.passes = 2
    scene.glslppm.photons_per_pass = 1024
    glow = helpers.emission_material("Glow", (1, 1, 1), 1.0)
    tree = glow.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.new("Gone", 2, 2)
    texture.image.source = 'FILE'
    texture.image.filepath = "/nonexistent/gone.png"
    node = next(n for n in tree.nodes if n.type == 'EMISSION')
    tree.links.new(texture.outputs["Color"], node.inputs["Color"])
    panel = add_mesh_object("Panel", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)],
                            [(0, 1, 2, 3)], material=glow)
    panel.data.uv_layers.new()
    add_camera((0, 0, 3), (0, 0, 0), lens=50.0)
    ours, error, engine = helpers.render_recorded("missing_image")
    assert error is None, error
    reference = helpers.render_cycles_box_filter("missing_image", 4)
    seen = ours[..., :3].reshape(-1, 3).mean(axis=0)
    cycles = reference[..., :3].reshape(-1, 3).mean(axis=0)
    print(f"  missing image: GLSLPPM {seen.round(5).tolist()} Cycles {cycles.round(5).tolist()}")
    helpers.assert_close(cycles, (1.0, 0.0, 1.0), 1e-4, "Cycles")
    helpers.assert_close(seen, (1.0, 0.0, 1.0), 1e-4, "GLSLPPM")
    assert any("image 'Gone' is missing" in w and "magenta" in w
               for w in helpers.warnings_of(engine)), engine.reports


def test_negative_light_is_off_with_a_warning():
    """Cycles 3.4 subtracts a negative light's light (measured: a -50 W point light beside a
    100 W one renders 0.5005x the 100 W one alone, and alone renders a negative image).
    SPPM's photons carry no negative flux here, so the light is off and the warning names
    it: the image is the one without it, exactly."""
    _floor_under_point_light()
    without, error, _ = helpers.render_recorded("negative_light_without")
    assert error is None, error
    add_light('POINT', -50.0, location=(0, 0, 3), shadow_soft_size=0.0).name = "Sink"
    bpy.data.objects["Sink"].data.name = "Sink"
    ours, error, engine = helpers.render_recorded("negative_light")
    assert error is None, error
    warning = "light 'Sink': negative power -50 is not supported (Cycles subtracts its " \
              "light); the light is off"
    assert warning in helpers.warnings_of(engine), engine.reports
    print(f"  negative light: mean {ours[..., :3].mean():.5f} without it "
          f"{without[..., :3].mean():.5f}")
    assert np.array_equal(ours, without)


def _floor_under_point_light():
    scene = helpers.reset_scene(size=(32, 32))
    scene.glslppm.passes = 4
    scene.glslppm.photons_per_pass = 4096
    white = diffuse_material("White", (0.8, 0.8, 0.8))
    add_mesh_object("Floor", [(-10, -10, 0), (10, -10, 0), (10, 10, 0), (-10, 10, 0)],
                    [(0, 1, 2, 3)], material=white)
    add_light('POINT', 100.0, location=(0, 0, 3), shadow_soft_size=0.0)
    location = (0, -4, 2)
    add_camera(location, helpers.look_at_rotation(location, (0, 0, 0)), lens=35.0)
