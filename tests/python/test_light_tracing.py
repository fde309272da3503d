"""Light tracing of caustics seen directly (Settings.light_tracing, docs/light_tracing.md):
photons of pure mirror and glass chains (L S+) splat to the camera where they land on a
diffuse surface, and the gather leaves them out at visible points seen directly.

Checked against a closed form (a spot mirrored onto a diffuse ceiling), against the very
photons the renderer stored (the glass ball's caustic), against the gather (the same scenes
with light tracing off), and for what must not change: a scene without mirrors or glass
compiles nothing new and renders bit for bit as before, and the fixed-point splats sum to
the same film whatever order the threads add them in.
"""
import json
import math
import os
import subprocess

import numpy as np
import pytest

from conftest import BUILD, look_at, merge, quad
from scene_builders import floor_footprints, glass_ball_beam, grow, lamp_over_floor, pixel_of

CEILING, SPOT_HEIGHT, ALBEDO, POWER = 1.0, 0.5, 0.5, 10.0
EYE_HEIGHT, FOV = 0.25, math.radians(90.0)


def mirrored_spot(g, orthographic=False, lobes=False, camera=None, ceiling_materials=None,
                  spot_size=math.pi / 2, mirror_roughness=0.0):
    """A spot light SPOT_HEIGHT above a perfect mirror (a conductor of colour 1: Schlick's
    Fresnel is then 1 at every angle), pointing down with a 90 degree cone, under a diffuse
    ceiling at height CEILING facing down; the camera between them looks straight up. The
    spot lights the ceiling only through the mirror: as if from its mirror image, SPOT_HEIGHT
    below the mirror and pointing up, so at a ceiling point (x, z)
        L = albedo / pi * I cos(theta) / d^2,  I = P / (4 pi),  d^2 = x^2 + z^2 + h^2,
    h = CEILING + SPOT_HEIGHT, cos(theta) = h / d, inside the cone (cos(theta) > cos 45°).
    With max_bounces=1 a path scatters once before its last bounce: L S D E is all there is
    (the ceiling's light going on by the mirror to the ceiling again is cut). camera: another
    camera than the one looking up. lobes: the
    mirror as Blender's Glossy BSDF exports it (Schlick's Fresnel, still 1 at colour 1),
    which compiles the rough lobes (HAS_ROUGH_LOBES) for the whole scene. ceiling_materials: the
    ceiling's materials in place of the diffuse ALBEDO (the first is the ceiling's; a mix's
    parts follow, as indices 2, 3, ...). spot_size: the cone's full angle (the closed form
    below takes the default's). mirror_roughness: a glossy mirror (GGX) instead, which the
    closed form does not describe."""
    s = 20.0
    mirror = quad((-s, 0, -s), (-s, 0, s), (s, 0, s), (s, 0, -s))
    ceiling = quad((-s, CEILING, -s), (s, CEILING, -s), (s, CEILING, s), (-s, CEILING, s))
    positions, indices, ids = merge((*mirror, 0), (*ceiling, 1))
    materials = [g.Material("conductor", color=(1.0, 1.0, 1.0), schlick=lobes,
                            roughness=mirror_roughness),
                 *(ceiling_materials or [g.Material("diffuse", color=(ALBEDO,) * 3)])]
    spot = g.Light("spot", power=POWER, position=(0, SPOT_HEIGHT, 0), direction=(0, -1, 0),
                   spot_size=spot_size, spot_blend=0.0)
    to_world = look_at((0, EYE_HEIGHT, 0), (0, CEILING, 0), up=(0, 0, -1))
    if camera is None and orthographic:  # the same square of the ceiling
        camera = g.Camera(to_world, projection="orthographic", ortho_scale=2.0 * half_view())
    elif camera is None:
        camera = g.Camera(to_world, fov_x=FOV)
    return g.Scene(positions, indices, material_ids=ids, materials=materials, lights=[spot],
                   camera=camera)


def half_view(distance=CEILING - EYE_HEIGHT):
    """Half the side of the ceiling's square the camera sees, `distance` away."""
    return distance * math.tan(0.5 * FOV)


