"""VCM (estimator "vcm", docs/vcm.md), so far its path tracing technique: the closed forms the
suite checks the other estimators against, its passes' independence, and the clear errors for
what it does not model yet.

Where every pixel has the same expected value (the furnace, the slab, the glass cube's
centre), the noise bound comes from the image itself: each pixel is the mean of its passes'
independent paths, so the image mean's standard error is the pixels' spread over
sqrt(pixels). Each test asserts that its bound is below 1% of the answer, so that a 1% bias
fails it, and then that the render lies within the bound.
"""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import test_direct_light as direct_light_tests
import test_glass_equilibrium as equilibrium_tests
import test_glossy_sky as glossy_sky_tests
import test_light_linking
import test_specular_closed_forms as specular_tests
from closed_forms import furnace_scene
from conftest import BUILD, merge

SIGMAS = 4.0


def vcm_render(g, scene, size, passes, seed=3, **settings):
    r = g.Renderer(scene, g.Settings(width=size, height=size, seed=seed, estimator="vcm",
                                     **settings))
    r.run(passes)
    image = r.film()[..., :3].astype(np.float64)
    stats = r.stats()
    r.close()
    assert np.isfinite(image).all()
    assert "estimator=vcm" in stats["variant"].split(","), stats["variant"]
    return image


def mean_and_bound(values):
    """The mean of equally distributed independent pixel values and SIGMAS standard errors
    of it, relative to the mean."""
    values = np.asarray(values, dtype=np.float64).ravel()
    mean = values.mean()
    return mean, SIGMAS * values.std(ddof=1) / math.sqrt(values.size) / mean


@pytest.mark.parametrize("limit", [0, 1, 2, None])
def test_vcm_furnace_follows_the_diffuse_limit(glslppm, limit):
    """Inside a closed diffuse sphere of albedo a = 0.5 that emits Le = 1, a diffuse limit N
    gives L = Le sum_{k=0..N+1} a^k (test_bounce_limits' closed form): the emission seen, the
    light sample's direct light at each vertex and the path's N further bounces. None: the
    default limits (max_bounces 16: 18 terms), where Russian roulette ends most paths first."""
    g = glslppm
    albedo, emission = 0.5, 1.0
    settings = {} if limit is None else {"max_diffuse_bounces": limit}
    terms = 16 + 2 if limit is None else limit + 2
    image = vcm_render(g, furnace_scene(g, albedo, emission), 24, 64, **settings)
    expected = emission * sum(albedo ** k for k in range(terms))
    mean, bound = mean_and_bound(image.mean(axis=2))
    error = mean / expected - 1.0
    print(f"  vcm diffuse limit {limit}: L {mean:.5f}, closed form {expected:.5f}, "
          f"error {error:+.5f}, bound {bound:.5f}")
    assert bound < 0.005, bound
    assert abs(error) < bound, (mean, expected, bound)


def test_vcm_point_light_over_a_diffuse_plane(glslppm):
    """A point light of intensity I = P / 4 pi at height h over a plane of albedo 0.5, seen
    by an orthographic camera: E = I h / (h^2 + r^2)^(3/2) averaged over each pixel
    (test_direct_light's closed form). Nothing comes back from the open plane, so a pixel's
    value is the light sample's: the same bounds as the light-sampled test there (a 1% bias
    fails the foot block, the blocks near it and the mean)."""
    g = glslppm
    power, h, size = 100.0, 1.0, 47
    intensity = power / (4 * math.pi)
    scene = direct_light_tests.plane_scene(g, [g.Light("point", power=power,
                                                       position=(0.0, 0.0, h))])
    image = vcm_render(g, scene, size, 16)
    e = image[..., 0] * math.pi / direct_light_tests.ALBEDO
    expected = direct_light_tests.footprint(
        lambda x, y: intensity * h / (h * h + x * x + y * y) ** 1.5, size)
    foot = e[22:25, 22:25].mean() / expected[22:25, 22:25].mean() - 1.0
    blocks = e[:45, :45].reshape(15, 3, 15, 3).mean(axis=(1, 3)) / \
        expected[:45, :45].reshape(15, 3, 15, 3).mean(axis=(1, 3)) - 1.0
    mean = e.mean() / expected.mean() - 1.0
    print(f"  foot block {foot:+.6f}, 3x3 blocks max {np.abs(blocks).max():.5f}, "
          f"image mean {mean:+.6f}")
    assert abs(foot) < 0.001
    assert np.abs(blocks).max() < 0.02
    assert abs(mean) < 0.002


