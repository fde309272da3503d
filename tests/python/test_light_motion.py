"""Moving lamps (issue 32, docs/motion_blur.md): a point, spot or sun light given transform
steps (Scene.set_motion's lights) stands, in each pass, where it is at the pass's time, for
its light samples, its photons and the specular rays that see a sphere light; the passes'
mean is the blurred image."""
import math

import numpy as np
import pytest

from conftest import quad
from test_motion_blur import OPEN, SHUTTER, passes_equal_still_frames, translation

HALF = 2.0  # the orthographic camera sees x, y in [-2, 2]


def rotation(axis, angle, move=(0.0, 0.0, 0.0)):
    """A rotation about the x or y axis by angle, then a translation: row-major 4 x 4."""
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4, dtype=np.float32)
    if axis == "x":
        m[1:3, 1:3] = ((c, -s), (s, c))
    else:
        m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    m[:3, 3] = move
    return m


def placed(g, kind, m, **kw):
    """A light at matrix m (row-major): at its origin, shining along its -Z."""
    m = np.asarray(m, np.float64)
    return g.Light(kind, position=tuple(m[:3, 3]), direction=tuple(-m[:3, 2]), **kw)


# Three lamps over a floor whose right half is a mirror: a point light of radius 0.25
# crossing it (the mirror shows the sphere to the camera's reflected rays), a spot light
# turning and a sun tilting.
STEPS = [-1.0, 0.0, 1.0]
POINT = np.array([translation(x, 0.3, 1.0) for x in (-1.2, 0.0, 1.4)])
SPOT = np.array([rotation("y", a, (0.0, -1.0, 1.5)) for a in (-0.5, 0.1, 0.6)])
SUN = np.array([rotation("x", a) for a in (0.3, 0.0, -0.4)])
LIGHTS = (("point", POINT, dict(power=40.0, radius=0.25)),
          ("spot", SPOT, dict(power=60.0, spot_size=1.0, spot_blend=0.2)),
          ("sun", SUN, dict(power=0.5)))


def lamps_scene(g, at=None):
    """The lamps moving over the shutter (at None), or standing where they are at time at."""
    left, lt = quad((-3, -3, 0), (0, -3, 0), (0, 3, 0), (-3, 3, 0))
    right, rt = quad((0, -3, 0), (3, -3, 0), (3, 3, 0), (0, 3, 0))
    positions = np.concatenate([left, right])
    indices = np.concatenate([lt, rt + 4])
    lights = []
    for kind, mats, kw in LIGHTS:
        m = mats[1] if at is None else g.interpolate_transform(STEPS, mats, at)
        lights.append(placed(g, kind, m, **kw))
    scene = g.Scene(positions, indices, material_ids=np.array([0, 0, 1, 1], np.uint32),
                    materials=[g.Material("diffuse", color=(0.8,) * 3),
                               g.Material("conductor", color=(0.9,) * 3)],
                    lights=lights,
                    camera=g.Camera(translation(0, 0, 4), projection="orthographic",
                                    ortho_scale=2 * HALF))
    if at is None:
        scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                         lights=[(k, STEPS, mats) for k, (_, mats, _) in enumerate(LIGHTS)])
    return scene


def test_moving_lamps_are_the_mean_of_still_frames_at_the_pass_times(glslppm):
    """PPPM pass i of the moving lamps equals pass i of a still scene with each lamp placed at
    interpolate_transform(steps, t_i), t_i = open + length shutter_sample(seed, i): light
    samples, photons and the mirrored sphere light alike; their mean over 8 passes within
    the farm merge's 1e-6 relative."""
    g = glslppm
    settings = g.Settings(width=32, height=32, photons_per_pass=2048, seed=11,
                          estimator="pppm", initial_radius=0.1)
    stills = passes_equal_still_frames(g, lamps_scene(g), settings, "lights",
                                       lambda t: lamps_scene(g, at=t))
    # The stills differ from each other: the lamps did move.
    assert np.abs(stills[0] - stills[1]).max() > 0.1
    # The mirror shows the sphere light (radiance 40 / (4 pi^2 0.25^2) 0.9 = 14.6) where it is
    # over the mirror: a point light of radius 0 shows nothing there.
    assert max(float(s[:, 16:, 0].max()) for s in stills) > 5.0


