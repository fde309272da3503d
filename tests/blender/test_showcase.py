"""The showcase scene of `make demo` (demo/showcase.py) rendered tiny by both engines, so
that the demo cannot silently break: its glass, tea, gold, copper and frosted glass, its
point light and its world, against Cycles (caustics on, no clamping, 1-px box filter)."""
import os
import sys

import bpy
import numpy as np

import helpers


def _showcase():
    demo = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                        "demo"))
    if demo not in sys.path:
        sys.path.insert(0, demo)
    import showcase
    return showcase


CYCLES_SAMPLES = 4096
# Both images are clamped here before comparing: the lamp's own image seen in the glass,
# the tea and the gold is a sub-pixel highlight of up to 70 (and Cycles' caustics are
# fireflies of that size), which ~100 samples per pixel resolve only as noise of +-15 in a
# pixel, several percent of a region.
CLAMP = 2.0


# Regions (row, column) of the 4x4 grid that hold the caustics in the shadows: the tea's, the
# cube's and the ring's cardioid.
CAUSTIC_REGIONS = {(2, 1), (2, 2)}


@helpers.slow("Cycles at 4,096 samples and glslppm at 96 passes of the whole showcase; 54 s "
              "on a loaded 2-core machine")
def test_showcase_matches_cycles():
    """The image mean within 3% of Cycles', the regions without caustics within 6% each,
    the two caustic regions within 30%, nothing infinite. These bounds catch a broken demo
    (a missing object or material, a black or blown-out image), not a 1% bias: tests/python's
    closed forms do. Why the caustic bound is wide: the demo's lamp of 2 cm radius is 30 cm
    here, and still Cycles finds the caustics in the shadows only through paths that happen
    to hit the lamp: at 512 samples those regions were 23-24% under GLSLPPM's, at 4,096
    12-24% (still rising). Measured at 4,096 samples: image mean ratio 1.0242 (3.4.1),
    1.0183 (4.3.2), 1.0182 (5.2.2); worst region outside the caustics 4.1%, 3.6%, 3.5%; in
    them 23.6%, 20.3%, 20.2%. The means' 2% is not noise: part of it is the caustic
    regions' shortfall (1/8 of the image, ~20% low), the rest unexplained (issue 30's
    question); 3.x exports the gold, copper and tea as Principled v1."""
    helpers.reset_scene(size=(64, 64))
    showcase = _showcase()
    showcase.build_showcase(light_radius=0.3)
    helpers.load_native()
    scene = bpy.context.scene
    scene.glslppm.passes = 96
    scene.glslppm.photons_per_pass = 32768
    ours = helpers.render_image("showcase_glslppm", 'GLSLPPM')
    showcase.use_cycles(scene, CYCLES_SAMPLES)
    reference = helpers.render_image("showcase_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    assert np.isfinite(ours).all()
    ours, reference = (np.minimum(image[..., :3], CLAMP) for image in (ours, reference))
    a, b = (helpers.region_means(image, 4).mean(axis=2) for image in (ours, reference))
    ratio = a.mean() / b.mean()
    errors = np.abs(a / b - 1.0)
    caustic = np.array([[(r, c) in CAUSTIC_REGIONS for c in range(4)] for r in range(4)])
    print(f"  showcase: image mean GLSLPPM {a.mean():.4f} Cycles {b.mean():.4f} (ratio "
          f"{ratio:.4f}); worst region {errors[~caustic].max():.4f} outside the caustics, "
          f"{errors[caustic].max():.4f} in them")
    assert b.mean() > 0.05
    detail = ((a / b).round(3).tolist(), b.round(4).tolist())
    assert abs(ratio - 1.0) < 0.03, detail
    assert errors[~caustic].max() < 0.06, detail
    assert errors[caustic].max() < 0.30, detail
