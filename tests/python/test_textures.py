"""Base-colour textures: sRGB decoding (of the filtered bytes, as Cycles), bilinear and Closest
filtering, wrapping, downscaling, and a variant that leaves texture lookups (and uvs) out
when nothing is textured.

A textured diffuse quad alone under a uniform environment of radiance L sees the whole sky
above it, so its radiance is texel * L; an orthographic camera looks straight at it.
"""
import math
import re

import numpy as np
import pytest

L = 2.0
SIZE = 48


def srgb_to_linear(byte):
    c = byte / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def textured_quad(g, texture, uv_scale=1.0, uv_offset=0.0, uvs=True, textured=True, seed=2):
    p = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    # u runs from uv_offset to uv_offset + uv_scale across the quad; v from 0 to 1.
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=np.float32)
    uv[:, 0] = uv[:, 0] * uv_scale + uv_offset
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 2.0
    camera = g.Camera(to_world, projection="orthographic", ortho_scale=2.0)
    material = g.Material("diffuse", color=(1, 1, 1), color_texture=0 if textured else -1)
    scene = g.Scene(p, t, uvs=uv.astype(np.float32) if uvs else None, materials=[material],
                    camera=camera, environment=(L, L, L), textures=[texture])
    r = g.Renderer(scene, g.Settings(width=SIZE, height=SIZE, photons_per_pass=65536, seed=seed,
                                     hash="exact"))
    r.run(16)
    return r.film()[..., 0], r.stats()


def stripes(values, texels_each=4, dtype=np.uint8):
    """A 1-row image of vertical stripes, texels_each texels per value."""
    row = np.repeat(np.asarray(values), texels_each)
    pixels = np.zeros((1, len(row), 4), dtype=dtype)
    pixels[0, :, 0] = pixels[0, :, 1] = pixels[0, :, 2] = row
    pixels[0, :, 3] = 255 if dtype == np.uint8 else 1.0
    return pixels


def stripe_means(film, count):
    """Mean of each stripe's central half (away from the bilinear blend and the gather disc)."""
    width = SIZE // count
    return [film[4:-4, k * width + width // 4:(k + 1) * width - width // 4].mean()
            for k in range(count)]


def test_srgb_texture_decoded_exactly_at_0_half_and_1(glslppm):
    g = glslppm
    texture = g.Texture(stripes([0, 128, 255]), name="stripes")
    film, stats = textured_quad(g, texture)
    assert "textures" in stats["variant"]
    got = stripe_means(film, 3)
    assert got[0] == pytest.approx(0.0, abs=1e-6)
    # sRGB 128/255 is linear 0.2158605; the noise of a stripe mean is below 1.5%.
    assert got[1] == pytest.approx(srgb_to_linear(128) * L, rel=0.03)
    assert got[2] == pytest.approx(1.0 * L, rel=0.03)


def test_float_texture_and_bilinear_blend_between_texels(glslppm):
    """Two float texels 0.2 and 1.0 with extend wrapping: flat halves, and between the texel
    centres a linear ramp (bilinear filtering) from one value to the other."""
    g = glslppm
    texture = g.Texture(stripes([0.2, 1.0], texels_each=1, dtype=np.float32), wrap="extend")
    film, _ = textured_quad(g, texture)
    profile = film[4:-4].mean(axis=0) / L
    x = (np.arange(SIZE) + 0.5) / SIZE  # u of each pixel column
    expected = 0.2 + 0.8 * np.clip((x - 0.25) / 0.5, 0.0, 1.0)
    inner = slice(3, SIZE - 3)  # away from the quad's edges, where the gather disc spills
    assert np.abs(profile[inner] - expected[inner]).max() < 0.04


def test_repeat_and_clip_wrapping(glslppm):
    """uv from -0.5 to 1.5: repeat shows the two-stripe image twice over, clip shows it once
    in the middle and black around it. (16 rows: Clip blends with black within half a texel
    of every edge, as Cycles does, which for a one-row image is its whole height.)"""
    g = glslppm
    image = np.repeat(stripes([0, 255], texels_each=8), 16, axis=0)
    repeat, _ = textured_quad(g, g.Texture(image, wrap="repeat"), uv_scale=2.0, uv_offset=-0.5)
    clip, _ = textured_quad(g, g.Texture(image, wrap="clip"), uv_scale=2.0, uv_offset=-0.5)
    quarters_repeat = stripe_means(repeat, 8)   # u: -0.5..1.5 in quarter-units of 0.25
    quarters_clip = stripe_means(clip, 8)
    # u in [-0.5, 0): second half of the image (white); [0, 0.5): black; [0.5, 1): white ...
    want_repeat = [1, 1, 0, 0, 1, 1, 0, 0]
    want_clip = [0, 0, 0, 0, 1, 1, 0, 0]
    for got, want in ((quarters_repeat, want_repeat), (quarters_clip, want_clip)):
        for value, w in zip(got, want):
            assert value == pytest.approx(w * L, abs=0.06 * L), (got, want)


def test_oversized_image_is_downscaled_with_a_warning(glslppm):
    """An image wider than the texture limit is halved until it fits, with a warning, and
    still shows its mean colour."""
    g = glslppm
    image = stripes([255] * 12, texels_each=1)
    r_film, stats = None, None
    p = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=np.float32)
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 2.0
    scene = g.Scene(p, t, uvs=uv, materials=[g.Material(color=(1, 1, 1), color_texture=0)],
                    camera=g.Camera(to_world, projection="orthographic", ortho_scale=2.0),
                    environment=(L, L, L), textures=[g.Texture(image, name="wide.png")])
    r = g.Renderer(scene, g.Settings(width=16, height=16, photons_per_pass=16384,
                                     max_texture_size=4))
    r.run(8)
    r_film, stats = r.film()[..., 0], r.stats()
    assert any("wide.png" in w and "12x1" in w and "downscaled to 3x1" in w
               for w in stats["warnings"]), stats["warnings"]
    assert r_film[3:-3, 3:-3].mean() == pytest.approx(L, rel=0.05)


