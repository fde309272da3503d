"""Image tiles: a frame whose visible points exceed the GPU's largest storage buffer
(llvmpipe allows 128 MiB) renders as bands of rows one after another, each a whole SPPM
render with the whole frame's radius and random streams (native/render/tiled_render.h)."""
import json
import math
import os
import subprocess

import numpy as np
import pytest

from conftest import BUILD, quad

RENDER = os.path.join(BUILD, "glslppm-render")
SIZE = 48
ROWS = 16  # the cap below: 16 rows of visible points (4 vec4 per pixel)


def capped(g, hash="stochastic", rows=ROWS, **kwargs):
    return g.Settings(width=SIZE, height=SIZE, photons_per_pass=4096, hash=hash,
                      max_block_bytes=SIZE * rows * 4 * 16, **kwargs)


def test_plan_bands_rows_by_the_largest_buffer(glslppm):
    g = glslppm
    box = g.cornell_box(sphere_rings=8)
    plan = g.plan_tiles(box, capped(g))
    assert plan["tiles"] == [(0, 0, 48, 16), (0, 16, 48, 16), (0, 32, 48, 16)]
    # Visible points 4 vec4, pixel statistics 2, direct light 2, film 1, and light tracing's
    # splats (48 bytes: the box has a mirror and glass).
    assert plan["block_bytes_per_pixel"] == 64 and plan["gpu_bytes_per_pixel"] == 192
    # 17 rows fit twice in 48: three bands as equal as rows allow.
    plan = g.plan_tiles(box, capped(g, rows=17))
    assert [t[3] for t in plan["tiles"]] == [16, 16, 16]
    plan = g.plan_tiles(box, capped(g, rows=47))
    assert [t[1:] for t in plan["tiles"]] == [(0, 48, 24), (24, 48, 24)]
    assert len(g.plan_tiles(box, g.Settings(width=SIZE, height=SIZE))["tiles"]) == 1
    # Every material model has the same visible point (what the gather's f(wo, wi) reads,
    # and the point's colour with the eye subpath's bounce word: docs/bounces.md).
    p, t = quad((-1, -1, -3), (1, -1, -3), (1, 1, -3), (-1, 1, -3))
    plastic = g.Scene(p, t, materials=[g.Material("plastic", roughness=0.3)])
    plan = g.plan_tiles(plastic, capped(g))
    assert plan["block_bytes_per_pixel"] == 64 and plan["gpu_bytes_per_pixel"] == 144
    assert len(plan["tiles"]) == math.ceil(SIZE / ROWS)
    # Vertex colours read by a material fill the colour of its fourth vec4, as the renderer
    # allocates (its gpu_bytes_per_pixel).
    colors = np.ones((4, 3), np.float32)
    painted = g.Scene(p, t, colors=colors,
                      materials=[g.Material("plastic", roughness=0.3, vertex_color=True)],
                      environment=(1, 1, 1))
    plan = g.plan_tiles(painted, capped(g))
    assert plan["block_bytes_per_pixel"] == 64 and plan["gpu_bytes_per_pixel"] == 144
    r = g.Renderer(painted, g.Settings(width=8, height=8, photons_per_pass=64))
    assert r.stats()["gpu_bytes_per_pixel"] == 144


def untiled(g, scene, settings, passes):
    r = g.Renderer(scene, settings)
    r.run(passes)
    film, stats = r.film(), r.stats()
    r.close()
    return film, stats


