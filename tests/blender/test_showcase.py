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


CYCLES_SAMPLES = 512
# Both images are clamped here before comparing: the lamp's own image seen in the glass,
# the tea and the gold is a sub-pixel highlight of up to 70 (and Cycles' caustics are
# fireflies of that size), which ~100 samples per pixel resolve only as noise of +-15 in a
# pixel, several percent of a region.
CLAMP = 2.0


def test_showcase_matches_cycles():
    """The image mean within 3% of Cycles', every region of a 4x4 grid within 25% of its
    Cycles level, nothing infinite. These bounds catch a broken demo (a missing object or
    material, a black or blown-out image), not a 1% bias: tests/python's closed forms do.
    Why they are wide: the demo's lamp of 2 cm radius is 30 cm here, and still the ring's
    cardioid, the tumbler's and the blue ball's caustics reach Cycles only through paths
    that happen to hit the lamp, as fireflies (its caustic regions are 5-19% under
    GLSLPPM's at 512 samples). Measured (clamped at 2): mean ratio 1.0144 under 3.4.1,
    1.0153 under 4.3.2 and 1.0152 under 5.2.2; worst region 19%, 21%, 21% (the ring's
    cardioid)."""
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
    worst = float(np.abs(a / b - 1.0).max())
    print(f"  showcase: image mean GLSLPPM {a.mean():.4f} Cycles {b.mean():.4f} (ratio "
          f"{ratio:.4f}); worst region {worst:.4f}")
    assert b.mean() > 0.05
    assert abs(ratio - 1.0) < 0.03, (a.round(4).tolist(), b.round(4).tolist())
    assert worst < 0.25, (a.round(4).tolist(), b.round(4).tolist())
