"""A BSDF's own Fresnel-weighted layer (mix_mode "layer_fresnel": Principled's specular and
coat) reflects as seen from the front on both sides of a surface, as Cycles sets up those
closures (svm_closure.h: the specular's and the coat's index are never inverted on back faces;
only transmission's is). Blender's Fresnel node inverts it behind (mix_mode "fresnel"), and
so did these layers: seen from behind, an index of 1.5 reflected totally beyond 42 degrees.
Inside a closed mesh, whose walls are seen from behind, Principled v1's doubled specular
(Mix(0.5, Lambert 1.6, Mix(Fresnel, black, GGX of colour 2))) then had an albedo near 1.8:
emissive text in Blender 3.4 was 1.09x to 1.50x Cycles over seeds (1.11x at 2048 passes),
its excess in a few fireflies from the letters' insides.

- Closed form, seen directly: a quad emitting 1 through the layer's second part only, seen
  at a cosine of 0.5 by an orthographic camera, is F(0.5) = 0.0891 of index 1.5 on either
  side (one choice of the part a pass: over 256 passes and about 220 pixels the mean's standard
  deviation is 0.0012; bound 0.004). Measured before: 0.0892 from the front, 1.0000 from behind
  (now 0.0863 from either side; 0.0888 at 2048 passes in three seeds).
- Photons: a room seen from inside, a closed box of Principled v1 emitting 1, is the same
  whichever way its faces are wound (Cycles' Principled does not depend on the side; near
  1 / (1 - albedo) = 7 either way). Measured before: wound outward (the walls seen from
  behind) 1506 against 6.91 inward, 218x (seed 2: 231x); after: 6.925 against 6.913, 1.0017
  (seeds 2 and 3: 1.021, 0.998; bound 5%, about 4 standard deviations).
"""
import math

import numpy as np
import pytest

from closed_forms import fresnel_dielectric
from conftest import look_at
from test_photon_sides import box, principled_v1

IOR = 1.5


def tilted_quad(from_behind):
    """A 3 x 3 quad through the origin whose front normal makes 60 degrees with +z (the
    view), wound so that the camera above sees its front or its back."""
    n = np.array([math.sin(math.pi / 3), 0.0, math.cos(math.pi / 3)])
    u = np.array([0.0, 1.0, 0.0])
    v = np.cross(n, u)
    corners = [1.5 * (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    p = np.array(corners, np.float32)
    if np.dot(np.cross(p[1] - p[0], p[2] - p[1]), n) < 0:
        p = p[::-1].copy()
    if from_behind:
        p = p[::-1].copy()
    return p, np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


@pytest.mark.parametrize("from_behind", [False, True])
@pytest.mark.parametrize("mode", ["layer_fresnel", "fresnel"])
def test_layer_is_seen_with_the_front_fresnel_on_both_sides(glslppm, mode, from_behind):
    g = glslppm
    p, t = tilted_quad(from_behind)
    # The mix's own emission only sizes the photons it emits (none land anywhere).
    materials = [g.Material("mix", mix_a=1, mix_b=2, mix_mode=mode, mix_ior=IOR,
                            emission=(0.1, 0.1, 0.1)),
                 g.Material("diffuse", color=(0.0,) * 3),
                 g.Material("diffuse", color=(0.0,) * 3, emission=(1.0, 1.0, 1.0))]
    camera = g.Camera(look_at((0, 0, 5), (0, 0, 0)), projection="orthographic",
                      ortho_scale=4.0)
    scene = g.Scene(p, t, material_ids=np.zeros(len(t), np.uint32), materials=materials,
                    camera=camera)
    renderer = g.Renderer(scene, g.Settings(width=32, height=32, photons_per_pass=1024,
                                            seed=1))
    renderer.run(256)
    image = renderer.film()[..., :3].astype(np.float64).mean(axis=2)
    renderer.close()
    # Wholly on the quad: the pixel and its 8 neighbours hit it (a rendered mask: the
    # emission itself is 0 or 1 a pass).
    covered = _coverage(g, p, t, camera)
    inner = covered.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            inner &= np.roll(np.roll(covered, dy, axis=0), dx, axis=1)
    # Blender's Fresnel node (mode "fresnel") reflects totally from behind beyond 42 degrees.
    expected = 1.0 if (mode == "fresnel" and from_behind) else float(fresnel_dielectric(0.5, 1.0 / IOR)[0])
    mean = image[inner].mean()
    print(f"  {mode}, {'behind' if from_behind else 'front'}: {int(inner.sum())} pixels, "
          f"mean {mean:.4f} (expected {expected:.4f})")
    assert inner.sum() > 200, int(inner.sum())
    assert abs(mean - expected) < 4e-3, (mean, expected)


def _coverage(g, p, t, camera):
    """Pixels that see the quad: the same scene with the quad a plain emitter."""
    scene = g.Scene(p, t, material_ids=np.zeros(len(t), np.uint32),
                    materials=[g.Material("diffuse", color=(0.0,) * 3,
                                          emission=(1.0, 1.0, 1.0))],
                    camera=camera)
    renderer = g.Renderer(scene, g.Settings(width=32, height=32, photons_per_pass=1024,
                                            seed=1))
    renderer.run(4)
    image = renderer.film()[..., :3].mean(axis=2)
    renderer.close()
    return image > 0.999


def render_inside(g, outward, seed):
    """The mean of a 24 x 24 view from inside a closed 2 x 2 x 2 box of Principled v1
    emitting 1 (tests/python/test_photon_sides.py's material), its faces wound outward (as
    any closed mesh: the camera sees their backs) or inward."""
    p, t, n = box((-1, -1, -1), (1, 1, 1), smooth=False)
    if not outward:
        t, n = t[:, ::-1].copy(), -n
    camera = g.Camera(look_at((0.2, -0.5, 0.1), (0.6, 1.0, -0.3), (0, 0, 1)),
                      fov_x=math.radians(90))
    scene = g.Scene(p, t, normals=n, material_ids=np.zeros(len(t), np.uint32),
                    materials=principled_v1(g, (1.0, 1.0, 1.0)), camera=camera)
    renderer = g.Renderer(scene, g.Settings(width=24, height=24, photons_per_pass=16384,
                                            seed=seed))
    renderer.run(32)
    image = renderer.film()[..., :3].astype(np.float64).mean(axis=2)
    renderer.close()
    return image.mean()


def test_closed_principled_v1_room_is_the_same_from_either_side(glslppm):
    outward = render_inside(glslppm, True, 1)
    inward = render_inside(glslppm, False, 1)
    print(f"  inside a closed Principled v1 box: wound outward {outward:.4f}, "
          f"inward {inward:.4f} (ratio {outward / inward:.4f})")
    assert abs(outward / inward - 1.0) < 0.05, (outward, inward)