def sun_scene(g, moving=True, shutter=SHUTTER):
    """A diffuse floor under a sun that tilts about y from TILT[0] at the shutter's opening to
    TILT[1] at its closing (two steps), seen straight down by an orthographic camera."""
    p, t = quad((-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0))
    mats = np.array([rotation("y", a) for a in TILT])
    frame = g.interpolate_transform([OPEN, OPEN + SHUTTER], mats, 0.0)
    scene = g.Scene(p, t, materials=[g.Material("diffuse", color=(ALBEDO,) * 3)],
                    lights=[placed(g, "sun", frame, power=SUN_POWER)],
                    camera=g.Camera(translation(0, 0, 4), projection="orthographic",
                                    ortho_scale=2 * HALF))
    if moving:
        scene.set_motion(shutter_open=OPEN, shutter_length=shutter,
                         lights=[(0, [OPEN, OPEN + SHUTTER], mats)])
    return scene


TILT, ALBEDO, SUN_POWER = (0.2, 1.2), 0.8, 2.0


def test_a_tilting_sun_lights_the_floor_by_its_mean_cosine(glslppm):
    """The sun turns at a constant rate (slerp) from 0.2 to 1.2 rad off the vertical over the
    shutter, over a diffuse floor: the floor's radiance is albedo E / pi times the mean cosine
    of its angle. Over the 64 passes' own times (theta_i = 0.2 + shutter_sample(seed, i)) that
    mean is exact: the image's mean within 1e-5 relative (a still sun's floor is exact to
    1.2e-7). Against the shutter's continuous mean, (sin 1.2 - sin 0.2) / 1.0 = 0.7334, within
    the 64 strata's error, |cos 1.2 - cos 0.2| / 64 / 0.7334 = 1.3%, and the frame's cos 0.7
    (4.3% above) is not."""
    g = glslppm
    settings = g.Settings(width=32, height=32, photons_per_pass=1024, seed=3)
    r = g.Renderer(sun_scene(g), settings)
    r.run(64)
    film = r.film()
    assert r.stats()["motion"] == "lights"
    r.close()
    radiance = ALBEDO * SUN_POWER / math.pi
    angles = [TILT[0] + (TILT[1] - TILT[0]) * g.shutter_sample(3, i) for i in range(64)]
    at_pass_times = radiance * np.mean(np.cos(angles))
    continuous = radiance * (math.sin(TILT[1]) - math.sin(TILT[0])) / (TILT[1] - TILT[0])
    measured = float(film[..., :3].astype(np.float64).mean())
    print(f"  floor {measured:.6f}: the passes' times {measured / at_pass_times - 1:+.2e}, "
          f"the continuous mean {measured / continuous - 1:+.3%}")
    assert abs(measured / at_pass_times - 1) < 1e-5
    strata = abs(math.cos(TILT[1]) - math.cos(TILT[0])) / 64 * radiance / continuous
    assert abs(measured / continuous - 1) < strata
    r = g.Renderer(sun_scene(g, moving=False), settings)
    r.run(64)
    frame = float(r.film()[..., :3].astype(np.float64).mean())
    r.close()
    print(f"  the still sun at the frame: {frame / continuous - 1:+.3%}")
    assert frame / continuous - 1 > 0.03


# A square area light (two triangles) crossing the floor, turning about y on the
# way, over a floor whose right half is a mirror, seen from above (its back, dark) and in the
# mirror (its front).
AREA = np.array([rotation("y", a, (x, 0.2, 1.2)) for a, x in ((-0.3, -1.3), (0.0, 0.0),
                                                                (0.4, 1.2))])


# With `drifting`: a small diffuse square instance at z 0.5 drifting along y (two levels).
DRIFT = np.array([translation(-1.0, y, 0.5) for y in (-1.0, 0.0, 1.0)])