def test_untextured_scene_compiles_no_texture_lookups_and_uploads_no_uvs(glslppm):
    """The same quad with uvs but no texture: the variant has no textures and the packed
    triangles carry no uv records (fewer bytes per triangle than the textured scene)."""
    g = glslppm
    texture = g.Texture(stripes([255, 255, 255]))
    _, plain = textured_quad(g, texture, textured=False)
    _, textured = textured_quad(g, texture)
    assert "textures" not in plain["variant"].split(",")
    assert "textures" in textured["variant"].split(",")
    # 2 vec4 of uvs per triangle are left out.
    assert textured["bvh_bytes_per_triangle"] - plain["bvh_bytes_per_triangle"] == \
        pytest.approx(32.0)


def test_texture_without_uvs_is_a_warning_and_uses_the_colour(glslppm):
    g = glslppm
    film, stats = textured_quad(g, g.Texture(stripes([0, 0, 0])), uvs=False)
    assert any("no uvs" in w for w in stats["warnings"]), stats["warnings"]
    assert film[8:-8, 8:-8].mean() == pytest.approx(L, rel=0.03)


@pytest.mark.parametrize("bad,message", [
    (np.zeros((2, 2, 3), dtype=np.uint8), "expected shape (height, width, 4)"),
    (np.zeros((2, 2, 4), dtype=np.float64), "expected uint8 (sRGB) or float32"),
])
def test_malformed_images_are_rejected_with_their_name(glslppm, bad, message):
    with pytest.raises(ValueError, match=r"Texture 'sky\.png'.*" + re.escape(message)):
        glslppm.Texture(bad, name="sky.png")


def test_texture_index_out_of_range_names_the_material(glslppm):
    g = glslppm
    p = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0)], dtype=np.float32)
    t = np.array([[0, 1, 2]], dtype=np.uint32)
    scene = g.Scene(p, t, uvs=np.zeros((3, 2), dtype=np.float32),
                    materials=[g.Material(color_texture=3)], environment=(1, 1, 1))
    with pytest.raises(ValueError, match=r"materials\[0\]\.color_texture: 3 is not one of"):
        g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=1024))


