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

import bpy
import numpy as np

import helpers
from helpers import add_camera, add_light, add_mesh_object, diffuse_material

REFERENCE_SAMPLES = 64


def _render(name, engine=None):
    """(image or None, error or None, the recording engine) for the current scene."""
    helpers.load_native()
    engine = engine or helpers.recording_engine()
    try:
        return helpers.render_image(name, engine.bl_idname), None, engine
    except RuntimeError as error:
        path = os.path.join(helpers.OUT, f"{name}.exr")
        image = helpers.load_image(path) if os.path.exists(path) else None
        return image, str(error), engine


def _warnings(engine):
    return [message for level, message in engine.reports if level == 'WARNING']


def _cycles(name, samples=REFERENCE_SAMPLES):
    helpers.setup_cycles(samples=samples)
    cycles = bpy.context.scene.cycles
    cycles.pixel_filter_type = 'BOX'
    cycles.filter_width = 1.0
    image = helpers.render_image(f"{name}_cycles", 'CYCLES')
    bpy.context.scene.render.engine = 'GLSLPPM'
    return image


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
    ours, error, engine = _render("region_crop")
    assert error is None, error
    reference = _cycles("region_crop")
    assert ours.shape == reference.shape == (21, 32, 4), (ours.shape, reference.shape)
    measured = _pixel_error(ours, reference)
    print(f"  region with crop: pixel error {measured:.4f} (tolerance 0.05)")
    assert measured < 0.05, measured
    assert np.isfinite(ours).all()


def test_render_region_without_crop_matches_cycles():
    """The same region in the full 64x48 frame: pixel error below 5% against Cycles and
    nothing outside the region (Blender leaves it transparent black)."""
    _region_scene(crop=False)
    ours, error, engine = _render("region_full")
    assert error is None, error
    reference = _cycles("region_full")
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
        ours, error, engine = _render("pixel_aspect")
        assert error is None, error
        reference = _cycles("pixel_aspect")
        means = float(ours[..., :3].mean()), float(reference[..., :3].mean())
        measured = _pixel_error(ours, reference)
        print(f"  pixel aspect {aspect} {fit}: mean GLSLPPM {means[0]:.4f} Cycles "
              f"{means[1]:.4f}; pixel error {measured:.4f} (tolerances 0.02, 0.05)")
        assert abs(means[0] - means[1]) < 0.02 * means[1], means
        assert measured < 0.05, measured
