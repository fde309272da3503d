"""Deformation motion blur (issue 32, docs/motion_blur.md): an instance mesh's vertices at
the motion steps, placed per pass at the pass's time, its bottom tree refitted.

The sweep and the bending bar reuse test_motion_blur's scenes: the same strip, here moved
by its vertices instead of its transform, must give the same box-filtered sweep; a bending
bar, pass by pass, must equal still scenes whose vertices are placed at each pass's time."""
import math

import numpy as np
import pytest

from conftest import quad
from test_motion_blur import (ALBEDO, HALF, OPEN, RADIANCE, SHUTTER, SUN, WIDTH, analytic_columns,
                              passes_equal_still_frames, render, spread, strip_left, sweep_scene,
                              translation)

STEPS = [-1.0, 0.0, 1.0]


def deforming_strip(g, shutter=SHUTTER):
    """The sweep's strip with its transform fixed at the frame's place and its vertices
    carrying the motion: at step s every vertex moved by strip_left(s) - strip_left(0)."""
    scene = sweep_scene(g, None)
    p, _ = quad((0, -1, 0), (0.5, -1, 0), (0.5, 1, 0), (0, 1, 0))
    positions = np.array([p + np.float32((strip_left(s) - strip_left(0.0), 0, 0))
                          for s in STEPS], np.float32)
    scene.set_motion(shutter_open=OPEN, shutter_length=shutter,
                     meshes=[(0, STEPS, positions, None)])
    return scene


def test_a_strip_moved_by_its_vertices_is_the_box_filtered_sweep(glslppm):
    """test_motion_blur's sweep check, the motion given as deformation: every pixel within
    0.1 L of its analytic coverage and the profile's spread within 0.3% of the analytic one
    (the bounds' derivation is in test_moving_strip_is_the_box_filtered_sweep; a 1% longer
    or shorter shutter moves the spread 1.9%)."""
    g = glslppm
    film, stats = render(g, deforming_strip(g))
    assert stats["motion"] == "deformation"
    assert stats["instancing"] == "two-level"
    assert np.isfinite(film).all()
    rows = film[..., 0].astype(np.float64) / RADIANCE
    want = analytic_columns()
    worst = np.abs(rows - want[None, :]).max()
    measured = rows.mean(axis=0)
    error = spread(measured) / spread(want) - 1
    print(f"  worst pixel {worst:.3f} L, spread error {error:+.4%}")
    assert worst < 0.1
    assert abs(error) < 0.003
    # The same check fails a render whose shutter is 1% longer.
    longer, _ = render(g, deforming_strip(g, 1.01 * SHUTTER))
    wrong = spread(longer[..., 0].astype(np.float64).mean(axis=0) / RADIANCE) / spread(want) - 1
    print(f"  1% longer shutter: spread error {wrong:+.4%}")
    assert abs(wrong) > 0.003


def bar(bend):
    """A bar of 16 quads along x (length 2.4, width 0.4) bent about the y axis into an arc
    of angle `bend`, centred at the origin, with smooth normals: (positions, indices,
    normals)."""
    n = 16
    s = np.linspace(-1.2, 1.2, n + 1)
    if abs(bend) < 1e-9:
        x, z, nx, nz = s, np.zeros_like(s), np.zeros_like(s), np.ones_like(s)
    else:
        radius = 2.4 / bend
        a = s / radius
        x, z = radius * np.sin(a), radius * (1 - np.cos(a))
        nx, nz = -np.sin(a), np.cos(a)
    positions, normals = [], []
    for y in (-0.2, 0.2):
        positions += [(xi, y, zi) for xi, zi in zip(x, z)]
        normals += [(a, 0.0, c) for a, c in zip(nx, nz)]
    indices = []
    for i in range(n):
        a, b, c, d = i, i + 1, n + 2 + i, n + 1 + i
        indices += [(a, b, c), (a, c, d)]
    return (np.array(positions, np.float32), np.array(indices, np.uint32),
            np.array(normals, np.float32))


BENDS = (0.0, 1.2, 2.0)  # the bar's bend at the steps -1, 0, +1


def at_time(steps, t):
    """deform_mesh.comp at DeformMotion::segment's steps: linear between the bracketing steps (u in double, then float32),
    normals renormalized in float32, held at the ends."""
    positions = [bar(b)[0] for b in BENDS]
    normals = [bar(b)[2] for b in BENDS]
    k = min(max(int(np.searchsorted(steps, t, side="right")), 1), len(steps) - 1)
    u = np.float32(min(max((t - steps[k - 1]) / (steps[k] - steps[k - 1]), 0.0), 1.0))
    p = positions[k - 1] + u * (positions[k] - positions[k - 1])
    m = normals[k - 1] + u * (normals[k] - normals[k - 1])
    length = np.sqrt(m[:, 0] * m[:, 0] + m[:, 1] * m[:, 1] + m[:, 2] * m[:, 2])
    return p, m / length[:, None]