def test_nan_in_a_float_texture_is_rejected(glslppm):
    g = glslppm
    pixels = np.ones((2, 2, 4), dtype=np.float32)
    pixels[1, 0, 2] = math.nan
    p = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0)], dtype=np.float32)
    t = np.array([[0, 1, 2]], dtype=np.uint32)
    scene = g.Scene(p, t, uvs=np.zeros((3, 2), dtype=np.float32),
                    materials=[g.Material(color_texture=0)], environment=(1, 1, 1),
                    textures=[g.Texture(pixels, name="bad.exr")])
    with pytest.raises(ValueError, match=r"textures\[0\] 'bad\.exr': holds NaN or Inf"):
        g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=1024))


# ---- 8-bit sRGB images: filtered as bytes, then decoded (Cycles' NODE_IMAGE_COMPRESS_AS_SRGB)

EDGE_BYTES = np.array([(200, 30, 90), (20, 220, 160)], dtype=np.uint8)  # left, right texel


def srgb_decode(c):
    """The sRGB EOTF (IEC 61966-2-1) on values in [0, 1]."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def edge_radiance(g, passes=128):
    """An unlit quad (black diffuse emitting 1 through a 2x1 sRGB byte image, extend wrap)
    filling an orthographic view, nothing else in the scene: each pixel's radiance is the
    filtered texel. Between the texel centres (u = 0.25 and 0.75, 24 pixel columns) bilinear
    filtering blends the two colours."""
    pixels = np.full((1, 2, 4), 255, dtype=np.uint8)
    pixels[0, :, :3] = EDGE_BYTES
    return unlit_textured_quad(g, g.Texture(pixels, wrap="extend", name="edge"), passes, seed=3)


def unlit_textured_quad(g, texture, passes, seed):
    """A black diffuse quad emitting 1 through `texture`, filling an orthographic SIZE x SIZE
    view, nothing else in the scene: the film is the looked-up texels."""
    p = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=np.float32)
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 2.0
    material = g.Material("diffuse", color=(0, 0, 0), emission=(1, 1, 1), emission_texture=0)
    scene = g.Scene(p, t, uvs=uv, materials=[material],
                    camera=g.Camera(to_world, projection="orthographic", ortho_scale=2.0),
                    textures=[texture])
    r = g.Renderer(scene, g.Settings(width=SIZE, height=SIZE, photons_per_pass=1024, seed=seed))
    r.run(passes)
    return r.film()[..., :3].astype(np.float64)


def edge_reference(decode_first):
    """Each pixel column's radiance: the lookup averaged over 64 points across the pixel,
    filtering the bytes then decoding (Cycles), or decoding each texel then filtering (a GL
    sRGB texture)."""
    u = ((np.arange(SIZE)[:, None] + (np.arange(64) + 0.5)[None, :] / 64) / SIZE)[..., None]
    f = np.clip((u - 0.25) / 0.5, 0.0, 1.0)  # extend wrap: flat outside the texel centres
    left, right = EDGE_BYTES[0] / 255.0, EDGE_BYTES[1] / 255.0
    if decode_first:
        values = (1 - f) * srgb_decode(left) + f * srgb_decode(right)
    else:
        values = srgb_decode((1 - f) * left + f * right)
    return values.mean(axis=1)  # (SIZE columns, 3)


def test_srgb_bytes_are_filtered_then_decoded_across_an_edge(glslppm):
    """Radiance across a sharp edge between two sRGB byte colours, magnified so that the
    bilinear blend spans 24 pixels, against the closed form of Cycles' filter-then-decode.
    Per pixel the only error is where the jittered samples fell (measured on llvmpipe: rms
    8.0e-5, worst 3.6e-4); bounds rms 4e-4 and worst 1.5e-3. Decoding each texel first (the
    GL sRGB8 atlas before) is 0.066 rms off (0.16 in the worst channel mid-blend): it read
    rms 6.5e-2 here and failed. Away from the blend a pixel is one texel's decode (what
    Closest reads too), as before, to 1e-5 relative."""
    g = glslppm
    film = edge_radiance(g)
    profile = film[2:-2].mean(axis=0)  # columns; every row looks at the same u
    want = edge_reference(decode_first=False)
    wrong = edge_reference(decode_first=True)
    inner = slice(2, SIZE - 2)  # away from the quad's edges, where pixels see the void
    error = profile[inner] - want[inner]
    rms, worst = float(np.sqrt(np.mean(error ** 2))), float(np.abs(error).max())
    rms_wrong = float(np.sqrt(np.mean((profile[inner] - wrong[inner]) ** 2)))
    print(f"  filter then decode: rms {rms:.2e} worst {worst:.2e}; "
          f"decode then filter: rms {rms_wrong:.3f}")
    assert rms < 4e-4 and worst < 1.5e-3, (rms, worst)
    assert rms_wrong > 0.02, rms_wrong
    # Flat halves (whole pixels before the first texel centre and past the second).
    np.testing.assert_allclose(film[2:-2, 2:12], np.broadcast_to(
        srgb_decode(EDGE_BYTES[0] / 255.0), film[2:-2, 2:12].shape), rtol=1e-5)
    np.testing.assert_allclose(film[2:-2, 36:-2], np.broadcast_to(
        srgb_decode(EDGE_BYTES[1] / 255.0), film[2:-2, 36:-2].shape), rtol=1e-5)


# ---- Closest interpolation: the one texel a point falls in (Cycles' interp_closest)

CHECKER_BYTES = np.random.default_rng(30).integers(0, 256, size=(4, 4, 3)).astype(np.uint8)


def checker_radiance(g, interpolation, passes=8):
    """An unlit quad emitting 1 through the 4x4 sRGB byte image CHECKER_BYTES (16 distinct
    colours, extend wrap) filling an orthographic 48x48 view, nothing else in the scene: each
    pixel's radiance is the looked-up texel, and every pixel lies inside one texel (12x12
    pixels a texel)."""
    pixels = np.full((4, 4, 4), 255, dtype=np.uint8)
    pixels[..., :3] = CHECKER_BYTES
    texture = g.Texture(pixels, wrap="extend", name="checker", interpolation=interpolation)
    assert texture.interpolation == interpolation
    return unlit_textured_quad(g, texture, passes, seed=5)


def checker_texels():
    """Each pixel's texel, decoded (the film's row 0 is the top, the image's row 0 v = 0)."""
    cell = SIZE // 4
    texels = np.repeat(np.repeat(srgb_decode(CHECKER_BYTES / 255.0), cell, 0), cell, 1)
    return texels[::-1]


