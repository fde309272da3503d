"""Light groups (docs/light_groups.md, issue 33 item 1): every emitter may belong to a group
(Scene.light_groups; Light.light_group, Material.light_group, Scene.world_light_group), and
each group gets a Combined-like pass (Renderer.light_group_passes) of the light its emitters
give: emission and the world seen by the eye path, light samples and photons (their
emitter's group rides with them from emission on).

Two kinds of check:
- Exact: the groups plus the light of no group split Combined's own sums (the eye stage's
  compensated sum, the gather's tau under the same radius updates), so they add up to
  Combined to float rounding; and the groups change nothing in Combined (bit-identical to
  the same scene without groups).
- Statistical: a group's pass estimates what a render with only its emitters on estimates,
  but with other random numbers (the emitter table differs) and, in SPPM, other radii (they
  shrink with every group's photons), so they agree within noise only. The bounds were
  measured over seeds 1-3 (see each test) and are tight enough that a 1% bias of a group's
  mean fails them.
"""
import json
import math
import os
import subprocess

import numpy as np
import pytest

from conftest import BUILD, look_at, merge, quad, sphere
from test_merge_passes import assert_layers_equal, layers_of, merge as merge_files

RENDER = os.path.join(BUILD, "glslppm-render")
SIZE = dict(width=64, height=64)


def sum_bound(combined):
    """As the light split's (test_render_passes): each part's compensated sum and the film's
    float products round once, a few 1e-7 of the pixel."""
    return 4e-6 * np.abs(combined) + 1e-6 * combined.mean()


def floor_and_wall(g):
    floor = quad((-2, 0, -2), (-2, 0, 2), (2, 0, 2), (2, 0, -2))
    wall = quad((-2, 0, -2), (2, 0, -2), (2, 3, -2), (-2, 3, -2))
    materials = [g.Material("diffuse", color=(0.7, 0.7, 0.7)),
                 g.Material("diffuse", color=(0.5, 0.6, 0.7))]
    return (*floor, 0), (*wall, 1), materials


def two_lights(g, on=(True, True), groups=True):
    """Two point lights of other colours over a floor before a wall: "key" (warm, left) and
    "fill" (cool, right), each in its own group (or none, for the references)."""
    floor, wall, materials = floor_and_wall(g)
    p, t, ids = merge(floor, wall)
    key = g.Light("point", power=60.0, color=(1.0, 0.6, 0.3), position=(-1, 1.5, 0))
    fill = g.Light("point", power=40.0, color=(0.3, 0.6, 1.0), position=(1, 1.0, 0.5))
    if groups:
        key.light_group, fill.light_group = 0, 1
    lights = [light for light, lit in zip((key, fill), on) if lit]
    camera = g.Camera(look_at((0, 1.5, 4), (0, 0.8, 0)), fov_x=0.9)
    scene = g.Scene(p, t, material_ids=ids, materials=materials, lights=lights, camera=camera)
    if groups:
        scene.light_groups = ["key", "fill"]
    return scene


def film(g, scene, passes, **settings):
    r = g.Renderer(scene, g.Settings(**{**SIZE, **settings}))
    r.run(passes)
    image = r.film()[..., :3].astype(np.float64)
    r.close()
    return image


