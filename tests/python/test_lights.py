"""Each light kind's irradiance on a diffuse plane against its closed form.

The plane z = 0 (albedo a) is seen by an orthographic camera looking straight down, so each
pixel shows one plane point and its radiance is a E / pi. Blocks of pixels are compared with
the closed form averaged over the same pixels; the tolerances are the noise of the block
means at the pass and photon counts used (measured: rms well under half the bound). Exact
hashing keeps every photon, so the noise is the photons' alone. These test the photons'
estimate (direct_light="photons"); test_direct_light.py tests light sampling.
"""
import math

import numpy as np
import pytest

from closed_forms import area_irradiance_brute_force, disk_irradiance, spot_expected

ALBEDO = 0.5
HALF = 1.5  # the camera sees [-HALF, HALF]^2 of the plane


def plane_irradiance(g, lights, size=48, passes=24, photons=65536, radius=0.08, seed=3):
    """The irradiance the renderer gives on the plane, per pixel, and the pixel centres."""
    e = HALF * 1.05
    p = np.array([(-e, -e, 0), (e, -e, 0), (e, e, 0), (-e, e, 0)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 3.0
    camera = g.Camera(to_world, projection="orthographic", ortho_scale=2 * HALF)
    scene = g.Scene(p, t, materials=[g.Material("diffuse", color=(ALBEDO,) * 3)],
                    lights=lights, camera=camera)
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=photons,
                                     initial_radius=radius, seed=seed, hash="exact",
                                     direct_light="photons"))
    r.run(passes)
    film = r.film()
    assert np.isfinite(film).all()
    c = ((np.arange(size) + 0.5) / size * 2.0 - 1.0) * HALF
    x, y = np.meshgrid(c, -c)  # row 0 is the top of the image: +y
    return film[..., 0] * math.pi / ALBEDO, x, y, r.stats()


def block_errors(measured, expected, step=6, floor=0.05):
    """Relative errors of 3x3 block means where the expected irradiance is substantial."""
    errors = []
    top = expected.max()
    for row in range(1, measured.shape[0] - 1, step):
        for col in range(1, measured.shape[1] - 1, step):
            want = expected[row - 1:row + 2, col - 1:col + 2].mean()
            if want < floor * top:
                continue
            got = measured[row - 1:row + 2, col - 1:col + 2].mean()
            errors.append((got - want) / want)
    return np.array(errors)


def test_point_light_with_radius_lights_like_a_point(glslppm):
    """A Lambertian sphere light wholly above the plane gives the point light's I cos / d^2
    (I = P / 4 pi) at every plane point; only its shadows are soft."""
    g = glslppm
    power, h = 100.0, 1.0
    light = g.Light("point", power=power, position=(0.0, 0.0, h), radius=0.5)
    e, x, y, stats = plane_irradiance(g, [light])
    assert "point-lights" in stats["variant"]
    expected = power / (4 * math.pi) * h / (h * h + x * x + y * y) ** 1.5
    errors = block_errors(e, expected)
    assert np.sqrt(np.mean(errors ** 2)) < 0.05, errors
    assert abs(np.mean(errors)) < 0.02


@pytest.mark.parametrize("cosine", [False, True])
def test_spot_light_centre_edge_and_outside(glslppm, cosine):
    """The spot's falloff at the cone's centre, through its smooth edge and outside it,
    compared ring by ring about the axis; Blender 3.x's extra cos(angle) factor when asked.
    The closed form is averaged over each pixel's gather disc, as the estimate is."""
    g = glslppm
    power, h, size, blend = 100.0, 1.0, math.radians(90), 0.4
    light = g.Light("spot", power=power, position=(0.0, 0.0, h), direction=(0, 0, -1),
                    spot_size=size, spot_blend=blend, spot_cosine=cosine)
    e, x, y, stats = plane_irradiance(g, [light], size=64, passes=32)
    assert "spot-lights" in stats["variant"]
    radius = 0.5 * (stats["initial_radius"] + stats["mean_radius"])
    disc = np.random.default_rng(1).uniform(-1, 1, (600, 2))
    disc = disc[(disc ** 2).sum(1) <= 1.0][:300] * radius
    expected = np.mean([spot_expected(x + dx, y + dy, h, power, size, blend, cosine)
                        for dx, dy in disc], axis=0)
    r = np.sqrt(x * x + y * y)
    edge = h * math.tan(size / 2)   # the cone's edge on the plane
    inner = h * math.tan(math.acos(math.cos(size / 2) + (1 - math.cos(size / 2)) * blend))
    rings = [(0.0, 0.2), (0.2, 0.4), (inner, 0.5 * (inner + edge)), (0.5 * (inner + edge), edge)]
    for lo, hi in rings:
        ring = (r >= lo) & (r < hi)
        assert ring.sum() > 20
        got, want = e[ring].mean(), expected[ring].mean()
        assert got == pytest.approx(want, rel=0.06), (lo, hi)
    outside = r > edge + 0.1   # beyond the gather radius and a pixel from the edge
    assert e[outside].mean() < 0.005 * expected.max()