def test_closest_reads_each_pixel_as_its_texel(glslppm):
    """Closest: every pixel is its texel's decoded value, whatever the jittered samples hit
    inside it, to float rounding (measured on llvmpipe: largest relative difference 5.5e-7
    over the 44x44 inner pixels; bound 1e-5, so a 1% bias fails). Linear on the same image
    blends neighbours within half a texel of each texel edge and filters the bytes before
    decoding: measured 0.63 off in the worst pixel and the mean 12.5% darker (these random
    colours jump far; the bounds ask 0.05 and 0.5%)."""
    g = glslppm
    inner = (slice(2, -2), slice(2, -2))  # away from the quad's edges, which see the void
    want = checker_texels()[inner]
    closest = checker_radiance(g, "closest")[inner]
    worst = float(np.abs(closest / want - 1.0).max())
    linear = checker_radiance(g, "linear")[inner]
    linear_off = float(np.abs(linear - want).max())
    linear_mean = float(linear.mean() / want.mean() - 1.0)
    print(f"  closest: largest relative difference {worst:.2e}; linear: largest "
          f"difference {linear_off:.3f}, mean {linear_mean:+.4f}")
    assert worst < 1e-5, worst
    assert linear_off > 0.05 and linear_mean < -0.005, (linear_off, linear_mean)


def test_unknown_interpolation_is_rejected_with_the_texture_name(glslppm):
    pixels = np.zeros((2, 2, 4), dtype=np.uint8)
    with pytest.raises(ValueError, match=r"Texture 'sky\.png' interpolation: 'cubic' is not "
                                         r"one of linear, closest"):
        glslppm.Texture(pixels, name="sky.png", interpolation="cubic")