def block_means(image, block=8):
    h, w, c = image.shape
    return image.reshape(h // block, block, w // block, block, c).mean(axis=(1, 3))


def assert_matches(group, reference, mean_bound, block_bound, where=None):
    """The group's pass against a render with only its emitters: the means (over `where`)
    within mean_bound, and the 8x8-pixel blocks that hold light within block_bound of
    their reference (each relative)."""
    if where is None:
        where = np.ones(group.shape[:2], dtype=bool)
    mean, ref = group[where].mean(), reference[where].mean()
    assert ref > 0.0
    assert abs(mean / ref - 1.0) <= mean_bound, (mean, ref)
    if block_bound is not None:
        a, b = block_means(group).sum(axis=-1), block_means(reference).sum(axis=-1)
        lit = b > 0.05 * b.max()
        worst = np.abs(a[lit] / b[lit] - 1.0).max()
        assert worst <= block_bound, worst


def test_two_groups_sum_to_combined_and_each_is_its_light_alone(glslppm):
    """Key and fill in two groups, SPPM with light sampling, 64 passes of 65536 photons:
    the groups sum to Combined to float rounding; each group's mean is a render with only
    its light on to 0.5% (measured over seeds 1-3 of the reference: within 0.13%), and
    each lit 8x8 block to 7% (measured: 4.4% at most: both renders' noise, and SPPM's radii,
    which shrink with both lights' photons in the group's render, blur the floor's edges
    otherwise). A 1% bias fails the mean."""
    g = glslppm
    r = g.Renderer(two_lights(g), g.Settings(seed=3, photons_per_pass=65536, **SIZE))
    r.run(64)
    combined = r.film()[..., :3].astype(np.float64)
    groups = {k: v.astype(np.float64) for k, v in r.light_group_passes().items()}
    assert list(groups) == ["key", "fill"]
    assert "light-groups" in r.stats()["variant"].split(",")
    total = groups["key"] + groups["fill"]
    assert np.all(np.abs(total - combined) <= sum_bound(combined)), np.abs(total - combined).max()
    # Each light gives about half the image's light: neither group is near 0 or Combined.
    for name in groups:
        assert 0.3 < groups[name].mean() / combined.mean() < 0.7
    for name, on in (("key", (True, False)), ("fill", (False, True))):
        alone = film(g, two_lights(g, on, groups=False), 64, seed=1, photons_per_pass=65536)
        assert_matches(groups[name], alone, 0.005, 0.07)
        # The key light is warm, the fill cool: the pass has its light's colour, not the other's.
        red_over_blue = groups[name][..., 0].sum() / groups[name][..., 2].sum()
        assert (red_over_blue > 1.5) if name == "key" else (red_over_blue < 0.7)


def test_groups_leave_combined_bit_identical(glslppm):
    """Groups add passes; Combined is the same numbers as the same scene's without groups
    (the photons' record word changes its encoding, not its value; the eye stage and the
    gather add the same terms in the same order)."""
    g = glslppm
    settings = dict(seed=3, photons_per_pass=16384, **SIZE)
    with_groups = film(g, two_lights(g), 8, **settings)
    without = film(g, two_lights(g, groups=False), 8, **settings)
    assert np.array_equal(with_groups, without)


@pytest.mark.parametrize("settings,bound", [
    ({}, 0.006), ({"direct_light": "photons"}, 0.02), ({"estimator": "pppm"}, 0.01)])
def test_light_of_no_group_is_what_the_groups_leave_out(glslppm, settings, bound):
    """Key in a group, fill in none (one group only): the group is the key light's render
    alone and Combined minus the group the fill light's, for light sampling, photon direct
    light and PPPM, means within `bound`. Measured over seeds 1-2 of the references at 48
    passes: light sampling within 0.35% (a 1% bias of the split fails); photon direct light
    within 1.2%, two seeds of Combined itself 0.4% apart, the fill's part converging (0.3-0.5%
    at 192 passes: SPPM's radii shrink with both lights' photons in the group's render), so
    there a bias below 2% cannot be told from noise at this size."""
    g = glslppm
    floor, wall, materials = floor_and_wall(g)
    p, t, ids = merge(floor, wall)
    key = g.Light("point", power=60.0, color=(1.0, 0.6, 0.3), position=(-1, 1.5, 0))
    key.light_group = 0
    fill = g.Light("point", power=40.0, color=(0.3, 0.6, 1.0), position=(1, 1.0, 0.5))
    lights = [key, fill]
    camera = g.Camera(look_at((0, 1.5, 4), (0, 0.8, 0)), fov_x=0.9)
    scene = g.Scene(p, t, material_ids=ids, materials=materials, lights=lights, camera=camera)
    scene.light_groups = ["key"]
    options = dict(photons_per_pass=65536, **settings)
    r = g.Renderer(scene, g.Settings(seed=3, **SIZE, **options))
    r.run(48)
    combined = r.film()[..., :3].astype(np.float64)
    group = r.light_group_passes()["key"].astype(np.float64)
    assert np.all(group <= combined + sum_bound(combined))
    key_alone = film(g, two_lights(g, (True, False), groups=False), 48, seed=1, **options)
    fill_alone = film(g, two_lights(g, (False, True), groups=False), 48, seed=1, **options)
    assert_matches(group, key_alone, bound, None)
    assert_matches(combined - group, fill_alone, bound, None)


def ball_caustic(g, key=True, fill=True, groups=True):
    """A glass ball (radius 0.5, its centre 0.6 above a white floor) under a point light
    "key" straight above it, which it focuses into a caustic on the floor beneath it, where
    its own shadow keeps the key's direct light out; a point light "fill" off to the side."""
    floor = quad((-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3))
    ball_p, ball_t, ball_n = sphere((0.0, 0.6, 0.0), 0.5, 24, 48)
    positions, indices, ids = merge((*floor, 0), (ball_p, ball_t, 1))
    normals = np.concatenate([np.tile([0.0, 1.0, 0.0], (4, 1)), ball_n]).astype(np.float32)
    materials = [g.Material("diffuse", color=(0.8, 0.8, 0.8)),
                 g.Material("dielectric", color=(1.0, 1.0, 1.0), ior=1.5)]
    top = g.Light("point", power=200.0, position=(0.0, 3.0, 0.0))
    side = g.Light("point", power=50.0, position=(2.0, 2.0, 1.5))
    if groups:
        top.light_group, side.light_group = 0, 1
    lights = [light for light, on in ((top, key), (side, fill)) if on]
    scene = g.Scene(positions, indices, normals=normals, material_ids=ids,
                    materials=materials, lights=lights,
                    camera=g.Camera(look_at((0.0, 2.5, 3.0), (0.0, 0.3, 0.0)), fov_x=0.8))
    if groups:
        scene.light_groups = ["key", "fill"]
    return scene


def grow(mask, pixels):
    out = mask.copy()
    for dy in range(-pixels, pixels + 1):
        for dx in range(-pixels, pixels + 1):
            out |= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    return out


def test_caustic_of_one_group_is_its_light_alone(glslppm):
    """A glass ball's caustic comes from the key light's group: the groups sum to Combined
    to float rounding, and over the caustic (the render's Caustics pass above a tenth of its
    peak, grown by 3 pixels: about 165 pixels) the key's pass matches a render of the key
    alone to 8% in the mean. Noise bound, not bias bound: three seeds of the reference
    spread 6.4% there (0.310-0.330; the group's 0.315), the caustic's photons being few at 64
    pixels and 48 passes, so a 1% bias of the caustic alone cannot be seen at this size (the
    two-light test's 0.5% bound sees one of the photons' groups). The fill's pass holds under
    a third of the key's there. Light tracing is off in both: this test is of the gathered
    caustic (test_light_traced_caustic_goes_to_its_group has the light-traced one)."""
    g = glslppm
    options = dict(photons_per_pass=65536, light_tracing=False, **SIZE)
    r = g.Renderer(ball_caustic(g), g.Settings(seed=3, passes=["caustics"], **options))
    r.run(48)
    combined = r.film()[..., :3].astype(np.float64)
    groups = {k: v.astype(np.float64) for k, v in r.light_group_passes().items()}
    total = groups["key"] + groups["fill"]
    assert np.all(np.abs(total - combined) <= sum_bound(combined)), np.abs(total - combined).max()
    caustics = r.render_pass("caustics").sum(axis=-1)
    caustic = grow(caustics > 0.1 * caustics.max(), 3)
    assert 50 <= caustic.sum() < 0.1 * caustic.size
    key_alone = film(g, ball_caustic(g, fill=False, groups=False), 48, seed=1, **options)
    assert_matches(groups["key"], key_alone, 0.08, None, where=caustic)
    assert groups["fill"][caustic].sum() < 0.33 * groups["key"][caustic].sum()



def test_light_traced_caustic_goes_to_its_group(glslppm):
    """Light tracing on with groups (docs/light_tracing.md): each splat of the glass ball's
    caustic goes into its emitter's group's splats as well (common/light_splats.glsl), whose
    integers partition Combined's. 32^2, SPPM, 32 passes of 262144 photons (seed 3):
    (a) the groups sum to Combined to float rounding (measured 1.8e-7 relative at most);
    (b) each group's image mean is a render with only its light on (seed 1): the key's to
    2% (measured 0.9886), the fill's to 4% (measured 1.0257; its photons are a fifth of the
    pass). Noise bounds, not bias bounds: over group seeds 1-3 at 48 passes the key's ratio
    spread 0.9961-1.0047 and the fill's 0.9951-1.0110, so at this test's cost a 1% bias of
    a group is not resolved (docs/light_groups.md, Not done);
    (c) over the caustic (the Caustics pass of a light-split render above a tenth of its
    peak, grown by 2 pixels: 86 pixels) the key's group holds 0.82 of Combined's light
    (bound 0.75-0.9): the caustic seen there is the key's splats alone (the key's direct
    light is the ball's shadow, and the gather leaves light-traced photons out), so a
    group without splats would hold far less."""
    g = glslppm
    options = dict(width=32, height=32, photons_per_pass=262144)
    r = g.Renderer(ball_caustic(g), g.Settings(seed=3, **options))
    r.run(32)
    stats = r.stats()
    assert "light-tracing" in stats["variant"].split(",")
    # 192 bytes a pixel without groups (48 of them splats), 64 a group, 48 a group's splats.
    assert stats["gpu_bytes_per_pixel"] == 192 + 2 * 64 + 2 * 48
    assert stats["pass_state_bytes"] == g.memory_estimate(
        g.Settings(**options), ball_caustic(g), largest_block=1 << 30)["gpu"]
    combined = r.film()[..., :3].astype(np.float64)
    groups = {k: v.astype(np.float64) for k, v in r.light_group_passes().items()}
    r.close()
    total = groups["key"] + groups["fill"]
    assert np.all(np.abs(total - combined) <= sum_bound(combined)), np.abs(total - combined).max()
    split = g.Renderer(ball_caustic(g), g.Settings(seed=7, passes=["caustics"],
                                                  **{**options, "photons_per_pass": 65536}))
    split.run(8)
    caustics = split.render_pass("caustics").sum(axis=-1)
    split.close()
    caustic = grow(caustics > 0.1 * caustics.max(), 2)
    assert 40 <= caustic.sum() < 0.15 * caustic.size
    share = groups["key"][caustic].sum() / combined[caustic].sum()
    assert 0.75 < share < 0.9, share
    for name, on in (("key", dict(fill=False)), ("fill", dict(key=False))):
        alone = g.Renderer(ball_caustic(g, groups=False, **on), g.Settings(seed=1, **options))
        alone.run(32)
        reference = alone.film()[..., :3].astype(np.float64)
        alone.close()
        assert_matches(groups[name], reference, 0.02 if name == "key" else 0.04, None)


@pytest.mark.parametrize("estimator", ["sppm", "pppm"])
def test_groups_leave_the_light_traced_combined_bit_identical(glslppm, estimator):
    """With light tracing on, the groups only add splats beside Combined's (and the stored
    photon's word carries the group in its float's exponent, from which the gather still
    reads the light-traced class): the ball caustic's Combined is the same bits with and
    without groups, for both estimators (32^2, 8 passes of 16384, seed 3). With (a) of
    test_light_traced_caustic_goes_to_its_group, the groups split this very Combined."""
    g = glslppm
    settings = g.Settings(width=32, height=32, photons_per_pass=16384, seed=3,
                          estimator=estimator)
    films = []
    for groups in (True, False):
        r = g.Renderer(ball_caustic(g, groups=groups), settings)
        r.run(8)
        assert "light-tracing" in r.stats()["variant"].split(",")
        films.append(r.film())
        r.close()
    assert films[0][..., :3].mean() > 0.01
    assert np.array_equal(films[0], films[1])

def world_and_glowing_panel(g, world=True, panel=True, lamp=True, groups=True):
    """A floor under a grey world ("sky"), an emissive panel seen by the camera ("panel",
    two-sided mesh emission) and a point light in no group."""
    floor, wall, materials = floor_and_wall(g)
    glow = quad((-1.8, 0.2, -1.0), (-1.8, 1.4, -1.0), (-0.6, 1.4, -0.6), (-0.6, 0.2, -0.6))
    emissive = g.Material("diffuse", color=(0.0, 0.0, 0.0),
                          emission=(4.0, 2.0, 1.0) if panel else (0.0, 0.0, 0.0))
    if groups:
        emissive.light_group = 1
    p, t, ids = merge(floor, (*glow, 2))
    lights = []
    if lamp:
        lights.append(g.Light("point", power=40.0, position=(1, 1.5, 0.5)))
    scene = g.Scene(p, t, material_ids=ids, materials=[materials[0], materials[1], emissive],
                    lights=lights, environment=(0.3, 0.4, 0.5) if world else (0, 0, 0),
                    camera=g.Camera(look_at((0, 1.5, 4), (0, 0.6, 0)), fov_x=1.0))
    if groups:
        scene.light_groups = ["sky", "panel"]
        scene.world_light_group = 0
    return scene


def test_world_and_emissive_mesh_in_groups(glslppm):
    """The world in group "sky", an emissive mesh in group "panel", a point light in none:
    the sky's pass is the world's render alone (seen directly above the floor, by light
    samples and photons on it), the panel's the panel's alone, and Combined minus both the
    lamp's alone. Means within 1% (measured over seeds 1-3: within 0.4%); where the camera
    sees only the world it holds all of Combined and the panel none (to float rounding).
    (The reference with the lamp alone has no world: the world is black there.)"""
    g = glslppm
    options = dict(photons_per_pass=65536, **SIZE)
    r = g.Renderer(world_and_glowing_panel(g), g.Settings(seed=3, **options))
    r.run(48)
    combined = r.film()[..., :3].astype(np.float64)
    groups = {k: v.astype(np.float64) for k, v in r.light_group_passes().items()}
    sky = np.array([0.3, 0.4, 0.5])
    sky_seen = np.all(np.abs(combined - sky) <= 1e-6, axis=-1)
    assert sky_seen.sum() > 100
    assert np.all(np.abs(groups["sky"][sky_seen] - sky) <= 1e-6)
    assert np.all(groups["panel"][sky_seen] == 0.0)
    references = {
        "sky": dict(panel=False, lamp=False),
        "panel": dict(world=False, lamp=False),
    }
    for name, off in references.items():
        alone = film(g, world_and_glowing_panel(g, groups=False, **off), 48, seed=1, **options)
        assert_matches(groups[name], alone, 0.01, None)
    lamp = film(g, world_and_glowing_panel(g, world=False, panel=False, groups=False), 48,
                seed=1, **options)
    assert_matches(combined - groups["sky"] - groups["panel"], lamp, 0.01, None)


def test_bad_group_indices_are_refused(glslppm):
    g = glslppm
    scene = two_lights(g)
    scene.light_groups = ["key"]  # the fill light's group 1 is gone
    with pytest.raises(ValueError, match=r"lights\[1\]\.light_group: light group 1"):
        g.Renderer(scene, g.Settings(width=8, height=8))
    scene = two_lights(g)
    scene.world_light_group = 2
    with pytest.raises(ValueError, match="world_light_group"):
        g.Renderer(scene, g.Settings(width=8, height=8))


def test_memory_estimate_counts_64_bytes_a_group_and_pixel(glslppm):
    """Each group keeps two (sum, compensation) pairs of vec4 per pixel."""
    g = glslppm
    settings = g.Settings(width=64, height=32, photons_per_pass=4096)
    without = g.memory_estimate(settings, two_lights(g, groups=False), largest_block=1 << 30)
    with_groups = g.memory_estimate(settings, two_lights(g), largest_block=1 << 30)
    assert with_groups["gpu"] - without["gpu"] == 2 * 64 * 64 * 32
    r = g.Renderer(two_lights(g), settings)
    assert r.stats()["pass_state_bytes"] == with_groups["gpu"]


def test_pppm_farm_halves_and_two_workers_carry_the_groups(glslppm, tmp_path):
    """PPPM: two farm halves (passes 0-3 and 3-6, Renderer.write_passes_exr) merged by
    glslppm-merge equal one process with two workers over passes 0-6 in every layer,
    Combined_key and Combined_fill included (test_merge_passes' bound), and the merged
    groups still sum to Combined."""
    g = glslppm
    settings = dict(width=32, height=32, photons_per_pass=4096, estimator="pppm", seed=5,
                    passes=["direct", "indirect"])
    halves = []
    for first in (0, 3):
        r = g.Renderer(two_lights(g), g.Settings(**settings))
        r.run_passes(list(range(first, first + 3)))
        halves.append(tmp_path / f"half_{first}.exr")
        r.write_passes_exr(str(halves[-1]))
        r.close()
    result = merge_files(tmp_path / "merged.exr", *halves)
    assert result.returncode == 0, result.stderr
    whole = g.Renderer(two_lights(g), g.Settings(devices=[0, 0], **settings))
    whole.run_passes(list(range(6)))
    # Each worker takes the next pass when its GPU has caught up (renderer.cpp), so the deal
    # follows the machine's load: [4, 2] in a clean-clone run beside other work. Both ran.
    dealt = [d["passes"] for d in whole.stats()["devices"]]
    assert sum(dealt) == 6 and min(dealt) >= 1, dealt
    images = whole.render_passes(["direct", "indirect"])
    expected = {"Combined": whole.film().astype(np.float64),
                "Direct": images["direct"].astype(np.float64),
                "Indirect": images["indirect"].astype(np.float64)}
    for name, image in whole.light_group_passes().items():
        expected["Combined_" + name] = image.astype(np.float64)
    whole.close()
    merged = layers_of(g, tmp_path / "merged.exr")
    assert {"Combined_key", "Combined_fill"} <= set(merged)
    assert_layers_equal(merged, expected)
    combined = merged["Combined"][..., :3]
    total = merged["Combined_key"] + merged["Combined_fill"]
    assert np.all(np.abs(total - combined) <= sum_bound(combined))
    assert merged["Combined_key"].mean() > 0.2 * combined.mean()


def test_cli_writes_the_group_layers(glslppm, tmp_path):
    """glslppm-render --light-groups 2 --passes-out: the built-in box's ceiling light is
    group0, its (black) world group1; the file holds Combined_group0 and Combined_group1,
    which sum to Combined, all of it the ceiling light's. Two PPPM halves merge into the
    whole's layers."""
    def render(name, *extra):
        path = tmp_path / name
        result = subprocess.run(
            [RENDER, "--width", "32", "--height", "24", "--photons", "4096", "--estimator",
             "pppm", "--light-groups", "2", "--passes-out", "combined", "--out", str(path),
             *extra], capture_output=True, text=True, timeout=300, cwd="/")
        assert result.returncode == 0, result.stderr
        return path
    whole = layers_of(glslppm, render("whole.exr", "--passes", "6"))
    assert set(whole) == {"Combined", "Combined_group0", "Combined_group1"}
    combined = whole["Combined"][..., :3]
    assert combined.mean() > 0.01
    assert np.all(np.abs(whole["Combined_group0"] - combined) <= sum_bound(combined))
    assert np.all(whole["Combined_group1"] == 0.0)
    first = render("first.exr", "--passes", "3")
    second = render("second.exr", "--passes", "3", "--first-pass", "3")
    result = merge_files(tmp_path / "merged.exr", first, second)
    assert result.returncode == 0, result.stderr
    assert_layers_equal(layers_of(glslppm, tmp_path / "merged.exr"), whole)


def test_cli_tiled_frame_writes_the_group_layers(glslppm, tmp_path):
    """glslppm-render --light-groups 2 --passes-out on a frame split in bands of rows
    (--max-block-bytes, as test_tiles): each band's group passes are placed as its Combined
    is, so every layer equals the untiled render's within test_tiles' bound (2e-5 of the
    pixel, 1e-2 floor; measured 3.1e-6 in Combined and Combined_group0, 7 bands of 48 x 6-7
    rows: the groups' splats, 144 B a pixel, are the largest block), and the tiled groups
    sum to the tiled Combined. The built-in box's mirror and glass sphere are light traced
    into group0 (the ceiling light's) in each band; group1 (the black world) is zero."""
    def render(name, *extra):
        path = tmp_path / name
        result = subprocess.run(
            [RENDER, "--width", "48", "--height", "48", "--photons", "4096", "--passes", "8",
             "--light-groups", "2", "--passes-out", "combined", "--out", str(path), "--json",
             *extra], capture_output=True, text=True, timeout=300, cwd="/")
        assert result.returncode == 0, result.stderr
        return layers_of(glslppm, path), json.loads(result.stdout)
    whole, whole_stats = render("whole.exr")
    tiled, tiled_stats = render("tiled.exr", "--max-block-bytes", str(48 * 16 * 4 * 16))
    assert whole_stats["tiles"] == 1 and tiled_stats["tiles"] > 1, tiled_stats["tiles"]
    assert "light-tracing" in whole_stats["variant"].split(",")
    assert set(tiled) == {"Combined", "Combined_group0", "Combined_group1"}
    combined = tiled["Combined"][..., :3]
    assert combined.mean() > 0.01
    assert np.all(np.abs(tiled["Combined_group0"] - combined) <= sum_bound(combined))
    assert np.all(tiled["Combined_group1"] == 0.0)
    for name, image in whole.items():
        difference = np.abs(tiled[name] - image)
        assert (difference <= 2e-5 * np.maximum(np.abs(image), 1e-2)).all(), \
            (name, difference.max())


def vcm_groups(g, scene, seed, passes, vcm_techniques="pt+lt+vm", groups=True):
    """Combined and the groups (none when groups is False) of a VCM render, 16384 light
    paths a pass."""
    r = g.Renderer(scene, g.Settings(seed=seed, estimator="vcm", vcm_techniques=vcm_techniques,
                                     photons_per_pass=16384, **SIZE))
    r.run(passes)
    assert "light-groups" in r.stats()["variant"].split(",") or not groups
    combined = r.film()[..., :3].astype(np.float64)
    parts = {k: v.astype(np.float64) for k, v in r.light_group_passes().items()}
    r.close()
    return combined, parts


@pytest.mark.parametrize("techniques", ["pt+lt+vm", "pt+lt+vm:merge", "pt+lt"])
def test_vcm_groups_split_combined_and_leave_it_bit_identical(glslppm, techniques):
    """VCM (docs/vcm.md): each technique's light goes to its emitter's group as well: the
    eye paths' emission, world and light samples (common/vcm_eye_paths.glsl), light tracing's
    splats (their path's group, common/vcm_light_paths.glsl) and merging's photons (the
    gather's, as PPPM's). The ball caustic's key and fill groups sum to Combined to float
    rounding, and Combined is the same bits as without groups, for the full technique, its
    merges alone (the floor seen through the ball: nonzero in both groups) and path + light
    tracing (64^2, 8 passes, seed 3)."""
    g = glslppm
    combined, groups = vcm_groups(g, ball_caustic(g), 3, 8, techniques)
    total = groups["key"] + groups["fill"]
    assert np.all(np.abs(total - combined) <= sum_bound(combined)), np.abs(total - combined).max()
    assert groups["key"].mean() > 0.0 and groups["fill"].mean() > 0.0
    without, _ = vcm_groups(g, ball_caustic(g, groups=False), 3, 8, techniques, groups=False)
    assert np.array_equal(combined, without)


def test_vcm_groups_are_each_their_lights_alone(glslppm):
    """VCM with merging, 64^2, 128 passes: each group's mean against a render with only its
    emitters on (seed 1): the ball caustic's key (a point light through glass: light tracing's
    splats and the merges) and fill, the sky (the world), the panel (an emissive mesh) and,
    in no group, the lamp (Combined minus the groups). Measured over seeds 3-5: key within
    0.30%, fill 0.47%, sky 0.04%, panel 0.35%, lamp 0.61%. Bounds: 1% for key and panel,
    0.5% for the sky, so a 1% bias fails them; 1.2% for the fill and the lamp, whose paths are
    the noisiest (a fifth of the ball scene's light; a point light lighting the floor through
    the panel's surroundings), where a 1% bias is within the noise of this test's cost."""
    g = glslppm
    passes = 128
    _, balls = vcm_groups(g, ball_caustic(g), 3, passes)
    combined, room = vcm_groups(g, world_and_glowing_panel(g), 3, passes)
    room["lamp"] = combined - room["sky"] - room["panel"]
    alone = {
        "key": (balls, ball_caustic(g, fill=False, groups=False), 0.01),
        "fill": (balls, ball_caustic(g, key=False, groups=False), 0.012),
        "sky": (room, world_and_glowing_panel(g, groups=False, panel=False, lamp=False), 0.005),
        "panel": (room, world_and_glowing_panel(g, groups=False, world=False, lamp=False), 0.01),
        "lamp": (room, world_and_glowing_panel(g, groups=False, world=False, panel=False), 0.012),
    }
    for name, (parts, scene, bound) in alone.items():
        reference, _ = vcm_groups(g, scene, 1, passes, groups=False)
        ratio = parts[name].mean() / reference.mean()
        print(f"  {name}: {ratio:.5f} of its light alone (bound {bound})")
        assert abs(ratio - 1.0) <= bound, (name, ratio)
