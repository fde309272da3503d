"""Object > Visibility: camera and shadow ray visibility against Cycles, and the
settings without a counterpart (other rays, holdout, shadow catcher) warned about by
name while the image is still written.

The scene: a grey floor, a grey box 1 m above it and a point light 3 m up, seen from
above and a little to the side, so that the box's top, its shadow and the lit floor all
fill several regions of a 3x3 grid. Cycles renders with a 1-pixel box filter."""

import bpy
import numpy as np

import helpers
from helpers import add_camera, add_cube, add_light, add_mesh_object, diffuse_material

# Region means against Cycles: 6% for a region (measured noise of both renderers at
# these settings about 2%), 4% for the image's mean.
REGION_TOLERANCE = 0.06
MEAN_TOLERANCE = 0.04


def _box_over_floor():
    scene = helpers.reset_scene(size=(48, 48))
    scene.glslppm.passes = 96
    scene.glslppm.photons_per_pass = 1 << 15
    grey = diffuse_material("Grey", (0.5, 0.5, 0.5))
    add_mesh_object("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)],
                    [(0, 1, 2, 3)], material=grey)
    box = add_cube("Box", location=(0.3, 0, 1.2), scale=(0.5, 0.5, 0.2), material=grey)
    add_light('POINT', 600.0, location=(0, 0, 3), shadow_soft_size=0.0)
    location = (0.8, -1.2, 5.5)
    add_camera(location, helpers.look_at_rotation(location, (0.2, 0, 0)), lens=40.0)
    return scene, box


def _compare(name):
    ours, error, engine = helpers.render_recorded(name)
    assert error is None, error
    assert np.isfinite(ours).all()
    reference = helpers.render_cycles_box_filter(name)
    a, b, region_error, mean_error = helpers.region_comparison(ours, reference)
    print(f"  {name}: regions GLSLPPM {np.round(a, 3).tolist()} Cycles "
          f"{np.round(b, 3).tolist()}; worst region {region_error:.4f} of the brightest "
          f"(tolerance {REGION_TOLERANCE}), mean {mean_error:.4f} (tolerance "
          f"{MEAN_TOLERANCE})")
    return ours, reference, region_error, mean_error, engine


def test_hidden_from_camera_matches_cycles():
    """The box off for camera rays: the floor and the box's shadow show where its top
    was, as in Cycles. Without the flag the image differs from Cycles' by far more (the
    box's bright top is in the way), which the test checks too."""
    scene, box = _box_over_floor()
    box.visible_camera = False
    ours, reference, region_error, mean_error, engine = _compare("hidden_from_camera")
    assert region_error < REGION_TOLERANCE and mean_error < MEAN_TOLERANCE
    assert not helpers.warnings_of(engine), engine.reports
    box.visible_camera = True
    seen, error, engine = helpers.render_recorded("hidden_from_camera_control")
    control = float(np.abs(helpers.region_means(seen, 3) - helpers.region_means(reference, 3))
                    .max() / helpers.region_means(reference, 3).max())
    print(f"  the same box seen by the camera: worst region {control:.3f}")
    assert control > 2 * REGION_TOLERANCE, control


def test_shadow_off_matches_cycles():
    """The box off for shadow rays: the floor under it is lit, the box's top still
    seen, as in Cycles."""
    scene, box = _box_over_floor()
    box.visible_shadow = False
    ours, reference, region_error, mean_error, engine = _compare("shadow_off")
    assert region_error < REGION_TOLERANCE and mean_error < MEAN_TOLERANCE
    assert not helpers.warnings_of(engine), engine.reports


def test_other_ray_visibility_holdout_and_shadow_catcher_warn():
    """Glossy and transmission visibility off, holdout and shadow catcher: one warning
    each, in these words, and the image is still written (the box as an ordinary one)."""
    scene, box = _box_over_floor()
    scene.glslppm.passes = 8
    box.visible_glossy = False
    box.visible_transmission = False
    box.is_holdout = True
    floor = bpy.data.objects["Floor"]
    floor.is_shadow_catcher = True
    image, error, engine = helpers.render_recorded("visibility_warnings")
    assert error is None, error
    expected = [
        "object 'Box': ray visibility off for Glossy, Transmission is not "
        "supported; those rays still see it (Object > Visibility > Ray Visibility)",
        "object 'Box': Holdout is not supported; it renders as an ordinary "
        "object (Object > Visibility > Mask > Holdout)",
        "object 'Floor': Shadow Catcher is not supported; it renders as an "
        "ordinary object (Object > Visibility > Mask > Shadow Catcher)",
    ]
    warnings = helpers.warnings_of(engine)
    for message in expected:
        assert warnings.count(message) == 1, (message, engine.reports)
    assert image is not None and np.isfinite(image).all() and image[..., :3].mean() > 0.05