# ---- uv maps (Blender's Mapping node on the UVs) and the four extensions, against a numpy
# copy of Cycles' bilinear lookup (kernel/device/cpu/image.h, interp_linear).

def _wrap_index(i, n, wrap):
    """Cycles' wrap_periodic / wrap_clamp / wrap_mirror; -1 for clip outside."""
    if wrap == "repeat":
        return np.mod(i, n)
    if wrap == "extend":
        return np.clip(i, 0, n - 1)
    if wrap == "mirror":
        m = np.abs(i + (i < 0)) % (2 * n)
        return np.where(m >= n, 2 * n - m - 1, m)
    return np.where((i < 0) | (i >= n), -1, i)


def cycles_linear(image, s, t, wrap):
    """Bilinear lookup of image (H, W) (row 0 at v = 0) at image uv (s, t), as Cycles."""
    h, w = image.shape
    x, y = s * w - 0.5, t * h - 0.5
    ix, iy = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    fx, fy = x - ix, y - iy

    def texel(px, py):
        qx, qy = _wrap_index(px, w, wrap), _wrap_index(py, h, wrap)
        inside = (qx >= 0) & (qy >= 0)
        return np.where(inside, image[np.maximum(qy, 0), np.maximum(qx, 0)], 0.0)

    a = (1 - fx) * texel(ix, iy) + fx * texel(ix + 1, iy)
    b = (1 - fx) * texel(ix, iy + 1) + fx * texel(ix + 1, iy + 1)
    return (1 - fy) * a + fy * b


def cycles_closest(image, s, t, wrap):
    """Closest lookup of image (H, W) at image uv (s, t), as Cycles' interp_closest: texel
    floor(s W), floor(t H) under the extension (Clip: black outside the image)."""
    h, w = image.shape
    ix, iy = np.floor(s * w).astype(np.int64), np.floor(t * h).astype(np.int64)
    qx, qy = _wrap_index(ix, w, wrap), _wrap_index(iy, h, wrap)
    inside = (qx >= 0) & (qy >= 0)
    return np.where(inside, image[np.maximum(qy, 0), np.maximum(qx, 0)], 0.0)


def mapping_point(scale, rotation_z, location):
    """Blender's Mapping node (Point): R (v S) + L, as the add-on's uv map rows."""
    c, s = math.cos(rotation_z), math.sin(rotation_z)
    return ((c * scale[0], -s * scale[1], location[0]), (s * scale[0], c * scale[1], location[1]))


