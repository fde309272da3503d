"""Alpha cut-outs: a Mix of a Transparent leaf and an opaque one, factor alpha, lets light
through with probability 1 - alpha, in each of the three places light crosses it: camera
rays, photons (the transparent lobe) and light sampling's shadow rays (common/mtbvh.glsl's
any-hit filter resolving the mix at the crossing).
"""
import math

import numpy as np
import pytest

from conftest import look_at, quad


def cutout_scene(g, alpha):
    """A point light 1 above a grey floor; a black square cut-out of the given alpha halfway
    between them (hidden from the camera, so that the camera sees the floor through it),
    shadowing [-0.4, 0.4]^2 of the floor."""
    floor_p, floor_t = quad((-30, 0, -30), (-30, 0, 30), (30, 0, 30), (30, 0, -30))
    s = 0.2
    occ_p, occ_t = quad((-s, 0.5, -s), (-s, 0.5, s), (s, 0.5, s), (s, 0.5, -s))
    positions = np.concatenate([floor_p, occ_p]).astype(np.float32)
    indices = np.concatenate([floor_t, occ_t + len(floor_p)]).astype(np.uint32)
    ids = np.array([0] * len(floor_t) + [1] * len(occ_t), dtype=np.uint32)
    materials = [
        g.Material("diffuse", color=(0.5,) * 3),
        g.Material("mix", mix_a=2, mix_b=3, mix_factor=alpha, visible_to_camera=False),
        g.Material("transparent", color=(1.0,) * 3),
        g.Material("diffuse", color=(0.0,) * 3),
    ]
    light = g.Light("point", power=200.0, position=(0.0, 1.0, 0.0))
    camera = g.Camera(look_at((0.0, 4.0, 0.0), (0.0, 0.0, 0.0), up=(0, 0, -1)),
                      fov_x=math.radians(30))
    return g.Scene(positions, indices, material_ids=ids, materials=materials, lights=[light],
                   camera=camera)


@pytest.mark.parametrize("direct,passes", [("sampled", 64), ("photons", 96)])
def test_cutout_passes_one_minus_alpha_of_the_light(glslppm, direct, passes):
    g = glslppm
    size = 64
    images = {}
    for alpha in (0.0, 0.3):
        r = g.Renderer(cutout_scene(g, alpha),
                       g.Settings(width=size, height=size, photons_per_pass=65536, seed=7,
                                  direct_light=direct))
        r.run(passes)
        image = r.film()[..., :3]
        assert np.isfinite(image).all()
        images[alpha] = image.mean(axis=2)
    # The shadow's core, |x|, |z| < 0.3 on the floor: the camera 4 above with a 30 degree
    # field sees +-1.07, so the core is the central 18 x 18 pixels.
    half = 4.0 * math.tan(math.radians(15))
    core = int(round(0.3 / half * size / 2))
    c = slice(size // 2 - core, size // 2 + core)
    ratio = images[0.3][c, c].mean() / images[0.0][c, c].mean()
    print(f"  {direct}: core ratio {ratio:.4f} (expected 0.7)")
    # Sampled: each pass is one Bernoulli(0.7) crossing per pixel, sigma of the core mean
    # 0.4%; photons add their own noise (about 0.6%): bounds 1.5% and 2%.
    bound = 0.015 if direct == "sampled" else 0.02
    assert abs(ratio - 0.7) < bound * 0.7, ratio
    # Outside the shadow the cut-out changes nothing: the corners agree within 1%.
    corner = slice(0, 12)
    assert abs(images[0.3][corner, corner].mean() / images[0.0][corner, corner].mean() - 1) < 0.01
