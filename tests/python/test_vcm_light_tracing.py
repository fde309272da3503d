"""VCM's light tracing technique alone (vcm_techniques "lt", docs/vcm.md): light subpaths
traced whole in each pass, every vertex on a surface that only reflects connected to the
camera and splatted into the fixed-point film; the eye path keeps only the emission it meets
before any rough scatter. Checked against the closed forms path tracing meets in test_vcm.py
(the furnace, the point light over a plane) and light tracing's own caustic (the spot seen
through a mirror, test_light_tracing's closed form: an L S D E path a path tracer cannot
sample with its light sample).

The noise bound is SIGMAS standard errors of the image's mean ratio to the closed form, from
the pixels' spread (a splat lands in one pixel, so the pixels are independent); each test
asserts that bound below 1% first, so that a 1% bias fails.
"""
import math

import numpy as np
import pytest

import test_direct_light as direct_light_tests
import test_light_tracing as light_tracing_tests
from closed_forms import furnace_scene
from test_vcm import mean_and_bound, vcm_render


def lt_render(g, scene, size, passes, **settings):
    return vcm_render(g, scene, size, passes, vcm_techniques="lt", **settings)


@pytest.mark.parametrize("limit", [0, 2, None])
def test_vcm_light_tracing_furnace_follows_the_diffuse_limit(glslppm, limit):
    """test_vcm's furnace (a closed diffuse sphere of albedo 0.5 emitting Le = 1, L = Le
    sum_{k=0..N+1} a^k for a diffuse limit N) by light tracing: the emission seen directly by
    the eye path, every other term by the light subpaths' camera connections (their first
    vertex, the direct light, included). Limits as the photons count them."""
    g = glslppm
    albedo, emission = 0.5, 1.0
    settings = {} if limit is None else {"max_diffuse_bounces": limit}
    terms = 16 + 2 if limit is None else limit + 2
    image = lt_render(g, furnace_scene(g, albedo, emission), 24, 32, photons_per_pass=65536,
                      **settings)
    expected = emission * sum(albedo ** k for k in range(terms))
    mean, bound = mean_and_bound(image.mean(axis=2))
    error = mean / expected - 1.0
    print(f"  vcm lt diffuse limit {limit}: L {mean:.5f}, closed form {expected:.5f}, "
          f"error {error:+.5f}, bound {bound:.5f}")
    assert bound < 0.008, bound
    assert abs(error) < bound, (mean, expected, bound)


def test_vcm_light_tracing_point_light_over_a_diffuse_plane(glslppm):
    """test_vcm's point light over a plane of albedo 0.5 (orthographic camera): every pixel
    by light tracing alone (the plane's direct light is the light subpaths' first vertex). The
    pixels' ratios to the closed form's footprint means: their mean within SIGMAS standard
    errors, and the 16 blocks of 11x11 pixels within 5% each (their own noise, about 1%)."""
    g = glslppm
    power, h, size = 100.0, 1.0, 44
    intensity = power / (4 * math.pi)
    scene = direct_light_tests.plane_scene(g, [g.Light("point", power=power,
                                                       position=(0.0, 0.0, h))])
    image = lt_render(g, scene, size, 32, photons_per_pass=65536)
    e = image[..., 0] * math.pi / direct_light_tests.ALBEDO
    expected = direct_light_tests.footprint(
        lambda x, y: intensity * h / (h * h + x * x + y * y) ** 1.5, size)
    ratio = e / expected
    mean, bound = mean_and_bound(ratio)
    blocks = ratio.reshape(4, 11, 4, 11).mean(axis=(1, 3)) - 1.0
    print(f"  vcm lt point light: mean ratio {mean:.5f}, bound {bound:.5f}, "
          f"blocks max {np.abs(blocks).max():.4f}")
    assert bound < 0.008, bound
    assert abs(mean - 1.0) < bound, (mean, bound)
    assert np.abs(blocks).max() < 0.05, blocks


def test_vcm_light_tracing_finds_the_mirrored_spot(glslppm):
    """test_light_tracing's spot seen through a mirror on a diffuse ceiling (max_bounces 1:
    L S D E alone), L = albedo / pi I cos / d^2 per pixel: VCM's light tracing connects the
    ceiling's vertices to the camera; the mean ratio within SIGMAS standard errors."""
    g = glslppm
    size = 64
    scene = light_tracing_tests.mirrored_spot(g)
    image = lt_render(g, scene, size, 32, max_bounces=1, seed=1, photons_per_pass=65536)
    ratio = image.mean(axis=2) / light_tracing_tests.mirrored_spot_radiance(size)
    mean, bound = mean_and_bound(ratio)
    print(f"  vcm lt mirrored spot: mean ratio {mean:.5f}, bound {bound:.5f}")
    assert bound < 0.008, bound
    assert abs(mean - 1.0) < bound, (mean, bound)


def test_vcm_path_tracing_misses_the_mirrored_spot(glslppm):
    """The same scene by path tracing alone: its light sample cannot reach a point light
    through a mirror, so the ceiling is black (why light tracing is a technique of VCM)."""
    g = glslppm
    image = vcm_render(g, light_tracing_tests.mirrored_spot(g), 16, 4, max_bounces=1)
    assert image.max() == 0.0


def test_vcm_techniques_is_checked(glslppm):
    g = glslppm
    with pytest.raises(ValueError, match="vcm_techniques: 'vm' is not built"):
        g.Settings(estimator="vcm", vcm_techniques="vm")
    with pytest.raises(ValueError, match="vcm_techniques: needs estimator vcm"):
        g.Settings(estimator="pppm", vcm_techniques="lt")
    assert g.Settings(estimator="vcm", vcm_techniques="lt").vcm_techniques == "lt"
    assert g.Settings().vcm_techniques == "pt"


def test_vcm_light_tracing_passes_are_independent(glslppm):
    """A pass of light tracing is a function of (seed, pass index) too (its splats divided by
    its own paths): passes 0-7 in one run give the mean of passes 0-3 and 4-7 run apart."""
    g = glslppm
    scene = furnace_scene(g, 0.5, 1.0)

    def film(indices):
        r = g.Renderer(scene, g.Settings(width=16, height=16, seed=4, estimator="vcm",
                                         vcm_techniques="lt", photons_per_pass=4096))
        r.run_passes(indices)
        image = r.film()[..., :3].astype(np.float64)
        r.close()
        return image

    whole = film(list(range(8)))
    halves = 0.5 * (film([0, 1, 2, 3]) + film([4, 5, 6, 7]))
    assert np.abs(whole - halves).max() <= 1e-5 * np.abs(whole).max()
    assert np.abs(film([0, 1]) - film([2, 3])).max() > 1e-3  # the passes do differ
