"""The flux of a glass-ball caustic: the photons that reach a floor through the ball against
the ball's closed form, and the rendered caustic against the photons it was estimated from.

A caustic's rendered flux can go wrong in two places: in the photons' transport through the
glass (Fresnel, refraction, the shading normals of a tessellated sphere), or in the density
estimate that turns the floor's photons into radiance (the gather radius at a caustic's
sharp edge). The two tests separate them.
"""
import math

import numpy as np
import pytest

from closed_forms import fresnel_dielectric
from conftest import look_at, merge, quad, sphere
from scene_builders import floor_footprints, glass_ball_beam, grow, pixel_of

IOR = 1.5


def ball_floor_paths(b, radius, height, ior, max_internal):
    """A ray falling straight down at distance b from the axis of a ball (centre `height` above
    the floor y = 0): every path by which it leaves the ball towards the floor, as (weight,
    distance from the axis where it lands; inf where it goes up). The ray stays in its
    meridional plane, so the plane's 2D optics is exact: first the reflection off the outside,
    then the ray refracted in (1 - F) and out after k internal reflections, (1 - F) F^k (1 - F)
    (the internal angle is the same at every bounce, so is F)."""
    b = np.asarray(b, dtype=np.float64)
    paths = []

    def land(p, d, w):
        down = d[:, 1] < 0.0
        t = np.where(down, -p[:, 1] / np.where(down, d[:, 1], -1.0), 0.0)
        return np.where(down, w, 0.0), np.where(down, np.abs(p[:, 0] + t * d[:, 0]), np.inf)

    y = np.sqrt(np.maximum(radius * radius - b * b, 0.0))
    p = np.stack([b, height + y], axis=-1)
    n = np.stack([b, y], axis=-1) / radius
    d = np.stack([np.zeros_like(b), -np.ones_like(b)], axis=-1)
    cos_i = n[:, 1]
    f, cos_t = fresnel_dielectric(cos_i, 1.0 / ior)
    paths.append(land(p, d + 2.0 * cos_i[:, None] * n, f))
    eta = 1.0 / ior
    d = eta * d + (eta * cos_i - cos_t)[:, None] * n
    w = 1.0 - f
    centre = np.array([0.0, height])
    for _ in range(max_internal + 1):
        p = p + (2.0 * radius * cos_t)[:, None] * d  # a chord of a circle at angle cos_t
        n = (p - centre) / radius
        c = np.clip(np.sum(d * n, axis=-1), 0.0, 1.0)
        f_out, cos_out = fresnel_dielectric(c, ior)
        out = ior * d - (ior * c - cos_out)[:, None] * n
        paths.append(land(p, out, w * (1.0 - f_out)))
        w = w * f_out
        d = d - 2.0 * c[:, None] * n
    return paths


def ball_landing_area(rho_max, radius, height, ior, max_internal, rings=200_000):
    """The area of a parallel beam's cross-section whose light lands on the floor within
    rho_max of the ball's axis, weighted by Fresnel: the integral over the ball's projected
    disc of the landing paths' weights, 2 pi int b w(b) [rho(b) < rho_max] db, by the midpoint
    rule on equal-area rings (a rho step at a ring only moves the sum by 1 / rings)."""
    b = radius * np.sqrt((np.arange(rings) + 0.5) / rings)
    total = 0.0
    for w, rho in ball_floor_paths(b, radius, height, ior, max_internal):
        total += np.sum(np.where(rho < rho_max, w, 0.0))
    return math.pi * radius * radius * total / rings


def inward_box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    return [quad((x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0)),  # floor, facing up
            quad((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)),
            quad((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)),
            quad((x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1)),
            quad((x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)),
            quad((x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0))]


@pytest.mark.slow("10.5 million photons read back pass by pass to hold the Fresnel flux "
                  "to its bound")
