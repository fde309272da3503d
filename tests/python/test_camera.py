"""Camera models: orthographic size, shift, thin-lens focus."""
import math

import numpy as np
import pytest

import test_specular_closed_forms as specular_tests
from conftest import merge, quad


def emitter_scene(g, z, camera, size=1.0, radiance=2.0):
    h = size / 2
    p, t = quad((-h, -h, z), (h, -h, z), (h, h, z), (-h, h, z))  # faces +z, the camera
    emitter = g.Material("diffuse", color=(0, 0, 0), emission=(radiance,) * 3)
    return g.Scene(p, t, materials=[emitter], camera=camera)


def covered_pixels(g, scene, width=32):
    r = g.Renderer(scene, g.Settings(width=width, height=width, photons_per_pass=256))
    r.run(16)
    return r.film()[..., 0].sum() / 2.0, r.stats()["variant"]


def test_orthographic_image_size_is_independent_of_distance(glslppm):
    g = glslppm
    camera = g.Camera(np.eye(4, dtype=np.float32), projection="orthographic", ortho_scale=4.0)
    near, variant = covered_pixels(g, emitter_scene(g, -2.0, camera))
    far, _ = covered_pixels(g, emitter_scene(g, -8.0, camera))
    # The projection is the Frame's: no program of its own (a viewport switch restarts
    # the camera, tests/python/test_restart.py).
    assert "orthographic" not in variant
    # A 1 x 1 square in a 4 x 4 view of 32 x 32 pixels covers 64 pixels, at any distance
    # (jittered samples: the edge pixels are fractions).
    assert near == pytest.approx(64.0, rel=0.03)
    assert far == pytest.approx(64.0, rel=0.03)


def test_perspective_image_size_falls_with_distance_squared(glslppm):
    g = glslppm
    camera = g.Camera(np.eye(4, dtype=np.float32), fov_x=math.radians(60))
    near, _ = covered_pixels(g, emitter_scene(g, -2.0, camera))
    far, _ = covered_pixels(g, emitter_scene(g, -4.0, camera))
    # Image-plane size of a 1 x 1 square at distance d: (1 / (2 d tan 30deg) * 32)^2 pixels.
    for d, got in ((2.0, near), (4.0, far)):
        expected = (32.0 / (2.0 * d * math.tan(math.radians(30)))) ** 2
        assert got == pytest.approx(expected, rel=0.04)


def test_shift_moves_the_image_by_the_fraction_of_the_larger_side(glslppm):
    g = glslppm
    camera = g.Camera(np.eye(4, dtype=np.float32), projection="orthographic", ortho_scale=4.0,
                      shift_x=0.25)
    r = g.Renderer(emitter_scene(g, -2.0, camera),
                   g.Settings(width=32, height=32, photons_per_pass=256))
    r.run(16)
    image = r.film()[..., 0]
    cols = np.nonzero(image.sum(axis=0) > 0)[0]
    # Shift 0.25 of a 4-unit view moves the view 1 unit right: the square (centre 0) appears
    # 8 pixels left of the centre column.
    centre = (image.sum(axis=0) * np.arange(32)).sum() / image.sum()
    assert centre == pytest.approx(15.5 - 8.0, abs=0.3), cols


