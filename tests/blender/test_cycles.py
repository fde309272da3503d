"""GLSLPPM against Cycles rendering the same Blender scene (Cycles on the CPU,
unclamped, no denoising, the same bounce limit).

Tolerances: Cycles' noise at REFERENCE_SAMPLES and SPPM's noise and radius bias at
the pass counts below both stay well under them on these region sizes (measured
errors are 0.1-2%, the Cornell box's worst region 5%); each test prints its
measured errors so a regression shows as a number, not only a failure.
"""

import math
import os
import sys

import bpy
import numpy as np

import helpers

REFERENCE_SAMPLES = 128


def _scenes_module():
    scenes = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scenes")
    if scenes not in sys.path:
        sys.path.insert(0, os.path.abspath(scenes))
    import demo_cornell
    return demo_cornell


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
    """Mean relative error over a 4x4 grid of regions below 6%, every region below 15%
    (measured: 2.0% and 5.3% under both Blenders).
    Pixels showing the ceiling light itself are left out of both images: Cycles does
    not show area lights to the camera, GLSLPPM's emissive stand-in does."""
    helpers.reset_scene(size=(64, 64))
    _scenes_module().build_cornell_box(glass=False, mirror=False)
    ours, reference = _render_both("cornell", passes=128, photons=32768)
    light_pixels = ours[..., :3].max(axis=2) > 4.0
    ours, reference = ours.copy(), reference.copy()
    ours[light_pixels] = reference[light_pixels] = np.nan
    errors, a, b = _relative_errors(ours, reference, 4)
    print(f"  cornell: region errors mean {errors.mean():.3f} max {errors.max():.3f}; "
          f"image mean GLSLPPM {np.nanmean(ours[..., :3]):.4f} "
          f"Cycles {np.nanmean(reference[..., :3]):.4f}")
    assert errors.mean() < 0.06, (errors.round(3).tolist(), a.round(4).tolist(),
                                  b.round(4).tolist())
    assert errors.max() < 0.15, errors.round(3).tolist()


def _floor_under_light(kind, energy, **settings):
    """A white diffuse floor (albedo 0.8) lit from 3 m above, seen from below the light
    (Cycles hides area lights from the camera; GLSLPPM's emissive stand-in must
    then stay out of view, not in front of the floor)."""
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
    (Cycles 4.x). Cycles 3.x also multiplied by the cosine of the angle to the spot's
    axis (its spot_attenuation, dropped in 4.0), which the module does not model: under
    3.x the reference is Cycles' point light, and the 3.x spot is only checked on axis."""
    spot = {"shadow_soft_size": 0.0, "spot_size": math.radians(120), "spot_blend": 0.0}
    if helpers.BLENDER_4:
        _compare_light('SPOT', 300.0, 0.05, **spot)
        return
    ours, cycles_spot = _compare_light('SPOT', 300.0, 0.15, **spot)
    point_ours, cycles_point = _compare_light('POINT', 300.0, 0.10, shadow_soft_size=0.0)
    assert abs(ours - cycles_point) < 0.10 * cycles_point, (ours, cycles_point)
    assert abs(ours - point_ours) < 0.05 * point_ours, (ours, point_ours)


def test_sun_light_brightness_matches_cycles_and_theory():
    ours, reference = _compare_light('SUN', 3.0, 0.05, angle=math.radians(1))
    # A sun of strength S (W/m^2) straight above a Lambertian floor of albedo 0.8:
    # radiance = 0.8 S / pi.
    expected = 0.8 * 3.0 / math.pi
    assert abs(reference - expected) < 0.05 * expected, (reference, expected)
    assert abs(ours - expected) < 0.05 * expected, (ours, expected)


def test_area_light_brightness_matches_cycles():
    _compare_light('AREA', 300.0, 0.05, shape='SQUARE', size=1.0)
