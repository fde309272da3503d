"""Cheap restarts (the viewport's): set_camera and update_tables start the image again
without a BVH build or program compile, and the image after a restart is the image a new
renderer of the changed scene makes, pass for pass (the PCG generator is seeded by seed,
pass index and stage, and a restart begins again at pass 0)."""
import math
import time

import numpy as np

from conftest import look_at
from scene_builders import join_shapes, shape_quad

PASSES = 4


def box_scene(g, camera, wall=(0.75, 0.25, 0.25), lights=None, extra_kind=None, roughness=0.0):
    """A floor, a back wall and a left wall under a point light; the left wall's colour,
    the lights and the camera vary; extra_kind adds a small quad of that material kind (of
    that roughness)."""
    parts = [
        (shape_quad((-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)), 0),
        (shape_quad((-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)), 0),
        (shape_quad((-1, 0, -1), (-1, 2, -1), (-1, 2, 1), (-1, 0, 1)), 1),
    ]
    materials = [g.Material("diffuse", color=(0.75, 0.75, 0.75)),
                 g.Material("diffuse", color=wall)]
    if extra_kind is not None:
        parts.append((shape_quad((0.2, 0.01, 0.2), (0.2, 0.01, 0.4), (0.4, 0.01, 0.4),
                                 (0.4, 0.01, 0.2)), 2))
        materials.append(g.Material(extra_kind, color=(0.9, 0.9, 0.9), roughness=roughness))
    positions, normals, triangles, ids = join_shapes(parts)
    if lights is None:
        lights = [g.Light("point", power=40.0, position=(0.0, 1.6, 0.2))]
    return g.Scene(positions, triangles, normals=normals, material_ids=ids,
                   materials=materials, lights=lights, camera=camera)


def camera_a(g):
    return g.Camera(look_at((0, 1, 3.5), (0, 0.8, 0)), fov_x=math.radians(50))


def camera_b(g):
    return g.Camera(look_at((1.2, 1.4, 3.0), (-0.3, 0.6, -0.5)), fov_x=math.radians(40))


def settings(g):
    return g.Settings(width=48, height=36, photons_per_pass=4096, seed=7)


def fresh_film(g, scene):
    renderer = g.Renderer(scene, settings(g))
    renderer.run(passes=PASSES)
    film = renderer.film()
    renderer.close()
    return film


def test_set_camera_renders_what_a_new_renderer_of_that_camera_renders(glslppm):
    g = glslppm
    renderer = g.Renderer(box_scene(g, camera_a(g)), settings(g))
    renderer.run(passes=PASSES)
    before = renderer.film()
    assert renderer.set_camera(camera_b(g)) is True
    stats = renderer.stats()
    assert stats["passes"] == 0 and stats["photons_emitted"] == 0
    assert stats["camera_updates"] == 1 and stats["film_resets"] == 1
    renderer.run(passes=PASSES)
    after = renderer.film()
    expected = fresh_film(g, box_scene(g, camera_b(g)))
    renderer.close()
    # Same passes, same generator states: equal to float rounding.
    assert np.abs(after - expected).max() <= 1e-5 * max(1.0, float(expected.max()))
    # And the restart did change the image (the views differ by far more than noise).
    assert np.abs(after - before).mean() > 0.05 * before[..., :3].mean()


def test_update_tables_renders_what_a_new_renderer_of_the_edited_scene_renders(glslppm):
    g = glslppm
    renderer = g.Renderer(box_scene(g, camera_a(g)), settings(g))
    renderer.run(passes=PASSES)
    green = box_scene(g, camera_a(g), wall=(0.1, 0.8, 0.1),
                      lights=[g.Light("point", power=60.0, position=(0.3, 1.5, 0.0)),
                              g.Light("point", power=20.0, position=(-0.5, 1.2, 0.5))])
    assert renderer.update_tables(green) is True
    assert renderer.stats()["table_updates"] == 1
    renderer.run(passes=PASSES)
    after = renderer.film()
    renderer.close()
    expected = fresh_film(g, green)
    assert np.abs(after - expected).max() <= 1e-5 * max(1.0, float(expected.max()))
    # The left wall (left third of the image) turned green.
    left = after[:, :12, :3].reshape(-1, 3).mean(axis=0)
    assert left[1] > 2.0 * left[0], left