def test_focus_plane_stays_sharp_and_defocus_blurs(glslppm):
    """Thin lens: an edge on the focus plane keeps a one-pixel transition; off the plane it
    spreads over the circle of confusion, of diameter D = 2 A |d - f| / d on the focus plane.
    A disc blur takes an edge from 10% to 90% over 0.69 D (the disc's area fraction left
    of a line reaches 0.9 at 0.69 of its radius)."""
    g = glslppm
    width, fov = 48, math.radians(40)

    def edge_profile(z, focus, aperture):
        camera = g.Camera(np.eye(4, dtype=np.float32), fov_x=fov, aperture_radius=aperture,
                          focus_distance=focus)
        # An emitting half-plane x >= 0 (a 6 x 6 square with its left edge on the axis).
        p, t = quad((0, -3, z), (6, -3, z), (6, 3, z), (0, 3, z))
        scene = g.Scene(p, t, camera=camera,
                        materials=[g.Material("diffuse", color=(0, 0, 0), emission=(2.0,) * 3)])
        r = g.Renderer(scene, g.Settings(width=width, height=width, photons_per_pass=256))
        r.run(64)
        assert "depth-of-field" in r.stats()["variant"]
        return r.film()[width // 2 - 4: width // 2 + 4, :, 0].mean(axis=0) / 2.0

    def transition_width(profile):
        return np.sum((profile > 0.1) & (profile < 0.9))

    sharp = edge_profile(-5.0, 5.0, 0.2)
    blurred = edge_profile(-5.0, 2.5, 0.2)
    assert transition_width(sharp) <= 2
    # Circle of confusion on the focus plane: diameter 2 A |d - f| / d = 0.2 at f = 2.5,
    # seen in pixels: 0.2 / (2 f tan(fov/2)) * width.
    coc_pixels = 0.2 / (2 * 2.5 * math.tan(fov / 2)) * width
    expected = 0.69 * coc_pixels
    assert abs(transition_width(blurred) - expected) <= 1.5, (transition_width(blurred), expected)


def test_region_renders_the_window_of_the_full_frame(glslppm):
    """A region (x 8..24, y 4..20 from the top, of 32 x 32) renders those pixels of the
    full frame: the 1 x 1 square of a 4 x 4 orthographic view covers pixels 12..20 in both,
    so the window sees it at 4..12 across and 8..16 down (exactly, away from its edges)."""
    g = glslppm
    camera = g.Camera(np.eye(4, dtype=np.float32), projection="orthographic", ortho_scale=4.0,
                      region=(8, 4, 32, 32))
    r = g.Renderer(emitter_scene(g, -2.0, camera),
                   g.Settings(width=16, height=16, photons_per_pass=256))
    r.run(16)
    image = r.film()[..., 0]
    assert image.shape == (16, 16)
    assert image[9:15, 5:11].min() == pytest.approx(2.0)
    inside = np.zeros((16, 16), dtype=bool)
    inside[7:17, 3:13] = True
    assert image[~inside].max() == 0.0
    assert image.sum() / 2.0 == pytest.approx(64.0, rel=0.03)
    with pytest.raises(ValueError, match="does not fit"):
        g.Renderer(emitter_scene(g, -2.0, camera), g.Settings(width=32, height=16))


def test_pixel_aspect_stretches_the_film_vertically(glslppm):
    """Pixels twice as tall as wide: a 4-unit-wide orthographic view of 32 x 32 pixels spans
    8 units vertically, so the 1 x 1 square covers 8 columns by 4 rows (32 pixels)."""
    g = glslppm
    camera = g.Camera(np.eye(4, dtype=np.float32), projection="orthographic", ortho_scale=8.0,
                      pixel_aspect=2.0)
    covered, _ = covered_pixels(g, emitter_scene(g, -2.0, camera))
    assert covered == pytest.approx(32.0, rel=0.03)


@pytest.mark.parametrize("estimator", ["sppm", "vcm"])
def test_transparent_film_alpha_is_coverage(glslppm, estimator):
    """With transparent on, alpha is the fraction of camera rays that hit something: the
    1 x 1 square in a 4 x 4 view covers 1/16 of the image; the world (radiance 3) is not
    seen, and without transparent the alpha is 1 everywhere. VCM's eye paths as SPPM's."""
    g = glslppm
    camera = g.Camera(np.eye(4, dtype=np.float32), projection="orthographic", ortho_scale=4.0)
    p, t = quad((-0.5, -0.5, -2.0), (0.5, -0.5, -2.0), (0.5, 0.5, -2.0), (-0.5, 0.5, -2.0))
    scene = g.Scene(p, t, materials=[g.Material("diffuse", color=(0, 0, 0),
                                                emission=(2.0,) * 3)],
                    camera=camera, environment=(3.0, 3.0, 3.0))
    for transparent in (True, False):
        r = g.Renderer(scene, g.Settings(width=32, height=32, photons_per_pass=256,
                                         transparent=transparent, estimator=estimator))
        r.run(16)
        film = r.film()
        if transparent:
            assert "transparent" in r.stats()["variant"]
            assert film[..., 3].mean() == pytest.approx(1.0 / 16.0, rel=0.03)
            assert film[..., 3].min() == 0.0 and film[..., 3].max() == 1.0
            assert np.all(film[film[..., 3] == 0.0][:, :3] == 0.0)
        else:
            assert np.all(film[..., 3] == 1.0)
            assert film[0, 0, 0] == pytest.approx(3.0)
        r.close()


@pytest.mark.parametrize("estimator", ["sppm", "vcm"])
def test_transparent_glass_film_sees_through_a_slab_as_often_as_it_transmits(glslppm,
                                                                            estimator):
    """Film > Transparent with Transparent Glass: a lossless glass slab (IOR 1.5) seen head-on
    before a uniform world of radiance L. A camera ray that crosses both faces without a
    reflection, with probability (1 - R)^2 = 0.9216 (R = 0.04), is transparent film; every
    other one is reflected, leaves to the world and is seen. So the film's transparency
    (1 - alpha) is (1 - R)^2 and its colour L (1 - (1 - R)^2). Bound: 5 sigma of the
    Bernoulli draws on the transparency (0.28%, so a 1% bias is 18 sigma)."""
    g = glslppm
    t = specular_tests
    radiance = 2.0
    front = t.oriented_quad([(-5, -5, 0.25), (5, -5, 0.25), (5, 5, 0.25), (-5, 5, 0.25)],
                            (0, 0, 1))
    back = t.oriented_quad([(-5, -5, -0.25), (5, -5, -0.25), (5, 5, -0.25), (-5, 5, -0.25)],
                           (0, 0, -1))
    p, tri, ids = merge((*front, 0), (*back, 0))
    scene = g.Scene(p, tri, material_ids=ids,
                    materials=[g.Material("dielectric", color=(1, 1, 1), ior=t.IOR)],
                    camera=t.ortho_camera(g, (0, 0, 5), (0, 0, 0), (0, 1, 0), 1.0),
                    environment=(radiance,) * 3)
    size, passes = 64, 64
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=1024,
                                     max_bounces=1024, seed=1, estimator=estimator,
                                     transparent=True, transparent_glass=True))
    r.run(passes)
    film = r.film().astype(np.float64)
    r.close()
    assert np.isfinite(film).all()
    reflectance = ((t.IOR - 1) / (t.IOR + 1)) ** 2
    expected = (1.0 - reflectance) ** 2
    transparency = 1.0 - film[..., 3].mean()
    bound = t.bernoulli_bound(expected, size * size * passes)
    print(f"  transparency {transparency:.5f} against {expected:.5f}, bound {bound:.5f}")
    assert bound < 0.003
    assert abs(transparency / expected - 1.0) < bound
    # What is not transparent is the world, seen by reflection: the colour is L alpha.
    assert film[..., :3].mean() == pytest.approx(radiance * (1.0 - transparency), rel=1e-4)


def test_radius_scale_multiplies_the_automatic_radius_only(glslppm):
    """radius_scale scales the automatic initial radius in one renderer; an absolute
    radius is used as given."""
    g = glslppm
    scene = g.cornell_box(sphere_rings=8)
    radii = {}
    for scale, absolute in ((1.0, 0.0), (0.5, 0.0), (0.5, 0.03)):
        r = g.Renderer(scene, g.Settings(width=16, height=16, photons_per_pass=64,
                                         initial_radius=absolute, radius_scale=scale))
        radii[(scale, absolute)] = r.stats()["initial_radius"]
        r.close()
    assert radii[(0.5, 0.0)] == pytest.approx(0.5 * radii[(1.0, 0.0)], rel=1e-6)
    assert radii[(0.5, 0.03)] == pytest.approx(0.03, rel=1e-6)
    with pytest.raises(ValueError, match="radius_scale"):
        g.Settings(radius_scale=0.0)
