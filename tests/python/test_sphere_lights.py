"""Point and spot lights of a radius seen in a mirror and through glass (issue 26: a chrome
sphere showed no highlight of a point light of radius 0.25, a bulb inside a clear glass shell
was missing). As in Cycles, such a light is a sphere that specular rays hit, of radiance
L = I / (pi r^2) with I = P / 4 pi (the spot's inside its cone), the radiance its light
samples and photons already assume. An orthographic camera looks straight down; the light
hangs between it and a mirror (or under a glass pane) and fills the view, so each pixel is
L times the mirror's reflectance or the pane's Bernoulli mean. Camera rays pass the sphere
(Cycles' camera rays do not see point lights either).
"""
import math

import numpy as np
import pytest

from conftest import merge
from test_specular_closed_forms import IOR, bernoulli_bound, oriented_quad, ortho_camera, render

POWER = 40.0
RADIUS = 1.5
COLOR = np.array([1.0, 0.5, 0.25])


def radiance():
    return COLOR * POWER / (4.0 * math.pi * math.pi * RADIUS * RADIUS)


def light(g, kind):
    extra = dict(direction=(0, 0, -1), spot_size=math.radians(120), spot_blend=0.0) \
        if kind == "spot" else {}
    return g.Light(kind, color=tuple(COLOR), power=POWER, position=(0, 0, 3), radius=RADIUS,
                   **extra)


def floor(material):
    return (*oriented_quad([(-9, -9, 0), (9, -9, 0), (9, 9, 0), (-9, 9, 0)], (0, 0, 1)),
            material)


@pytest.mark.parametrize("kind", ["point", "spot"])
def test_mirror_shows_a_sphere_light(glslppm, kind):
    """A perfect mirror (white conductor, roughness 0) below the light: each camera ray
    reflects straight up into the sphere's underside, L exactly (no random choice)."""
    g = glslppm
    p, t, ids = merge(floor(0))
    scene = g.Scene(p, t, material_ids=ids,
                    materials=[g.Material("conductor", color=(1, 1, 1))],
                    lights=[light(g, kind)],
                    camera=ortho_camera(g, (0, 0, 5.5), (0, 0, 0), (0, 1, 0), 1.0))
    image, _ = render(g, scene, passes=4)
    measured = image.mean(axis=(0, 1))
    print(f"  {kind}: measured {measured}, expected {radiance()}")
    assert np.allclose(measured, radiance(), rtol=1e-4), (measured, radiance())


def test_bulb_under_a_glass_pane(glslppm):
    """The light under a glass pane (IOR 1.5) above a black floor: the camera sees it through
    the pane, L (1 - R) at normal incidence, R = 0.04 (was black)."""
    g = glslppm
    pane = (*oriented_quad([(-9, -9, 5), (9, -9, 5), (9, 9, 5), (-9, 9, 5)], (0, 0, 1)), 0)
    p, t, ids = merge(pane, floor(1))
    scene = g.Scene(p, t, material_ids=ids,
                    materials=[g.Material("dielectric", color=(1, 1, 1), ior=IOR),
                               g.Material("diffuse", color=(0, 0, 0))],
                    lights=[light(g, "point")],
                    camera=ortho_camera(g, (0, 0, 8), (0, 0, 0), (0, 1, 0), 1.0))
    image, samples = render(g, scene)
    r = ((IOR - 1) / (IOR + 1)) ** 2
    measured = image.mean(axis=(0, 1)) / radiance()
    bound = bernoulli_bound(1.0 - r, samples)
    print(f"  measured {measured}, expected {1 - r:.4f}, bound {bound:.4f}")
    assert np.all(np.abs(measured / (1.0 - r) - 1.0) < bound), (measured, bound)
