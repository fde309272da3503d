"""GLSLPPM against Cycles rendering the same Blender scene (Cycles on the CPU,
unclamped, no denoising, the same bounce limit).

Tolerances: Cycles' noise at REFERENCE_SAMPLES and SPPM's noise and radius bias at
the pass counts below both stay well under them on these region sizes (measured
errors are 0.1-2%, the Cornell box's worst region 5%); each test prints its
measured errors so a regression shows as a number, not only a failure.
"""

import importlib
import math
import os
import sys

import bpy
import numpy as np

import helpers

REFERENCE_SAMPLES = 128


def _demo_module():
    demo = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "demo")
    if demo not in sys.path:
        sys.path.insert(0, os.path.abspath(demo))
    import cornell_box
    return cornell_box


def _render_both(name, passes, photons, samples=REFERENCE_SAMPLES):
    helpers.load_native()
    scene = bpy.context.scene
    scene.glslppm.passes = passes
    scene.glslppm.photons_per_pass = photons
    ours = helpers.render_image(f"{name}_glslppm", 'GLSLPPM')
    helpers.setup_cycles(samples=samples)
    reference = helpers.render_image(f"{name}_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    return ours, reference


def _relative_errors(ours, reference, grid):
    a = helpers.region_means(ours, grid).mean(axis=2)
    b = helpers.region_means(reference, grid).mean(axis=2)
    return np.abs(a - b) / np.maximum(b, 1e-6), a, b


def test_diffuse_cornell_box_matches_cycles():
    """Mean relative error over a 4x4 grid of regions below 2.5%, every region below 7%
    (measured before these bounds: 1.5% and 3.4% under 3.4, 1.4% and 3.3% under 4.3; a 3%
    loss at diffuse surfaces gave 4.3% and 6.3%). The ceiling light, which the demo shows,
    is hidden from the camera here: seen edge-on it is a sliver one pixel tall, whose
    40 W/m^2 sr Cycles' pixel filter spreads over its neighbours."""
    helpers.reset_scene(size=(64, 64))
    _demo_module().build_cornell_box(glass=False, mirror=False)
    bpy.data.objects["CeilingLight"].visible_camera = False
    ours, reference = _render_both("cornell", passes=128, photons=32768)
    errors, a, b = _relative_errors(ours, reference, 4)
    print(f"  cornell: region errors mean {errors.mean():.4f} max {errors.max():.4f}; "
          f"image mean GLSLPPM {np.nanmean(ours[..., :3]):.4f} "
          f"Cycles {np.nanmean(reference[..., :3]):.4f}")
    assert errors.mean() < 0.025, (errors.round(3).tolist(), a.round(4).tolist(),
                                   b.round(4).tolist())
    assert errors.max() < 0.07, errors.round(3).tolist()


def test_demo_cornell_box_with_glass_and_mirror_spheres_matches_cycles():
    """The demo scene itself: a glass sphere (IOR 1.5) and a mirror sphere in the Cornell
    box, against Cycles with caustics on and no glossy blur. The light is hidden from the
    camera as above. Cycles finds the glass sphere's caustic only by BSDF sampling through
    the sphere onto a small light, so its reference is the noisier one: at 1024 samples two
    other Cycles seeds differ from this one by 0.7% and 1.2% (mean region error) and 2.4%
    and 4.8% (worst region, the caustic's). That noise keeps these bounds from catching a 1%
    bias in the glass alone; tests/python/test_specular_closed_forms.py does. Measured under
    3.4: mean 1.3%, worst 5.8%, image mean ratio 0.9955."""
    helpers.reset_scene(size=(64, 64))
    _demo_module().build_cornell_box(glass=True, mirror=True)
    bpy.data.objects["CeilingLight"].visible_camera = False
    ours, reference = _render_both("cornell_spheres", passes=192, photons=32768,
                                   samples=1024)
    errors, a, b = _relative_errors(ours, reference, 4)
    mean_ratio = np.nanmean(ours[..., :3]) / np.nanmean(reference[..., :3])
    print(f"  cornell with spheres: region errors mean {errors.mean():.4f} "
          f"max {errors.max():.4f}; image mean ratio {mean_ratio:.4f}")
    assert abs(mean_ratio - 1.0) < 0.02, mean_ratio
    assert errors.mean() < 0.03, (errors.round(3).tolist(), a.round(4).tolist(),
                                  b.round(4).tolist())
    assert errors.max() < 0.09, errors.round(3).tolist()


def test_unequal_light_path_limits_match_cycles():
    """Cycles' Light Paths with kinds cut apart (Total 12, Diffuse 1, Glossy 4,
    Transmission 8) on the Cornell box with its glass and mirror spheres: GLSLPPM reads
    scene.cycles' limits and cuts its eye subpaths, photon subpaths and their joins at the
    visible points as Cycles cuts its paths (docs/bounces.md). The limits matter here: the
    same scene at 16 of every kind is brighter by far more than the bounds (printed; the
    diffuse interreflection of the walls). Bounds as the demo box's test, whose noise they
    come from (Cycles' glass caustic): image mean within 2%, 4x4 region errors mean 3%,
    worst 9%. Measured under 3.4: ratio 1.0021, regions mean 1.1% and worst 6.0%; at 16 of
    every kind 1.223."""
    helpers.reset_scene(size=(64, 64))
    _demo_module().build_cornell_box(glass=True, mirror=True)
    bpy.data.objects["CeilingLight"].visible_camera = False
    scene = bpy.context.scene
    helpers.load_native()
    scene.glslppm.passes = 48
    scene.glslppm.photons_per_pass = 32768
    unlimited = helpers.render_image("light_paths_16", 'GLSLPPM')
    helpers.set_light_paths(scene, 12, diffuse=1, glossy=4, transmission=8)
    scene.glslppm.passes = 192
    ours = helpers.render_image("light_paths_glslppm", 'GLSLPPM')
    helpers.setup_cycles(samples=1024)  # (at 16 of every kind: set again below)
    helpers.set_light_paths(scene, 12, diffuse=1, glossy=4, transmission=8)
    reference = helpers.render_image("light_paths_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    errors, a, b = _relative_errors(ours, reference, 4)
    mean_ratio = np.nanmean(ours[..., :3]) / np.nanmean(reference[..., :3])
    gap = np.nanmean(unlimited[..., :3]) / np.nanmean(reference[..., :3])
    print(f"  light paths 12/1/4/8: region errors mean {errors.mean():.4f} "
          f"max {errors.max():.4f}; image mean ratio {mean_ratio:.4f}; GLSLPPM at 16 of "
          f"every kind against Cycles at 12/1/4/8: {gap:.4f}")
    assert gap > 1.06, gap
    assert abs(mean_ratio - 1.0) < 0.02, mean_ratio
    assert errors.mean() < 0.03, (errors.round(3).tolist(), a.round(4).tolist(),
                                  b.round(4).tolist())
    assert errors.max() < 0.09, errors.round(3).tolist()


def build_window_lit_interior():
    """A closed white room (4 x 4 x 2.5, albedo 0.8) with one window (1.2 x 1) in its east
    wall, lit by a sun through it and a blue sky; the camera stands by the window looking
    at the sunlit floor and the far walls. Most of its light has bounced several times."""
    white = helpers.diffuse_material("White", (0.8, 0.8, 0.8))
    x, y, z = 2.0, 2.0, 2.5
    quads = {
        "Floor": [(-x, -y, 0), (x, -y, 0), (x, y, 0), (-x, y, 0)],
        "Ceiling": [(-x, -y, z), (-x, y, z), (x, y, z), (x, -y, z)],
        "West": [(-x, -y, 0), (-x, y, 0), (-x, y, z), (-x, -y, z)],
        "North": [(-x, y, 0), (x, y, 0), (x, y, z), (-x, y, z)],
        "South": [(-x, -y, 0), (-x, -y, z), (x, -y, z), (x, -y, 0)],
        # The east wall around the window (y -0.6..0.6, z 0.8..1.8).
        "EastBelow": [(x, -y, 0), (x, -y, 0.8), (x, y, 0.8), (x, y, 0)],
        "EastAbove": [(x, -y, 1.8), (x, -y, z), (x, y, z), (x, y, 1.8)],
        "EastLeft": [(x, -y, 0.8), (x, -y, 1.8), (x, -0.6, 1.8), (x, -0.6, 0.8)],
        "EastRight": [(x, 0.6, 0.8), (x, 0.6, 1.8), (x, y, 1.8), (x, y, 0.8)],
    }
    for name, corners in quads.items():
        helpers.add_quad(name, corners, white)
    # The sun travels west and down 30 degrees, through the window onto the floor.
    helpers.add_light('SUN', 4.0, rotation=(0.0, math.radians(60.0), 0.0), angle=0.0)
    helpers.set_world((0.4, 0.6, 1.0), 1.0)
    location = (1.8, 1.2, 1.4)
    helpers.add_camera(location, helpers.look_at_rotation(location, (-2.0, -0.8, 0.6)),
                       lens=18.0)


def test_window_lit_interior_follows_default_cycles_light_paths():
    """Issue 26 (item 8): a window-lit interior came out 22% brighter than default Cycles
    (12 in all, 4 diffuse, 4 glossy, 12 transmission) when the engine had its own limit of
    16 surfaces for every kind. Now it reads Cycles' Light Paths: at their defaults the image
    mean agrees with Cycles' within 3% and every 3x3 region within 5%, while the same room at
    16 of every kind is brighter than default Cycles by far more. Measured under 3.4: ratio
    1.0036, regions mean 0.8% and worst 1.6%; at 16 of every kind 1.228 (32 passes, whose
    path-regeneration start-up leaves it low: 1.328 at 512 passes, where it is 0.994 of
    Cycles at 16). Before this engine followed Cycles' limits it rendered the room at 1.322 of
    default Cycles (docs/bounces.md)."""
    helpers.reset_scene(size=(48, 48))
    build_window_lit_interior()
    scene = bpy.context.scene
    helpers.load_native()
    scene.glslppm.passes = 128
    scene.glslppm.photons_per_pass = 32768
    helpers.set_light_paths(scene, 12, diffuse=4, glossy=4, transmission=12)  # the defaults
    ours = helpers.render_image("interior_glslppm", 'GLSLPPM')
    helpers.setup_cycles(samples=512)
    helpers.set_light_paths(scene, 12, diffuse=4, glossy=4, transmission=12)
    reference = helpers.render_image("interior_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    helpers.set_light_paths(scene, 16)
    scene.glslppm.passes = 32
    sixteen = helpers.render_image("interior_glslppm_16", 'GLSLPPM')
    errors, a, b = _relative_errors(ours, reference, 3)
    ratio = np.nanmean(ours[..., :3]) / np.nanmean(reference[..., :3])
    gap = np.nanmean(sixteen[..., :3]) / np.nanmean(reference[..., :3])
    print(f"  interior at Cycles' defaults: image mean ratio {ratio:.4f}, 3x3 region errors "
          f"mean {errors.mean():.4f} max {errors.max():.4f}; at 16 of every kind "
          f"against default Cycles {gap:.4f}")
    assert abs(ratio - 1.0) < 0.03, ratio
    assert errors.max() < 0.05, (errors.round(3).tolist(), a.round(4).tolist(),
                                 b.round(4).tolist())
    assert gap > 1.05, gap


def _box(name, lo, hi, material):
    """An axis-aligned box of six outward quads."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    vertices = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (1, 2, 6, 5), (3, 0, 4, 7)]
    return helpers.add_mesh_object(name, vertices, faces, material=material)


def test_cornell_box_with_boxes_matches_cycles_in_both_direct_light_modes():
    """Two boxes under the ceiling's area light cast hard-edged, penumbra-graded shadows:
    light sampling (the default) and photons alone against one Cycles render, on an 8x8
    grid of regions, so that the shadows' shapes count. Measured under 3.4: sampled mean
    2.1% / worst region 8.7%, photons 3.9% / 16.8% (the gather radius blurs the shadow
    edges). An 8x8-pixel region holds 32k Cycles samples, whose noise and the light's
    one-pixel sliver keep these bounds at 3.5% / 13% (sampled) and 5.5% / 22% (photons):
    too loose for a 1% bias, which the closed-form module tests catch; here the shadows'
    placement is what is tested, and that light sampling is the closer of the two. A region
    darker than a tenth of the brightest (the image's two top corners, 0.005 against 0.33,
    mostly outside the box) is measured against that tenth: relative to itself its noise
    read 10-13% (2026-11-26, after SPPM's warm-up; the ceiling's row, lit by photons alone,
    reads 8-10% below Cycles, as the 8.7% above)."""
    helpers.reset_scene(size=(64, 64))
    _demo_module().build_cornell_box(glass=False, mirror=False)
    bpy.data.objects["CeilingLight"].visible_camera = False
    white = bpy.data.materials["White"]
    _box("ShortBox", (-0.65, -0.55, 0.0), (-0.05, 0.05, 0.6), white)
    _box("TallBox", (0.1, 0.15, 0.0), (0.7, 0.75, 1.2), white)
    scene = bpy.context.scene
    results = {}
    for mode in ('SAMPLED', 'PHOTONS'):
        scene.glslppm.direct_light = mode
        helpers.load_native()
        scene.glslppm.passes = 128
        scene.glslppm.photons_per_pass = 32768
        results[mode] = helpers.render_image(f"cornell_boxes_{mode.lower()}", 'GLSLPPM')
    helpers.setup_cycles(samples=512)
    reference = helpers.render_image("cornell_boxes_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    scene.glslppm.direct_light = 'SAMPLED'
    bounds = {'SAMPLED': (0.035, 0.13), 'PHOTONS': (0.055, 0.22)}
    means = {}
    for mode, image in results.items():
        _, a, b = _relative_errors(image, reference, 8)
        errors = np.abs(a - b) / np.maximum(b, 0.1 * b.max())
        print(f"  cornell with boxes, {mode.lower()}: region errors mean {errors.mean():.4f} "
              f"max {errors.max():.4f}")
        mean_bound, max_bound = bounds[mode]
        means[mode] = errors.mean()
        assert errors.mean() < mean_bound, (mode, errors.mean())
        assert errors.max() < max_bound, (mode, errors.round(3).tolist())
    assert means['SAMPLED'] < means['PHOTONS'], means


def _floor_under_light(kind, energy, **settings):
    """A white diffuse floor (albedo 0.8) lit from 3 m above, seen from below the light
    (lights are hidden from the camera by default, in both renderers)."""
    helpers.reset_scene(size=(32, 32))
    white = helpers.diffuse_material("White", (0.8, 0.8, 0.8))
    helpers.add_mesh_object("Floor", [(-10, -10, 0), (10, -10, 0), (10, 10, 0), (-10, 10, 0)],
                            [(0, 1, 2, 3)], material=white)
    helpers.add_light(kind, energy, location=(0, 0, 3), **settings)
    location = (0, -4, 2)
    helpers.add_camera(location, helpers.look_at_rotation(location, (0, 0, 0)), lens=35.0)


def _compare_light(kind, energy, tolerance, **settings):
    _floor_under_light(kind, energy, **settings)
    ours, reference = _render_both(f"light_{kind.lower()}", passes=64, photons=16384)
    errors, a, b = _relative_errors(ours, reference, 2)
    centre = (float(ours[8:24, 8:24, :3].mean()), float(reference[8:24, 8:24, :3].mean()))
    print(f"  {kind.lower()}: centre GLSLPPM {centre[0]:.4f} Cycles {centre[1]:.4f}; "
          f"quadrant errors {[round(float(e), 3) for e in errors.ravel()]}")
    assert abs(centre[0] - centre[1]) < tolerance * centre[1], centre
    return centre


def test_point_light_brightness_matches_cycles():
    _compare_light('POINT', 300.0, 0.05, shadow_soft_size=0.0)


def test_spot_light_brightness_matches_cycles():
    """Inside its cone a spot light is as bright as a point light of the same power
    (Cycles 4.x); Cycles 3.x also multiplied by the cosine of the angle to the spot's
    axis (its spot_attenuation, dropped in 4.0), which the add-on asks the module for
    under 3.x (spot_cosine)."""
    spot = {"shadow_soft_size": 0.0, "spot_size": math.radians(120), "spot_blend": 0.0}
    _compare_light('SPOT', 300.0, 0.05, **spot)


def test_point_and_spot_lights_of_a_large_radius_match_cycles():
    """Radius 1 at 3 m above the floor. Cycles lights from a disc of the radius facing the lit
    point (3.x always; 4.x and later while the light's Soft Falloff is on, its default) and,
    with Soft Falloff off (4.x and later), from the sphere: 11% apart under the light
    (D^2 / (D^2 + r^2)). The floor's centre within 0.6% of Cycles in each case (measured
    0.04-0.11% on 3.4.1, 4.3.2 and 5.2.2; each render's noise about 0.1% on it at these
    counts), so a 1% bias fails, let alone either model in place of the other."""
    spot = {"spot_size": math.radians(120), "spot_blend": 0.0}
    has_soft = "use_soft_falloff" in bpy.types.PointLight.bl_rna.properties
    falloffs = [True, False] if has_soft else [None]
    for soft in falloffs:
        extra = {} if soft is None else {"use_soft_falloff": soft}
        print(f"  soft falloff: {'(none in this Blender)' if soft is None else soft}")
        for kind, settings in (('POINT', {}), ('SPOT', spot)):
            _compare_light(kind, 300.0, 0.006, shadow_soft_size=1.0, **settings, **extra)


def test_sun_light_brightness_matches_cycles_and_theory():
    ours, reference = _compare_light('SUN', 3.0, 0.05, angle=math.radians(1))
    # A sun of strength S (W/m^2) straight above a Lambertian floor of albedo 0.8:
    # radiance = 0.8 S / pi.
    expected = 0.8 * 3.0 / math.pi
    assert abs(reference - expected) < 0.05 * expected, (reference, expected)
    assert abs(ours - expected) < 0.05 * expected, (ours, expected)


def test_area_light_brightness_matches_cycles():
    _compare_light('AREA', 300.0, 0.05, shape='SQUARE', size=1.0)


def test_area_light_shapes_match_cycles():
    """Every shape, native in the module: the floor's brightness within 5% of Cycles
    (Blender 3.x's P / (4A) and 4.x's P / (pi A) radiance conventions both)."""
    shapes = (('SQUARE', {"size": 1.0}), ('RECTANGLE', {"size": 2.0, "size_y": 0.5}),
              ('DISK', {"size": 1.5}), ('ELLIPSE', {"size": 0.5, "size_y": 2.0}))
    for shape, sizes in shapes:
        _compare_light('AREA', 300.0, 0.05, shape=shape, **sizes)


def test_visible_area_light_radiance_matches_cycles():
    """An area light seen by the camera (object visibility Camera on) shows its radiance:
    P / (pi A) under 4.x, P / (4 A) under 3.x, as Cycles shows it."""
    helpers.reset_scene(size=(16, 16))
    light = helpers.add_light('AREA', 100.0, location=(0, 0, 3), shape='SQUARE', size=10.0)
    light.visible_camera = True
    helpers.add_camera((0, 0, 0), (math.pi, 0, 0), lens=50.0)  # looking up at it
    ours, reference = _render_both("visible_area", passes=2, photons=1024, samples=4)
    expected = 100.0 / (100.0 * (math.pi if helpers.BLENDER_4 else 4.0))
    print(f"  visible area light: GLSLPPM {ours[..., :3].mean():.5f} "
          f"Cycles {reference[..., :3].mean():.5f} expected {expected:.5f}")
    helpers.assert_close(reference[..., :3].mean(), expected, 1e-3 * expected, "Cycles")
    helpers.assert_close(ours[..., :3].mean(), expected, 1e-3 * expected, "GLSLPPM")


def test_point_radius_and_sun_angle_match_cycles():
    """A sphere light (radius 0.5 m at 3 m) and a 10-degree sun: within 5% of Cycles."""
    _compare_light('POINT', 300.0, 0.05, shadow_soft_size=0.5)
    _compare_light('SUN', 3.0, 0.05, angle=math.radians(10))


def _environment_image(name):
    """A float equirectangular map (16 x 8): a blue-white sky brightening towards the
    zenith, a dark ground, and a bright warm patch low in the sky between +Y and +X
    (u in [0.25, 0.375); Blender's mapping: u = 0.5 at +X, 0.25 at +Y)."""
    import os
    pixels = np.zeros((8, 16, 4), dtype=np.float32)
    pixels[..., 3] = 1.0
    for row in range(8):  # row 0 at the bottom: the nadir
        elevation = (row + 0.5) / 8.0 - 0.5
        pixels[row, :, :3] = (0.05, 0.05, 0.05) if elevation < 0 else \
            (0.3 + elevation, 0.5 + elevation, 1.0 + elevation)
    pixels[4:6, 4:6, :3] = (8.0, 6.0, 3.0)
    image = bpy.data.images.new(name, 16, 8, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"  # else save() writes sRGB-encoded
    image.pixels.foreach_set(pixels.ravel())
    path = os.path.join(helpers.OUT, f"{name}.exr")
    image.filepath_raw = path
    image.file_format = 'OPEN_EXR'
    image.save()
    bpy.data.images.remove(image)
    return bpy.data.images.load(path, check_existing=False)


def _compare_environment(name, rotation_z=None):
    """A diffuse floor and cube under an environment map (turned by a Mapping node when
    rotation_z is given), and the map seen directly above the horizon: 2x2 region means
    within 6% of Cycles, the mean within 4%."""
    helpers.reset_scene(size=(32, 32))
    grey = helpers.diffuse_material("Grey", (0.8, 0.8, 0.8))
    helpers.add_mesh_object("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)],
                            [(0, 1, 2, 3)], material=grey)
    helpers.add_cube(location=(0, 0, 0.5), scale=(0.5, 0.5, 0.5), material=grey)
    world = helpers.set_world((1, 0, 1), strength=1.5)
    tree = world.node_tree
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image = _environment_image("sky")
    background = next(n for n in tree.nodes if n.type == 'BACKGROUND')
    tree.links.new(texture.outputs["Color"], background.inputs["Color"])
    if rotation_z is not None:
        mapping = tree.nodes.new("ShaderNodeMapping")
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, rotation_z)
        coordinates = tree.nodes.new("ShaderNodeTexCoord")
        tree.links.new(coordinates.outputs["Generated"], mapping.inputs["Vector"])
        tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    location = (0, -5, 1.5)
    helpers.add_camera(location, helpers.look_at_rotation(location, (0, 0, 0.8)), lens=30.0)
    ours, reference = _render_both(name, passes=64, photons=16384)
    errors, a, b = _relative_errors(ours, reference, 2)
    means = float(ours[..., :3].mean()), float(reference[..., :3].mean())
    print(f"  {name}: mean GLSLPPM {means[0]:.4f} Cycles {means[1]:.4f}; "
          f"quadrant errors {[round(float(e), 3) for e in errors.ravel()]}")
    assert abs(means[0] - means[1]) < 0.04 * means[1], means
    assert errors.max() < 0.06, (errors.round(3).tolist(), a.round(4).tolist(),
                                 b.round(4).tolist())
    return a


def test_environment_texture_matches_cycles():
    _compare_environment("environment")


def test_rotated_environment_texture_matches_cycles():
    """A Mapping node turning the lookup by -45 degrees about Z moves the bright patch
    from the right of the view to the left (a wrong sign would leave it right)."""
    quadrants = _compare_environment("environment_rotated", math.radians(-45))
    assert quadrants[0, 0] > quadrants[0, 1], quadrants.tolist()


def _texture_image(name):
    """A 32x32 sRGB PNG of 4x4 blocks of distinct colours (no symmetry, so a flip or a
    transpose shows); blocks of 8x8 texels keep bilinear blending to their edges."""
    import os
    rng = np.random.default_rng(5)
    cells = np.ones((4, 4, 4), dtype=np.float32)
    cells[..., :3] = rng.uniform(0.1, 1.0, size=(4, 4, 3)).round(2)
    pixels = np.repeat(np.repeat(cells, 8, axis=0), 8, axis=1)
    image = bpy.data.images.new(name, 32, 32)
    image.pixels.foreach_set(pixels.ravel())
    path = os.path.join(helpers.OUT, f"{name}.png")
    image.filepath_raw = path
    image.file_format = 'PNG'
    image.save()
    bpy.data.images.remove(image)
    return bpy.data.images.load(path, check_existing=False)


def test_image_texture_base_colour_matches_cycles():
    """A textured plane filling an orthographic view (one texel per pixel) under a sun
    straight above: each block's mean within 4% of Cycles, leaving out the pixels on
    block edges, where bilinear filtering blends neighbours."""
    helpers.reset_scene(size=(32, 32))
    material = helpers.node_material("Checker", "ShaderNodeBsdfPrincipled")
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _texture_image("cells")
    principled = next(node for node in tree.nodes if node.type == 'BSDF_PRINCIPLED')
    # Rough and without specular: Lambertian at normal incidence in 3.x and 4.x alike.
    principled.inputs["Roughness"].default_value = 1.0
    specular = "Specular IOR Level" if helpers.BLENDER_4 else "Specular"
    principled.inputs[specular].default_value = 0.0
    tree.links.new(texture.outputs["Color"], principled.inputs["Base Color"])
    plane = helpers.add_quad("Plane", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)],
                             material=material)
    layer = plane.data.uv_layers.new()
    layer.data.foreach_set("uv", [0, 0, 1, 0, 1, 1, 0, 1])
    helpers.add_light('SUN', 3.0)
    helpers.add_camera((0, 0, 5), (0, 0, 0), type='ORTHO', ortho_scale=2.0)
    ours, reference = _render_both("texture", passes=32, photons=16384)
    inner = np.zeros((32, 32), dtype=bool)
    for row in range(0, 32, 8):
        for col in range(0, 32, 8):
            inner[row + 1:row + 7, col + 1:col + 7] = True
    ours, reference = ours.copy(), reference.copy()
    ours[~inner] = reference[~inner] = np.nan
    errors, a, b = _relative_errors(ours, reference, 4)
    print(f"  texture: region errors mean {errors.mean():.3f} max {errors.max():.3f}")
    assert errors.max() < 0.04, (errors.round(3).tolist(), a.round(4).tolist(),
                                 b.round(4).tolist())


def test_srgb_image_texture_on_a_disk_matches_cycles():
    """test_deformation_blur's disk standing still (64x64, sun straight above) with the 4x4
    blocks as an 8-bit sRGB PNG under Linear interpolation: Cycles filters the bytes and
    decodes the result (NODE_IMAGE_COMPRESS_AS_SRGB), and so does GLSLPPM now. Image mean
    within 0.2% of Cycles', each 8x8-pixel region within 0.8% of the brightest region
    (Blender 3.4.1: mean 0.01%, worst region 0.15%; decoding each texel before filtering, as
    the GL sRGB8 atlas did, read 1.66% off in the mean and 2.26% in the worst region, and
    fails)."""
    _textured_disk_matches_cycles("srgb_disk", "disk_cells", 'Linear')


def _textured_disk_matches_cycles(name, image, interpolation):
    """test_deformation_blur's disk standing still under an sRGB image read with
    `interpolation`, against Cycles at 1,024 samples: mean within 0.2%, each 8x8-pixel region
    within 0.8% of the brightest."""
    from test_deformation_blur import _spinning_disk_scene
    helpers.load_native()
    scene, disk = _spinning_disk_scene()
    scene.render.use_motion_blur = False
    texture = next(node for node in disk.data.materials[0].node_tree.nodes
                   if node.type == 'TEX_IMAGE')
    texture.image = _texture_image(image)
    texture.interpolation = interpolation
    assert texture.image.colorspace_settings.name == "sRGB"
    scene.glslppm.passes = 128
    scene.glslppm.photons_per_pass = 16384
    ours, error, _ = helpers.render_recorded(name)
    assert error is None, error
    reference = helpers.render_cycles_box_filter(name, samples=1024)
    _, _, region_error, mean_error = helpers.region_comparison(ours, reference, grid=8)
    signed = float(ours[..., :3].mean() / reference[..., :3].mean() - 1.0)
    print(f"  {name}: mean {mean_error:.5f} ({signed:+.5f}), worst region {region_error:.4f}")
    assert mean_error < 0.002, mean_error
    assert region_error < 0.008, region_error


def test_closest_image_texture_on_a_disk_matches_cycles():
    """The sRGB disk above with its Image Texture set to Closest: both engines read the one
    texel a point falls in (Cycles' interp_closest), decoded. Image mean within 0.2% of
    Cycles', each 8x8-pixel region within 0.8% of the brightest region: the Linear test's
    bounds, whose noise is the same (Blender 3.4.1: mean -0.01%, worst region 0.17%).
    Filtering bilinearly as before (the node's interpolation ignored) read 1.69% darker in
    the mean (worst region 2.8%), and fails."""
    _textured_disk_matches_cycles("closest_disk", "closest_cells", 'Closest')


def _smooth_float_image(name):
    """A 5x4 float image (Linear) of random colours saved as EXR: bilinear filtering makes it
    smooth, so that the two engines' pixel sampling differs by little."""
    rng = np.random.default_rng(11)
    pixels = np.ones((4, 5, 4), dtype=np.float32)
    pixels[..., :3] = rng.uniform(0.1, 0.9, size=(4, 5, 3))
    return helpers.linear_image(name, pixels)


def _mapped_texture_plane(extension):
    """A plane of a Diffuse BSDF whose colour is the image through Texture Coordinate UV,
    Vector Math (multiply by (1.2, 0.9, 1)) and a Mapping (Point: scale 1.7 x 2.3, turned 30
    degrees about Z, moved by (-0.4, -0.6)): uvs leave [0, 1] on every side."""
    material = helpers.node_material("Mapped", "ShaderNodeBsdfDiffuse")
    tree = material.node_tree
    diffuse = next(node for node in tree.nodes if node.type == 'BSDF_DIFFUSE')
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    multiply = tree.nodes.new("ShaderNodeVectorMath")
    multiply.operation = 'MULTIPLY'
    multiply.inputs[1].default_value = (1.2, 0.9, 1.0)
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = 'POINT'
    mapping.inputs["Location"].default_value = (-0.4, -0.6, 0.0)
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(30.0))
    mapping.inputs["Scale"].default_value = (1.7, 2.3, 1.0)
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _smooth_float_image(f"smooth_{extension.lower()}")
    texture.extension = extension
    tree.links.new(coordinates.outputs["UV"], multiply.inputs[0])
    tree.links.new(multiply.outputs["Vector"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    tree.links.new(texture.outputs["Color"], diffuse.inputs["Color"])
    plane = helpers.add_quad("Plane", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)],
                             material=material)
    layer = plane.data.uv_layers.new()
    layer.data.foreach_set("uv", [0, 0, 1, 0, 1, 1, 0, 1])


def test_image_texture_through_mapping_matches_cycles_per_extension():
    """Texture Coordinate UV -> Vector Math -> Mapping -> Image Texture, under each of
    Blender's extensions, against Cycles: Denoising Albedo (the texel, free of light noise)
    per pixel, both engines with 16 one-pixel box-filtered samples. They differ only in where
    the samples fall (measured rms 2-3e-3); bounds: rms 6e-3 and mean 1.5e-3 per channel
    (dropping the Mapping is 0.2 rms off; a uv map 1% larger 8e-3 rms; a texture 1% brighter
    5e-3 in the mean)."""
    extensions = ['REPEAT', 'EXTEND', 'CLIP']
    probe = bpy.data.materials.new("probe")
    probe.use_nodes = True
    image_node = probe.node_tree.nodes.new("ShaderNodeTexImage")
    if 'MIRROR' in image_node.bl_rna.properties["extension"].enum_items.keys():
        extensions.append('MIRROR')  # Blender 3.5+
    bpy.data.materials.remove(probe)
    for extension in extensions:
        scene = helpers.reset_scene(size=(64, 64))
        _mapped_texture_plane(extension)
        helpers.set_world((1.0, 1.0, 1.0))
        helpers.add_camera((0, 0, 5), (0, 0, 0), type='ORTHO', ortho_scale=2.0)
        layer = scene.view_layers[0]
        layer.glslppm.use_pass_denoising_data = True
        layer.cycles.denoising_store_passes = True
        scene.glslppm.passes = 16
        scene.glslppm.photons_per_pass = 1024
        from test_passes import render_multilayer
        ours = render_multilayer(f"mapping_{extension.lower()}")
        helpers.setup_cycles(samples=16)
        scene.cycles.pixel_filter_type = 'BOX'
        scene.cycles.filter_width = 1.0
        reference = render_multilayer(f"mapping_{extension.lower()}_cycles", 'CYCLES')
        scene.render.engine = 'GLSLPPM'
        for c in "RGB":
            a = ours["ViewLayer.Denoising Albedo." + c].astype(np.float64)
            b = reference["ViewLayer.Denoising Albedo." + c].astype(np.float64)
            rms, mean = float(np.sqrt(np.mean((a - b) ** 2))), float(np.mean(a - b))
            print(f"  {extension} {c}: rms {rms:.4f} mean {mean:+.5f}")
            assert rms < 6e-3 and abs(mean) < 1.5e-3, (extension, c, rms, mean)


def test_default_cube_matches_cycles_once_its_material_is_diffuse():
    """Blender's default scene (cube, point light, camera) was 2-4% darker than Cycles. With
    light sampling that stays 2% (measured 0.980 under 3.4), so it is not the gather
    radius; with the cube's Principled BSDF replaced by a Diffuse BSDF of the same colour
    the image matches Cycles to 0.04% (photons alone: 0.3%). The rest was Principled's
    specular layer: exported with it, the Principled cube measures 0.996 (3.4) and 0.9985
    (4.3). The bound below is 1%, on the diffuse cube, and the Principled cube's ratio is
    printed."""
    helpers.reset_scene(size=(96, 54))
    scene = bpy.context.scene
    # Blender's startup file, as it stands: a 2 m cube with the default Principled BSDF, a
    # 1000 W point light of radius 0.1, a 50 mm camera and a grey world.
    material = bpy.data.materials.new("Material")
    helpers.compat().use_nodes(material)
    h = 1.0
    corners = [(x, y, z) for z in (-h, h) for y in (-h, h) for x in (-h, h)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    helpers.add_mesh_object("Cube", corners, faces, material=material)
    helpers.add_light('POINT', 1000.0, location=(4.0762, 1.0055, 5.9039), shadow_soft_size=0.1)
    helpers.add_camera((7.3589, -6.9258, 4.9583),
                       (math.radians(63.559), 0.0, math.radians(46.692)), lens=50.0)
    helpers.set_world((0.0508, 0.0508, 0.0508), 1.0)
    scene.glslppm.passes = 128
    scene.glslppm.photons_per_pass = 65536
    helpers.load_native()
    principled = helpers.render_image("default_cube_glslppm", 'GLSLPPM')
    helpers.setup_cycles(samples=512)
    principled_cycles = helpers.render_image("default_cube_cycles", 'CYCLES')
    tree = bpy.data.materials["Material"].node_tree
    for node in [n for n in tree.nodes if n.type == 'BSDF_PRINCIPLED']:
        tree.nodes.remove(node)
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(diffuse.outputs[0], output.inputs["Surface"])
    diffuse_cycles = helpers.render_image("diffuse_cube_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    diffuse_ours = helpers.render_image("diffuse_cube_glslppm", 'GLSLPPM')
    ratios = [np.nanmean(a[..., :3]) / np.nanmean(b[..., :3])
              for a, b in ((principled, principled_cycles), (diffuse_ours, diffuse_cycles))]
    print(f"  default cube / Cycles: Principled {ratios[0]:.4f}, Diffuse {ratios[1]:.4f}")
    assert abs(ratios[1] - 1.0) < 0.01, ratios


def _issue30_scene(*changes):
    """Issue 30's Cornell box as scripts/cornell_vs_cycles.py builds it (its docstring lists
    the changes); Light Paths at 64 of every kind in both engines."""
    scripts = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts")
    if scripts not in sys.path:
        sys.path.insert(0, os.path.abspath(scripts))
    import cornell_vs_cycles
    scene = cornell_vs_cycles.build(list(changes))
    helpers.set_light_paths(scene, 64)
    return scene


def _light_and_rest(ours, reference):
    """The image means' ratio, the ratio over the light's own pixels (the reference above 1:
    the emitter seen by the camera, half the image's mean) and over the rest."""
    a, b = ours[..., :3].astype(np.float64), reference[..., :3].astype(np.float64)
    light = b.mean(axis=2) > 1.0
    return (a.mean() / b.mean(), a[light].sum() / b[light].sum(),
            a[~light].mean() / b[~light].mean())


def test_issue30_cornell_box_matches_cycles_within_one_percent():
    """Issue 30's Cornell box (Diffuse walls, two turned boxes, a warm emissive quad of
    strength 40 seen by the camera, 1 mm below the ceiling) against Cycles at 64 bounces,
    unclamped, a 1-px box filter. docs/cornell_vs_cycles.md has the bisection and its two
    fixes: Lambertian points weigh a BSDF sample against the light sample (the light sample
    alone missed the spike of the gap's ceiling seen past the light's edge: 0.987), and
    SPPM's photon paths start each film after a warm-up (those in flight at the end left the
    rest of the image about 0.7% dark at 400 passes).
    Measured here (16384 photons against 1024 samples, seeds 0-3 under 3.4.1): mean 0.9976 /
    0.9949 / 1.0004 / 0.9961, the light's pixels 0.9993 / 0.9952 / 1.0039 / 0.9982, the rest
    0.9956 / 0.9946 / 0.9962 / 0.9936; at 65536 photons against 4096 samples 0.9977, 0.9994,
    0.9957. Bounds: the rest within [0.989, 1.001] (its spread 0.1%, one sigma; its 0.5%
    below Cycles is not bisected yet, the radius about 0.2% of it): a 1% bias either way
    fails it. The light's pixels (spread 0.4%: the gap's spike) and the mean within 1%,
    which their noise allows no tighter. The worst 4x4 region (16x16 pixels) within 5%:
    1.7 / 1.2 / 1.9 / 2.2% over the four seeds; the floor in the boxes' shadow was 2.0% at
    65536 photons (the radius' bias there); the seeds' spread (0.8%, one sigma) and Cycles'
    noise in a region at 1024 samples (0.8%: 0.4% at 4096) give 2.5% plus three sigmas of
    the two."""
    _issue30_box_matches_cycles("cornell")


def _issue30_box_matches_cycles(name, *changes):
    """Issue 30's box with `changes` (cornell_vs_cycles.build's), 400 passes of 16384 photons
    against Cycles at 1024 samples (64 bounces, unclamped, a 1-px box filter): the rest of
    the image within [0.989, 1.001], the mean and the light's pixels within 1%, every 4x4
    region (16x16 pixels) within 5% (the first test's docstring says why)."""
    helpers.reset_scene(size=(64, 64))
    scene = _issue30_scene(*changes)
    scene.glslppm.passes = 400
    scene.glslppm.photons_per_pass = 16384
    helpers.load_native()
    ours = helpers.render_image(f"issue30_{name}_glslppm", 'GLSLPPM')
    helpers.setup_cycles(samples=1024, bounces=64)
    scene.cycles.pixel_filter_type = 'BOX'
    scene.cycles.filter_width = 1.0
    reference = helpers.render_image(f"issue30_{name}_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    mean, light, rest = _light_and_rest(ours, reference)
    errors, a, b = _relative_errors(ours, reference, 4)
    print(f"  issue 30 {name} / Cycles: mean {mean:.4f}, light's pixels {light:.4f}, "
          f"rest {rest:.4f}; 4x4 region errors max {errors.max():.4f}")
    assert 0.989 < rest < 1.001, (mean, light, rest)
    assert abs(mean - 1.0) < 0.01 and abs(light - 1.0) < 0.01, (mean, light, rest)
    assert errors.max() < 0.05, errors.round(3).tolist()


def test_issue30_box_with_a_mirror_and_a_glass_ball_matches_cycles_within_one_percent():
    """Issue 30's second scene: the box's two white boxes replaced by a mirror ball (Glossy,
    roughness 0) and a glass ball (Glass, IOR 1.5, roughness 0), smooth UV spheres of 64 x
    32. Bounds as the plain box's (above). Measured under 3.4.1 (seeds 0-2): mean 0.9982 /
    0.9941 / 0.9991, the light's pixels 0.9995 / 0.9926 / 1.0037, the rest 0.9968 / 0.9956 /
    0.9943 (SPPM's 0.5% below Cycles, as on the plain box), worst region 1.5 / 1.3 / 1.2%;
    at 65536 photons against 4096 samples: mean 0.9996, rest 0.9991, worst region 0.8%."""
    _issue30_box_matches_cycles("balls", "balls")


def test_issue30_glossy_box_matches_cycles_within_one_percent():
    """Issue 30's glossy variant: a gold Principled ball (metallic 1, roughness 0.3), a
    frosted Principled glass ball (transmission 1, roughness 0.15, IOR 1.45), a blue plastic
    Principled box (roughness 0.4) and a floor mixing Diffuse 0.73 with Glossy 0.2 at 0.3.
    Its 2.2% region was the frosted ball, 6.5% dark in its 8x8 regions: Principled v1's glass
    reflection was exported tinted by the base colour (0.8), where Cycles 3.x tints it by
    Specular Tint alone (addon/export/principled.py); a Glass BSDF in its place matched.
    Bounds as the plain box's. Measured under 3.4.1 (seeds 0-2): mean 0.9994 / 0.9946 /
    1.0017, the light's pixels 1.0001 / 0.9925 / 1.0051, the rest 0.9987 / 0.9970 / 0.9978,
    worst region 0.9 / 1.8 / 2.0%; at 65536 photons against 4096 samples: mean 0.9999, rest
    0.9989, worst region 1.1% (with the tinted reflection: 0.9979, 2.15%)."""
    _issue30_box_matches_cycles("glossy", "glossy")


def test_vcm_path_tracing_through_the_addon_matches_cycles_on_the_issue30_box():
    """The estimator VCM chosen in Render Properties, its path tracing technique (VCM
    Techniques > Path Tracing; docs/vcm.md) on issue 30's Cornell box, 1 mm gap, against Cycles as above: both are
    unbiased path tracers with MIS of light and BSDF samples, so the image means agree within
    their noise. Measured (Blender 3.4.1, 1024 passes against 1024 samples): mean 0.9974,
    the light's pixels 0.9962, the rest 0.9989, worst 4x4 region 0.49%: the rest's 0.5%
    deficit that SPPM shows on this box (the test above) is SPPM's own, not the scene's
    export. Bounds: the rest within 0.6% (a 1% bias fails), the mean and the light's pixels
    within 1% (the gap's spike, as above), each region within 2.5%."""
    helpers.reset_scene(size=(64, 64))
    scene = _issue30_scene()
    scene.glslppm.estimator = 'VCM'
    scene.glslppm.vcm_techniques = 'PT'
    scene.glslppm.passes = 1024
    helpers.load_native()
    bpy.context.view_layer.use_pass_z = True  # Blender's default: VCM writes it
    # The light split VCM does not write yet: left empty, with one warning naming it.
    bpy.context.view_layer.glslppm.use_pass_light_split = True
    ours, error, engine = helpers.render_recorded("issue30_cornell_vcm")
    bpy.context.view_layer.glslppm.use_pass_light_split = False
    assert error is None, error
    assert helpers.last_render_stats()["estimator"] == "vcm"
    assert any("does not split Combined's light yet: the passes caustics, direct, indirect "
               "stay empty" in w for w in helpers.warnings_of(engine)), \
        helpers.warnings_of(engine)
    helpers.setup_cycles(samples=1024, bounces=64)
    scene.cycles.pixel_filter_type = 'BOX'
    scene.cycles.filter_width = 1.0
    reference = helpers.render_image("issue30_cornell_vcm_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    mean, light, rest = _light_and_rest(ours, reference)
    errors, a, b = _relative_errors(ours, reference, 4)
    print(f"  VCM on issue 30's box / Cycles: mean {mean:.4f}, light's pixels {light:.4f}, "
          f"rest {rest:.4f}; 4x4 region errors max {errors.max():.4f}")
    assert abs(rest - 1.0) < 0.006 and abs(mean - 1.0) < 0.01 and abs(light - 1.0) < 0.01, \
        (mean, light, rest)
    assert errors.max() < 0.025, errors.round(3).tolist()


def test_vcm_techniques_in_render_properties_reach_the_module():
    """Render Properties > VCM Techniques: the default, Path + Light Tracing + Merging,
    compiles the three (variant vcm=pt+lt+vm), Path + Light Tracing the weighted pair
    (vcm=pt+lt), Path Tracing the eye paths alone; each renders a finite, lit image of issue
    30's box. Nothing there for light tracing or merging to take (no glass or mirror), and
    the eye paths draw the same numbers every way, so the images' means are equal: measured
    identical (Blender 3.4.1), asserted within 1e-6 relative, which any weight below one on
    the eye side would break."""
    helpers.reset_scene(size=(32, 32))
    scene = _issue30_scene()
    scene.glslppm.estimator = 'VCM'
    scene.glslppm.passes = 16
    scene.glslppm.photons_per_pass = 4096
    helpers.load_native()
    assert scene.glslppm.vcm_techniques == 'PT_LT_VM'
    means = {}
    for technique, variant in (('PT_LT_VM', "vcm=pt+lt+vm"), ('PT_LT', "vcm=pt+lt"),
                               ('PT', None)):
        scene.glslppm.vcm_techniques = technique
        image, error, _ = helpers.render_recorded(f"issue30_vcm_{technique.lower()}")
        assert error is None, error
        variants = helpers.last_render_stats()["variant"].split(",")
        assert (variant in variants) if variant else not any(v.startswith("vcm=") for v in variants), variants
        assert np.isfinite(image).all()
        means[technique] = float(image[..., :3].mean())
        # The status line speaks of light paths where pt+lt traces them, never of a radius.
        progressive = importlib.import_module(helpers.ADDON.__name__ + ".engine.progressive")
        line = progressive.stats_line(progressive.PassSchedule(16),
                                      helpers.last_render_stats(), 1.0)
        assert "radius" not in line and "photons/s" not in line, line
        assert ("light paths/s" in line) == (technique != 'PT'), line
    print(f"  VCM techniques: means {means}")
    assert means['PT'] > 0.0
    for technique in ('PT_LT', 'PT_LT_VM'):
        assert abs(means[technique] / means['PT'] - 1.0) < 1e-6, means


def harness_scene(name, size, bounces):
    """The equal-cost harness's scene `name` (scripts/equal_cost_scenes.py) at size x size,
    no world, every Light Paths limit `bounces`."""
    helpers.reset_scene(size=(size, size))
    scripts = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts")
    if scripts not in sys.path:
        sys.path.insert(0, os.path.abspath(scripts))
    import equal_cost_scenes
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    equal_cost_scenes.SCENES[name]()
    scene = bpy.context.scene
    scene.world = None
    helpers.set_light_paths(scene, bounces)
    return scene


def test_vcm_path_and_light_tracing_quiets_the_caustic_through_the_addon():
    """The equal-cost harness's caustic scene (scripts/equal_cost_scenes.py: a glass ball on a
    white floor under a small area light) through Render Properties > VCM: Path + Light
    Tracing takes the caustic by the light's paths, Path Tracing by the eye paths' rare hits
    of the light through the ball. Two seeds of each at 64x64, 24 passes: in a box on the
    caustic (clear of the ball's edge, where the caustic seen through the glass is path
    tracing's alone) the two seeds of pt+lt differ by under a tenth of what the two of pt
    differ by (each technique's noise, RMS over the box's pixels). Measured (Blender 3.4.1):
    0.126 against 6.27, a fiftieth. The means are not compared: pt's is as noisy as its
    fireflies (its standard error in the box about 0.4 against a mean of 1.0). A first pt+lt
    left every scene with an area light to path tracing alone; this test would have caught
    it."""
    scene = harness_scene("caustic", 64, 16)
    scene.glslppm.estimator = 'VCM'
    scene.glslppm.passes = 24
    scene.glslppm.photons_per_pass = 16384
    helpers.load_native()
    images = {}
    for technique in ('PT_LT', 'PT'):
        scene.glslppm.vcm_techniques = technique
        for seed in (1, 2):
            scene.glslppm.seed = seed
            image, error, _ = helpers.render_recorded(f"caustic_vcm_{technique.lower()}_{seed}")
            assert error is None, error
            images[technique, seed] = image[..., :3].astype(np.float64).mean(axis=2)
    box = (slice(34, 42), slice(32, 46))  # rows, columns: the caustic in the ball's shadow
    noise = {t: np.sqrt(np.mean((images[t, 1][box] - images[t, 2][box]) ** 2) / 2.0)
             for t in ('PT_LT', 'PT')}
    print(f"  caustic box: noise pt+lt {noise['PT_LT']:.4f}, pt {noise['PT']:.4f}")
    assert noise['PT_LT'] < noise['PT'] / 10.0, noise


@helpers.slow("three renders of the pool (8,202 triangles), PPPM's at 32,768 photons a pass "
              "traced whole: 21 CPU-s, over 30 s of wall time on two shared cores")
def test_vcm_merging_renders_the_pool_floor_through_the_addon():
    """The equal-cost harness's pool (scripts/equal_cost_scenes.py: a sun of 0.5 degrees over
    wavy water over a white floor in a pool; the camera sees the floor through the water,
    L S D S E, which neither light tracing nor the light sample can sample and path tracing
    never meets a sun) through Render Properties > VCM > Path + Light Tracing + Merging (the
    default), against PPPM, both at 32x32, 16 passes of 32,768 photons: the image means within
    4% (measured on Blender 3.4.1: 1.0003). One render's mean is about 0.8% noisy here, so
    this holds the add-on's merging against a missing floor (Path + Light Tracing, asserted
    below a quarter of PPPM's: measured 0.171), not a 1% bias, which
    tests/python/test_vcm_merging.py holds against a closed form."""
    scene = harness_scene("pool", 32, 12)
    scene.glslppm.passes = 16
    scene.glslppm.photons_per_pass = 32768
    scene.glslppm.seed = 1
    helpers.load_native()
    assert scene.glslppm.vcm_techniques == 'PT_LT_VM'
    means = {}
    for estimator, technique in (('VCM', 'PT_LT_VM'), ('PPPM', None), ('VCM', 'PT_LT')):
        scene.glslppm.estimator = estimator
        if technique:
            scene.glslppm.vcm_techniques = technique
        name = technique or estimator
        image, error, _ = helpers.render_recorded(f"pool_{name.lower()}")
        assert error is None, error
        means[name] = float(image[..., :3].mean())
    ratio = means['PT_LT_VM'] / means['PPPM']
    print(f"  pool: pt+lt+vm {means['PT_LT_VM']:.5f}, PPPM {means['PPPM']:.5f} (ratio "
          f"{ratio:.4f}), pt+lt {means['PT_LT']:.5f} ({means['PT_LT'] / means['PPPM']:.3f})")
    assert abs(ratio - 1.0) < 0.04, means
    assert means['PT_LT'] < 0.25 * means['PPPM'], means


def test_issue30_gltf_export_renders_as_the_addon_does():
    """The same box with Principled BSDF walls (roughness 1, no specular: what glTF keeps;
    Blender's exporter writes a Diffuse BSDF as glTF's default white metal) exported by
    Blender's glTF exporter and rendered by the module's loader (the CLI's), against the
    add-on's render of the scene. Same passes and photons, so SPPM's biases are the same in
    both. Measured at 400 passes x 65536 photons with the light 1 mm below the ceiling: outside
    the light 0.9993 (1.0332 before the loader read the exporter's black specularColorFactor);
    here the light is 5 cm lower, out of the 1 mm gap's noisy strip (under 3.4, 4.3 and 5.2
    alike: mean 0.9994, rest 1.0035, worst region 2.0%). Bounds: the image mean and the mean outside the light
    within 1%, each 4x4 region within 5%: two GLSLPPM renders of 16384 photons a pass, each
    0.8% noisy (one sigma) in a region as the test above measured at 400 passes, so 1.1% at
    the 200 here: three sigmas of their difference are 4.7%."""
    helpers.reset_scene(size=(64, 64))
    scene = _issue30_scene("gap0.05", "principled", "spec0")
    scene.glslppm.passes = 200
    scene.glslppm.photons_per_pass = 16384
    module = helpers.load_native()
    ours = helpers.render_image("issue30_gltf_addon", 'GLSLPPM')
    path = os.path.join(helpers.OUT, "issue30_cornell.glb")
    bpy.ops.export_scene.gltf(filepath=path, export_format='GLB', export_cameras=True,
                              export_lights=True)
    loaded, warnings = module.load_scene(path, 1.0)
    settings = module.Settings(width=64, height=64, photons_per_pass=16384, max_bounces=64,
                               max_diffuse_bounces=64, max_glossy_bounces=64,
                               max_transmission_bounces=64)
    renderer = module.Renderer(loaded, settings)
    renderer.run(200)
    gltf = np.asarray(renderer.film())
    renderer.close()
    mean, light, rest = _light_and_rest(gltf, ours)
    errors, a, b = _relative_errors(gltf, ours, 4)
    print(f"  issue 30 box, glTF through the loader / the add-on: mean {mean:.4f}, light's "
          f"pixels {light:.4f}, rest {rest:.4f}; 4x4 region errors max {errors.max():.4f}; "
          f"loader warnings {warnings}")
    assert abs(mean - 1.0) < 0.01 and abs(rest - 1.0) < 0.01, (mean, light, rest)
    assert errors.max() < 0.05, errors.round(3).tolist()
