#!/usr/bin/env python3
"""RMSE of both direct-light modes against the converge benchmark's references, over the
whole image and over the image less the regions where one estimate is known to be biased
or both share the same noise (docs/direct_light.md):

- cornell, cornell-diffuse: the four 8x8 blocks showing the light, whose edge pixels
  (radiance 17 against 0.5 around) carry the camera jitter's noise in both modes alike.
- caustic: the blocks whose error is dominated by the small light seen through the glass
  sphere (the same camera rays and Fresnel choices in both modes for one seed) and the
  focus of the caustic (photons in both modes).

    PYTHONPATH=build python3 scripts/direct_light_regions.py [passes] [seeds]
"""
import os
import sys

import numpy as np

import _glslppm as g

HERE = os.path.dirname(os.path.abspath(__file__))
REFERENCES = os.path.join(HERE, "..", "build", "references")


def scenes():
    cornell = np.ones((6, 6), bool)
    cornell[0:2, 2:4] = False
    caustic = np.ones((6, 6), bool)
    caustic[2, 1] = caustic[2, 2] = caustic[3, 3] = False
    return {
        "cornell": (lambda: g.cornell_box(sphere_rings=48), cornell),
        "cornell-diffuse": (lambda: g.cornell_box(mirror_sphere=False, glass_sphere=False),
                            cornell),
        "caustic": (lambda: g.caustic_scene(), caustic),
    }


def main(passes=256, seeds=2):
    for name, (make, keep) in scenes().items():
        path = os.path.join(REFERENCES, name.replace("-", "_") + "_48x48.exr")
        ref = np.asarray(g.read_exr(path)[0])[..., :3]
        mask = np.repeat(np.repeat(keep, 8, 0), 8, 1)
        for direct in ("sampled", "photons"):
            whole, part = [], []
            for seed in range(1, seeds + 1):
                r = g.Renderer(make(), g.Settings(width=48, height=48, photons_per_pass=16384,
                                                  seed=seed, direct_light=direct))
                r.run(passes)
                d = (r.film()[..., :3] - ref) ** 2
                whole.append(np.sqrt(d.mean()))
                part.append(np.sqrt(d[mask].mean()))
            print(f"{name:16s} {direct:8s} {passes} passes: RMSE whole "
                  f"{np.mean(whole):.4f}, outside the masked blocks {np.mean(part):.4f} "
                  f"(mean of {seeds} seeds)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:]))
