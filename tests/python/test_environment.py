"""The world: constant radiance and equirectangular maps in Blender's mapping, seen by the
camera and emitting photons by importance."""
import math

import numpy as np
import pytest

from conftest import sphere
from scene_builders import direction_of_texel


def ortho_camera(g, position, rotation=None, scale=2.4):
    m = np.eye(4, dtype=np.float32)
    if rotation is not None:
        m[:3, :3] = rotation
    m[:3, 3] = position
    return g.Camera(m, projection="orthographic", ortho_scale=scale)


@pytest.mark.parametrize("as_map", [False, True])
def test_diffuse_sphere_in_uniform_environment_has_radiance_albedo_times_l(glslppm, as_map):
    """A convex diffuse object of albedo a sees only the sky: radiance a L everywhere on it,
    whether the world is a colour or a constant map (importance sampling then is uniform)."""
    g = glslppm
    albedo, radiance = 0.6, 1.5
    p, t, n = sphere((0, 0, 0), 1.0, 24, 48)
    kwargs = {"environment": (radiance,) * 3}
    if as_map:
        pixels = np.full((8, 16, 4), radiance / 3.0, dtype=np.float32)
        kwargs = {"environment": (3.0,) * 3, "textures": [g.Texture(pixels)],
                  "environment_texture": 0}
    scene = g.Scene(p, t, normals=n, materials=[g.Material(color=(albedo,) * 3)],
                    camera=ortho_camera(g, (0, 0, 3)), **kwargs)
    size = 40
    # The photons' estimate; light sampling's is in test_direct_light.py.
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=65536, seed=4,
                                     hash="exact", direct_light="photons"))
    r.run(16)
    film = r.film()[..., 0]
    assert ("environment-map" in r.stats()["variant"].split(",")) == as_map
    c = ((np.arange(size) + 0.5) / size * 2 - 1) * 1.2
    x, y = np.meshgrid(c, c)
    on_sphere = x * x + y * y < 0.75 ** 2   # away from the silhouette
    off_sphere = x * x + y * y > 1.05 ** 2
    assert film[on_sphere].mean() == pytest.approx(albedo * radiance, rel=0.02)
    # The worst pixel's noise: over seeds 4-7 (as a map) 0.124-0.160 of a L with the one
    # material model and 0.124-0.150 with the closed model before it (0.1498 at this seed,
    # against a bound of 0.15 then): a tail of the per-pixel noise, the means within 0.6%.
    assert np.abs(film[on_sphere] - albedo * radiance).max() < 0.2 * albedo * radiance
    assert film[off_sphere] == pytest.approx(radiance, rel=1e-5)


def test_camera_sees_the_map_in_blenders_orientation(glslppm):
    """Rays escaping along d show the texel at Blender's (u, v) of d, also with the map's
    frame rotated by environment_to_world (here: the map's Z up is the scene's Y up)."""
    g = glslppm
    w, h = 16, 8
    pixels = np.zeros((h, w, 4), dtype=np.float32)
    pixels[..., 0] = np.arange(w)[None, :]       # red: the column
    pixels[..., 1] = np.arange(h)[:, None]       # green: the row (0 at the bottom)
    pixels[..., 3] = 1
    tiny = np.array([(100, 100, 100), (100.1, 100, 100), (100, 100.1, 100)], dtype=np.float32)
    tri = np.array([[0, 1, 2]], dtype=np.uint32)
    for x_texel, y_texel in [(3, 2), (12, 5), (7, 6)]:
        d = direction_of_texel(x_texel, y_texel, w, h)
        for rotated in (False, True):
            # Y-up scene: the map's +Z is the scene's +Y.
            to_world = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]],
                                dtype=np.float32) if rotated else None
            d_world = to_world[:3, :3] @ d if rotated else d
            # An orthographic camera looking along d_world: its -Z column is d_world.
            back = -d_world
            right = np.cross([0.3, 0.5, 0.8], back)
            right /= np.linalg.norm(right)
            up = np.cross(back, right)
            rotation = np.stack([right, up, back], axis=1)
            scene = g.Scene(tiny, tri, camera=ortho_camera(g, (0, 0, 0), rotation, scale=1e-4),
                            environment=(1, 1, 1), textures=[g.Texture(pixels)],
                            environment_texture=0, environment_to_world=to_world)
            r = g.Renderer(scene, g.Settings(width=4, height=4, photons_per_pass=256))
            r.run(1)
            film = r.film()
            # At a texel's centre the bilinear filter returns that texel exactly.
            assert film[..., 0].mean() == pytest.approx(x_texel, abs=1e-3), (x_texel, rotated)
            assert film[..., 1].mean() == pytest.approx(y_texel, abs=1e-3), (y_texel, rotated)


