"""Normal maps (tangent space): a map that encodes one constant tilt shades a flat plane
exactly as the plane tilted by that angle, in both direct-light modes.

A white-ish Lambert plane under a sun of irradiance E (no world, nothing else to bounce
from) has radiance rho / pi * E * cos(n, sun) wherever it faces the sun, seen from any
direction: the normal map's tilt must move that cosine, the flat plane's geometric cosine
must not. An orthographic camera looks down at the plane's middle.
"""
import math

import numpy as np
import pytest

SIZE = 32
RHO = 0.8
E = 3.0
TILT = math.radians(30.0)     # the normal map's tilt about the tangent frame
SUN = math.radians(-25.0)     # where the sun stands, from the zenith towards -x / +x
SETTINGS = dict(width=SIZE, height=SIZE, photons_per_pass=65536, seed=3, hash="exact")


def tilt_texture(g, tangent_space_normal):
    """A 2 x 2 float image holding one tangent-space normal as Blender stores it (rgb =
    (n + 1) / 2, Non-Color)."""
    rgb = (np.asarray(tangent_space_normal, np.float64) + 1.0) / 2.0
    pixels = np.ones((2, 2, 4), np.float32)
    pixels[..., :3] = rgb
    return g.Texture(pixels, name="tilt")


def sun_direction(angle_x=SUN, angle_y=0.0):
    """Where the sun stands: turned from the zenith towards +x by angle_x, +y by angle_y."""
    d = np.array([math.sin(angle_x), math.sin(angle_y), math.cos(angle_x) * math.cos(angle_y)])
    return d / np.linalg.norm(d)


def plane(g, rotation=np.eye(3), material=None, textures=(), tangents=None, uvs=True,
          sun_from=None):
    """A 4 x 4 quad in z = 0 turned by `rotation` about the origin, u along x and v along y."""
    p = np.array([(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], np.float64) @ rotation.T
    n = np.repeat((np.array([[0.0, 0.0, 1.0]]) @ rotation.T), 4, axis=0)
    t = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], np.float32)
    sun_from = sun_direction() if sun_from is None else sun_from
    light = g.Light("sun", power=E, direction=tuple(-sun_from))
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 3.0
    camera = g.Camera(to_world, projection="orthographic", ortho_scale=3.0)
    material = material or g.Material("diffuse", color=(RHO, RHO, RHO))
    return g.Scene(p.astype(np.float32), t, normals=n.astype(np.float32),
                   uvs=uv if uvs else None, tangents=tangents, materials=[material],
                   lights=[light], camera=camera, textures=list(textures))


def radiance(g, scene, direct_light, passes=8, **settings):
    r = g.Renderer(scene, g.Settings(direct_light=direct_light, **SETTINGS, **settings))
    r.run(passes)
    return float(r.film()[4:-4, 4:-4, 0].mean()), r.stats()