def area_scene(g, at=None, shape="square", drifting=False):
    """The area light (and the drifting instance) moving over the shutter (at None), or
    standing where they are at time at."""
    left, lt = quad((-3, -3, 0), (0, -3, 0), (0, 3, 0), (-3, 3, 0))
    right, rt = quad((0, -3, 0), (3, -3, 0), (3, 3, 0), (0, 3, 0))
    m = AREA[1] if at is None else g.interpolate_transform(STEPS, AREA, at)
    extra = {}
    if drifting:
        p, t = quad((-0.3, -0.3, 0), (0.3, -0.3, 0), (0.3, 0.3, 0), (-0.3, 0.3, 0))
        placed_at = DRIFT[1] if at is None else g.interpolate_transform(STEPS, DRIFT, at)
        extra = dict(instance_meshes=[{"positions": p, "indices": t}],
                     instances=np.array([placed_at], np.float32),
                     instance_mesh=np.zeros(1, np.uint32))
    scene = g.Scene(np.concatenate([left, right]), np.concatenate([lt, rt + 4]),
                    material_ids=np.array([0, 0, 1, 1], np.uint32),
                    materials=[g.Material("diffuse", color=(0.8,) * 3),
                               g.Material("conductor", color=(0.9,) * 3)],
                    lights=[g.Light("area", power=30.0, to_world=np.asarray(m, np.float32),
                                    shape=shape, size_x=0.6)],
                    camera=g.Camera(translation(0, 0, 4), projection="orthographic",
                                    ortho_scale=2 * HALF), **extra)
    if at is None:
        scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER, lights=[(0, STEPS, AREA)],
                         instances=[(0, STEPS, DRIFT)] if drifting else [])
    return scene


@pytest.mark.parametrize("drifting", [False, True])
def test_a_moving_area_light_is_the_mean_of_still_frames_at_the_pass_times(glslppm, drifting):
    """PPPM pass i of the moving area light (its triangles, normals and emitter records
    rewritten per pass; the tree's leaves grown over its sweep) equals pass i of a still scene
    with the light at interpolate_transform(steps, t_i); mean of 8 passes within 1e-6
    relative. A square (two triangles) and leaf_size 8: one leaf, so that both trees pack the
    triangles (and so order the emitters) alike. drifting: with a moving instance too, so the
    grown placed-once tree is the two-level tree's mesh 0."""
    g = glslppm
    settings = g.Settings(width=32, height=32, photons_per_pass=2048, seed=13,
                          estimator="pppm", initial_radius=0.1, leaf_size=8,
                          instancing="two-level" if drifting else "auto")
    stills = passes_equal_still_frames(
        g, area_scene(g, drifting=drifting), settings,
        "instances,lights" if drifting else "lights",
        lambda t: area_scene(g, at=t, drifting=drifting))
    assert np.abs(stills[0] - stills[1]).max() > 0.1
    # The mirror shows the light's front where it is over the mirror.
    assert max(float(s[:, 16:, 0].max()) for s in stills) > 5.0


def emitting_instance_scene(g, at=None):
    """A 0.6-wide emitting square (black, emission 20, facing down) as an instance moving as
    AREA moves, over the half-mirror floor (at None), or standing where it is at time at."""
    left, lt = quad((-3, -3, 0), (0, -3, 0), (0, 3, 0), (-3, 3, 0))
    right, rt = quad((0, -3, 0), (3, -3, 0), (3, 3, 0), (0, 3, 0))
    p, t = quad((-0.3, -0.3, 0), (-0.3, 0.3, 0), (0.3, 0.3, 0), (0.3, -0.3, 0))
    m = AREA[1] if at is None else g.interpolate_transform(STEPS, AREA, at)
    scene = g.Scene(np.concatenate([left, right]), np.concatenate([lt, rt + 4]),
                    material_ids=np.array([0, 0, 1, 1], np.uint32),
                    materials=[g.Material("diffuse", color=(0.8,) * 3),
                               g.Material("conductor", color=(0.9,) * 3),
                               g.Material("diffuse", color=(0.0,) * 3, emission=(20.0,) * 3)],
                    camera=g.Camera(translation(0, 0, 4), projection="orthographic",
                                    ortho_scale=2 * HALF),
                    instance_meshes=[{"positions": p, "indices": t}],
                    instances=np.array([m], np.float32), instance_mesh=np.zeros(1, np.uint32),
                    instance_material_offset=np.array([2], np.uint32))
    if at is None:
        scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                         instances=[(0, STEPS, AREA)])
    return scene