def mirrored_spot_radiance(size, sub=4, distance=CEILING - EYE_HEIGHT):
    """Each pixel's mean of the closed form over sub x sub points (the box filter): a pixel
    covers a square of the ceiling, perspective (the ceiling parallel to the film) and
    orthographic alike."""
    u = ((np.arange(size * sub) + 0.5) / (size * sub) * 2.0 - 1.0) * half_view(distance)
    x, z = np.meshgrid(u, u)
    h = CEILING + SPOT_HEIGHT
    d2 = x * x + z * z + h * h
    cos_theta = h / np.sqrt(d2)
    radiance = ALBEDO / math.pi * POWER / (4.0 * math.pi) * cos_theta / d2
    radiance *= cos_theta > math.cos(math.pi / 4)  # the cone (seen from the mirror)
    return radiance.reshape(size, sub, size, sub).mean(axis=(1, 3))


def render_luminance(g, scene, passes, **settings):
    r = g.Renderer(scene, g.Settings(**settings))
    r.run(passes)
    film, stats = r.film()[..., :3].astype(np.float64), r.stats()
    r.close()
    return film.mean(axis=2), stats


@pytest.mark.parametrize("estimator,projection,lobes", [
    ("sppm", "perspective", False), ("pppm", "perspective", False),
    ("sppm", "orthographic", False), ("sppm", "perspective", True)])
def test_mirrored_spot_matches_closed_form(glslppm, estimator, projection, lobes):
    """Light tracing alone lights the ceiling here (the gather leaves the L S photons out at
    the points the camera sees directly), so the image is the splats' sum. Each pixel's
    ratio to the closed form is an independent sample (a photon splats into one pixel): their
    mean's standard error, from their spread, is the noise bound. Measured (seed 1, 64
    passes): mean within 0.1% of the closed form, standard error 0.1%, each estimator and
    camera (PPPM: the film divides the splats by the paths emitted, as SPPM's; each of its
    passes starts them all). The test asks for 4 standard errors and a standard error below
    0.2%, so a 1% bias fails."""
    g = glslppm
    size = 64
    scene = mirrored_spot(g, orthographic=projection == "orthographic", lobes=lobes)
    luminance, stats = render_luminance(g, scene, 64, width=size, height=size, max_bounces=1,
                                        seed=1, estimator=estimator)
    assert "light-tracing" in stats["variant"].split(",")
    assert ("rough-lobes" in stats["variant"].split(",")) == lobes
    ratio = luminance / mirrored_spot_radiance(size)
    mean, standard_error = ratio.mean(), ratio.std() / math.sqrt(ratio.size)
    print(f"mean ratio {mean:.5f}, standard error {standard_error:.5f}")
    assert standard_error < 0.002, standard_error
    assert abs(mean - 1.0) < 4.0 * standard_error, (mean, standard_error)


@pytest.mark.parametrize("roughness,traced", [(0.25, False), (0.05, True)])
def test_light_tracing_takes_the_caustics_of_sharp_lobes_only(glslppm, roughness, traced):
    """Light tracing follows a photon past a mirror or glass whose roughness is up to 0.1
    (LIGHT_TRACED_ROUGHNESS in photon_trace.comp): behind a rougher lobe the eye paths
    follow (a glossy mirror of roughness 0.25, below the glossy threshold) the caustic is
    spread and dim, and splatting its few photons a pixel one by one was salt-like noise (the
    showcase's shadows, issue 34), so the gather takes it: light tracing on renders bit for
    bit what it renders off (no photon is splatted, no number drawn). Behind a mirror of
    roughness 0.05 light tracing splats the caustic: the image differs and its mean agrees
    with the gather's within 0.5% (measured 1.00015 at seed 1, 64 passes; the perfect
    mirror's 1.00001), so a 1% bias fails."""
    g = glslppm
    scene = mirrored_spot(g, mirror_roughness=roughness)
    films = {on: render_luminance(g, scene, 64, width=64, height=64, max_bounces=1, seed=1,
                                  light_tracing=on)[0] for on in (True, False)}
    assert np.array_equal(films[True], films[False]) != traced
    ratio = films[True].mean() / films[False].mean()
    print(f"roughness {roughness}: light tracing on / off {ratio:.5f}")
    assert abs(ratio - 1.0) < 0.005, ratio


