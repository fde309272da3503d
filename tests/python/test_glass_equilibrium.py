"""A white object inside clear glass under a uniform sky is invisible.

Kirchhoff: in an enclosure at equilibrium whose surfaces absorb nothing, the radiance
inside a medium of index n is n^2 L wherever the sky outside is L, and the light leaving
towards the camera is L again: a white (albedo 1) Lambertian sphere inside a clear glass
cube, under a world of constant radiance L, renders as L everywhere. That holds only if
the eye path divides the radiance by n^2 when it enters the glass (and multiplies when it
leaves), while photons, which carry flux, do not: without the factor the sphere rendered
n^2 = 2.25 times too bright. Smooth glass around Lambert, smooth glass around a white
plastic and frosted glass around Lambert (the eye path follows frosted glass by sampling).
"""
import math

import numpy as np
import pytest

from conftest import look_at, sphere
from scene_builders import inward_box


def equilibrium_scene(g, glass, inner):
    box_p, box_t = inward_box(1.0)
    box_t = box_t[:, ::-1].copy()  # facing outwards
    ball_p, ball_t, _ = sphere((0.0, 0.0, 0.0), 0.5, 24, 48)
    positions = np.concatenate([box_p, ball_p]).astype(np.float32)
    indices = np.concatenate([box_t, ball_t + len(box_p)]).astype(np.uint32)
    ids = np.array([0] * len(box_t) + [1] * len(ball_t), dtype=np.uint32)
    camera = g.Camera(look_at((0.6, 0.8, 4.0), (0.0, 0.0, 0.0)), fov_x=math.radians(40))
    return g.Scene(positions, indices, material_ids=ids, materials=[glass, inner],
                   camera=camera, environment=(1.0, 1.0, 1.0))


CASES = {
    "smooth glass, Lambert": (dict(kind="dielectric"), dict(kind="diffuse"), False),
    "smooth glass, plastic": (dict(kind="dielectric"), dict(kind="plastic", roughness=0.5), True),
    "frosted glass, Lambert": (dict(kind="dielectric", roughness=0.3), dict(kind="diffuse"), True),
}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("direct", ["sampled", "photons"])
def test_white_object_in_clear_glass_is_invisible(glslppm, case, direct):
    g = glslppm
    glass_args, inner_args, _ = CASES[case]
    glass = g.Material(color=(1.0,) * 3, ior=1.5, **glass_args)
    inner = g.Material(color=(1.0,) * 3, **inner_args)
    size, passes = 32, 160
    r = g.Renderer(equilibrium_scene(g, glass, inner),
                   g.Settings(width=size, height=size, photons_per_pass=16384, max_bounces=256,
                              seed=2, direct_light=direct))
    r.run(passes)
    image = r.film()[..., :3].mean(axis=2)
    assert np.isfinite(image).all()
    # The cube covers the middle of the frame, the sphere its centre.
    centre = image[10:22, 10:22].mean()
    blocks = image.reshape(4, 8, 4, 8).mean(axis=(1, 3))
    print(f"  {case}, {direct}: centre {centre:.4f}, blocks {np.round(blocks, 3).tolist()}")
    # Photons trapped between the glass and the white sphere take many passes to leave:
    # path regeneration's start-up deficit here is about 3% after 160 passes (5% after 40),
    # so the bound is one-sided: 0.95..1.01. The missing n^2 would read 2.25.
    assert 0.95 < centre < 1.01, centre
    assert np.all((blocks > 0.93) & (blocks < 1.03)), blocks