def albedo_of_mapped_quad(g, image, wrap, uv_map, passes=128, interpolation="linear"):
    """Denoising Albedo of the unit-uv quad filling an orthographic view (texel x 1: exact,
    no light noise), and the reference: Cycles' lookup averaged over 8 x 8 points a pixel."""
    p = np.array([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=np.float32)
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 2.0
    pixels = np.ones(image.shape + (4,), dtype=np.float32)
    pixels[..., :3] = image[..., None]
    scene = g.Scene(p, t, uvs=uv, camera=g.Camera(to_world, projection="orthographic",
                                                  ortho_scale=2.0),
                    materials=[g.Material("diffuse", color=(1, 1, 1), color_texture=0)],
                    environment=(1.0, 1.0, 1.0),
                    textures=[g.Texture(pixels, wrap=wrap, uv_map=uv_map,
                                        interpolation=interpolation)])
    r = g.Renderer(scene, g.Settings(width=SIZE, height=SIZE, photons_per_pass=1024, seed=4,
                                     passes=["denoising_albedo"]))
    r.run(passes)
    got = r.render_pass("denoising_albedo")[..., 0]
    sub = (np.arange(8) + 0.5) / 8
    u = ((np.arange(SIZE)[:, None] + sub[None, :]) / SIZE).ravel()       # columns
    v = 1.0 - ((np.arange(SIZE)[:, None] + sub[None, :]) / SIZE).ravel()  # rows, top first
    uu, vv = np.meshgrid(u, v)
    (a, b, c), (d, e, f) = uv_map
    lookup = cycles_closest if interpolation == "closest" else cycles_linear
    want = lookup(image, a * uu + b * vv + c, d * uu + e * vv + f, wrap)
    want = want.reshape(SIZE, 8, SIZE, 8).mean(axis=(1, 3))
    return got, want


SMOOTH = np.random.default_rng(7).uniform(0.1, 0.9, size=(5, 4)).astype(np.float32)


@pytest.mark.parametrize("wrap", ["repeat", "extend", "clip", "mirror"])
def test_uv_map_and_extension_match_cycles_lookup(glslppm, wrap):
    """A 4x5 image looked up through a Mapping (scale 1.7 x 2.3, turned 30 degrees, moved by
    (-0.4, -0.6)), so that uvs leave [0, 1] on every side, under each extension. Denoising
    Albedo per pixel against Cycles' lookup averaged over the pixel: the only difference is
    the 128 jittered samples' spread over the pixel (measured rms 1.4-1.8e-3, mean below
    6e-5). Bounds: rms 3e-3 and mean difference 5e-4 (a 1% brighter texture is 5e-3 off in
    the mean; a uv map 1% larger is 2.1e-2 rms off, test below). Before the fix of negative
    texel indices, Repeat read the wrong row of this 5-row image at v = 0 seams: rms 1.7e-2."""
    g = glslppm
    uv_map = mapping_point((1.7, 2.3), math.radians(30.0), (-0.4, -0.6))
    got, want = albedo_of_mapped_quad(g, SMOOTH, wrap, uv_map)
    rms = float(np.sqrt(np.mean((got - want) ** 2)))
    mean = float(np.mean(got - want))
    print(f"  {wrap}: rms {rms:.5f} mean {mean:+.6f}")
    assert rms < 3e-3 and abs(mean) < 5e-4, (rms, mean)


def test_uv_map_off_by_one_percent_is_caught(glslppm):
    """The bound above separates a uv map 1% off in scale from the right one."""
    g = glslppm
    uv_map = mapping_point((1.7, 2.3), math.radians(30.0), (-0.4, -0.6))
    wrong = mapping_point((1.7 * 1.01, 2.3 * 1.01), math.radians(30.0), (-0.4, -0.6))
    got, _ = albedo_of_mapped_quad(g, SMOOTH, "repeat", wrong)
    _, want = albedo_of_mapped_quad(g, SMOOTH, "repeat", uv_map, passes=1)
    rms = float(np.sqrt(np.mean((got - want) ** 2)))
    print(f"  1% larger uv map: rms {rms:.5f}")
    assert rms > 3e-3, rms



@pytest.mark.parametrize("wrap", ["repeat", "extend", "clip", "mirror"])
def test_closest_under_uv_map_and_extension_matches_cycles_lookup(glslppm, wrap):
    """The same mapped 4x5 image under Closest against Cycles' interp_closest averaged over
    each pixel: it differs only where a texel edge crosses a pixel and the 128 jittered
    samples split it otherwise than the 8 x 8 reference points (measured on llvmpipe: rms
    5.0-8.3e-3, mean at most 1.1e-4). Bounds: rms 1.5e-2 and mean 1e-3; the same image
    under Linear is 0.069-0.111 rms off (the bound asks 3e-2)."""
    g = glslppm
    uv_map = mapping_point((1.7, 2.3), math.radians(30.0), (-0.4, -0.6))
    got, want = albedo_of_mapped_quad(g, SMOOTH, wrap, uv_map,
                                      interpolation="closest")
    rms = float(np.sqrt(np.mean((got - want) ** 2)))
    mean = float(np.mean(got - want))
    linear, _ = albedo_of_mapped_quad(g, SMOOTH, wrap, uv_map, passes=1)
    rms_linear = float(np.sqrt(np.mean((linear - want) ** 2)))
    print(f"  closest {wrap}: rms {rms:.5f} mean {mean:+.6f}; linear rms {rms_linear:.4f}")
    assert rms < 1.5e-2 and abs(mean) < 1e-3, (rms, mean)
    assert rms_linear > 3e-2, rms_linear