def bar_scene(g, vertices=None):
    """The bar (bend BENDS[1] at the frame) as an instance seen from above under a slanted
    sun, its bend changing over the shutter; or standing still with `vertices`
    (positions, normals). A black fence fixes the scene's box for both."""
    p, t, nrm = bar(BENDS[1])
    if vertices is not None:
        p, nrm = vertices
    fence = np.array([(-12, -12, -5), (-10, 12, 3), (-11, 0, -5),
                      (12, -12, -5), (10, 12, 3), (11, 0, -5)], np.float32)
    scene = g.Scene(fence, np.array([[0, 1, 2], [3, 4, 5]], np.uint32),
                    material_ids=np.array([1, 1], np.uint32),
                    materials=[g.Material("diffuse", color=(ALBEDO,) * 3),
                               g.Material("diffuse", color=(0, 0, 0))],
                    lights=[g.Light("sun", power=SUN, direction=(0.3, 0.1, -1))],
                    camera=g.Camera(translation(0, 0, 4), projection="orthographic",
                                    ortho_scale=2 * HALF),
                    instance_meshes=[{"positions": p, "indices": t, "normals": nrm}],
                    instances=np.array([np.eye(4, dtype=np.float32)]),
                    instance_mesh=np.zeros(1, np.uint32))
    if vertices is None:
        scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                         meshes=[(0, STEPS, np.array([bar(b)[0] for b in BENDS]),
                                  np.array([bar(b)[2] for b in BENDS]))])
    return scene


def test_a_bending_bar_is_the_mean_of_still_frames_at_the_pass_times(glslppm):
    """Vertices, normals and the refitted bottom tree together: PPPM pass i of the bending
    bar equals pass i of a still scene whose bar has the vertices and normals interpolated
    at t_i = open + length shutter_sample(seed, i) (a fresh tree); their mean over 8 passes
    within the farm merge's 1e-6 relative. The hit rule does not depend on the tree, so
    only the arithmetic of the interpolation could differ, and it is the same."""
    g = glslppm
    settings = g.Settings(width=WIDTH, height=WIDTH, photons_per_pass=1024, seed=9,
                          estimator="pppm", instancing="two-level", initial_radius=0.05)
    stills = passes_equal_still_frames(g, bar_scene(g), settings, "deformation",
                                       lambda t: bar_scene(g, at_time(STEPS, t)))
    # The stills differ: the bar did bend (its shading and its outline).
    assert np.abs(stills[0] - stills[1]).max() > 0.1 * RADIANCE


def test_steps_that_do_not_deform_render_bit_identically(glslppm):
    """Deformation given with every step the frame's vertices is none: the same image bit
    for bit, and nothing moves."""
    g = glslppm
    still, still_stats = render(g, sweep_scene(g, None), passes=4)
    scene = sweep_scene(g, None)
    p, _ = quad((0, -1, 0), (0.5, -1, 0), (0.5, 1, 0), (0, 1, 0))
    scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                     meshes=[(0, STEPS, np.array([p] * 3, np.float32), None)])
    assert scene.has_motion
    same, same_stats = render(g, scene, passes=4)
    assert same_stats["motion"] == still_stats["motion"] == "none"
    assert np.array_equal(same, still)


@pytest.mark.parametrize("change, message", [
    ({"mesh": 3}, r"motion.meshes\[0\].mesh: 3 is out of range"),
    ({"twice": True}, r"mesh 0 is given deformation twice"),
    ({"vertices": 3}, r"step 0: 3 positions for the mesh's 4 vertices"),
    ({"times": [0.0, 0.0, 1.0]}, r"times are not finite and increasing"),
    ({"nan": True}, r"a vertex's positions is not finite"),
    ({"normals": True}, r"normals given for a mesh that has none"),
])
def test_bad_deformation_is_an_error_naming_it(glslppm, change, message):
    g = glslppm
    scene = sweep_scene(g, None)
    p, _ = quad((0, -1, 0), (0.5, -1, 0), (0.5, 1, 0), (0, 1, 0))
    positions = np.array([p] * 3, np.float32)
    if "vertices" in change:
        positions = positions[:, :change["vertices"]]
    if "nan" in change:
        positions[1, 2, 0] = math.nan
    entry = (change.get("mesh", 0), change.get("times", STEPS), positions,
             positions if "normals" in change else None)
    with pytest.raises(ValueError, match=message):
        scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                         meshes=[entry, entry] if "twice" in change else [entry])
    assert not scene.has_motion