def test_pppm_restarts_every_worker_and_its_pass_indices(glslppm):
    """Two PPPM workers with a rough conductor (microfacet visible points): set_camera and
    update_tables restart both workers' films, the pass indices start again from first_pass,
    and the merged image equals one worker's of a new renderer of the changed scene (a PPPM
    pass depends on its index alone). The farm attributes' scene hash follows the changes."""
    g = glslppm

    def pppm(**extra):
        return g.Settings(width=48, height=36, photons_per_pass=4096, seed=7, max_bounces=8,
                          estimator="pppm", first_pass=3, **extra)

    def scene(camera, **extra):
        return box_scene(g, camera, extra_kind="conductor", roughness=0.5, **extra)

    def fresh(changed):
        renderer = g.Renderer(changed, pppm())
        renderer.run(passes=PASSES)
        film, attributes = renderer.film(), renderer.farm_attributes()
        renderer.close()
        return film, attributes["glslppm.scene_hash"]

    probe = g.Renderer(scene(camera_a(g)), pppm())
    device = probe.stats()["devices"][0]["device"]
    probe.close()
    renderer = g.Renderer(scene(camera_a(g)), pppm(devices=[device, device]))
    renderer.run(passes=PASSES)
    assert renderer.set_camera(camera_b(g)) is True
    stats = renderer.stats()
    assert stats["passes"] == 0 and stats["pass_ranges"] == [] and stats["film_resets"] == 1
    renderer.run(passes=PASSES)
    stats = renderer.stats()
    assert stats["pass_ranges"] == [(3, 3 + PASSES)]
    assert sum(d["passes"] for d in stats["devices"]) == PASSES
    expected, expected_hash = fresh(scene(camera_b(g)))
    assert np.abs(renderer.film() - expected).max() <= 1e-5 * max(1.0, float(expected.max()))
    assert renderer.farm_attributes()["glslppm.scene_hash"] == expected_hash

    green = scene(camera_a(g), wall=(0.1, 0.8, 0.1),
                  lights=[g.Light("point", power=60.0, position=(0.3, 1.5, 0.0))])
    assert renderer.update_tables(green) is True
    renderer.run(passes=PASSES)
    stats = renderer.stats()
    assert stats["pass_ranges"] == [(3, 3 + PASSES)] and stats["table_updates"] == 1
    expected, expected_hash = fresh(green)
    assert np.abs(renderer.film() - expected).max() <= 1e-5 * max(1.0, float(expected.max()))
    assert renderer.farm_attributes()["glslppm.scene_hash"] == expected_hash
    renderer.close()


def test_a_switch_to_orthographic_is_a_camera_restart(glslppm):
    """The projection is the Frame's, not the programs': the viewport's numpad-5 switch
    between perspective and orthographic restarts the camera (no rebuild), and renders what
    a new renderer of the orthographic camera renders, pass for pass."""
    g = glslppm
    ortho = g.Camera(look_at((0, 1, 3.5), (0, 0.8, 0)), projection="orthographic",
                     ortho_scale=3.0)
    renderer = g.Renderer(box_scene(g, camera_a(g)), settings(g))
    renderer.run(passes=2)
    assert renderer.set_camera(ortho) is True
    assert renderer.stats()["camera_updates"] == 1
    renderer.run(passes=PASSES)
    after = renderer.film()
    renderer.close()
    expected = fresh_film(g, box_scene(g, ortho))
    assert np.abs(after - expected).max() <= 1e-5 * max(1.0, float(expected.max()))
    assert expected[..., :3].mean() > 0.01


def test_restarts_that_need_other_programs_or_geometry_change_nothing(glslppm):
    g = glslppm
    renderer = g.Renderer(box_scene(g, camera_a(g)), settings(g))
    renderer.run(passes=2)
    # Depth of field is compiled only where a camera has an aperture.
    lens = g.Camera(look_at((0, 1, 3.5), (0, 0.8, 0)), fov_x=math.radians(50),
                    aperture_radius=0.05, focus_distance=3.5)
    assert renderer.set_camera(lens) is False
    # A new material kind (a mirror) would need the conductor lobe compiled in, a sun light
    # its sampling.
    assert renderer.update_tables(box_scene(g, camera_a(g), extra_kind="conductor")) is False
    sun = [g.Light("sun", power=2.0, direction=(0.2, -1.0, -0.3))]
    assert renderer.update_tables(box_scene(g, camera_a(g), lights=sun)) is False
    stats = renderer.stats()
    assert stats["passes"] == 2 and stats["film_resets"] == 0
    assert stats["camera_updates"] == 0 and stats["table_updates"] == 0
    renderer.close()


def test_a_bad_camera_is_an_error_and_the_renderer_goes_on(glslppm):
    g = glslppm
    renderer = g.Renderer(box_scene(g, camera_a(g)), settings(g))
    renderer.run(passes=1)
    bad = g.Camera(look_at((0, 1, 3.5), (0, 0.8, 0)), fov_x=4.0)
    try:
        renderer.set_camera(bad)
    except ValueError as error:
        assert "fov_x" in str(error)
    else:
        raise AssertionError("a field of view of 4 radians was accepted")
    assert renderer.run(passes=1) == 1
    assert renderer.stats()["passes"] == 2
    renderer.close()


def test_a_camera_restart_is_cheaper_than_a_new_renderer(glslppm):
    """On llvmpipe at 160x120: set_camera + one pass + film against a new renderer (BVH
    build, GL set-up, programs loaded from the process's binaries) + one pass + film,
    without SPPM's photon warm-up (both would pay it alike; under load it left too thin a
    margin)."""
    g = glslppm
    small = g.Settings(width=160, height=120, photons_per_pass=16384, seed=7,
                       photon_warm_up=False)
    scene = g.cornell_box()
    renderer = g.Renderer(scene, small)
    renderer.run(passes=2)
    restarts = []
    for k in range(5):
        camera = g.Camera(look_at((0.1 * k, 1, 4), (0, 1, 0)), fov_x=2.0 * math.atan(1.15 / 3))
        began = time.perf_counter()
        renderer.set_camera(camera)
        renderer.run(passes=1)
        renderer.film()
        restarts.append(time.perf_counter() - began)
    renderer.close()
    rebuilds = []
    for _ in range(3):
        began = time.perf_counter()
        other = g.Renderer(scene, small)
        other.run(passes=1)
        other.film()
        rebuilds.append(time.perf_counter() - began)
        other.close()
    restart, rebuild = float(np.median(restarts)), float(np.median(rebuilds))
    print(f"camera restart to first image {restart * 1e3:.1f} ms, "
          f"new renderer to first image {rebuild * 1e3:.1f} ms (160x120, llvmpipe)")
    assert restart < rebuild, (restart, rebuild)
