"""The memory estimate has one owner, the module (native/render/memory_estimate.h): the
add-on's refusal (addon/engine/memory.py) and plan_tiles ask memory_estimate for the pass
state's GPU bytes, and a Renderer allocates those very sizes. Each case below compares the
estimate with the bytes a Renderer reports it allocated (stats()["pass_state_bytes"], summed
by make_buffer as it allocates)."""
import math

import numpy as np
import pytest

from conftest import look_at, quad

SIZE = 24
PHOTONS = 4096


def mirror_scene(g, aperture=0.0, cut_out=False):
    """A grey floor, a mirror above it and a point light; the camera looks down. With
    aperture: depth of field; cut_out: a Transparent leaf among the materials."""
    floor_p, floor_t = quad((-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3))
    mirror_p, mirror_t = quad((-1, 1, -1), (1, 1, -1), (1, 1, 1), (-1, 1, 1))
    positions = np.concatenate([floor_p, mirror_p]).astype(np.float32)
    indices = np.concatenate([floor_t, mirror_t + len(floor_p)]).astype(np.uint32)
    ids = np.array([0, 0, 1, 1], dtype=np.uint32)
    materials = [g.Material("diffuse", color=(0.5,) * 3), g.Material("conductor")]
    if cut_out:
        ids = np.array([0, 0, 2, 2], dtype=np.uint32)
        materials += [g.Material("mix", mix_a=3, mix_b=1, mix_factor=0.5),
                      g.Material("transparent", color=(1.0,) * 3)]
    camera = g.Camera(look_at((0.0, 5.0, 0.5), (0.0, 0.0, 0.0)), fov_x=math.radians(40),
                      aperture_radius=aperture, focus_distance=5.0)
    return g.Scene(positions, indices, material_ids=ids, materials=materials,
                   lights=[g.Light("point", power=100.0, position=(0.0, 3.0, 0.0))],
                   camera=camera)


def allocated(g, scene, settings):
    r = g.Renderer(scene, settings)
    try:
        return r.stats()
    finally:
        r.close()


def assert_estimate_is_allocation(g, scene, settings):
    estimate = g.memory_estimate(settings, scene)
    stats = allocated(g, scene, settings)
    assert estimate["gpu"] == stats["pass_state_bytes"], (estimate, stats["pass_state_bytes"])
    assert estimate["gpu"] == sum(estimate["buffers"].values())
    assert estimate["gpu_bytes_per_pixel"] == stats["gpu_bytes_per_pixel"]
    assert estimate["gpu_bytes_per_photon"] == pytest.approx(stats["gpu_bytes_per_photon"],
                                                             rel=1e-12)
    # The rest of the renderer's buffers are the scene's (BVH, materials, lights).
    assert stats["gpu_bytes"] > estimate["gpu"]
    return estimate, stats


# (settings, whether light tracing's splats are allocated): the Cornell box has a mirror and
# glass, so they are unless the settings rule light tracing out (off, or the photons carry
# their path's class: the light split, or Direct with photon direct light).
CASES = {
    "sppm": ({}, True),
    "exact hash": (dict(hash="exact"), True),
    "pcg": (dict(rng="pcg"), True),
    "passes": (dict(passes=["depth", "normal", "denoising_albedo"]), True),
    "light split": (dict(passes=["direct", "indirect", "caustics"]), False),
    "no light tracing": (dict(light_tracing=False), False),
    "photon direct light": (dict(direct_light="photons", passes=["direct"]), False),
    "pppm": (dict(estimator="pppm"), True),
    "pppm exact": (dict(estimator="pppm", hash="exact", photons_per_pass=1000), True),
    "vcm": (dict(estimator="vcm"), False),
    "vcm light tracing": (dict(estimator="vcm", vcm_techniques="lt"), True),
}


@pytest.mark.parametrize("case", list(CASES))
def test_estimate_is_what_the_renderer_allocates(glslppm, case):
    g = glslppm
    fields = dict(width=SIZE, height=SIZE + 8, photons_per_pass=PHOTONS)
    fields.update(CASES[case][0])
    settings = g.Settings(**fields)
    estimate, stats = assert_estimate_is_allocation(g, g.cornell_box(sphere_rings=8), settings)
    splats = CASES[case][1]
    assert estimate["light_tracing"] == splats
    assert (estimate["buffers"]["light_splats"] > 0) == splats
    pixels = fields["width"] * fields["height"]
    assert estimate["buffers"]["visible_points"] == pixels * 4 * 16
    assert estimate["buffers"]["film"] == pixels * 16


