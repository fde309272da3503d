"""Cycles' Light Paths limits (docs/bounces.md) against closed forms.

Cycles counts a path's scatters in its total and in its kind (diffuse, glossy,
transmission) and keeps the path's light while the scatters before its last one are within
every limit, so a limit N admits N + 1 scatters of its kind on a path: 0 keeps direct light.
"""
import math

import numpy as np
import pytest

from closed_forms import furnace_scene
from conftest import look_at, merge, quad


def startup_ratio(albedo, limit, passes):
    """Photons stored per photon path started after `passes` passes of path regeneration,
    with light sampling (a path's first landing is not stored): each thread's path lands
    once a pass, goes on with probability a (Russian roulette on the albedo) while the
    limit lets a later photon count, and starts anew otherwise. The thread's landing index
    is a Markov chain that starts at 1; in its stationary state the ratio is
    sum_{h=2..limit+1} a^(h-1), and the finite run's is lower by the paths still in
    flight."""
    states = limit + 1  # landing index 1..limit+1
    p = np.zeros(states)
    p[0] = 1.0
    started = stored = 0.0
    for _ in range(passes):
        started += p[0]
        stored += p[1:].sum()
        nxt = np.zeros(states)
        for h in range(states):
            go_on = albedo if h + 1 < states else 0.0
            if h + 1 < states:
                nxt[h + 1] += p[h] * go_on
            nxt[0] += p[h] * (1.0 - go_on)
        p = nxt
    return stored / started


@pytest.mark.parametrize("which,limit", [("diffuse", 0), ("diffuse", 1), ("diffuse", 2),
                                         ("diffuse", 4), ("total", 2)])
def test_diffuse_furnace_follows_the_limit(glslppm, which, limit):
    """Inside a closed diffuse sphere of albedo a = 0.5 that emits Le = 1, a diffuse (or
    total) limit N gives L = Le sum_{k=0..N+1} a^k: the emission seen, direct light (a Le,
    by light sampling) and N more bounces, as Cycles renders it (its diffuse 0 is direct
    light only). The photons' part is corrected for path regeneration's start-up
    (startup_ratio). The totals differ by a^(N+1)/2 between neighbouring limits (3.1% of L
    at N = 4): a limit off by one fails."""
    g = glslppm
    albedo, emission, passes = 0.5, 1.0, 200
    kind = {"diffuse": "max_diffuse_bounces", "total": "max_bounces"}[which]
    r = g.Renderer(furnace_scene(g, albedo, emission),
                   g.Settings(width=24, height=24, photons_per_pass=8192, seed=3,
                              hash="exact", **{kind: limit}))
    r.run(passes)
    image = r.film()[..., :3].astype(np.float64)
    r.close()
    stationary = sum(albedo ** (h - 1) for h in range(2, limit + 2))
    closed_form = emission * sum(albedo ** k for k in range(limit + 2))
    expected = emission * (1.0 + albedo + albedo * startup_ratio(albedo, limit, passes))
    assert expected == pytest.approx(
        closed_form - emission * albedo * (stationary - startup_ratio(albedo, limit, passes)))
    error = image.mean() / expected - 1.0
    print(f"  {which} {limit}: L {image.mean():.5f}, closed form {closed_form:.5f}, "
          f"after start-up {expected:.5f}, error {error:+.5f}")
    # Measured (seed 3): |error| <= 0.04% for every N. A 1% bias fails.
    assert abs(error) < 0.004, (image.mean(), expected)
    blocks = image.reshape(6, 4, 6, 4, 3).mean(axis=(1, 3, 4))
    assert np.all(np.abs(blocks / expected - 1.0) <= 0.03), blocks


@pytest.mark.parametrize("limit", [1, 2])
def test_pppm_furnace_follows_the_diffuse_limit(glslppm, limit):
    """PPPM traces each pass's photon paths whole, in max_bounces + 1 steps: no start-up to
    correct, L = Le sum_{k=0..N+1} a^k for a diffuse limit N (a = 0.5, Le = 1). Measured
    (seed 3): +0.03% (N = 1), +0.13% (N = 2); a 1% bias fails."""
    g = glslppm
    albedo, emission = 0.5, 1.0
    r = g.Renderer(furnace_scene(g, albedo, emission),
                   g.Settings(width=24, height=24, photons_per_pass=8192, seed=3,
                              estimator="pppm", max_diffuse_bounces=limit))
    r.run(100)
    image = r.film()[..., :3].astype(np.float64)
    r.close()
    expected = emission * sum(albedo ** k for k in range(limit + 2))
    error = image.mean() / expected - 1.0
    print(f"  pppm diffuse {limit}: L {image.mean():.5f}, closed form {expected:.5f}, "
          f"error {error:+.5f}")
    assert abs(error) < 0.004, (image.mean(), expected)


