"""Glass and mirrors against closed forms: a slab at normal incidence with all its internal
reflections, Fresnel reflectance at 45 degrees, tinted conductors, and total internal
reflection in a prism.

Each camera ray chooses reflection or refraction by Fresnel (probability = reflectance), so
a pixel's value in one pass is a Bernoulli draw times the radiance behind it: the bounds
below are several standard deviations of that draw over every sample the test takes, and
each is tight enough that a 1% bias fails it.
"""
import math

import numpy as np
import pytest

from closed_forms import fresnel_dielectric
from conftest import look_at, merge, quad

IOR = 1.5


def oriented_quad(corners, normal):
    """A quad whose winding faces `normal` (the renderer's emitters and glass read the
    geometric normal from the winding)."""
    p, t = quad(*corners)
    n = np.cross(p[1] - p[0], p[2] - p[0])
    if np.dot(n, normal) < 0:
        t = t[:, ::-1].copy()
    return p, t


def ortho_camera(g, eye, target, up, scale):
    return g.Camera(look_at(eye, target, up), projection="orthographic", ortho_scale=scale)


def render(g, scene, size=64, passes=64, seed=1, **settings):
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=1024,
                                     max_bounces=1024, hash="exact", seed=seed, **settings))
    r.run(passes)
    image = r.film()[..., :3].astype(np.float64)
    assert np.isfinite(image).all()
    return image, size * size * passes


def emitter_material(g, radiance):
    return g.Material("diffuse", color=(0, 0, 0), emission=radiance)


def slab_transmittance(r):
    """Two parallel faces with reflectance R each, all internal reflections summed:
    (1 - R)^2 (1 + R^2 + R^4 + ...) = (1 - R) / (1 + R)."""
    return (1.0 - r) / (1.0 + r)


def bernoulli_bound(p, samples, sigmas=5.0):
    """`sigmas` standard deviations of the mean of `samples` Bernoulli(p) draws, relative
    to p."""
    return sigmas * math.sqrt(p * (1.0 - p) / samples) / p


def test_glass_slab_at_normal_incidence_transmits_one_minus_r_over_one_plus_r(glslppm):
    """An emitter of radiance L behind a glass slab (IOR 1.5), seen head-on by an
    orthographic camera: L (1 - R) / (1 + R) with R = ((n - 1) / (n + 1))^2 = 0.04, that is
    0.9231 L, per channel."""
    g = glslppm
    radiance = np.array([2.0, 1.0, 0.5])
    front = oriented_quad([(-5, -5, 0.25), (5, -5, 0.25), (5, 5, 0.25), (-5, 5, 0.25)], (0, 0, 1))
    back = oriented_quad([(-5, -5, -0.25), (5, -5, -0.25), (5, 5, -0.25), (-5, 5, -0.25)],
                         (0, 0, -1))
    light = oriented_quad([(-9, -9, -2), (9, -9, -2), (9, 9, -2), (-9, 9, -2)], (0, 0, 1))
    p, t, ids = merge((*front, 0), (*back, 0), (*light, 1))
    scene = g.Scene(p, t, material_ids=ids,
                    materials=[g.Material("dielectric", color=(1, 1, 1), ior=IOR),
                               emitter_material(g, tuple(radiance))],
                    camera=ortho_camera(g, (0, 0, 5), (0, 0, 0), (0, 1, 0), 1.0))
    image, samples = render(g, scene)
    r = ((IOR - 1) / (IOR + 1)) ** 2
    expected = slab_transmittance(r)
    assert expected == pytest.approx(0.9231, abs=1e-4)
    measured = image.mean(axis=(0, 1)) / radiance
    print(f"  measured/expected - 1: {measured / expected - 1.0}")
    # 5 sigma of 262,144 Bernoulli(0.923) draws is 0.28%; a 1% bias is 18 sigma.
    bound = bernoulli_bound(expected, samples)
    assert bound < 0.003
    assert np.all(np.abs(measured / expected - 1.0) < bound), (measured, expected, bound)


def test_glass_plane_at_45_degrees_reflects_the_fresnel_fraction_of_the_sky(glslppm):
    """A glass plane (IOR 1.5, z up) under a sky of radiance L above the horizon and black
    below, seen at 45 degrees: only the reflected ray finds light, so the image is R(45) L
    with R(45) = 0.0503. The ray refracted into the glass escapes downwards into black."""
    g = glslppm
    sky = 3.0
    pixels = np.zeros((16, 32, 4), dtype=np.float32)
    pixels[8:, :, :] = 1.0  # rows from the bottom: the upper half is the sky above the horizon
    plane = oriented_quad([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)], (0, 0, 1))
    scene = g.Scene(*plane, materials=[g.Material("dielectric", color=(1, 1, 1), ior=IOR)],
                    environment=(sky,) * 3, textures=[g.Texture(pixels)], environment_texture=0,
                    camera=ortho_camera(g, (0, -5, 5), (0, 0, 0), (0, 0, 1), 1.0))
    image, samples = render(g, scene, size=128, passes=192)
    expected = float(fresnel_dielectric(math.cos(math.radians(45)), 1.0 / IOR)[0])
    assert expected == pytest.approx(0.0503, abs=1e-4)
    measured = image.mean() / sky
    print(f"  measured/expected - 1: {measured / expected - 1.0:.4f}")
    # Over 3.1 million Bernoulli(0.05) draws, 4 sigma is 1.0% of R.
    bound = bernoulli_bound(expected, samples, sigmas=4.0)
    assert bound < 0.011
    assert abs(measured / expected - 1.0) < bound, (measured, expected, bound)