def test_glass_ball_photon_flux_matches_fresnel_closed_form(glslppm):
    """A parallel beam of radius 0.7 falls straight down onto a glass ball of radius 0.5
    (centre 1 above the floor) inside a black box. Every photon is stored where it first lands;
    those that passed the ball beside it carry the beam's irradiance over the beam's area
    outside the ball's silhouette (a 2n-gon: the tessellated equator), so the flux of the
    photons through the ball that land within rho of the axis, over the flux of those that
    passed beside it, is ball_landing_area(rho) / (pi 0.7^2 - silhouette area). The ratio
    needs no emitted count and no kernel."""
    g = glslppm
    radius, height, beam, rings = 0.5, 1.0, 0.7, 64
    faces = inward_box((-3.0, 0.0, -3.0), (3.0, 4.0, 3.0))
    ball_p, ball_t, ball_n = sphere((0.0, height, 0.0), radius, rings, 2 * rings)
    positions, indices, ids = merge(*[(p, t, 0) for p, t in faces], (ball_p, ball_t, 1))
    face_normals = []
    for p, _ in faces:
        e = np.cross(p[1] - p[0], p[2] - p[0])
        face_normals.append(np.repeat((e / np.linalg.norm(e))[None], len(p), axis=0))
    normals = np.concatenate(face_normals + [ball_n]).astype(np.float32)
    materials = [g.Material("diffuse", color=(0.0, 0.0, 0.0)),
                 g.Material("dielectric", color=(1.0, 1.0, 1.0), ior=IOR)]
    # A spot light of radius `beam` and a 2 mrad cone: parallel to 1e-3 rad.
    light = g.Light("spot", power=1000.0, position=(0.0, 3.5, 0.0), direction=(0.0, -1.0, 0.0),
                    spot_size=0.002, spot_blend=0.0, radius=beam)
    camera = g.Camera(look_at((0.0, 0.3, 0.0), (0.0, 0.0, 0.0), up=(0, 0, -1)),
                      projection="orthographic", ortho_scale=2.0)
    scene = g.Scene(positions, indices, normals=normals, material_ids=ids,
                    materials=materials, lights=[light], camera=camera)
    # Photons alone: the photons that pass beside the ball land on their first hit, which
    # light sampling leaves unstored.
    r = g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=131072, seed=1,
                                     direct_light="photons"))
    limits = [0.2, 0.4, 1.0]
    through = np.zeros(len(limits))
    through_count = np.zeros(len(limits))
    beside, beside_count = 0.0, 0
    # Paths regenerate (one bounce per pass), so the photons through the ball land two passes
    # after those beside it: counted from the start, the last passes' are missing (3% here).
    # After 20 passes the threads' path starts have spread out evenly (path lengths 1, 2, 3
    # and more mix them); from then on each kind is stored at its rate per path started.
    r.run(20)
    for _ in range(60):
        r.run(1)
        ph = r.photons()
        ph = ph[(ph[:, 11] > 0.0) & (np.abs(ph[:, 1]) < 1e-5)].astype(np.float64)
        # Photons that passed beside the ball arrive within the cone's 1e-3 rad of vertical.
        straight = ph[:, 5] > math.cos(2e-3)
        rho = np.hypot(ph[:, 0], ph[:, 2])
        carries = ph[:, 8] > 0.0
        beside += ph[straight, 8].sum()
        beside_count += int((straight & carries).sum())
        for k, rho_max in enumerate(limits):
            inside = ~straight & (rho < rho_max)
            through[k] += ph[inside, 8].sum()
            through_count[k] += (inside & carries).sum()

    segments = 2 * rings
    silhouette = 0.5 * segments * radius * radius * math.sin(2.0 * math.pi / segments)
    beside_area = math.pi * beam * beam - silhouette
    # 16 bounces at most (Settings' max_bounces): in, k internal reflections, out, floor.
    expected = np.array([ball_landing_area(m, radius, height, IOR, max_internal=13)
                         for m in limits]) / beside_area
    measured = through / beside
    # Noise: the photons that carry flux carry the same (a few at the float edge of the cone
    # carry none, on both sides alike), so the ratio is one of multinomial counts n1, n2 of
    # independent paths: var(ln n1 / n2) = 1 / n1 + 1 / n2, sigma 0.11-0.14% here. The
    # 64-ring smooth-normal sphere itself transports within 0.05% of the analytic ball in
    # this set-up (measured: -0.03%, +0.03%, 0.00% at 3.3M stored photons); 0.15% allows
    # for it. The bound, 0.15% + 4 sigma, stays below 0.75%: a 1% bias lies 2.2 sigma
    # (rho < 0.2) to 3.7 sigma (rho < 1) beyond it and fails.
    sigma = np.sqrt(1.0 / through_count + 1.0 / beside_count)
    bound = 0.0015 + 4.0 * sigma
    assert np.all(bound < 0.0075), bound
    error = measured / expected - 1.0
    assert np.all(np.abs(error) <= bound), (measured, expected, error, bound)


def test_rendered_caustic_flux_equals_its_photons(glslppm):
    """The built-in caustic scene's set-up (ball of radius 0.5 on a white floor, the same
    camera), lit by a parallel beam from the light's place through the ball's centre, so the
    ball focuses it near the floor into a small spot with sharp edges and a halo. Over the
    caustic (and 1, 3 and 12 pixels around it) the rendered flux, sum of pi L / albedo times
    each pixel's floor area, must equal the flux of the very photons the renderer stored there,
    counted at their exact positions: the same photons and the same emitted count, so only the
    density estimate (gather radius, progressive update, film) can tell them apart."""
    g = glslppm
    size = 256
    scene, to_world, fov_x, centre, radius, albedo = glass_ball_beam(g, ior=IOR)
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=65536, hash="exact",
                                     seed=1))
    photon_flux = np.zeros(size * size)
    for _ in range(40):
        r.run(1)
        ph = r.photons()
        ph = ph[(ph[:, 11] > 0.0) & (np.abs(ph[:, 1]) < 1e-5)].astype(np.float64)
        pixel = pixel_of(ph[:, :3], to_world, fov_x, size)
        inside = pixel >= 0
        photon_flux += np.bincount(pixel[inside], weights=ph[inside, 8], minlength=size * size)
    photon_flux = photon_flux.reshape(size, size) / r.stats()["photons_emitted"]
    area, visible = floor_footprints(to_world, fov_x, size, centre, radius)
    rendered_flux = r.film()[..., 0].astype(np.float64) * (math.pi / albedo) * area
    irradiance = np.where(visible, photon_flux / area, 0.0)
    caustic = visible & (irradiance > 0.05 * irradiance.max())  # about 85 pixels
    ratios = []
    for margin in [0, 1, 3, 12]:
        region = grow(caustic, margin) & visible
        ratios.append(rendered_flux[region].sum() / photon_flux[region].sum())
    ratios = np.array(ratios)
    # The gather disc (initial radius two pixel footprints, 0.03 here) blurs the spot's flux
    # outwards: the caustic alone keeps 98.5-99.2% of it, with 3 pixels 99.5-99.7%, with 12
    # (several initial radii) 99.7-100.0% (measured with seeds 1-3; what is still missing was
    # blurred onto the pixels at the ball's silhouette, left out). Blur moves flux, it cannot
    # add any: no region may hold more than its photons, beyond the noise (the spread over
    # seeds, 0.15%, from where each pass's jittered visible points fall). With 12 pixels the
    # estimate must hold all of it within 0.5%, so a 1% bias of the density estimate fails.
    assert np.all(ratios <= 1.005), ratios
    assert ratios[-1] >= 0.995, ratios