@pytest.mark.parametrize("hash", ["exact", "stochastic"])
def test_tiled_render_equals_the_untiled_render(glslppm, hash):
    """Every band traces the same photons (streams after the whole frame's pixels) and its
    pixels the same eye paths (streams keyed by the frame's pixel index), gathering with the
    whole frame's radius. The photons a pixel gathers are then the same set; only the hash
    grid's cell size (each band's largest radius) can differ, which changes the order of
    the float sums (exact hash) and, for the stochastic hash, which photon a shared cell
    keeps. In this box every band holds a pixel that gathered no photon in 8 passes, so
    every band's largest radius stays the initial one (checked below) and the cells agree
    too: 2e-5 relative holds for both hashes (measured 4e-6). Where bands' largest radii
    differ, the stochastic hash's bound is the noise, not float rounding."""
    g = glslppm
    box = g.cornell_box(sphere_rings=16)
    settings = capped(g, hash)
    whole, stats = untiled(g, box, g.Settings(width=SIZE, height=SIZE, photons_per_pass=4096,
                                              hash=hash), 8)
    assert stats["tiles"] == 1 and stats["gpu_bytes_per_pixel"] == 192
    # Per photon of a pass: its path and its stored photon (48 bytes each), 2 hash cells of
    # 16 bytes (8192 for 4096 photons), and for the exact hash the sorted index of 4 bytes
    # plus the scan's 8 block sums.
    per_photon = 48 + 48 + 32 + ((4096 + 8) * 4 / 4096 if hash == "exact" else 0)
    assert stats["gpu_bytes_per_photon"] == pytest.approx(per_photon, rel=1e-12), stats
    seen = []
    tiled, tiled_stats = g.render_tiled(box, settings, 8,
                                        on_tile=lambda i, tile, rgba: seen.append((i, tile,
                                                                                   rgba.shape)))
    assert seen == [(0, (0, 0, 48, 16), (16, 48, 4)), (1, (0, 16, 48, 16), (16, 48, 4)),
                    (2, (0, 32, 48, 16), (16, 48, 4))]
    assert tiled_stats["tiles"] == 3 and tiled_stats["passes"] == 8
    assert tiled_stats["gpu_bytes_per_pixel"] == 192
    assert tiled_stats["initial_radius"] == stats["initial_radius"]
    # Each band emits the frame's photons again: three times the photon paths.
    assert tiled_stats["photons_emitted"] == 3 * stats["photons_emitted"]
    for tile in g.plan_tiles(box, settings)["tiles"]:
        band, band_stats = untiled(g, *g.tile_render_inputs(box, settings, tile), 8)
        assert band_stats["max_radius"] == band_stats["initial_radius"], tile
        x, y, w, h = tile
        if hash == "stochastic":
            np.testing.assert_array_equal(band, tiled[y:y + h, x:x + w])
        else:
            # The exact hash sums a cell's photons in the order the GPU's atomics give, so
            # two runs of one band agree to float rounding only.
            np.testing.assert_allclose(band, tiled[y:y + h, x:x + w], rtol=1e-6, atol=1e-7)
    assert whole[..., :3].mean() > 0.1
    difference = np.abs(tiled - whole)
    assert (difference <= 2e-5 * np.maximum(np.abs(whole), 1e-2)).all(), difference.max()


@pytest.mark.parametrize("techniques", ["pt+lt+vm", "pt"])
def test_vcm_tiled_render_equals_the_untiled_render(glslppm, techniques):
    """VCM in bands (docs/vcm.md): each band traces its pixels' eye paths from the frame's
    streams and every light path of the frame again, whose splats land in the band when
    they project into it, and merges at the pass's radius, the frame's. So the bands make the
    untiled image but for float rounding along the eye paths (the band's camera rays differ
    in the last bits, and a path of several bounces may take another turn): measured (48^2,
    8 passes, the Cornell box with its glass sphere) a mean |difference| of 7.8e-7 of the
    image's mean, 0.1% of the pixels more than 1e-4 off and none more than 1e-2, with light
    tracing and merging (pt+lt+vm) as with path tracing alone. A light path splatted or
    merged by two bands, or by none, would be off by far more."""
    g = glslppm
    box = g.cornell_box(sphere_rings=16)
    options = dict(estimator="vcm", vcm_techniques=techniques)
    whole, _ = untiled(g, box, g.Settings(width=SIZE, height=SIZE, photons_per_pass=4096,
                                          **options), 8)
    tiled, stats = g.render_tiled(box, capped(g, **options), 8)
    assert stats["tiles"] == 3
    w, t = whole[..., :3].astype(np.float64), tiled[..., :3].astype(np.float64)
    difference = np.abs(t - w)
    relative = difference / np.maximum(w, 1e-2)
    assert w.mean() > 0.1
    assert difference.mean() < 1e-5 * w.mean(), difference.mean() / w.mean()
    assert (relative > 1e-4).mean() < 0.01 and relative.max() < 1e-2, relative.max()
    assert np.array_equal(whole[..., 3], tiled[..., 3])


