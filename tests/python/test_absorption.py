"""Absorption inside glass (Beer-Lambert) against closed forms: light that crosses a slab of
thickness d keeps exp(-sigma_a d) of itself, in the eye paths (an emitter seen through the
slab) and in the photons (a floor lit by the sun through it), for two thicknesses.

A dielectric of index 1 has no Fresnel reflection and does not bend rays: the slab is then
pure Beer-Lambert, and every eye path crosses it the same way (no noise at all). At index
1.5 the internal reflections add up to (1 - R)^2 tau / (1 - R^2 tau^2), tau = exp(-sigma d).
"""
import math

import numpy as np
import pytest

from conftest import look_at, merge, quad
from scene_builders import placement, unit_cube

SIGMA = np.array([0.2, 0.7, 1.6])  # per unit length, one per channel


def outward_box(lo, hi):
    """The six faces of an axis-aligned box, wound to face out (a closed glass object)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    return [quad((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),  # bottom, -z
            quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),  # top, +z
            quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),  # -y
            quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),  # +y
            quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),  # -x
            quad((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1))]  # +x


def slab_parts(thickness, material, z_bottom=0.0, half=5.0):
    return [(p, t, material) for p, t in
            outward_box((-half, -half, z_bottom), (half, half, z_bottom + thickness))]


def test_box_faces_point_outwards():
    for p, t in outward_box((0, 0, 0), (1, 1, 1)):
        n = np.cross(p[t[0][1]] - p[t[0][0]], p[t[0][2]] - p[t[0][0]])
        assert np.dot(n, p.mean(axis=0) - 0.5) > 0


def emitter_through_slab(g, thickness, glass, size=32, passes=16):
    """The mean radiance of an emitter (radiance 1) seen head-on through the slab."""
    light = quad((-9, -9, -2), (9, -9, -2), (9, 9, -2), (-9, 9, -2))  # facing +z
    p, t, ids = merge(*slab_parts(thickness, 0), (*light, 1))
    scene = g.Scene(p, t, material_ids=ids,
                    materials=[glass, g.Material("diffuse", color=(0, 0, 0), emission=(1, 1, 1))],
                    camera=g.Camera(look_at((0, 0, 5), (0, 0, 0)), projection="orthographic",
                                    ortho_scale=1.0))
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=1024,
                                     max_bounces=1024, hash="exact", seed=2))
    r.run(passes)
    image = r.film()[..., :3].astype(np.float64)
    assert np.isfinite(image).all()
    return image.mean(axis=(0, 1)), size * size * passes, r.stats()


@pytest.mark.parametrize("thickness", [0.5, 1.5])
def test_eye_path_through_index_one_slab_keeps_exp_minus_sigma_d(glslppm, thickness):
    """Index 1: no reflection, no bending; every pixel sees exp(-sigma d) of the emitter. The
    paths are deterministic, so the bound is float rounding (1e-4), not noise."""
    g = glslppm
    glass = g.Material("dielectric", color=(1, 1, 1), ior=1.0, absorption=tuple(SIGMA))
    measured, _, stats = emitter_through_slab(g, thickness, glass)
    assert "absorption" in stats["variant"].split(",")
    expected = np.exp(-SIGMA * thickness)
    print(f"  measured/expected - 1: {measured / expected - 1.0}")
    np.testing.assert_allclose(measured, expected, rtol=1e-4)


@pytest.mark.parametrize("tint_reflection", [False, True])
def test_eye_path_through_glass_slab_sums_absorbed_internal_reflections(glslppm,
                                                                        tint_reflection):
    """Index 1.5, thickness 0.5: (1 - R)^2 tau / (1 - R^2 tau^2) of the emitter, R = 0.04. Each
    path is a Bernoulli draw (reflect or refract) times its tau^k: the bound is 5 standard
    deviations of the mean of those draws, about 0.3%; a 1% bias is over 15."""
    g = glslppm
    d, ior = 0.5, 1.5
    glass = g.Material("dielectric", color=(1, 1, 1), ior=ior, absorption=tuple(SIGMA),
                       tint_reflection=tint_reflection)
    measured, samples, stats = emitter_through_slab(g, d, glass, size=64, passes=64)
    r = ((ior - 1) / (ior + 1)) ** 2
    tau = np.exp(-SIGMA * d)
    expected = (1 - r) ** 2 * tau / (1 - r * r * tau * tau)
    p = (1 - r) ** 2  # the probability of the straight-through path, which carries ~all
    bound = 5.0 * math.sqrt(p * (1 - p) / samples) / p
    print(f"  measured/expected - 1: {measured / expected - 1.0}, bound {bound:.4f}")
    assert bound < 0.004
    assert np.all(np.abs(measured / expected - 1.0) < bound), (measured, expected)


@pytest.mark.parametrize("instancing", ["two-level", "flattened"])
def test_scaled_instance_absorbs_over_its_world_thickness(glslppm, instancing):
    """The slab as a unit cube instanced with scale (10, 10, 0.8): light runs 0.8 world units
    inside, whatever the instance's own units (as Cycles integrates along world rays): still
    exp(-sigma 0.8), deterministic at index 1 (bound 1e-4)."""
    g = glslppm
    d = 0.8
    light_p, light_t = quad((-9, -9, -2), (9, -9, -2), (9, 9, -2), (-9, 9, -2))
    scene = g.Scene(light_p, light_t,
                    materials=[g.Material("diffuse", color=(0, 0, 0), emission=(1, 1, 1)),
                               g.Material("dielectric", color=(1, 1, 1), ior=1.0,
                                          absorption=tuple(SIGMA))],
                    instances=np.array([placement((0, 0, 1), 0.0, (10, 10, d), (0, 0, 0))],
                                       np.float32),
                    instance_mesh=np.array([0], np.uint32),
                    instance_material_offset=np.array([1], np.uint32),
                    instance_meshes=[unit_cube()],
                    camera=g.Camera(look_at((0, 0, 5), (0, 0, 0)), projection="orthographic",
                                    ortho_scale=1.0))
    r = g.Renderer(scene, g.Settings(width=16, height=16, photons_per_pass=1024, seed=2,
                                     instancing=instancing))
    r.run(4)
    measured = r.film()[..., :3].astype(np.float64).mean(axis=(0, 1))
    print(f"  {instancing}: measured/expected - 1: {measured / np.exp(-SIGMA * d) - 1.0}")
    np.testing.assert_allclose(measured, np.exp(-SIGMA * d), rtol=1e-4)


def test_clear_glass_compiles_no_absorption(glslppm):
    g = glslppm
    glass = g.Material("dielectric", color=(1, 1, 1), ior=1.0)
    measured, _, stats = emitter_through_slab(g, 0.5, glass, size=8, passes=2)
    assert "absorption" not in stats["variant"].split(",")
    np.testing.assert_allclose(measured, 1.0, rtol=1e-4)


def floor_under_slab(g, thickness, sigma, size=48, passes=24, photons=65536):
    """The irradiance on a floor (albedo 0.5) lit by a sun of strength 3 straight down
    through a slab of index 1 hidden from the camera, photons only (as tests/python/
    test_lights.py measures the sun)."""
    albedo, strength, half = 0.5, 3.0, 1.5
    e = half * 1.05
    floor = quad((-e, -e, 0), (e, -e, 0), (e, e, 0), (-e, e, 0))
    p, t, ids = merge((*floor, 0), *slab_parts(thickness, 1, z_bottom=0.5, half=2.0))
    glass = g.Material("dielectric", color=(1, 1, 1), ior=1.0, absorption=tuple(sigma),
                       visible_to_camera=False)
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 4.0
    scene = g.Scene(p, t, material_ids=ids,
                    materials=[g.Material("diffuse", color=(albedo,) * 3), glass],
                    lights=[g.Light("sun", power=strength, direction=(0, 0, -1))],
                    camera=g.Camera(to_world, projection="orthographic", ortho_scale=2 * half))
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=photons,
                                     initial_radius=0.08, seed=3, hash="exact",
                                     direct_light="photons"))
    r.run(passes)
    film = r.film()[..., :3].astype(np.float64)
    assert np.isfinite(film).all()
    return film[4:-4, 4:-4] * math.pi / albedo / strength


@pytest.mark.parametrize("thickness", [0.3, 1.0])
def test_photons_through_slab_keep_exp_minus_sigma_d(glslppm, thickness):
    """The floor's irradiance behind the slab is exp(-sigma d) of the clear slab's. With one
    seed the photons follow the same paths with and without absorption (index 1: nothing
    random depends on the flux), so the ratio is exact to float rounding (bound 1e-4).

    Not against E exp(-sigma d) itself: a photon crosses the slab in three passes (one
    bounce per pass, path regeneration), so those emitted in the last passes are counted
    but have not arrived: the clear slab's floor reads 0.92 E after 24 passes (measured;
    1.00 E without the slab), a transient the same with and without absorption."""
    g = glslppm
    clear = floor_under_slab(g, thickness, (0.0, 0.0, 0.0))
    absorbed = floor_under_slab(g, thickness, SIGMA)
    tau = np.exp(-SIGMA * thickness)
    ratio = absorbed.mean(axis=(0, 1)) / clear.mean(axis=(0, 1))
    print(f"  ratio/tau - 1: {ratio / tau - 1}, clear floor / E: {clear.mean():.4f}")
    np.testing.assert_allclose(ratio, tau, rtol=1e-4)
    # The photons did reach the floor: the clear slab passes most of the sun's E.
    assert 0.85 < clear.mean() < 1.0


def test_negative_absorption_is_an_error_naming_it(glslppm):
    g = glslppm
    p, t = quad((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))
    scene = g.Scene(p, t, materials=[g.Material("dielectric", absorption=(0.1, -1.0, 0.0))],
                    camera=g.Camera(look_at((0, 0, 5), (0, 0, 0))))
    with pytest.raises(ValueError, match=r"materials\[0\]\.absorption.*negative"):
        g.Renderer(scene, g.Settings(width=8, height=8))