def rotation_y(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def expected(normal_angle):
    """rho / pi E cos between a normal turned by normal_angle about y and the sun."""
    return RHO / math.pi * E * math.cos(normal_angle - SUN)


# Light samples of a sun are exact (measured 2e-7); the photons' estimate has 0.1-0.4% noise
# over the middle 24 x 24 pixels at 16 passes (three seeds), so 1% still fails a 1% bias.
@pytest.mark.parametrize("direct_light,bound,passes",
                         [("sampled", 0.002, 4), ("photons", 0.01, 16)])
def test_constant_tilt_map_equals_tilted_plane(glslppm, direct_light, bound, passes):
    g = glslppm
    mapped_normal = (math.sin(TILT), 0.0, math.cos(TILT))
    tangents = np.tile(np.array([1, 0, 0, 1], np.float32), (4, 1))
    mapped = plane(g, material=g.Material("diffuse", color=(RHO, RHO, RHO), normal_texture=0),
                   textures=[tilt_texture(g, mapped_normal)], tangents=tangents)
    got_mapped, stats = radiance(g, mapped, direct_light, passes)
    assert "normal-map" in stats["variant"]
    got_tilted, tilted_stats = radiance(g, plane(g, rotation=rotation_y(TILT)), direct_light,
                                        passes)
    assert "normal-map" not in tilted_stats["variant"]
    want = expected(TILT)
    flat = expected(0.0)
    message = (f"{direct_light}: mapped {got_mapped:.5f}, tilted {got_tilted:.5f}, "
               f"analytic {want:.5f} (untilted {flat:.5f})")
    assert got_mapped == pytest.approx(want, rel=bound), message
    assert got_tilted == pytest.approx(want, rel=bound), message
    assert got_mapped == pytest.approx(got_tilted, rel=bound), message


def test_bitangent_sign_and_generated_tangents(glslppm):
    """A tilt towards +bitangent: with sign -1 the bitangent runs along -y (a mirrored uv
    layout), so the shading turns the other way; without tangents they come from the uvs
    (u along x, v along y: sign +1)."""
    g = glslppm
    sun_y = math.radians(35.0)
    tilt = (0.0, math.sin(TILT), math.cos(TILT))
    material = g.Material("diffuse", color=(RHO, RHO, RHO), normal_texture=0)

    def render(tangents):
        scene = plane(g, material=material, textures=[tilt_texture(g, tilt)], tangents=tangents,
                      sun_from=sun_direction(0.0, sun_y))
        return radiance(g, scene, "sampled")[0]

    up = np.tile(np.array([1, 0, 0, 1], np.float32), (4, 1))
    down = np.tile(np.array([1, 0, 0, -1], np.float32), (4, 1))
    towards = RHO / math.pi * E * math.cos(sun_y - TILT)
    away = RHO / math.pi * E * math.cos(sun_y + TILT)
    assert render(up) == pytest.approx(towards, rel=0.005)
    assert render(down) == pytest.approx(away, rel=0.005)
    assert render(None) == pytest.approx(towards, rel=0.005)


def test_strength_blends_with_the_interpolated_normal(glslppm):
    """Blender's strength: normalize(n + (mapped - n) strength); 0 is the flat plane."""
    g = glslppm
    tangents = np.tile(np.array([1, 0, 0, 1], np.float32), (4, 1))
    mapped_normal = np.array([math.sin(TILT), 0.0, math.cos(TILT)])
    for strength in (0.0, 0.5):
        material = g.Material("diffuse", color=(RHO, RHO, RHO), normal_texture=0,
                              normal_strength=strength)
        scene = plane(g, material=material, textures=[tilt_texture(g, mapped_normal)],
                      tangents=tangents)
        got, _ = radiance(g, scene, "sampled")
        blended = np.array([0, 0, 1.0]) + (mapped_normal - [0, 0, 1.0]) * strength
        angle = math.atan2(blended[0], blended[2])
        assert got == pytest.approx(expected(angle), rel=0.005), (strength, got)


def test_bad_tangents_are_named(glslppm):
    g = glslppm
    bad = np.tile(np.array([1, 0, 0, 1], np.float32), (4, 1))
    bad[2] = (np.nan, 0, 0, 1)
    with pytest.raises(ValueError, match=r"tangents\[2\]: component is NaN"):
        plane(g, tangents=bad)
    with pytest.raises(ValueError, match=r"tangents: has 3 rows but positions has 4"):
        plane(g, tangents=bad[:3])
    with pytest.raises(ValueError, match=r"tangents: expected shape \(N, 4\)"):
        plane(g, tangents=bad[:, :3].copy())


def ramp_texture(g, texels=64):
    """A float image whose bilinear lookup is h = u across (clip wrap: no wrap-around),
    constant in v (the finite differences reach half a texel past the lookup: past the
    edge a clipped image reads 0, so the image is as tall as it is wide)."""
    row = (np.arange(texels, dtype=np.float32) + 0.5) / texels
    pixels = np.ones((texels, texels, 4), np.float32)
    pixels[..., :3] = row[None, :, None]
    return g.Texture(pixels, wrap="clip", name="ramp")


@pytest.mark.parametrize("distance,strength", [(2.0, 1.0), (-1.0, 1.0), (2.0, 0.5)])
def test_bump_of_a_linear_ramp_equals_tilted_plane(glslppm, distance, strength):
    """Height h = u on the 4-unit plane (u along x): grad h = x / 4 per unit, so Blender's
    Bump tilts the normal to normalize(z - distance x / 4) (distance -1: Invert), blended
    with z by the strength. Light samples of the sun make the comparison exact: bound 0.2%.
    Where the tilt turns the normal towards the sun by more than the sun's own angle, Cycles'
    shadow terminator term for bumped normals (Chiang et al. 2019) dims it: g = cos(ng, L) /
    (cos(n, L) cos(ng, n)) below 1 scales the light by g + g^2 - g^3 (0.9955 at strength 0.5)."""
    g = glslppm
    material = g.Material("diffuse", color=(RHO, RHO, RHO), bump_texture=0,
                          bump_distance=distance, bump_strength=strength)
    scene = plane(g, material=material, textures=[ramp_texture(g)])
    got, stats = radiance(g, scene, "sampled")
    assert "normal-map" in stats["variant"]
    bumped = np.array([-distance / 4.0, 0.0, 1.0])
    bumped /= np.linalg.norm(bumped)
    blended = strength * bumped + (1.0 - strength) * np.array([0.0, 0.0, 1.0])
    angle = math.atan2(blended[0], blended[2])
    ratio = math.cos(SUN) / (math.cos(angle - SUN) * math.cos(angle))
    terminator = 1.0 if ratio >= 1.0 else ratio + ratio ** 2 - ratio ** 3
    got_tilted, _ = radiance(g, plane(g, rotation=rotation_y(angle)), "sampled")
    want = expected(angle) * terminator
    assert got == pytest.approx(want, rel=0.002), (got, want, terminator)
    assert got == pytest.approx(got_tilted * terminator, rel=0.002), (got, got_tilted)


@pytest.mark.parametrize("distance", [3.8, -3.8])
def test_conty_bump_shadowing_of_a_linear_ramp(glslppm, distance):
    """A steeper ramp under Cycles 5.x's term (bump_shadowing="conty2021"; Conty Estevez,
    Lecocq and Stein 2021): the light is scaled by Smith's GGX G1 at cos(ng, L) with alpha^2 =
    tan^2(ng, n) / 8: 0.99394 for the normal tilted 43.5 degrees towards the sun or away from
    it (below 45 degrees, so that the camera's mirror direction stays above the plane and
    the normal is not bent), where Chiang's term (the default) is 1 for both. Light
    samples: bound 0.2%, a third of the term's 0.6%. Unknown names are refused naming
    both."""
    g = glslppm
    material = g.Material("diffuse", color=(RHO, RHO, RHO), bump_texture=0,
                          bump_distance=distance)
    scene = plane(g, material=material, textures=[ramp_texture(g)])
    got, _ = radiance(g, scene, "sampled", bump_shadowing="conty2021")
    bumped = np.array([-distance / 4.0, 0.0, 1.0])
    bumped /= np.linalg.norm(bumped)
    angle = math.atan2(bumped[0], bumped[2])
    alpha2 = min(0.125 * math.tan(angle) ** 2, 1.0)
    shadowing = 2.0 / (1.0 + math.sqrt(1.0 + alpha2 * math.tan(SUN) ** 2))
    assert shadowing < 0.995  # a comparison that tells the two terms apart
    want = expected(angle) * shadowing
    assert got == pytest.approx(want, rel=0.002), (got, want, shadowing)
    with pytest.raises(ValueError, match="bump_shadowing: 'cycles' is not a bump shadowing "
                                         r"term \(chiang2019, conty2021\)"):
        g.Settings(bump_shadowing="cycles")


def test_bump_and_normal_map_together_are_refused(glslppm):
    g = glslppm
    material = g.Material("diffuse", normal_texture=0, bump_texture=0)
    scene = plane(g, material=material, textures=[ramp_texture(g)])
    with pytest.raises(ValueError, match=r"materials\[0\]\.bump_texture: is set beside "
                                         r"normal_texture"):
        g.Renderer(scene, g.Settings(**SETTINGS))
