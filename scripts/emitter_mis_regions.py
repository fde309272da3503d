#!/usr/bin/env python3
"""RMSE of direct_light=sampled (light samples and BSDF samples of emissive triangles combined
by MIS at glossy visible points) and sampled-no-mis (light samples alone, as before MIS) on
the glossy Cornell box, against the converge benchmark's reference, over the whole image and
outside the four 8x8 blocks showing the light (whose edge pixels carry the camera jitter's
noise in both modes alike), at equal passes, with each mode's cost per pass and the ratio at
equal time (error falling as 1 / sqrt(time)). docs/direct_light.md has the numbers.

    nice build/glslppm-bench converge --scene cornell-glossy --size 48 --passes 256 \\
        --photons 16384 --reference-passes 512 --reference-photons 65536   # the reference
    PYTHONPATH=build python3 scripts/emitter_mis_regions.py [passes] [seeds] [thresholds]
"""
import math
import os
import sys

import numpy as np

import _glslppm as g

HERE = os.path.dirname(os.path.abspath(__file__))
REFERENCE = os.path.join(HERE, "..", "build", "references", "cornell_glossy_48x48.exr")
MODES = ("sampled", "sampled-no-mis")


def measure(direct, threshold, passes, seed, reference, keep):
    """(RMSE whole, RMSE outside the light, seconds per pass after the first)."""
    r = g.Renderer(g.cornell_box(glossy=True),
                   g.Settings(width=48, height=48, photons_per_pass=16384, seed=seed,
                              direct_light=direct, glossy_threshold=threshold))
    r.run(1)  # the first pass also compiles the programs
    start = r.stats()["seconds"]
    r.run(passes - 1)
    seconds = (r.stats()["seconds"] - start) / (passes - 1)
    d = (r.film()[..., :3] - reference) ** 2
    r.close()
    return math.sqrt(d.mean()), math.sqrt(d[keep].mean()), seconds


def main(passes=256, seeds=2, thresholds="0.2,0.5"):
    reference = np.asarray(g.read_exr(REFERENCE)[0])[..., :3]
    blocks = np.ones((6, 6), bool)
    blocks[0:2, 2:4] = False
    keep = np.repeat(np.repeat(blocks, 8, 0), 8, 1)
    for threshold in (float(t) for t in str(thresholds).split(",")):
        rows = {}
        for direct in MODES:
            runs = np.array([measure(direct, threshold, passes, seed, reference, keep)
                             for seed in range(1, seeds + 1)])
            rows[direct] = runs.mean(axis=0)
            whole, part, cost = rows[direct]
            print(f"glossy threshold {threshold}: {direct:15s} {passes} passes: RMSE whole "
                  f"{whole:.4f}, outside the light {part:.4f}, {1000 * cost:.1f} ms/pass "
                  f"(mean of {seeds} seeds)")
        (w1, p1, c1), (w0, p0, c0) = rows[MODES[0]], rows[MODES[1]]
        time_factor = math.sqrt(c1 / c0)
        print(f"glossy threshold {threshold}: MIS / alone at equal passes: whole {w1 / w0:.3f}, "
              f"outside the light {p1 / p0:.3f}; at equal time: whole "
              f"{w1 / w0 * time_factor:.3f}, outside the light {p1 / p0 * time_factor:.3f}; "
              f"cost per pass x{c1 / c0:.3f}")


if __name__ == "__main__":
    main(*(int(a) if i < 2 else a for i, a in enumerate(sys.argv[1:])))