def test_vcm_glass_slab_transmits_one_minus_r_over_one_plus_r(glslppm):
    """test_specular_closed_forms' slab (IOR 1.5) before an emitter, seen head-on: the path
    follows the glass by Fresnel and meets the emitter after smooth bounces only, whose
    emission it counts: L (1 - R) / (1 + R) = 0.9231 L per channel, within 5 sigma of the
    Bernoulli draws (0.28%: a 1% bias is 18 sigma)."""
    g = glslppm
    t = specular_tests
    radiance = np.array([2.0, 1.0, 0.5])
    front = t.oriented_quad([(-5, -5, 0.25), (5, -5, 0.25), (5, 5, 0.25), (-5, 5, 0.25)],
                            (0, 0, 1))
    back = t.oriented_quad([(-5, -5, -0.25), (5, -5, -0.25), (5, 5, -0.25), (-5, 5, -0.25)],
                           (0, 0, -1))
    light = t.oriented_quad([(-9, -9, -2), (9, -9, -2), (9, 9, -2), (-9, 9, -2)], (0, 0, 1))
    p, tri, ids = merge((*front, 0), (*back, 0), (*light, 1))
    scene = g.Scene(p, tri, material_ids=ids,
                    materials=[g.Material("dielectric", color=(1, 1, 1), ior=t.IOR),
                               t.emitter_material(g, tuple(radiance))],
                    camera=t.ortho_camera(g, (0, 0, 5), (0, 0, 0), (0, 1, 0), 1.0))
    size, passes = 64, 64
    image = vcm_render(g, scene, size, passes, seed=1, max_bounces=1024)
    r = ((t.IOR - 1) / (t.IOR + 1)) ** 2
    expected = t.slab_transmittance(r)
    measured = image.mean(axis=(0, 1)) / radiance
    bound = t.bernoulli_bound(expected, size * size * passes)
    print(f"  measured/expected - 1: {measured / expected - 1.0}, bound {bound:.5f}")
    assert bound < 0.003
    assert np.all(np.abs(measured / expected - 1.0) < bound), (measured, expected, bound)


EQUILIBRIUM_CASES = {
    **{name: args[:2] for name, args in equilibrium_tests.CASES.items()},
    # A coat below glossy_threshold (0.5): the path follows the coat as a smooth lobe and
    # leaves the base by vcm_rough_sample's cosine sample of the rough lobes alone.
    "smooth glass, plastic with a smooth coat": (dict(kind="dielectric"),
                                                 dict(kind="plastic", roughness=0.1)),
}


@pytest.mark.parametrize("case", list(EQUILIBRIUM_CASES))
def test_vcm_white_object_in_clear_glass_is_invisible(glslppm, case):
    """test_glass_equilibrium's white sphere inside a clear glass cube under a uniform sky
    of radiance 1 renders as 1 (Kirchhoff), the glass ball's transport through its Fresnel
    chains included: the path tracer has no start-up deficit, so the bound is two-sided, from
    the pixels of the cube's centre, and below 1%."""
    g = glslppm
    glass_args, inner_args = EQUILIBRIUM_CASES[case]
    glass = g.Material(color=(1.0,) * 3, ior=1.5, **glass_args)
    inner = g.Material(color=(1.0,) * 3, **inner_args)
    image = vcm_render(g, equilibrium_tests.equilibrium_scene(g, glass, inner), 32, 96,
                       seed=2, max_bounces=256)
    mean, bound = mean_and_bound(image[10:22, 10:22].mean(axis=2))
    print(f"  {case}: centre {mean:.5f}, bound {bound:.5f}")
    assert bound < 0.008, bound
    assert abs(mean - 1.0) < bound, (mean, bound)


@pytest.mark.parametrize("kind,roughness", [("conductor", 0.3), ("conductor", 0.6),
                                            ("plastic", 0.3), ("translucent", 0.0)])
def test_vcm_white_lobe_under_uniform_sky_reads_one(glslppm, kind, roughness):
    """test_glossy_sky's closed cube of white lossless material under a world of radiance 1
    reads 1 from every angle (glossy threshold 0.2: the lobes are rough vertices, where the
    world's light sample and the BSDF sample are combined by MIS; the translucent cube's light
    comes through two walls, the second vertex's light sample)."""
    g = glslppm
    material = g.Material(kind, color=(1.0,) * 3, roughness=roughness)
    for angle in (0, 40, 75):
        image = vcm_render(g, glossy_sky_tests.sky_cube(g, material, angle), 32, 128, seed=4,
                           glossy_threshold=0.2)
        mean, bound = mean_and_bound(image.mean(axis=2))
        print(f"  {kind} {roughness} at {angle} degrees: {mean:.5f}, bound {bound:.5f}")
        assert bound < 0.008, bound
        assert abs(mean - 1.0) < bound, (angle, mean, bound)