def test_mirrored_spot_on_a_mix_matches_closed_form(glslppm):
    """The ceiling a Mix of two Lambert leaves, albedo 0.3 and 0.7 at factor 0.5: its f is
    ALBEDO / pi as before, but the connection now picks a leaf as the eye path would (a
    number of its own) and evaluates it through the lobes (connection_f), so the closed form
    checks that path. The bound is the test above's: 4 standard errors, each below 0.2%."""
    g = glslppm
    size = 64
    ceiling = [g.Material("mix", mix_a=2, mix_b=3, mix_factor=0.5),
               g.Material("diffuse", color=(0.3,) * 3), g.Material("diffuse", color=(0.7,) * 3)]
    scene = mirrored_spot(g, lobes=True, ceiling_materials=ceiling)
    luminance, stats = render_luminance(g, scene, 64, width=size, height=size, max_bounces=1,
                                        seed=1)
    variant = stats["variant"].split(",")
    assert "light-tracing" in variant and "rough-lobes" in variant, variant
    ratio = luminance / mirrored_spot_radiance(size)
    mean, standard_error = ratio.mean(), ratio.std() / math.sqrt(ratio.size)
    print(f"mean ratio {mean:.5f}, standard error {standard_error:.5f}")
    assert standard_error < 0.002, standard_error
    assert abs(mean - 1.0) < 4.0 * standard_error, (mean, standard_error)


@pytest.mark.parametrize("kind", ["plastic", "conductor", "mix"])
def test_mirrored_spot_on_glossy_surfaces_agrees_with_the_gather(glslppm, kind):
    """The ceiling glossy (a plastic of roughness 0.5, a rough conductor of roughness 0.6,
    or a mix of the two): no closed form, so light tracing on (the splats alone light the
    ceiling the camera sees, as connection_f evaluates f) is checked against light tracing
    off (the gather alone, which evaluates the same f at its visible points). The photons
    stored on the ceiling must carry the L S+ class, which the gather leaves to light tracing
    at points seen directly (before, light tracing took Lambert surfaces only, and these
    photons were scattered light, class 1, for the gather). Measured
    (seed 1, 64 passes, 64^2) the two means within 0.5%; the bound is 1.5%, the gather's own
    on the Lambert ceiling above (its disc averages f's variation too). So a 1% bias of the
    connection's f alone would not fail the mean check: the closed-form mix test above holds
    connection_f to 0.5%, and here the class check fails outright if the glossy ceiling is
    not light-traced at all."""
    g = glslppm
    size = 64
    plastic = g.Material("plastic", color=(0.6, 0.5, 0.4), roughness=0.5)
    metal = g.Material("conductor", color=(0.9, 0.7, 0.5), roughness=0.6, schlick=True)
    ceiling = {"plastic": [plastic], "conductor": [metal],
               "mix": [g.Material("mix", mix_a=2, mix_b=3, mix_factor=0.4), plastic, metal]}
    means, classes = {}, {}
    for on in (False, True):
        r = g.Renderer(mirrored_spot(g, lobes=True, ceiling_materials=ceiling[kind]),
                       g.Settings(width=size, height=size, max_bounces=1, seed=1,
                                  light_tracing=on))
        r.run(64)
        assert ("light-tracing" in r.stats()["variant"].split(",")) == on
        means[on] = float(r.film()[..., :3].astype(np.float64).mean())
        # The last pass's photons stored on the ceiling, and their path class: L S+ (3)
        # where light tracing takes them, scattered light (1) where it leaves them to the
        # gather.
        ph = r.photons()
        ph = ph[(ph[:, 11] > 0.0) & (np.abs(ph[:, 1] - CEILING) < 1e-4)]
        classes[on] = set((ph[:, 7].astype(np.uint32) & 3).tolist())
        r.close()
    print(f"{kind}: gathered {means[False]:.6g}, traced {means[True]:.6g}, "
          f"ratio {means[True] / means[False]:.5f}, classes {classes}")
    assert means[False] > 1e-4, means
    assert classes[True] == {3}, classes
    assert abs(means[True] / means[False] - 1.0) < 0.015, means


def test_mirrored_spot_through_a_thin_lens_matches_closed_form(glslppm):
    """A thin lens of radius 0.3 (the ceiling 0.75 away) focused on the ceiling: every ray
    of a pixel meets the ceiling where the pinhole's does, and each splat, now connected
    through a point of the lens, lands in the pinhole's pixel with the pinhole's value (for a
    plane in focus parallel to the lens, d cos(theta_c) is the focus distance from every lens
    point). So the closed form holds as it is, with the pinhole's bound: 4 standard errors,
    each below 0.2%. The defocused test below is the one that tells the lens apart."""
    g = glslppm
    size = 64
    to_world = look_at((0, EYE_HEIGHT, 0), (0, CEILING, 0), up=(0, 0, -1))
    camera = g.Camera(to_world, fov_x=FOV, aperture_radius=0.3,
                      focus_distance=CEILING - EYE_HEIGHT)
    luminance, stats = render_luminance(g, mirrored_spot(g, camera=camera), 64, width=size,
                                        height=size, max_bounces=1, seed=1)
    variant = stats["variant"].split(",")
    assert "light-tracing" in variant and "depth-of-field" in variant, variant
    ratio = luminance / mirrored_spot_radiance(size)
    mean, standard_error = ratio.mean(), ratio.std() / math.sqrt(ratio.size)
    print(f"mean ratio {mean:.5f}, standard error {standard_error:.5f}")
    assert standard_error < 0.002, standard_error
    assert abs(mean - 1.0) < 4.0 * standard_error, (mean, standard_error)