def test_one_tile_is_the_untiled_render_bit_for_bit(glslppm):
    g = glslppm
    box = g.cornell_box(sphere_rings=16)
    settings = g.Settings(width=40, height=24, photons_per_pass=4096)
    whole, _ = untiled(g, box, settings, 4)
    tiled, stats = g.render_tiled(box, settings, 4)
    assert stats["tiles"] == 1
    assert np.array_equal(tiled, whole)


def test_for_each_tile_is_render_tileds_loop(glslppm):
    """The add-on's tiles come from the module's one tile loop (for_each_tile, which
    render_tiled runs too): each tile's scene and settings are tile_render_inputs', its
    renders join into render_tiled's frame bit for bit, and one tile hands back the
    caller's own scene and settings (the frame as it is)."""
    g = glslppm
    box = g.cornell_box(sphere_rings=8)
    settings = capped(g)
    tiles = g.plan_tiles(box, settings)["tiles"]
    frame = np.zeros((SIZE, SIZE, 4), np.float32)
    seen = []

    def visit(index, count, tile, tile_scene, tile_settings):
        seen.append((index, count, tile))
        x, y, w, h = tile
        assert (tile_settings.width, tile_settings.height) == (w, h)
        assert tile_settings.passes == settings.passes
        frame[y:y + h, x:x + w] = untiled(g, tile_scene, tile_settings, 2)[0]

    assert g.for_each_tile(box, settings, tiles, visit) == 3
    assert seen == [(i, 3, tile) for i, tile in enumerate(tiles)]
    tiled, _ = g.render_tiled(box, settings, 2)
    np.testing.assert_array_equal(frame, tiled)
    # A visit returning False stops before the next tile.
    assert g.for_each_tile(box, settings, tiles, lambda *args: False) == 1
    whole = g.Settings(width=SIZE, height=SIZE, photons_per_pass=4096)
    handed = []
    g.for_each_tile(box, whole, [(0, 0, SIZE, SIZE)],
                    lambda i, n, tile, s, st: handed.append((s, st)))
    assert handed[0][0] is box and handed[0][1] is whole


def test_a_tile_callback_that_returns_false_stops_the_render(glslppm):
    g = glslppm
    seen = []
    with pytest.raises(g.Cancelled):
        g.render_tiled(g.cornell_box(sphere_rings=8), capped(g), 2,
                       on_tile=lambda i, tile, rgba: seen.append(i) or False)
    assert seen == [0]
    flag = g.CancelFlag()
    flag.set()
    with pytest.raises(g.Cancelled):
        g.render_tiled(g.cornell_box(sphere_rings=8), capped(g), 2, cancel=flag)


@pytest.mark.slow("a 3840 x 2160 render, the size that needs tiles on llvmpipe")
def test_4k_renders_in_tiles_where_one_buffer_cannot_hold_it(glslppm, tmp_path):
    """3840 x 2160: 8.3 Mpixels of 64-byte visible points (506 MiB) are refused as one
    renderer on llvmpipe (128 MiB per buffer) and render as bands of rows instead."""
    g = glslppm
    largest = g.device_limits()["max_storage_buffer_bytes"]
    rows = largest // (3840 * 64)
    expected = math.ceil(2160 / rows)
    box = g.cornell_box(sphere_rings=16)
    if expected > 1:
        with pytest.raises(g.GlslppmError, match="visible points needs 506 MiB"):
            g.Renderer(box, g.Settings(width=3840, height=2160, photons_per_pass=4096))
    out = tmp_path / "4k.exr"
    result = subprocess.run(
        [RENDER, "--width", "3840", "--height", "2160", "--passes", "1", "--photons", "4096",
         "--out", str(out), "--json"], capture_output=True, text=True, timeout=600, cwd="/")
    assert result.returncode == 0, result.stderr
    stats = json.loads(result.stdout)
    assert stats["tiles"] == expected and stats["gpu_bytes_per_pixel"] == 192
    assert stats["passes"] == 1
    assert result.stderr.count("done (rows") == (expected if expected > 1 else 0)
    image, _ = g.read_exr(str(out))
    assert image.shape == (2160, 3840, 4) and np.isfinite(image).all()
    # The ceiling light (radiance 17) seen directly near the top centre.
    assert image[:, :, :3].max() >= 16.9