def mirror_corridor(g, reflectance, emission):
    """Two emissive mirrors (conductor of colour c, emission Le) facing each other 2 apart,
    200 wide, the camera halfway looking at one with a 1 degree view: every eye ray goes
    back and forth between them, meeting Le c^(j-1) at its j-th surface."""
    far, near = quad((-100, -100, -1), (100, -100, -1), (100, 100, -1), (-100, 100, -1)), \
        quad((-100, -100, 1), (-100, 100, 1), (100, 100, 1), (100, -100, 1))
    p, t, ids = merge((*far, 0), (*near, 0))
    mirror = g.Material("conductor", color=(reflectance,) * 3, emission=(emission,) * 3)
    camera = g.Camera(look_at((0, 0, 0), (0, 0, -1)), fov_x=math.radians(1.0))
    return g.Scene(p, t, material_ids=ids, materials=[mirror], camera=camera)


@pytest.mark.parametrize("glossy", [0, 1, 3])
def test_mirror_corridor_follows_the_glossy_limit(glslppm, glossy):
    """A glossy limit G lets the eye ray reflect G + 1 times and takes the emission of the
    surface it then meets: L = Le sum_{k=0..G+1} c^k exactly in every pixel (no random
    choice on the way). The total (16) and the other kinds do not cut it."""
    g = glslppm
    c, le = 0.5, 1.0
    r = g.Renderer(mirror_corridor(g, c, le),
                   g.Settings(width=8, height=8, photons_per_pass=1024, seed=1,
                              max_glossy_bounces=glossy, max_diffuse_bounces=0,
                              max_transmission_bounces=0))
    r.run(2)
    film = r.film()[..., :3]
    r.close()
    expected = le * sum(c ** k for k in range(glossy + 2))
    np.testing.assert_allclose(film, expected, rtol=1e-5)


def glass_sheets(g, sheets, tint, sheet_emission, sky):
    """`sheets` parallel glass sheets of IOR 1 (every ray goes straight through, taking the
    tint t) at z = -1, -2, ..., each emitting Le_s, before a uniform sky Ls; the camera at
    the origin looks through them with a 10 degree view."""
    parts = [(*quad((-50, -50, -k), (50, -50, -k), (50, 50, -k), (-50, 50, -k)), 0)
             for k in range(1, sheets + 1)]
    p, t, ids = merge(*parts)
    glass = g.Material("dielectric", color=(tint,) * 3, ior=1.0,
                       emission=(sheet_emission,) * 3)
    camera = g.Camera(look_at((0, 0, 0), (0, 0, -1)), fov_x=math.radians(10.0))
    return g.Scene(p, t, material_ids=ids, materials=[glass], environment=(sky,) * 3,
                   camera=camera)


@pytest.mark.parametrize("transmission", [0, 1, 2, 4])
def test_glass_sheets_follow_the_transmission_limit(glslppm, transmission):
    """Through three sheets (tint t, emission Le_s) to the sky (Ls): the ray crosses
    min(3, T + 1) sheets under a transmission limit T, meeting the emission of each sheet
    it reaches and the sky only if it crossed all three:
    L = Le_s sum_{j<min(3, T+2)} t^j + [T >= 2] Ls t^3. Exact in every pixel."""
    g = glslppm
    sheets, tint, le_s, sky = 3, 0.5, 1.0, 8.0
    r = g.Renderer(glass_sheets(g, sheets, tint, le_s, sky),
                   g.Settings(width=8, height=8, photons_per_pass=1024, seed=1,
                              max_transmission_bounces=transmission, max_glossy_bounces=0,
                              max_diffuse_bounces=0))
    r.run(2)
    film = r.film()[..., :3]
    r.close()
    reached = min(sheets, transmission + 2)
    expected = le_s * sum(tint ** j for j in range(reached))
    if transmission + 1 >= sheets:
        expected += sky * tint ** sheets
    np.testing.assert_allclose(film, expected, rtol=1e-5)


def test_settings_take_and_check_the_limits(glslppm):
    g = glslppm
    s = g.Settings(max_bounces=12, max_diffuse_bounces=4, max_glossy_bounces=4,
                   max_transmission_bounces=12)
    assert (s.max_bounces, s.max_diffuse_bounces, s.max_glossy_bounces,
            s.max_transmission_bounces) == (12, 4, 4, 12)
    d = g.Settings()
    assert (d.max_bounces, d.max_diffuse_bounces) == (16, 1024)
    for name in ("max_bounces", "max_diffuse_bounces", "max_glossy_bounces",
                 "max_transmission_bounces"):
        with pytest.raises(Exception, match=name):
            g.Settings(**{name: -1})
        with pytest.raises(Exception, match=name):
            g.Settings(**{name: 1025})
