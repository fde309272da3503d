#!/usr/bin/env python3
"""Issue 30's gap in small: a unit Cornell box (white walls of albedo 0.7, a red and a green
one) whose two-sided emissive quad (0.3 x 0.3, radiance 20) hangs 1 mm under the ceiling, the
ceiling in the gap lit by its back face: the spike a light sample by area misses and a
Lambertian point's BSDF sample finds. RMSE at equal passes against a long render at
emitter_mis_fraction q = 1, for q = 1 and q = 0.25, over the whole image and outside the
light's own pixels, and the image mean there against the reference's (one standard error
over the seeds). docs/direct_light.md has the numbers.

    PYTHONPATH=build python3 scripts/emitter_mis_fraction_gap_box.py \\
        [passes 256] [seeds 6] [reference passes 4096] [size 48]
"""
import math
import sys

import numpy as np

import _glslppm as g


def look_at(eye, target, up=(0.0, 0.0, 1.0)):
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    back = (eye - target) / np.linalg.norm(eye - target)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, np.cross(back, right), back, eye
    return m.astype(np.float32)


def gap_box(gap=0.001):
    points, triangles, ids = [], [], []

    def add(corners, material):
        base = len(points)
        points.extend(corners)
        triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]])
        ids.extend([material, material])

    materials = [g.Material("diffuse", color=(0.7, 0.7, 0.7)),
                 g.Material("diffuse", color=(0.7, 0.1, 0.1)),
                 g.Material("diffuse", color=(0.1, 0.7, 0.1)),
                 g.Material("diffuse", color=(0, 0, 0), emission=(20.0,) * 3,
                            emission_two_sided=True)]
    add([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], 0)  # floor
    add([(0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 0, 1)], 0)  # ceiling
    add([(0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)], 0)  # back wall
    add([(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)], 1)  # left, red
    add([(1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0)], 2)  # right, green
    h = 1.0 - gap
    add([(0.35, 0.35, h), (0.35, 0.65, h), (0.65, 0.65, h), (0.65, 0.35, h)], 3)  # the light
    camera = g.Camera(look_at((0.5, -1.2, 0.5), (0.5, 0.5, 0.5)), fov_x=math.radians(40))
    return g.Scene(np.array(points, np.float32), np.array(triangles, np.uint32),
                   material_ids=np.array(ids, np.uint32), materials=materials, camera=camera)


def render(scene, q, passes, seed, size):
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=4096, seed=seed,
                                     emitter_mis_fraction=q))
    r.run(passes)
    film = r.film()[..., :3].astype(np.float64)
    r.close()
    return film


def main():
    args = [int(a) for a in sys.argv[1:]] + [256, 6, 4096, 48][len(sys.argv) - 1:]
    passes, seeds, reference_passes, size = args
    scene = gap_box()
    reference = np.mean([render(scene, 1.0, reference_passes, 100 + s, size)
                         for s in range(2)], axis=0)
    light = reference.mean(axis=2) > 5.0  # the emitter's own pixels
    for q in (1.0, 0.25):
        whole, rest, means = [], [], []
        for seed in range(1, seeds + 1):
            error = render(scene, q, passes, seed, size) - reference
            whole.append(np.sqrt(np.mean(error ** 2)))
            rest.append(np.sqrt(np.mean(error[~light] ** 2)))
            means.append(1.0 + error[~light].mean() / reference[~light].mean())
        print(f"q = {q}: RMSE whole {np.mean(whole):.5f}, less the light {np.mean(rest):.5f}; "
              f"mean less the light / reference {np.mean(means):.5f} "
              f"+- {np.std(means, ddof=1) / math.sqrt(seeds):.5f}")


if __name__ == "__main__":
    main()
