"""The light sample's pick split between the world and the other emitters at the shading
point (common/light_sampling.glsl, light_world_share; native/render/emitters.cpp,
light_split). By power alone a dim world around a lamp takes most light samples (its flux
crosses the scene's whole bounding disc); the split gives them to the lamp where the lamp is
the brighter, and every density the samples are weighed with reads the same pick, so the
image keeps its closed form.

A white Lambertian floor (8 x 8, albedo 0.8) under a dim uniform world and one lamp, seen
straight down by an orthographic camera over its middle (1 x 1): the floor's radiance is
albedo / pi (E_lamp + pi L_world), the world lighting the upper hemisphere whole."""
import math

import numpy as np
import pytest

from conftest import look_at, merge, quad

ALBEDO, WORLD, HEIGHT, VIEW, SIZE, PASSES = 0.8, 0.05, 2.0, 1.0, 48, 32
SIGMAS = 4.0


def floor_scene(g, light):
    floor = quad((-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0))
    positions, indices, ids = merge((*floor, 0))
    camera = g.Camera(look_at((0, 0, 1.0), (0, 0, 0)), projection="orthographic",
                      ortho_scale=VIEW)
    return g.Scene(positions, indices, material_ids=ids,
                   materials=[g.Material("diffuse", color=(ALBEDO,) * 3)], lights=[light],
                   camera=camera, environment=(WORLD,) * 3)


def render(g, scene, seed=1):
    r = g.Renderer(scene, g.Settings(width=SIZE, height=SIZE, photons_per_pass=4096,
                                     seed=seed, max_diffuse_bounces=0))
    r.run(PASSES)
    image = r.film()[..., :3].astype(np.float64).mean(axis=2)
    r.close()
    assert np.isfinite(image).all()
    return image


def pixel_points():
    """Each pixel's centre on the floor (row 0 at the top: +y, as the camera's up)."""
    centres = ((np.arange(SIZE) + 0.5) / SIZE - 0.5) * VIEW
    return np.meshgrid(centres, centres[::-1])


def world_pick_by_power(power):
    """The world's power-based pick against a lamp of luminance power `power`: the world's
    flux pi R^2 4 pi L through the bounding disc of the floor (R its half diagonal)."""
    radius = math.hypot(4.0, 4.0)
    world = math.pi * radius ** 2 * 4.0 * math.pi * WORLD
    return world / (world + power)


@pytest.mark.parametrize("kind", ["point", "sun"])
def test_a_lamp_under_a_dim_world_keeps_its_closed_form_with_less_noise(glslppm, kind):
    """A point lamp 2 above the floor's middle (power 100: E = P h / 4 pi (h^2 + rho^2)^1.5)
    or a sun straight down (E = 2), under a world of radiance 0.05 (E = pi 0.05). Each pixel
    against the closed form at its centre: their mean ratio within 4 standard errors of it
    (asserted below 1%), and the per-pixel noise of one pass at most half of what the
    power-based pick gives the lamp's light, sqrt(p_world / (1 - p_world)) (binomial: the
    lamp's sample scaled by 1 / (1 - p_world) in the passes that pick it), p_world 0.39 and
    0.24 here; the split leaves the world at least a tenth of that."""
    g = glslppm
    if kind == "point":
        power = 100.0
        light = g.Light("point", power=power, position=(0.0, 0.0, HEIGHT))
        x, y = pixel_points()
        lamp = power / (4.0 * math.pi) * HEIGHT / (HEIGHT ** 2 + x ** 2 + y ** 2) ** 1.5
        p_world = world_pick_by_power(power)
    else:
        strength = 2.0
        light = g.Light("sun", power=strength, direction=(0.0, 0.0, -1.0))
        lamp = np.full((SIZE, SIZE), strength)
        p_world = world_pick_by_power(strength * math.pi * math.hypot(4.0, 4.0) ** 2)
    expected = ALBEDO / math.pi * (lamp + math.pi * WORLD)
    ratio = render(g, floor_scene(g, light)) / expected
    mean = ratio.mean()
    bound = SIGMAS * ratio.std(ddof=1) / math.sqrt(ratio.size)
    noise_per_pass = ratio.std(ddof=1) * math.sqrt(PASSES)
    by_power = math.sqrt(p_world / (1.0 - p_world))
    print(f"  {kind} lamp under a dim world: mean ratio {mean:.5f}, bound {bound:.5f}; "
          f"noise a pass {noise_per_pass:.3f} against {by_power:.3f} by power "
          f"(p_world {p_world:.2f})")
    assert bound < 0.01, bound
    assert abs(mean - 1.0) < bound, (mean, bound)
    assert noise_per_pass < 0.5 * by_power, (noise_per_pass, by_power)
