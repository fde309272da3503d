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
from conftest import look_at, merge, sphere
from test_caustic_flux import IOR, ball_landing_area, inward_box
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


def test_vcm_light_tracing_glass_ball_caustic_matches_fresnel_closed_form(glslppm):
    """test_caustic_flux's set-up (a parallel beam of radius 0.7 straight down onto a glass
    ball of radius 0.5, centre 1 above the floor, in a box), here with a white floor (albedo
    0.8) and black walls, seen by an orthographic camera tilted 70 degrees off the vertical
    (the ball hides none of the floor within 1 of the axis). max_diffuse_bounces 1 keeps only
    the light's first landing on the floor (a second needs another diffuse scatter). Every
    landing splats the same value (equal flux, orthographic, one cosine), so the flux within
    rho of the axis over that within 1.0 is ball_landing_area(rho) / (the beam's area outside
    the silhouette + ball_landing_area(1.0)), with no beam normalisation. Each pixel counts by
    the fraction of its floor footprint inside the circle (8x8 points). Noise: the ratio is
    binomial, p(1 - p) / n with n about 2 million landings: 0.1% (one standard error); the
    tessellated ball transports within 0.05% of the analytic one (test_caustic_flux), and the
    footprint fractions at the circle's edge are exact only for a smooth irradiance. The bound
    is 0.6%, so a 1% bias fails (rho 0.5, the silhouette's sharp shadow edge, is left out)."""
    g = glslppm
    radius, height, beam, rings = 0.5, 1.0, 0.7, 64
    faces = inward_box((-3.0, 0.0, -3.0), (3.0, 4.0, 3.0))
    ball_p, ball_t, ball_n = sphere((0.0, height, 0.0), radius, rings, 2 * rings)
    positions, indices, ids = merge(*[(p, t, 0 if k == 0 else 1) for k, (p, t) in enumerate(faces)],
                                    (ball_p, ball_t, 2))
    face_normals = []
    for p, _ in faces:
        e = np.cross(p[1] - p[0], p[2] - p[0])
        face_normals.append(np.repeat((e / np.linalg.norm(e))[None], len(p), axis=0))
    normals = np.concatenate(face_normals + [ball_n]).astype(np.float32)
    materials = [g.Material("diffuse", color=(0.8,) * 3), g.Material("diffuse", color=(0.0,) * 3),
                 g.Material("dielectric", color=(1.0, 1.0, 1.0), ior=IOR)]
    light = g.Light("spot", power=1000.0, position=(0.0, 3.5, 0.0), direction=(0.0, -1.0, 0.0),
                    spot_size=0.002, spot_blend=0.0, radius=beam)
    tilt, scale, size, sub = math.radians(70.0), 2.2, 128, 8
    to_world = look_at((2.5 * math.sin(tilt), 2.5 * math.cos(tilt), 0.0), (0.0, 0.0, 0.0))
    camera = g.Camera(to_world, projection="orthographic", ortho_scale=scale)
    scene = g.Scene(positions, indices, normals=normals, material_ids=ids, materials=materials,
                    lights=[light], camera=camera)
    radiance = lt_render(g, scene, size, 16, seed=2, photons_per_pass=131072,
                         max_diffuse_bounces=1).mean(axis=2)
    # Each pixel's sub x sub points on the floor (row 0 on top), along the camera's -Z.
    m = to_world.astype(np.float64)
    u = ((np.arange(size * sub) + 0.5) / (size * sub) * 2.0 - 1.0) * 0.5 * scale
    x, y = np.meshgrid(u, -u)
    film = m[:3, 3] + x[..., None] * m[:3, 0] + y[..., None] * m[:3, 1]
    floor = film - (film[..., 1] / m[1, 2])[..., None] * m[:3, 2]
    rho = np.hypot(floor[..., 0], floor[..., 2])

    def flux_within(a):
        return ((rho < a).reshape(size, sub, size, sub).mean(axis=(1, 3)) * radiance).sum()

    segments = 2 * rings
    beside = math.pi * beam * beam - 0.5 * segments * radius * radius * math.sin(
        2.0 * math.pi / segments)
    whole = beside + ball_landing_area(1.0, radius, height, IOR, max_internal=13)
    for a in (0.3, 0.4):
        measured = flux_within(a) / flux_within(1.0)
        expected = ball_landing_area(a, radius, height, IOR, max_internal=13) / whole
        print(f"  vcm lt glass ball: within {a}: {measured:.5f}, closed form {expected:.5f}, "
              f"error {measured / expected - 1.0:+.5f}")
        assert abs(measured / expected - 1.0) < 0.006, (a, measured, expected)