def test_vcm_passes_are_independent(glslppm):
    """A pass is a function of (seed, pass index): passes 0-7 in one run give the mean of
    the films of passes 0-3 and 4-7 run apart (to float rounding)."""
    g = glslppm
    scene = furnace_scene(g, 0.5, 1.0)

    def film(indices):
        r = g.Renderer(scene, g.Settings(width=16, height=16, seed=4, estimator="vcm"))
        r.run_passes(indices)
        image = r.film()[..., :3].astype(np.float64)
        r.close()
        return image

    whole = film(list(range(8)))
    halves = 0.5 * (film([0, 1, 2, 3]) + film([4, 5, 6, 7]))
    assert np.abs(whole - halves).max() <= 1e-5 * np.abs(whole).max()
    assert np.abs(film([0, 1]) - film([2, 3])).max() > 1e-3  # the passes do differ


@pytest.mark.parametrize("settings,feature", [
    (dict(passes=["depth", "direct"]), "render pass 'direct' \\(the light split"),
    (dict(direct_light="photons"), "direct_light"),
])
def test_vcm_names_the_settings_it_does_not_support(glslppm, settings, feature):
    g = glslppm
    with pytest.raises(ValueError, match=f"estimator vcm: {feature}"):
        g.Renderer(furnace_scene(g, 0.5, 1.0),
                   g.Settings(width=8, height=8, estimator="vcm", **settings))


def test_vcm_names_light_linking_as_not_supported(glslppm):
    """Light groups render under VCM (test_light_groups' test_vcm_*); light linking does not
    yet, and says so."""
    g = glslppm
    scene = test_light_linking.two_panels(g)
    with pytest.raises(ValueError, match="estimator vcm: light linking"):
        g.Renderer(scene, g.Settings(width=8, height=8, estimator="vcm"))


def test_cli_renders_vcm(glslppm, tmp_path):
    """glslppm-render --estimator vcm: the built-in scene, its statistics naming vcm and a
    finite image."""
    out = tmp_path / "vcm.exr"
    result = subprocess.run([os.path.join(BUILD, "glslppm-render"), "--width", "32", "--height",
                             "24", "--passes", "2", "--estimator", "vcm", "--out", str(out),
                             "--json"], capture_output=True, text=True, timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    stats = json.loads(result.stdout)
    assert stats["passes"] == 2 and "estimator=vcm" in stats["variant"], stats
    image, header = glslppm.read_exr(str(out))
    assert image.shape == (24, 32, 4) and np.isfinite(image).all()
    assert image[..., :3].max() >= 16.9  # the ceiling light seen directly


def test_vcm_farm_chunks_merge_into_the_whole_render(glslppm, tmp_path):
    """glslppm-render --estimator vcm in two chunks of passes (0-2, 3-5), merged by
    glslppm-merge, is the 6-pass render to test_farm_merge's bound (a few 2^-24)."""
    g = glslppm
    size = ["--width", "32", "--height", "24", "--estimator", "vcm"]

    def render(name, *extra):
        path = str(tmp_path / name)
        result = subprocess.run([os.path.join(BUILD, "glslppm-render"), *size, "--out", path,
                                 *extra], capture_output=True, text=True, timeout=300, cwd="/")
        assert result.returncode == 0, result.stderr
        return path

    whole = render("whole.exr", "--passes", "6")
    first = render("first.exr", "--passes", "3")
    second = render("second.exr", "--passes", "3", "--first-pass", "3")
    merged = str(tmp_path / "merged.exr")
    result = subprocess.run([os.path.join(BUILD, "glslppm-merge"), second, first, "-o", merged],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    a, header = g.read_exr(merged)
    b, _ = g.read_exr(whole)
    assert header["glslppm.passes"] == "6"
    scale = np.maximum(np.abs(a), np.abs(b))
    d = np.divide(np.abs(a - b), scale, out=np.zeros_like(scale), where=scale > 0)
    assert float(d.max()) <= 1e-6, float(d.max())
    c, _ = g.read_exr(first)
    assert float(np.abs(c - b).max()) > 1e-3  # the chunks do differ