def test_defocused_mirrored_spot_agrees_with_the_gather(glslppm):
    """The spot's cone narrowed to 30 degrees, so its disc on the ceiling (radius 0.4) lies in
    view, and the lens focused at 0.3, far in front of the ceiling: the disc's edge blurs over
    about 0.45. Light tracing on (splats through points of the lens) against off (the gather
    at the points the lens's rays find), 96 passes, in 8x8-pixel blocks. Measured (seeds 1 and
    2): the whole image 1.0009 and 1.0020, within 1%; the blocks within 4.2% of the brightest
    block, the gather's own noise (its two seeds differ by up to 5.3% there, light tracing's by
    0.4%); the bound is 10%. Splats placed as a pinhole would place them (the disc sharp) miss
    the blocks at its edge by far more: 72% of the brightest block (tried once)."""
    g = glslppm
    size = 64
    to_world = look_at((0, EYE_HEIGHT, 0), (0, CEILING, 0), up=(0, 0, -1))
    camera = g.Camera(to_world, fov_x=FOV, aperture_radius=0.3, focus_distance=0.3)
    images = {}
    for on in (False, True):
        luminance, stats = render_luminance(g, mirrored_spot(g, camera=camera, spot_size=0.52),
                                            96, width=size, height=size, max_bounces=1, seed=1,
                                            light_tracing=on)
        assert ("light-tracing" in stats["variant"].split(",")) == on
        images[on] = luminance.reshape(8, 8, 8, 8).mean(axis=(1, 3))
    whole = images[True].mean() / images[False].mean()
    blocks = np.abs(images[True] - images[False]) / images[False].max()
    print(f"whole {whole:.5f}, largest block difference {blocks.max():.4f} of the brightest")
    assert abs(whole - 1.0) < 0.01, whole
    assert blocks.max() < 0.1, blocks


def test_mirrored_spot_through_a_cut_out_matches_half_the_closed_form(glslppm):
    """A cut-out of alpha 0.5 (a Mix of Transparent and black Lambert) right in front of the
    camera, covering its view, casting no shadow (photons pass it as if it were not there):
    half of the camera's rays see the ceiling, half a black surface, so the image is half the
    closed form. The connection sees through the cut-out where the leaf it picks there is the
    Transparent one (camera_sees), as often as camera rays do. The spot's photons that cross
    the cut-out on their way down to the mirror count it as a surface and end there (max
    bounces 1): the ceiling they would light, |x|, |z| < 0.1875 (its photons cross at 0.16 x),
    is the central 16 x 16 pixels, left out. Bound as above (4 standard errors, each below
    0.2%), 96 passes. Before, a cut-out turned light tracing off."""
    g = glslppm
    size = 64
    s, h = 20.0, EYE_HEIGHT + 0.01
    mirror = quad((-s, 0, -s), (-s, 0, s), (s, 0, s), (s, 0, -s))
    ceiling = quad((-s, CEILING, -s), (s, CEILING, -s), (s, CEILING, s), (-s, CEILING, s))
    c = 0.03  # wider than the view 0.01 above the camera
    cut_out = quad((-c, h, -c), (c, h, -c), (c, h, c), (-c, h, c))
    positions, indices, ids = merge((*mirror, 0), (*ceiling, 1), (*cut_out, 2))
    materials = [g.Material("conductor", color=(1.0, 1.0, 1.0), schlick=True),
                 g.Material("diffuse", color=(ALBEDO,) * 3),
                 g.Material("mix", mix_a=3, mix_b=4, mix_factor=0.5, casts_shadow=False),
                 g.Material("transparent", color=(1.0,) * 3),
                 g.Material("diffuse", color=(0.0,) * 3)]
    spot = g.Light("spot", power=POWER, position=(0, SPOT_HEIGHT, 0), direction=(0, -1, 0),
                   spot_size=math.pi / 2, spot_blend=0.0)
    camera = g.Camera(look_at((0, EYE_HEIGHT, 0), (0, CEILING, 0), up=(0, 0, -1)), fov_x=FOV)
    scene = g.Scene(positions, indices, material_ids=ids, materials=materials, lights=[spot],
                    camera=camera)
    luminance, stats = render_luminance(g, scene, 96, width=size, height=size, max_bounces=1,
                                        seed=1)
    assert "light-tracing" in stats["variant"].split(","), stats["variant"]
    ratio = luminance / (0.5 * mirrored_spot_radiance(size))
    outside = np.ones((size, size), bool)
    outside[24:40, 24:40] = False
    assert luminance[28:36, 28:36].max() == 0.0  # the shadow, as computed
    ratio = ratio[outside]
    mean, standard_error = ratio.mean(), ratio.std() / math.sqrt(ratio.size)
    print(f"mean ratio {mean:.5f}, standard error {standard_error:.5f}")
    assert standard_error < 0.002, standard_error
    assert abs(mean - 1.0) < 4.0 * standard_error, (mean, standard_error)


