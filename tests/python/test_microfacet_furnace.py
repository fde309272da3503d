"""Energy of the microfacet lobes (shaders/common/lobes.glsl) through the whole renderer.

Inside a closed sphere whose surface is a 50/50 Mix of a lossless lobe and black Lambert,
every surface reflects exactly half of what reaches it, whatever the directions, so the
radiance is Le / (1 - 0.5) = 2 Le everywhere (Le emitted by both leaves). That holds only if
the lobe's albedo is 1 at every angle: the energy-compensated white GGX conductor (Kulla and
Conty's multiple-scattering lobe) and the white plastic (a dielectric GGX layer over a white
base scaled by what the layer lets through). Roughness 0.1 is below the glossy threshold
(the eye path follows the lobe by sampling); 0.3 to 1 hold visible points that gather
photons weighted by f(wo, wi) (the tests set glossy_threshold 0.2), so both halves of the
SPPM extension are measured. There the walls' direct light is a light sample and a BSDF
sample of the emissive walls combined by MIS (direct_light="sampled", emitter-mis), the
rest photons that scattered at least once: light counted twice or missed between the two
would show here.
"""
import numpy as np
import pytest

from closed_forms import furnace_scene


def furnace(g, leaf, passes, leaf_roughness=1.0, **settings):
    emission = (1.0,) * 3
    materials = [g.Material("mix", emission=emission, mix_a=1, mix_b=2, mix_factor=0.5),
                 g.Material("diffuse", color=(0.0,) * 3, emission=emission), leaf]
    r = g.Renderer(furnace_scene(g, 0.5, 1.0, materials=materials),
                   g.Settings(width=24, height=24, photons_per_pass=8192, max_bounces=1024,
                              seed=3, glossy_threshold=0.2, **settings))
    r.run(passes)
    image = r.film()[..., :3]
    assert np.isfinite(image).all()
    variant = r.stats()["variant"].split(",")
    # MIS is compiled wherever light sampling meets emissive triangles (Lambertian points
    # take its BSDF sample too since issue 30), whatever the lobe's roughness.
    assert "emitter-mis" in variant, variant
    return image


# (kind, roughness, passes, hash): measured error after the start-up bias, seed 3 (before
# the warm-up of issue 30, which removed that bias: see the test's print for today's).
CASES = [
    ("conductor", 0.1, 100, "stochastic"),  # +0.14% (eye path only: no start-up bias)
    ("conductor", 0.3, 400, "exact"),       # +0.60% (-0.35% with other tables; the narrow
                                            # lobe's estimate is noisy: bound 1%, below)
    ("conductor", 0.5, 100, "stochastic"),  # +0.14%
    ("conductor", 1.0, 100, "stochastic"),  # +0.11%
    ("plastic", 0.1, 100, "stochastic"),    # smooth layer followed, base gathered: -0.25%
    ("plastic", 0.5, 100, "stochastic"),    # +0.11%
    ("plastic", 1.0, 100, "stochastic"),    # +0.14%
]


@pytest.mark.parametrize("kind,roughness,passes,hash_mode", CASES)
def test_lossless_lobe_in_closed_furnace(glslppm, kind, roughness, passes, hash_mode):
    g = glslppm
    leaf = g.Material(kind, color=(1.0,) * 3, emission=(1.0,) * 3, roughness=roughness)
    image = furnace(g, leaf, passes, roughness, hash=hash_mode)
    # No start-up bias: SPPM's warm-up (pass_stages.cpp) starts the photon paths in their
    # stationary state (test_sppm.py); before it, the gathered cases read 0.50% low here.
    expected = 2.0
    error = image.mean() / expected - 1.0
    print(f"  {kind} roughness {roughness}: mean {image.mean():.4f}, error {error:+.4f}")
    # A lobe that lost 1% of its energy per bounce would be 2% low here (the loss compounds
    # over the bounces at albedo 0.5), so 0.6% catches it. The narrow lobe of roughness 0.3
    # gathers few photons with a large f each: over seeds its error spreads from -0.58% to
    # -0.03% even at 200 passes of 32768 photons (40 s here), so its bound is 1% (a 1% loss
    # per bounce, 2% here, still fails it).
    bound = 0.01 if roughness == 0.3 else 0.006
    assert abs(error) < bound, error


def test_single_scatter_ggx_loses_what_its_albedo_says(glslppm):
    """Without compensation ("GGX" rather than "Multiscatter GGX") a white conductor of
    roughness 1 keeps only its single-scattering albedo: 0.307 at normal incidence, 0.35 at
    cos 0.8, 0.45 at 0.5, 0.76 at 0.1 (numerical integration of D G2 / (4 cos_o), 2M
    samples each). From the sphere's centre every first hit is at normal incidence and later
    ones are mostly steep, so the furnace's effective albedo 2 (1 - 1 / L) must lie between
    the first two (measured 0.325); with compensation it is 1 (above)."""
    g = glslppm
    leaf = g.Material("conductor", color=(1.0,) * 3, emission=(1.0,) * 3, roughness=1.0,
                      multiscatter=False)
    mean = furnace(g, leaf, 60).mean()
    albedo = 2.0 * (1.0 - 1.0 / mean)
    print(f"  single-scatter furnace mean {mean:.4f}, effective albedo {albedo:.4f}")
    assert 0.30 < albedo < 0.36, albedo


def test_f82_tint_is_compiled_only_where_a_metal_has_one(glslppm):
    """Blender 4.x's F82 tint (HAS_F82_TINT) is in the programs only when a conductor's tint
    is not white. A tint of (1, 0.5, 0.2) darkens the grazing green and blue (F at 82 degrees
    is Schlick's times the tint, lobes.glsl) and leaves red exactly: same seed, so the two
    renders trace the same paths and only the weights differ (measured green -1.26%, blue
    -0.72%, red 0 in the half-absorbing furnace)."""
    g = glslppm

    def render(tint):
        leaf = g.Material("conductor", color=(0.9, 0.8, 0.5), emission=(1.0,) * 3,
                          roughness=0.5, schlick=True, f82_tint=tint)
        materials = [g.Material("mix", emission=(1.0,) * 3, mix_a=1, mix_b=2, mix_factor=0.5),
                     g.Material("diffuse", color=(0.0,) * 3, emission=(1.0,) * 3), leaf]
        r = g.Renderer(furnace_scene(g, 0.5, 1.0, materials=materials),
                       g.Settings(width=24, height=24, photons_per_pass=8192, max_bounces=64,
                                  seed=3, glossy_threshold=0.2))
        r.run(64)
        return r.film()[..., :3].reshape(-1, 3).mean(axis=0), r.stats()["variant"].split(",")

    plain, plain_variant = render((1.0, 1.0, 1.0))
    tinted, tinted_variant = render((1.0, 0.5, 0.2))
    assert "f82-tint" not in plain_variant and "f82-tint" in tinted_variant
    ratio = tinted / plain
    print(f"  tinted / plain per channel: {ratio}")
    assert abs(ratio[0] - 1.0) < 1e-6, ratio
    assert ratio[1] < 0.995 and ratio[2] < 0.995, ratio
