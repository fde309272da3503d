"""Light samples at the glossy vertices the eye path follows (common/glossy_light_samples.glsl).

A lobe of roughness below the glossy threshold is not a visible point: the eye path goes on
by sampling it. Its direct light was then found only by that continuation: a small lamp by
chance (fireflies), a sun or a point light of radius 0 never (no highlight at all). Now the
vertex takes a light sample, weighted against the continuation by the balance heuristic.

The reference is the same surface held as a visible point (glossy threshold 0), whose direct
light is the tested light sample + BSDF sample of common/light_sampling.glsl. In these scenes
nothing else is lit (one plane, a black world or a uniform one that no photon stored before
a scatter carries), so the two renders estimate the same image by different techniques.
"""
import numpy as np
import pytest

from conftest import look_at, quad

SIZE = 32


def metal_plane(g, material, light):
    """A 4 x 4 plane of `material` seen from 45 degrees, the light above its middle at the
    mirror direction's height, so that the highlight is in view."""
    p, t = quad((-2.0, 0.0, -2.0), (-2.0, 0.0, 2.0), (2.0, 0.0, 2.0), (2.0, 0.0, -2.0))
    camera = g.Camera(look_at((0.0, 2.0, 2.0), (0.0, 0.0, 0.0)), fov_x=1.2)
    lights, environment = [], (0.0, 0.0, 0.0)
    if light == "point":
        lights = [g.Light("point", power=30.0, position=(0.0, 1.5, -1.5), radius=0.0)]
    elif light == "sphere":
        lights = [g.Light("point", power=30.0, position=(0.0, 1.5, -1.5), radius=0.4)]
    elif light == "sun":
        lights = [g.Light("sun", power=3.0, direction=(0.0, -1.0, 1.0), angle=0.05)]
    elif light == "world":
        environment = (0.5, 0.5, 0.5)
    parts = [(p, t)]
    ids = [np.zeros(len(t), dtype=np.uint32)]
    materials = [material]
    if light == "quad":
        # A small emissive square facing the plane.
        e_p, e_t = quad((-0.4, 1.5, -1.9), (0.4, 1.5, -1.9), (0.4, 1.5, -1.1),
                        (-0.4, 1.5, -1.1))
        parts.append((e_p, e_t + len(p)))
        ids.append(np.ones(len(e_t), dtype=np.uint32))
        materials.append(g.Material("diffuse", color=(0.0, 0.0, 0.0), emission=(8.0,) * 3))
    positions = np.concatenate([x for x, _ in parts]).astype(np.float32)
    triangles = np.concatenate([y for _, y in parts]).astype(np.uint32)
    return g.Scene(positions, triangles, material_ids=np.concatenate(ids), materials=materials,
                   camera=camera, lights=lights, environment=environment)


def render(g, scene, passes, **settings):
    r = g.Renderer(scene, g.Settings(width=SIZE, height=SIZE, photons_per_pass=4096,
                                     **settings))
    r.run(passes)
    image = r.film()[..., :3].astype(np.float64)
    variant = r.stats()["variant"]
    r.close()
    assert np.isfinite(image).all()
    return image, variant


# Both renders draw the pixel's numbers in the same order up to the lobe choice (seed for
# seed: common random numbers), so their difference is mostly the followed side's own noise:
# the pixel's jitter over a highlight a few pixels wide, and a plastic's choice between coat
# (probability p at wo) and base, each weighed by its inverse. Over a bright base p is about
# 0.05; a dark base makes it about one half.
SEEDS = range(1, 7)


# The bound on 4 standard errors: 1% where the two techniques' noise allows it at this cost
# (a point light's and a sun's highlight, the world), 2.5% where a light's size puts the
# continuation's hits and the held point's BSDF samples in the estimate (their difference's
# standard error measured 0.44-0.52% at 6 seeds of 32 passes; 1% would take about 25 seeds).
@pytest.mark.parametrize("kind,light,bound", [("conductor", "point", 0.01),
                                              ("conductor", "sun", 0.01),
                                              ("conductor", "world", 0.01),
                                              ("plastic", "world", 0.01),
                                              ("conductor", "sphere", 0.025),
                                              ("conductor", "quad", 0.025),
                                              ("plastic", "point", 0.025),
                                              ("plastic", "quad", 0.025)])
def test_a_followed_glossy_lobe_sees_the_light_a_visible_point_sees(glslppm, kind, light, bound):
    """The followed lobe (threshold 0.5, roughness 0.45) against the same lobe held as a
    visible point (threshold 0), over six seeds: the mean of the image means' relative
    difference within 4 standard errors of it, and those below `bound`. Before the light
    sample, the point light's and the sun's highlight read 0 (-100%)."""
    g = glslppm
    color = (0.9, 0.6, 0.4) if kind == "conductor" else (0.03, 0.025, 0.02)
    material = g.Material(kind, color=color, roughness=0.45)
    scene = metal_plane(g, material, light)
    differences, held_means = [], []
    for seed in SEEDS:
        followed, variant = render(g, scene, 32, seed=seed)
        assert "glossy-light-samples" in variant.split(",")
        held, _ = render(g, scene, 32, seed=seed, glossy_threshold=0.0)
        differences.append(followed.mean() - held.mean())
        held_means.append(held.mean())
    scale = np.mean(held_means)
    bias = np.mean(differences) / scale
    error = np.std(differences, ddof=1) / np.sqrt(len(differences)) / scale
    print(f"  {kind} under {light}: followed - held = {bias:+.4f} (standard error {error:.4f},"
          f" held mean {scale:.4f})")
    assert scale > 0.003
    assert 4.0 * error < bound
    assert abs(bias) < 4.0 * error + 1e-4