def test_mirrored_spot_gathered_agrees(glslppm):
    """The same scene with light tracing off: the gather alone estimates the same ceiling
    (its kernel bias is second order on this smooth irradiance). Measured (seed 1, 64
    passes): the whole image's mean within 0.3% of the closed form either way; on the
    gathered image each pixel is no longer independent (a photon lands in several discs), so
    the bound is the larger 1.5%."""
    g = glslppm
    size = 64
    expected = mirrored_spot_radiance(size).mean()
    means = {}
    for on in (False, True):
        luminance, stats = render_luminance(g, mirrored_spot(g), 64, width=size, height=size,
                                            max_bounces=1, seed=1, light_tracing=on)
        assert ("light-tracing" in stats["variant"].split(",")) == on
        means[on] = luminance.mean() / expected
    print(f"whole image / closed form: gathered {means[False]:.5f}, traced {means[True]:.5f}")
    assert abs(means[False] - 1.0) < 0.015, means
    assert abs(means[True] - means[False]) < 0.015, means


def test_caustic_seen_in_a_mirror_stays_with_the_gather(glslppm):
    """The camera looks straight down at the mirror and sees the ceiling in it: the caustic is
    now an L S D S E path, which light tracing leaves to the gather (the visible point has a
    scatter before it); the ceiling lies behind the camera, so nothing is splatted either. The
    film is bit for bit the one with light tracing off. Against the closed form seen over the
    mirror (the ceiling 1.75 away along the folded ray) it is low by the photons still in
    flight: with max_bounces=2 paths go on past the ceiling, their starts spread over the
    passes, and the last pass's photons land after the film is read, about 1/passes of
    them (1/(passes + path length - 1)). Measured: 0.969 at 32 passes, 0.986 at 64; bound
    3%, so this checks the partition, and the closed-form tests above the normalisation.
    max_bounces=2: the eye's mirror bounce and the ceiling's."""
    g = glslppm
    size = 64
    eye = 0.75
    camera = g.Camera(look_at((0, eye, 0), (0, 0, 0), up=(0, 0, -1)), fov_x=FOV)
    films = {}
    for on in (False, True):
        scene = mirrored_spot(g, camera=camera)
        films[on], stats = render_luminance(g, scene, 64, width=size, height=size, seed=2,
                                            max_bounces=2, light_tracing=on)
        assert ("light-tracing" in stats["variant"].split(",")) == on
    assert np.array_equal(films[False], films[True])
    ratio = films[True].mean() / mirrored_spot_radiance(size, distance=eye + CEILING).mean()
    print(f"seen in the mirror: whole image / closed form {ratio:.5f}")
    assert abs(ratio - 1.0) < 0.03, ratio