@pytest.mark.parametrize("scene_kind", ["mirror", "depth of field", "cut-out", "diffuse"])
def test_estimate_decides_light_tracing_as_the_renderer(glslppm, scene_kind):
    """Light tracing's splats are allocated where the scene has a mirror or glass (with depth
    of field and cut-outs too: it connects through the lens and through cut-outs); the
    estimate decides the same from the scene before anything is prepared."""
    g = glslppm
    if scene_kind == "diffuse":
        p, t = quad((-1, -1, -3), (1, -1, -3), (1, 1, -3), (-1, 1, -3))
        scene = g.Scene(p, t, materials=[g.Material("diffuse")], environment=(1, 1, 1))
    else:
        scene = mirror_scene(g, aperture=0.05 if scene_kind == "depth of field" else 0.0,
                             cut_out=scene_kind == "cut-out")
    settings = g.Settings(width=SIZE, height=SIZE, photons_per_pass=PHOTONS)
    estimate, _ = assert_estimate_is_allocation(g, scene, settings)
    assert estimate["light_tracing"] == (scene_kind != "diffuse")
    # Without a scene (the add-on asks before it exports) the splats are counted wherever
    # the settings allow light tracing: never less than the renderer allocates.
    assert g.memory_estimate(settings)["gpu"] >= estimate["gpu"]


def test_tiles_allocate_their_band_of_the_estimate(glslppm):
    """A frame in bands: each band's renderer allocates the estimate for the band's settings
    (tile_render_inputs), and plan_tiles' per-pixel bytes are the estimate's."""
    g = glslppm
    box = g.cornell_box(sphere_rings=8)
    settings = g.Settings(width=48, height=48, photons_per_pass=PHOTONS,
                          passes=["depth", "normal"], max_block_bytes=48 * 16 * 4 * 16)
    plan = g.plan_tiles(box, settings)
    assert len(plan["tiles"]) == 3
    whole = g.memory_estimate(settings, box)
    assert plan["gpu_bytes_per_pixel"] == whole["gpu_bytes_per_pixel"]
    assert plan["block_bytes_per_pixel"] == whole["block_bytes_per_pixel"]
    for tile in plan["tiles"]:
        band_scene, band_settings = g.tile_render_inputs(box, settings, tile)
        estimate, _ = assert_estimate_is_allocation(g, band_scene, band_settings)
        assert estimate["buffers"]["visible_points"] == tile[2] * tile[3] * 4 * 16
    _, stats = g.render_tiled(box, settings, 1)
    band = g.tile_render_inputs(box, settings, plan["tiles"][0])[1]
    assert stats["pass_state_bytes"] == g.memory_estimate(band, box)["gpu"]


def test_pppm_stores_as_many_steps_as_the_largest_block_holds(glslppm):
    """PPPM's stored photon steps depend on the device's largest storage buffer (at most
    1 GiB, at most max_bounces + 1 steps): the estimate takes it as given."""
    g = glslppm
    settings = g.Settings(width=8, height=8, photons_per_pass=1 << 16, estimator="pppm",
                          max_bounces=9)
    slot = (1 << 16) * 48
    assert g.memory_estimate(settings, largest_block=3 * slot)["photon_steps_per_gather"] == 3
    assert g.memory_estimate(settings, largest_block=0)["photon_steps_per_gather"] == 10
    assert g.memory_estimate(settings, largest_block=1)["photon_steps_per_gather"] == 1
    estimate = g.memory_estimate(settings, largest_block=3 * slot)
    assert estimate["buffers"]["photons"] == 3 * slot
    sppm = g.Settings(width=8, height=8, photons_per_pass=1 << 16)
    assert g.memory_estimate(sppm, largest_block=1)["buffers"]["photons"] == slot


def test_bad_input_is_refused_with_a_message(glslppm):
    g = glslppm
    with pytest.raises(TypeError):
        g.memory_estimate("not settings")
    box = g.cornell_box(sphere_rings=8)
    settings = g.Settings(width=16, height=16, photons_per_pass=256)
    with pytest.raises(ValueError, match="does not lie within the 16x16 frame"):
        g.for_each_tile(box, settings, [(0, 8, 16, 16)], lambda *tile: True)
    with pytest.raises(TypeError, match="scene must be a Scene"):
        g.for_each_tile(settings, box, [(0, 0, 16, 16)], lambda *tile: True)
