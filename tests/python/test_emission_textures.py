"""Emission colour from an image (material emission_texture): the camera sees emission
times the texel, and a textured emissive quad lights a floor as the brute-force integral of
its textured radiance says, through light samples and through photons.

The emitter is one quad of two triangles whose texture varies within each triangle (red
ramps along u, green along v): triangle emitters are picked by their mean texel and weigh
each point by its own texel, so the light must follow the image, not the triangles' means.
"""
import math

import numpy as np
import pytest

E = 4.0          # the material's emission (radiance at texel 1)
RHO = 0.5
TEXELS = 32
EMITTER = (1.2, 2.2, -0.5, 0.5, 1.0)  # x0, x1, y0, y1, z: a square facing both ways


def ramp_pixels():
    """Red 0.1..2 along u, green 2..0.1 along v, blue 0.5 (float, linear)."""
    c = (np.arange(TEXELS) + 0.5) / TEXELS
    pixels = np.ones((TEXELS, TEXELS, 4), np.float32)
    pixels[..., 0] = 0.1 + 1.9 * c[None, :]
    pixels[..., 1] = 2.0 - 1.9 * c[:, None]
    pixels[..., 2] = 0.5
    return pixels


def bilinear(pixels, u, v):
    """The renderer's lookup (common/textures.glsl) with extend wrap: texel centres at
    (i + 0.5) / n, clamped at the edges."""
    h, w = pixels.shape[:2]
    x, y = u * w - 0.5, v * h - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    x1, y1 = np.clip(x0 + 1, 0, w - 1), np.clip(y0 + 1, 0, h - 1)
    x0, y0 = np.clip(x0, 0, w - 1), np.clip(y0, 0, h - 1)
    a = pixels[y0, x0] * (1 - fx) + pixels[y0, x1] * fx
    b = pixels[y1, x0] * (1 - fx) + pixels[y1, x1] * fx
    return (a * (1 - fy) + b * fy)[..., :3]


def scene(g, camera):
    x0, x1, y0, y1, z = EMITTER
    p = np.array([(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0),
                  (x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)], np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]], np.uint32)  # emitter faces down
    uv = np.array([(0, 0)] * 4 + [(0, 0), (1, 0), (1, 1), (0, 1)], np.float32)
    materials = [g.Material("diffuse", color=(RHO, RHO, RHO)),
                 g.Material("diffuse", color=(0, 0, 0), emission=(E, E, E), emission_texture=0)]
    return g.Scene(p, t, uvs=uv, material_ids=np.array([0, 0, 1, 1], np.uint32),
                   materials=materials, camera=camera,
                   textures=[g.Texture(ramp_pixels(), wrap="extend", name="ramp")])


def floor_radiance(points, n=256):
    """rho / pi * integral over the emitter of L(x) cos cos / d^2 dA, midpoint rule."""
    x0, x1, y0, y1, z = EMITTER
    u = (np.arange(n) + 0.5) / n
    uu, vv = np.meshgrid(u, u, indexing="xy")
    radiance = E * bilinear(ramp_pixels(), uu, vv)  # (n, n, 3)
    xs, ys = x0 + uu * (x1 - x0), y0 + vv * (y1 - y0)
    area = (x1 - x0) * (y1 - y0) / (n * n)
    out = []
    for px, py in points:
        d2 = (xs - px) ** 2 + (ys - py) ** 2 + z * z
        kernel = (z * z) / (d2 * d2) * area  # cos_floor cos_emitter / d^2 = z^2 / d^4
        out.append(RHO / math.pi * (radiance * kernel[..., None]).sum(axis=(0, 1)))
    return np.array(out)


def test_camera_sees_emission_times_texel(glslppm):
    """Looking up at the emitter's underside (it emits from both faces): E * texel."""
    g = glslppm
    x0, x1, y0, y1, _ = EMITTER
    to_world = np.diag([1.0, -1.0, -1.0, 1.0]).astype(np.float32)  # looking up (+z)
    to_world[:3, 3] = (0.5 * (x0 + x1), 0.0, 0.5)
    camera = g.Camera(to_world, projection="orthographic", ortho_scale=1.0)
    r = g.Renderer(scene(g, camera), g.Settings(width=32, height=32, photons_per_pass=1024,
                                                seed=2))
    r.run(64)
    assert "emission-texture" in r.stats()["variant"]
    film = r.film()[2:-2, 2:-2, :3] / E
    # Pixel (row i, column j) looks at u = (j + 0.5) / 32 and (the camera's y runs along
    # -y) v = (i + 0.5) / 32: red follows the columns, green the rows, blue is 0.5. Means
    # over a row or column (jittered pixels average a linear ramp to its centre value).
    c = (np.arange(2, 30) + 0.5) / 32
    np.testing.assert_allclose(film[..., 0].mean(axis=0), 0.1 + 1.9 * c, rtol=0.01)
    np.testing.assert_allclose(film[..., 1].mean(axis=1), 2.0 - 1.9 * c, rtol=0.01)
    np.testing.assert_allclose(film[..., 2], 0.5, rtol=1e-5)


# Measured worst errors over the 12 numbers: light samples 1.23%, photons 0.74%; what a
# triangle-mean emitter would miss by is 10-40%.
@pytest.mark.parametrize("direct_light,passes,photons,bound",
                         [("sampled", 512, 4096, 0.015), ("photons", 64, 262144, 0.03)])
def test_textured_emitter_lights_floor_as_brute_force(glslppm, direct_light, passes, photons,
                                                      bound):
    """Floor radiance at four points under and beside the textured quad, against the
    integral. A uniform quad of the same mean would miss by 10-40% in red and green here."""
    g = glslppm
    to_world = np.eye(4, dtype=np.float32)
    to_world[:3, 3] = (1.7, 0.0, 0.5)
    camera = g.Camera(to_world, projection="orthographic", ortho_scale=2.0)
    size = 40
    r = g.Renderer(scene(g, camera), g.Settings(width=size, height=size, hash="exact",
                                                photons_per_pass=photons, seed=5,
                                                direct_light=direct_light))
    r.run(passes)
    film = r.film()[..., :3]
    # Orthographic, looking down: pixel (i, j) sees x = 0.7 + 2 (j + 0.5) / size,
    # y = 1 - 2 (i + 0.5) / size. Blocks of 6 x 6 pixels around four points; the emitter
    # (z = 1) is above the camera (z = 0.5), so the floor is seen unobstructed.
    points, got = [], []
    for cx, cy in ((1.4, -0.3), (2.0, 0.3), (1.0, 0.6), (2.5, -0.6)):
        j = int(round((cx - 0.7) * size / 2 - 0.5))
        i = int(round((1.0 - cy) * size / 2 - 0.5))
        block = film[i - 3:i + 3, j - 3:j + 3]
        xs = 0.7 + 2 * (np.arange(j - 3, j + 3) + 0.5) / size
        ys = 1.0 - 2 * (np.arange(i - 3, i + 3) + 0.5) / size
        points.append([(x, y) for y in ys for x in xs])
        got.append(block.reshape(-1, 3).mean(axis=0))
    want = np.array([floor_radiance(p).mean(axis=0) for p in points])
    got = np.array(got)
    message = f"{direct_light}: got {got.round(5).tolist()} want {want.round(5).tolist()}"
    np.testing.assert_allclose(got, want, rtol=bound, err_msg=message)
