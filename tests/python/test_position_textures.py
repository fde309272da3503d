"""Textures looked up at the surface's world position (Texture(position_map=...)): Blender's
Generated and Object coordinates, the object's inverse transform and texture space folded
into the map by the add-on (addon/export/texture_mapping.py).

Each test renders a scene whose texture is looked up through a position map that equals a
known uv map on the surface, with the mesh's uvs all zero, so only the position can place
the image: against Cycles' lookup (Denoising Albedo, exact per pixel), and against the same
scene looked up through its uvs (eye path, gather, photons, textured emitters)."""
import math

import numpy as np

from test_textures import SIZE, SMOOTH, cycles_linear, mapping_point

Z = 0.5  # the quad's height: the position map's z column must be read


def position_map_of(uv_map, z_weight=(0.7, -0.3)):
    """The position map of the quad x, y in [-1, 1] at z = Z (mesh uv ((x + 1) / 2,
    (y + 1) / 2)) that looks up uv_map there, with z weights compensated in the offsets."""
    rows = []
    for (a, b, c), w in zip(uv_map, z_weight):
        rows.append((0.5 * a, 0.5 * b, w, 0.5 * a + 0.5 * b + c - w * Z))
    return tuple(rows)


def quad(g, texture, camera, material, zero_uvs=True):
    p = np.array([(-1, -1, Z), (1, -1, Z), (1, 1, Z), (-1, 1, Z)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=np.float32)
    return g.Scene(p, t, uvs=np.zeros_like(uv) if zero_uvs else uv, camera=camera,
                   materials=[material], environment=(1.0, 1.0, 1.0), textures=[texture])


def test_position_map_matches_cycles_lookup(glslppm):
    """The Mapping of test_textures (scale 1.7 x 2.3, 30 degrees, moved) through the
    position: Denoising Albedo per pixel against Cycles' lookup averaged over each pixel
    (the bounds of test_uv_map_and_extension_match_cycles_lookup: rms 3e-3, mean 5e-4)."""
    g = glslppm
    uv_map = mapping_point((1.7, 2.3), math.radians(30.0), (-0.4, -0.6))
    pixels = np.ones(SMOOTH.shape + (4,), dtype=np.float32)
    pixels[..., :3] = SMOOTH[..., None]
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 2.0
    camera = g.Camera(to_world, projection="orthographic", ortho_scale=2.0)
    texture = g.Texture(pixels, wrap="repeat", position_map=position_map_of(uv_map))
    r = g.Renderer(quad(g, texture, camera, g.Material("diffuse", color=(1, 1, 1),
                                                       color_texture=0)),
                   g.Settings(width=SIZE, height=SIZE, photons_per_pass=1024, seed=4,
                              passes=["denoising_albedo"]))
    r.run(128)
    assert "position-textures" in r.stats()["variant"].split(",")
    got = r.render_pass("denoising_albedo")[..., 0]
    sub = (np.arange(8) + 0.5) / 8
    u = ((np.arange(SIZE)[:, None] + sub[None, :]) / SIZE).ravel()
    v = 1.0 - ((np.arange(SIZE)[:, None] + sub[None, :]) / SIZE).ravel()
    uu, vv = np.meshgrid(u, v)
    (a, b, c), (d, e, f) = uv_map
    want = cycles_linear(SMOOTH, a * uu + b * vv + c, d * uu + e * vv + f, "repeat")
    want = want.reshape(SIZE, 8, SIZE, 8).mean(axis=(1, 3))
    rms = float(np.sqrt(np.mean((got - want) ** 2)))
    mean = float(np.mean(got - want))
    print(f"  position map: rms {rms:.5f} mean {mean:+.6f}")
    assert rms < 3e-3 and abs(mean) < 5e-4, (rms, mean)


def _render_pair(g, make_scene, settings, passes):
    films = []
    for by_position in (True, False):
        r = g.Renderer(make_scene(by_position), settings)
        r.run(passes)
        variant = r.stats()["variant"].split(",")
        assert ("position-textures" in variant) == by_position
        assert "emission-texture" in variant, variant
        films.append(r.film()[..., :3])
    return films


def test_position_map_in_every_stage_matches_the_uv_map(glslppm):
    """A floor (diffuse, a texture through the position) lit by a textured emitter (its
    emission texture through the position too), with a rough metal strip, so
    the gather weighs photons by f(wo, wi) at the visible point (HAS_MICROFACET): the same
    seed through uvs gives the same paths, so the two films differ only by rounding in the
    lookup. Measured: mean |difference| below 1e-4 of the mean."""
    g = glslppm
    uv_map = mapping_point((3.0, 2.0), math.radians(20.0), (0.1, 0.2))
    image = np.random.default_rng(3).uniform(0.2, 1.0, size=(6, 6, 4)).astype(np.float32)
    emitter_map = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))

    def make_scene(by_position):
        # Floor quad at z = Z, emitter quad above it facing down, a glossy strip.
        p = np.array([(-1, -1, Z), (1, -1, Z), (1, 1, Z), (-1, 1, Z),
                      (-0.3, -0.3, 1.5), (0.3, -0.3, 1.5), (0.3, 0.3, 1.5), (-0.3, 0.3, 1.5),
                      (0.6, -1, Z + 0.01), (1, -1, Z + 0.01), (1, 1, Z + 0.01),
                      (0.6, 1, Z + 0.01)], np.float32)
        t = np.array([[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6], [8, 9, 10], [8, 10, 11]],
                     np.uint32)
        uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)] * 3, np.float32)
        if by_position:
            floor = g.Texture(image, position_map=position_map_of(uv_map))
            # The emitter's uv over its own square: ((x + 0.3) / 0.6, (y + 0.3) / 0.6).
            light = g.Texture(image, wrap="extend", position_map=(
                (1 / 0.6, 0.0, 0.0, 0.5), (0.0, 1 / 0.6, 0.0, 0.5)))
            uv = np.zeros_like(uv)
        else:
            floor = g.Texture(image, uv_map=uv_map)
            light = g.Texture(image, wrap="extend", uv_map=emitter_map)
        materials = [g.Material("diffuse", color=(0.8, 0.8, 0.8), color_texture=0),
                     g.Material("diffuse", color=(0, 0, 0), emission=(6, 6, 6),
                                emission_texture=1),
                     g.Material("conductor", color=(0.9, 0.9, 0.9), roughness=0.3)]
        to_world = np.eye(4, dtype=np.float32)
        to_world[2, 3] = 1.2
        camera = g.Camera(to_world, projection="orthographic", ortho_scale=2.0)
        return g.Scene(p, t, uvs=uv, material_ids=np.array([0, 0, 1, 1, 2, 2], np.uint32),
                       materials=materials, camera=camera, textures=[floor, light])

    settings = g.Settings(width=24, height=24, photons_per_pass=4096, seed=9)
    by_position, by_uv = _render_pair(g, make_scene, settings, 16)
    difference = float(np.abs(by_position - by_uv).mean() / by_uv.mean())
    print(f"  mean |position - uv| / mean: {difference:.2e} (mean {by_uv.mean():.4f})")
    assert by_uv.mean() > 0.05
    assert difference < 1e-3, difference