@pytest.mark.parametrize("angle", [0.0, math.radians(10)])
def test_sun_gives_uniform_irradiance_times_cosine(glslppm, angle):
    """A sun of strength E (W/m^2) at 30 degrees from the zenith: E cos 30 everywhere on the
    open plane, also when its disc is 10 degrees wide."""
    g = glslppm
    strength, tilt = 3.0, math.radians(30)
    light = g.Light("sun", power=strength, direction=(math.sin(tilt), 0, -math.cos(tilt)),
                    angle=angle)
    e, _, _, stats = plane_irradiance(g, [light])
    assert "sun-lights" in stats["variant"]
    inner = e[4:-4, 4:-4]
    print(f"  inner mean / expected - 1: {inner.mean() / (strength * math.cos(tilt)) - 1:+.4f}")
    # Measured over seeds: within 0.2%.
    assert inner.mean() == pytest.approx(strength * math.cos(tilt), rel=0.006)
    # 6x6 blocks: no structure beyond noise.
    blocks = inner.reshape(10, 4, 10, 4).mean(axis=(1, 3))
    assert blocks.std() / blocks.mean() < 0.06


@pytest.mark.parametrize("shape,sx,sy", [("square", 1.0, 1.0), ("rectangle", 1.2, 0.5),
                                         ("disk", 1.0, 1.0), ("ellipse", 1.2, 0.6)])
def test_area_light_shapes_against_brute_force(glslppm, shape, sx, sy):
    """Area lights of every Blender shape, one-sided (facing the plane), hidden from the
    camera: block means against the irradiance integrated over the shape."""
    g = glslppm
    power, h = 40.0, 0.8
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = h
    light = g.Light("area", power=power, to_world=to_world, shape=shape, size_x=sx, size_y=sy,
                    visible_to_camera=False)
    e, x, y, stats = plane_irradiance(g, [light])
    assert "area-lights" in stats["variant"]
    if shape in ("square", "disk"):
        sy = sx
    area = sx * sy * (math.pi / 4 if shape in ("disk", "ellipse") else 1.0)
    radiance = power / (math.pi * area)
    rows = range(4, 48, 8)
    points = [(x[r, c], y[r, c], 0.0) for r in rows for c in rows]
    want = area_irradiance_brute_force(to_world, shape, sx, sy, radiance, points)
    got = np.array([e[r - 1:r + 2, c - 1:c + 2].mean() for r in rows for c in rows])
    errors = (got - want) / want
    # The whole image against the brute force at every pixel centre: the kernel moves light
    # but keeps it, so the mean tests energy with the noise of 2,304 pixels.
    every = [(x[r, c], y[r, c], 0.0) for r in range(48) for c in range(48)]
    whole = area_irradiance_brute_force(to_world, shape, sx, sy, radiance, every, n=160)
    error = e.mean() / whole.mean() - 1.0
    print(f"  block errors rms {np.sqrt(np.mean(errors ** 2)):.4f}; image mean {error:+.4f}")
    # Blocks: measured rms 1.6-2.9%. Image mean: measured within 0.1% over seeds.
    assert np.sqrt(np.mean(errors ** 2)) < 0.06, errors
    assert abs(error) < 0.005


def test_disk_light_closed_form(glslppm):
    """A disk light of radius b and radiance L at height h over the plane: every pixel
    against the closed form. The renderer's disk is a 64-gon; the disk of equal area stands
    for it (their irradiance differs by far less than the noise)."""
    g = glslppm
    power, h, b = 40.0, 0.8, 0.5
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = h
    light = g.Light("area", power=power, to_world=to_world, shape="disk", size_x=2 * b,
                    visible_to_camera=False)
    e, x, y, _ = plane_irradiance(g, [light], passes=32, radius=0.05)
    polygon_area = 32 * math.sin(2 * math.pi / 64) * b * b   # the 64-gon the renderer uses
    radiance = power / (math.pi * polygon_area)
    expected = disk_irradiance(radiance, math.sqrt(polygon_area / math.pi), h, np.hypot(x, y))
    assert expected[24, 24] == pytest.approx(math.pi * radiance * b * b / (h * h + b * b),
                                             rel=0.01)
    error = e.mean() / expected.mean() - 1.0
    centre = e[20:28, 20:28].mean() / expected[20:28, 20:28].mean() - 1.0
    print(f"  image mean / closed form - 1: {error:+.4f}, centre 8x8: {centre:+.4f}")
    # Measured over seeds: image mean within 0.05%, the centre within 0.4%. Blurring by the
    # gather radius moves light but keeps it, so the image mean carries no kernel bias
    # beyond what leaves across the border (E there is a fifth of the peak, and flat).
    assert abs(error) < 0.006
    assert abs(centre) < 0.015


def test_area_light_is_one_sided_and_seen_from_the_front(glslppm):
    """Seen from below (its front), a visible area light shows its radiance L = P / (pi A);
    from above (its back) nothing; hidden from the camera, nothing either."""
    g = glslppm
    power, side = 10.0, 2.0
    to_world = np.eye(4, dtype=np.float32)
    p = np.array([(-5, -5, -3), (5, -5, -3), (5, 5, -3), (-5, 5, -3)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    black = g.Material("diffuse", color=(0, 0, 0))
    results = {}
    for name, cam_z, flip, visible in [("front", -2.0, True, True), ("back", 2.0, False, True),
                                       ("hidden", -2.0, True, False)]:
        cam = np.eye(4, dtype=np.float32)
        if flip:   # look up +Z
            cam[:3, :3] = np.diag([1.0, -1.0, -1.0])
        cam[2, 3] = cam_z
        light = g.Light("area", power=power, to_world=to_world, size_x=side,
                        visible_to_camera=visible)
        scene = g.Scene(p, t, materials=[black], lights=[light],
                        camera=g.Camera(cam, projection="orthographic", ortho_scale=1.0))
        r = g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=1024))
        r.run(2)
        results[name] = r.film()[..., 0].mean()
    assert results["front"] == pytest.approx(power / (math.pi * side * side), rel=1e-4)
    assert results["back"] == 0.0
    assert results["hidden"] == 0.0