def test_glass_ball_caustic_equals_its_photons(glslppm):
    """The glass ball focusing a beam onto the floor (test_caustic_flux.py's scene): with light
    tracing each photon through the ball splats its flux into the very pixel it lands in, so
    the rendered flux over the caustic (sum of pi L / albedo times each pixel's floor area)
    equals the flux of the photons the renderer stored there, with no blur: the gather's
    caustic holds only 97% of it at the caustic's edge. Light tracing draws no random numbers,
    so both renders trace the same photons; with margins the two estimates must agree.
    Measured (seed 1, 40 passes at 128^2): traced 0.9997, 0.9994, 0.9992, 0.9994 of the
    photons at margins 0, 1, 3 and 12 pixels (the rest: the few photons gathered there, a
    diffuse bounce behind them); gathered 0.967, 0.991, 0.997, 1.002 with the closed material
    model. Bounds: traced within 0.5% at every margin (a 1% bias fails). The gathered estimate
    is SPPM's, blurred by its radius at 40 passes, and the one material model blurs this
    caustic differently: gathered 0.944, 0.959, 0.967, 0.976 (at 160 passes 0.9965 at 12
    pixels, where the closed model read 1.0129); why is not established (issue 27). So the
    two need only agree within 3% at 12 pixels: a check that the partition loses no caustic,
    not of SPPM's bias."""
    g = glslppm
    size, passes = 128, 40
    ratios = {}
    for on in (True, False):
        scene, to_world, fov_x, centre, radius, albedo = glass_ball_beam(g)
        r = g.Renderer(scene, g.Settings(width=size, height=size, seed=1, light_tracing=on))
        photon_flux = np.zeros(size * size)
        for _ in range(passes):
            r.run(1)
            ph = r.photons()
            ph = ph[(ph[:, 11] > 0.0) & (np.abs(ph[:, 1]) < 1e-5)].astype(np.float64)
            pixel = pixel_of(ph[:, :3], to_world, fov_x, size)
            inside = pixel >= 0
            photon_flux += np.bincount(pixel[inside], weights=ph[inside, 8],
                                       minlength=size * size)
        assert ("light-tracing" in r.stats()["variant"].split(",")) == on
        photon_flux = photon_flux.reshape(size, size) / r.stats()["photons_emitted"]
        area, visible = floor_footprints(to_world, fov_x, size, centre, radius)
        rendered_flux = r.film()[..., 0].astype(np.float64) * (math.pi / albedo) * area
        r.close()
        irradiance = np.where(visible, photon_flux / area, 0.0)
        caustic = visible & (irradiance > 0.05 * irradiance.max())
        ratios[on] = np.array([rendered_flux[grow(caustic, m) & visible].sum() /
                               photon_flux[grow(caustic, m) & visible].sum()
                               for m in (0, 1, 3, 12)])
    print("traced", np.round(ratios[True], 5), "gathered", np.round(ratios[False], 5))
    assert np.all(np.abs(ratios[True] - 1.0) < 0.005), ratios
    assert abs(ratios[True][-1] / ratios[False][-1] - 1.0) < 0.03, ratios


def test_scene_without_mirrors_or_glass_is_unchanged(glslppm):
    """Nothing to light-trace: the setting compiles nothing and the film is bit for bit the
    one rendered with it off."""
    g = glslppm
    films = []
    for on in (False, True):
        luminance, stats = render_luminance(g, lamp_over_floor(g, 1.0), 8, width=32, height=32,
                                            photons_per_pass=4096, seed=3, light_tracing=on)
        assert "light-tracing" not in stats["variant"].split(",")
        films.append(luminance)
    assert np.array_equal(films[0], films[1])


def test_splats_sum_in_any_order(glslppm):
    """The splats are added in 64-bit fixed point, so the film does not depend on the order
    the GPU's threads run in: two renders of the same seed are bit for bit the same (a float
    atomic add, or a compare-and-swap loop on float bits, would round in thread order)."""
    g = glslppm
    films = [render_luminance(g, mirrored_spot(g), 8, width=32, height=32, max_bounces=1,
                              photons_per_pass=16384, seed=5)[0] for _ in range(2)]
    assert films[0].max() > 0.0
    assert np.array_equal(films[0], films[1])


def test_cli_flag_switches_it(glslppm):
    """glslppm-render's built-in Cornell box (a mirror and a glass sphere): light tracing by
    default, none with --light-tracing off, and a word other than on or off refused."""
    render = os.path.join(BUILD, "glslppm-render")
    variants = {}
    for flag in ([], ["--light-tracing", "off"], ["--light-tracing", "on"]):
        out = subprocess.run([render, "--width", "16", "--height", "16", "--passes", "1",
                              "--photons", "1024", "--json", *flag],
                             capture_output=True, text=True, timeout=300, check=True)
        variants[" ".join(flag)] = json.loads(out.stdout)["variant"].split(",")
    assert "light-tracing" in variants[""] and "light-tracing" in variants["--light-tracing on"]
    assert "light-tracing" not in variants["--light-tracing off"]
    refused = subprocess.run([render, "--light-tracing", "maybe"], capture_output=True,
                             text=True, timeout=60)
    assert refused.returncode != 0 and "is not on or off" in refused.stderr