def test_a_moving_emitting_instance_is_the_mean_of_still_frames_at_the_pass_times(glslppm):
    """An instance that emits light, turning and crossing the half-mirror floor, is placed once
    with the emitters and rewritten per pass (its triangles and their emitter records:
    render/emitter_motion.cpp): PPPM pass i equals pass i of a still scene with the instance
    at interpolate_transform(steps, t_i), the mean of 8 passes within 1e-6 relative. Its light
    samples and photons light the diffuse half; the mirror shows it. leaf_size 8: one leaf, so
    that both trees pack its triangles (and so order its emitters) alike. Measured 2.1e-7;
    with the triangles' or the emitter records' rewrite left out it reads 1.0 or 0.68."""
    g = glslppm
    settings = g.Settings(width=32, height=32, photons_per_pass=2048, seed=13,
                          estimator="pppm", initial_radius=0.1, leaf_size=8)
    stills = passes_equal_still_frames(g, emitting_instance_scene(g), settings, "emitters",
                                       lambda t: emitting_instance_scene(g, at=t))
    assert np.abs(stills[0] - stills[1]).max() > 0.1
    assert max(float(s[:, 16:, 0].max()) for s in stills) > 5.0  # the mirror shows it
    assert min(float(s[:, :16, 0].mean()) for s in stills) > 0.01  # it lights the floor


def test_lamp_steps_that_do_not_move_render_bit_identically(glslppm):
    """Lamp steps that are all the frame's matrix are no motion: the same image, bit for bit,
    the same variant, nothing moves."""
    g = glslppm
    settings = g.Settings(width=32, height=32, photons_per_pass=1024, seed=4)

    def render(scene):
        r = g.Renderer(scene, settings)
        r.run(4)
        out = r.film(), r.stats()
        r.close()
        return out

    still, still_stats = render(lamps_scene(g, at=0.0))
    scene = lamps_scene(g, at=0.0)
    scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                     lights=[(k, STEPS, np.array([g.interpolate_transform(STEPS, mats, 0.0)] * 3))
                             for k, (_, mats, _) in enumerate(LIGHTS)])
    assert scene.has_motion
    same, same_stats = render(scene)
    assert same_stats["motion"] == still_stats["motion"] == "none"
    assert same_stats["variant"] == still_stats["variant"]
    assert np.array_equal(same, still)
    moved, _ = render(lamps_scene(g))
    assert not np.array_equal(moved, still)


@pytest.mark.parametrize("lights, message", [
    ([(3, [0.0, 1.0], np.array([np.eye(4)] * 2))], "motion.lights[0].light: 3 is out of range"),
    ([(0, [0.0, 1.0], np.array([np.eye(4)] * 2))] * 2, "light 0 is given motion twice"),
    ([(0, [1.0, 0.0], np.array([np.eye(4)] * 2))], "motion.lights[0]"),
])
def test_bad_lamp_motion_is_an_error_naming_it(glslppm, lights, message):
    g = glslppm
    p, t = quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0))
    scene = g.Scene(p, t, materials=[g.Material("diffuse")],
                    lights=[g.Light("point", position=(0, 0, 1)),
                            g.Light("area", to_world=translation(0, 0, 2))])
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        scene.set_motion(shutter_open=0.0, shutter_length=1.0, lights=lights)


def test_a_moving_disk_light_over_several_leaves_is_seen_where_still_frames_see_it(glslppm):
    """A disk area light (64 triangles over several leaves, each grown over its sweep): what
    the mirror shows of it (eye rays only) equals, pixel by pixel, the mean of still scenes at
    the pass times within 1e-6 relative (measured 1.3e-7). The diffuse half, lit by photons
    whose emitters the two trees order differently, agrees in its mean within 1% (measured
    -0.017% at 8 passes of 4096 photons)."""
    g = glslppm
    settings = g.Settings(width=32, height=32, photons_per_pass=4096, seed=13,
                          estimator="pppm", initial_radius=0.1)
    r = g.Renderer(area_scene(g, shape="disk"), settings)
    r.run_passes(list(range(8)))
    moving = r.film()
    assert r.stats()["motion"] == "lights"
    r.close()
    stills = []
    for i in range(8):
        at = OPEN + SHUTTER * g.shutter_sample(settings.seed, i)
        r = g.Renderer(area_scene(g, at=at, shape="disk"), settings)
        r.run_passes([i])
        stills.append(r.film())
        r.close()
    mean = g.merge_films(stills, [1] * 8)
    a, b = moving[:, 16:, :3], mean[:, 16:, :3]
    scale = np.maximum(np.abs(a), np.abs(b))
    mirror = float((np.abs(a - b) / np.where(scale > 0, scale, 1)).max())
    diffuse = float(moving[:, :16, :3].mean() / mean[:, :16, :3].mean() - 1)
    print(f"  mirror half: max relative {mirror:.2g}; diffuse half's mean {diffuse:+.3%}")
    assert mirror <= 1e-6 and a.max() > 5.0
    assert abs(diffuse) < 0.01
