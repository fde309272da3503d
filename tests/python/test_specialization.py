"""Programs model only what a scene requires, render what the full variant renders, and are
not compiled again for the next renderer of the same kind of scene."""
import numpy as np


def cornell(g, **settings):
    scene = g.cornell_box(mirror_sphere=False, glass_sphere=False)
    return g.Renderer(scene, g.Settings(width=32, height=32, photons_per_pass=16384, seed=11,
                                        **settings))


def test_plain_scene_variant_leaves_out_what_it_does_not_use(glslppm):
    r = cornell(glslppm)
    variant = r.stats()["variant"].split(",")
    for feature in ("textures", "environment-map", "spot-lights", "sun-lights",
                    "depth-of-field", "rough-lobes", "light-tracing"):
        assert feature not in variant, variant


def test_the_full_variant_compiles_every_row_of_the_table(glslppm):
    """The one table of specializations (native/render/specializations.h), read through the
    module: the full variant compiles every row it takes, and every row it does not take says
    why in its measured-gain field."""
    rows = glslppm.specializations()
    assert len(rows) >= 20, rows
    assert len({row["define"] for row in rows}) == len(rows)
    full = cornell(glslppm, full_variant=True).stats()["variant"].split(",")
    for row in rows:
        assert row["needs"] and row["gain"], row
        if row["in_full_variant"]:
            assert row["name"] in full, (row, full)
        else:
            assert "not in the full variant" in row["gain"], row
            assert row["name"] not in full, (row, full)


def test_specialized_and_full_variants_render_the_same_image(glslppm):
    """Same seed, same random numbers: the features the full variant adds are never taken
    for this scene, so the images agree to float rounding (far inside the noise). Both
    variants compile emitter-mis here (light sampling and an emissive quad): the row's
    predicate and the shader's condition (Lambertian and glossy points take its BSDF sample,
    issue 30) agree. Its BSDF sample is a cosine-sampled direction in the point's shading
    frame, which the full variant's normal code may round differently (orthonormal_basis
    branches on the sign of n.z, 0 on the walls; not bisected further), so with it the pixels
    are other draws of the same estimate: compared without it (direct_light="sampled-no-mis",
    to float rounding) and with it in the mean."""
    films = {}
    for direct in ("sampled-no-mis", "sampled"):
        for full in (False, True):
            r = cornell(glslppm, full_variant=full, direct_light=direct)
            assert ("emitter-mis" in r.stats()["variant"].split(",")) == (direct == "sampled")
            r.run(6)
            films[direct, full] = r.film()
            r.close()
    fa, fb = films["sampled-no-mis", False], films["sampled-no-mis", True]
    assert np.isfinite(fa).all() and fa.mean() > 0.01
    assert np.abs(fa - fb).max() <= 1e-4 * fa.max()
    # Measured: the means 0.40596 and 0.40658 (+0.15%), 114 of 1024 pixels differing by more
    # than 1e-3, none by more than 0.14. A 1% bias of either fails 0.5%.
    ma, mb = (films["sampled", f][..., :3].mean() for f in (False, True))
    assert abs(mb / ma - 1.0) < 0.005, (ma, mb)


def test_full_variant_renders_a_constant_world_as_the_specialized_one(glslppm):
    """A grey plane under a constant white world (no environment map): radiance 0.5 in
    both variants (it rendered black in the full one while it compiled the map's code)."""
    g = glslppm
    from conftest import look_at
    plane = np.array([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], np.float32)
    triangles = np.array([[0, 2, 1], [0, 3, 2]], np.uint32)
    camera = g.Camera(to_world=look_at((0, 2, 0.01), (0, 0, 0)))
    means = []
    for full in (False, True):
        scene = g.Scene(plane, triangles, materials=[g.Material("diffuse", color=(0.5,) * 3)],
                        camera=camera, environment=(1.0, 1.0, 1.0))
        r = g.Renderer(scene, g.Settings(width=16, height=16, photons_per_pass=4096, seed=2,
                                         full_variant=full))
        r.run(8)
        means.append(float(r.film()[..., :3].mean()))
        r.close()
    # A constant world sampled by the cosine on a Lambert plane has no noise: 0.5 to float
    # rounding (measured 0.5 in both); the plane sees no other surface, so photons add
    # nothing. Bound 0.1%: a 1% bias, or black, fails it.
    assert abs(means[0] - 0.5) < 5e-4 and abs(means[1] - 0.5) < 5e-4, means


def test_second_renderer_of_a_variant_reuses_the_compiled_programs(glslppm):
    """A new renderer has a new GL context; programs of a variant built before in this
    process are loaded from the driver's binaries instead of being compiled."""
    first = cornell(glslppm, alpha=0.71).stats()   # a variant no other test has built here
    second = cornell(glslppm, alpha=0.71).stats()
    assert first["programs_compiled"] + first["programs_reused"] == \
        second["programs_compiled"] + second["programs_reused"]
    assert second["programs_compiled"] == 0, second
    assert second["programs_reused"] >= 7