@pytest.mark.parametrize("colors", [[(0.5, 0.5, 0.5)], [(0.5, 0.25, 1.0), (0.8, 0.6, 0.4)]])
def test_tinted_mirrors_multiply_the_radiance_by_their_colours(glslppm, colors):
    """A sky of radiance L seen in one conductor of colour c at 45 degrees is c L; seen after
    two (a periscope: the second mirror parallel to the first, above it) is c1 c2 L.
    No randomness on this path, so the bound is float rounding."""
    g = glslppm
    sky = np.array([1.0, 2.0, 4.0])
    parts = [(*oriented_quad([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)],
                             (0, 0, 1)), 0)]
    if len(colors) == 2:
        # A wall mirror facing -y at y = 4: the ray leaving the floor along (0, 1, 1)
        # meets it at z = 4 and leaves along (0, -1, 1), up into the sky.
        parts.append((*oriented_quad([(-50, 4, -1), (50, 4, -1), (50, 4, 80), (-50, 4, 80)],
                                     (0, -1, 0)), 1))
    p, t, ids = merge(*parts)
    pixels = np.zeros((16, 32, 4), dtype=np.float32)
    pixels[8:, :, :] = 1.0
    materials = [g.Material("conductor", color=c) for c in colors]
    scene = g.Scene(p, t, material_ids=ids, materials=materials, environment=tuple(sky),
                    textures=[g.Texture(pixels)], environment_texture=0,
                    camera=ortho_camera(g, (0, -5, 5), (0, 0, 0), (0, 0, 1), 1.0))
    image, _ = render(g, scene, size=32, passes=4)
    expected = sky * np.prod(np.array(colors), axis=0)
    assert np.allclose(image, expected, rtol=1e-4), (image.mean(axis=(0, 1)), expected)


def prism(size, half_depth):
    """A right-angle glass prism: legs on x = 0 and y = 0, hypotenuse facing (1, 1, 0),
    extruded along z; outward windings."""
    s, h = size, half_depth
    faces = [
        oriented_quad([(0, 0, -h), (0, s, -h), (0, s, h), (0, 0, h)], (-1, 0, 0)),
        oriented_quad([(0, 0, -h), (s, 0, -h), (s, 0, h), (0, 0, h)], (0, -1, 0)),
        oriented_quad([(s, 0, -h), (0, s, -h), (0, s, h), (s, 0, h)], (1, 1, 0)),
    ]
    for z, nz in ((-h, -1.0), (h, 1.0)):
        p = np.array([(0, 0, z), (s, 0, z), (0, s, z)], dtype=np.float32)
        t = np.array([[0, 1, 2]], dtype=np.uint32)
        if np.cross(p[1] - p[0], p[2] - p[0])[2] * nz < 0:
            t = t[:, ::-1].copy()
        faces.append((p, t))
    return merge(*[(p, t, 0) for p, t in faces])[:2]


def test_total_internal_reflection_carries_the_full_weight(glslppm):
    """A camera ray enters a right-angle prism through one leg at normal incidence, meets
    the hypotenuse at 45 degrees (past the critical angle of 41.8 degrees for IOR 1.5), is
    reflected totally and leaves through the other leg at normal incidence towards an
    emitter. The two legs act as a slab folded by a perfect mirror: (1 - R) / (1 + R) L."""
    g = glslppm
    radiance = np.array([1.0, 3.0, 2.0])
    glass_p, glass_t = prism(1.0, 3.0)
    light = oriented_quad([(-2, -1, -6), (3, -1, -6), (3, -1, 6), (-2, -1, 6)], (0, 1, 0))
    p, t, ids = merge((glass_p, glass_t, 0), (*light, 1))
    scene = g.Scene(p, t, material_ids=ids,
                    materials=[g.Material("dielectric", color=(1, 1, 1), ior=IOR),
                               emitter_material(g, tuple(radiance))],
                    camera=ortho_camera(g, (-3, 0.5, 0), (0, 0.5, 0), (0, 1, 0), 0.5))
    image, samples = render(g, scene)
    r = ((IOR - 1) / (IOR + 1)) ** 2
    expected = slab_transmittance(r)
    assert math.degrees(math.asin(1 / IOR)) < 45.0
    measured = image.mean(axis=(0, 1)) / radiance
    print(f"  measured/expected - 1: {measured / expected - 1.0}")
    bound = bernoulli_bound(expected, samples)
    assert np.all(np.abs(measured / expected - 1.0) < bound), (measured, expected, bound)