def test_one_bright_texel_casts_a_shadow_where_its_direction_points(glslppm):
    """A black map with one bright texel lights a plane like a small sun: an occluder at
    height h casts its shadow at -h d.xy / d.z, and the lit plane's irradiance is the
    texel's radiance times its solid angle times cos(theta)."""
    g = glslppm
    w, hgt = 64, 32
    x_texel, y_texel = 16, 24   # azimuth: u = 0.26, elevation about 45 degrees
    d = direction_of_texel(x_texel, y_texel, w, hgt)
    pixels = np.zeros((hgt, w, 4), dtype=np.float32)
    pixels[y_texel, x_texel, :3] = 5000.0
    pixels[..., 3] = 1
    h, half = 0.5, 0.15
    # A ground just larger than the view, so that most photons through the scene's
    # bounding disc land where the camera looks.
    ground = [(-1.1, -1.1, 0), (1.1, -1.1, 0), (1.1, 1.1, 0), (-1.1, 1.1, 0)]
    blocker = [(-half, -half, h), (half, -half, h), (half, half, h), (-half, half, h)]
    p = np.array(ground + blocker, dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [4, 6, 5], [4, 7, 6]],
                 dtype=np.uint32)
    mids = np.array([0, 0, 1, 1, 1, 1], dtype=np.uint32)
    albedo = 0.5
    scene = g.Scene(p, t, material_ids=mids,
                    materials=[g.Material(color=(albedo,) * 3), g.Material(color=(0, 0, 0))],
                    camera=ortho_camera(g, (0, 0, 2), scale=2.0), environment=(1, 1, 1),
                    textures=[g.Texture(pixels)], environment_texture=0)
    size = 64
    # Photons: light sampling of the map's 3x3 texels around a tent-filtered one is too
    # noisy at 24 passes for the dark-pixel centroid (test_direct_light.py has its level).
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=65536, seed=9,
                                     hash="exact", direct_light="photons"))
    r.run(24)
    film = r.film()[..., 0]
    c = ((np.arange(size) + 0.5) / size * 2 - 1)
    x, y = np.meshgrid(c, -c)
    shadow_centre = -h * d[:2] / d[2]
    # Lit level: bilinear filtering spreads the texel over its neighbours, so the radiance
    # integrated over the sphere is the texel's times its solid angle.
    solid_angle = (2 * math.pi / w) * (math.pi / hgt) * math.cos((y_texel + 0.5) / hgt * math.pi
                                                                 - math.pi / 2)
    lit = albedo / math.pi * 5000.0 * solid_angle * d[2]
    far = ((x - shadow_centre[0]) ** 2 + (y - shadow_centre[1]) ** 2 > 0.4 ** 2) & \
        ((np.abs(x) > 0.3) | (np.abs(y) > 0.3))
    assert film[far].mean() == pytest.approx(lit, rel=0.05)
    dark = film < 0.3 * lit
    dark &= (np.abs(x) > half + 0.05) | (np.abs(y) > half + 0.05)   # not the blocker itself
    centre = np.array([x[dark].mean(), y[dark].mean()])
    # Within a pixel and a half of where the texel's direction puts it.
    assert np.linalg.norm(centre - shadow_centre) < 1.5 * 2.0 / size, (centre, shadow_centre)
    assert dark.sum() == pytest.approx((2 * half / (2.0 / size)) ** 2, rel=0.35)
