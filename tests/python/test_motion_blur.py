"""Motion blur (issue 32, docs/motion_blur.md): each pass renders the scene at one time of the
shutter, a function of (seed, pass index) only; the passes' mean is the blurred image.

The sweep scene: a white diffuse strip (W = 0.5 units wide, taller than the image) lit
straight down by a sun, seen by an orthographic camera from above, moving along x at V
units per frame. Its radiance is albedo E / pi, so a pixel reads that times the fraction of
the pixel and of the shutter the strip covers: the box-filtered sweep, in closed form."""
import math

import numpy as np
import pytest

from conftest import quad

WIDTH, HEIGHT, HALF = 64, 16, 2.0          # 64 x 16 px over x in [-2, 2]: 1/16 unit a pixel
STRIP, SPEED = 0.5, 3.0                    # strip width and speed (units, units per frame)
OPEN, SHUTTER = -0.25, 0.5                 # Blender's shutter 0.5 centred on the frame
ALBEDO, SUN = 0.8, 2.0
RADIANCE = ALBEDO * SUN / math.pi
EMITTED = 1.5  # the emitting strip's radiance
PASSES = 64


def translation(x, y=0.0, z=0.0):
    m = np.eye(4, dtype=np.float32)
    m[:3, 3] = (x, y, z)
    return m


def strip_left(t):
    """The strip's left edge at time t (frames): -1 at the shutter's opening."""
    return -1.0 + SPEED * (t - OPEN)


def sweep_scene(g, moving="strip", shutter=SHUTTER, steps=None, curve=(), emitter=None):
    """The strip as an instance (moving: "strip", the camera: "camera" moves the other way,
    None: no motion given). steps: the step times (default the frame's -1, 0, +1).
    emitter: "strip" makes the strip black and emitting EMITTED; "aside" adds a still
    emitting instance of the strip's mesh far below the camera's view, facing away."""
    p, t = quad((0, -1, 0), (STRIP, -1, 0), (STRIP, 1, 0), (0, 1, 0))
    steps = [-1.0, 0.0, 1.0] if steps is None else steps
    # The placed-once mesh: one triangle far below the camera's view, outside the image.
    world_p = np.array([(10, 10, -5), (11, 10, -5), (10, 11, -5)], np.float32)
    world_t = np.array([[0, 1, 2]], np.uint32)
    camera = translation(0.0, 0.0, 4.0)
    instances, offsets = [translation(strip_left(0.0))], [1 if emitter == "strip" else 0]
    if emitter == "aside":
        below = translation(10.0, -10.0, -5.0)
        below[2, 2] = -1.0  # upside down (a mirror: its corners are swapped, it faces down)
        instances.append(below)
        offsets.append(1)
    scene = g.Scene(world_p, world_t,
                    materials=[g.Material("diffuse", color=(ALBEDO,) * 3),
                               g.Material("diffuse", color=(0.0,) * 3,
                                          emission=(EMITTED,) * 3)],
                    lights=[g.Light("sun", power=SUN, direction=(0, 0, -1))],
                    camera=g.Camera(camera, projection="orthographic", ortho_scale=2 * HALF),
                    instance_meshes=[{"positions": p, "indices": t}],
                    instances=np.array(instances),
                    instance_mesh=np.zeros(len(instances), np.uint32),
                    instance_material_offset=np.array(offsets, np.uint32))
    if moving == "strip":
        mats = np.array([translation(strip_left(s)) for s in steps])
        scene.set_motion(shutter_open=OPEN, shutter_length=shutter,
                         instances=[(0, steps, mats)], shutter_curve=list(curve))
    elif moving == "camera":  # the strip stands at its frame place; the camera runs back
        cams = np.array([translation(-(strip_left(s) - strip_left(0.0)), 0, 4) for s in steps])
        scene.set_motion(shutter_open=OPEN, shutter_length=shutter, camera_times=steps,
                         camera_to_world=cams)
    return scene


def render(g, scene, passes=PASSES, **kw):
    settings = dict(width=WIDTH, height=HEIGHT, photons_per_pass=1024, seed=5)
    settings.update(kw)
    r = g.Renderer(scene, g.Settings(**settings))
    r.run(passes)
    film = r.film()
    stats = r.stats()
    r.close()
    return film, stats


def ramp_mean(a, b, c, d):
    """The mean over x in [a, b] of clip((x - c) / d, 0, 1), in closed form."""
    def antiderivative(u):
        return np.where(u < 0, 0.0, np.where(u < 1, 0.5 * u * u, u - 0.5))
    return d * (antiderivative((b - c) / d) - antiderivative((a - c) / d)) / (b - a)


def analytic_columns(shutter=SHUTTER):
    """Each column's covered fraction, box-filtered over the pixel and the shutter: at x the
    strip covers the times its left edge is in [x - W, x], so coverage(x) = ramp(x - c) -
    ramp(x - c - W) with c the edge at the opening and the ramp over the sweep D = V S."""
    edges = np.linspace(-HALF, HALF, WIDTH + 1)
    c, d = strip_left(OPEN), SPEED * shutter
    return ramp_mean(edges[:-1], edges[1:], c, d) - ramp_mean(edges[:-1], edges[1:], c + STRIP, d)


def spread(profile):
    """The profile's variance about its own centroid (units^2): W^2/12 + D^2/12 (+ the
    pixels'), so dD/D = 1% moves it by 2 D^2 / (W^2 + D^2) % = 1.9% here."""
    x = np.linspace(-HALF, HALF, WIDTH + 1)
    x = 0.5 * (x[:-1] + x[1:])
    w = profile / profile.sum()
    mean = (w * x).sum()
    return float((w * (x - mean) ** 2).sum())


@pytest.mark.parametrize("moving", ["strip", "camera"])
def test_moving_strip_is_the_box_filtered_sweep(glslppm, moving):
    """Every pixel against L times its analytic coverage, and the profile's spread against
    the analytic one so tightly that a shutter 1% longer or shorter fails.

    Per pixel: the 64 passes' times are a shifted lattice (one per 1/64 of the shutter), so
    the time integral of a pixel's coverage (variation <= 2) errs by <= 2/64 (Koksma); the
    jitter within the pixel adds a Bernoulli mean over 16 rows x 64 passes (sigma <= 0.016);
    bound 0.031 + 4 sigma = 0.1 of L. The spread: the lattice's variance is (1 - 1/64^2) of
    the continuous one and the centroid is measured, so only the jitter's noise is left;
    bound 0.3% (a 1% shutter error moves it 1.9%; measured error printed)."""
    g = glslppm
    film, stats = render(g, sweep_scene(g, moving))
    assert stats["motion"] == ("instances" if moving == "strip" else "camera")
    if moving == "strip":
        assert stats["instancing"] == "two-level"
        assert stats["instancing_reason"] == "instances move (motion blur)"
    assert np.isfinite(film).all()
    rows = film[..., 0].astype(np.float64) / RADIANCE
    want = analytic_columns()
    assert np.abs(rows - want[None, :]).max() < 0.1, np.abs(rows - want[None, :]).max()
    measured = rows.mean(axis=0)
    # The strip's area is conserved by the motion: the row's integral is W (within the
    # per-pixel bound over the 16 ramp pixels' worst case).
    assert measured.sum() * (2 * HALF / WIDTH) == pytest.approx(STRIP, rel=0.01)
    exact, longer, shorter = spread(want), spread(analytic_columns(1.01 * SHUTTER)), \
        spread(analytic_columns(0.99 * SHUTTER))
    error = spread(measured) / exact - 1
    print(f"  spread {spread(measured):.5f} analytic {exact:.5f} ({error:+.4%}); "
          f"shutter +1%: {longer / exact - 1:+.4%}, -1%: {shorter / exact - 1:+.4%}")
    assert abs(error) < 0.003
    assert abs(longer / exact - 1) > 0.015 and abs(shorter / exact - 1) > 0.015


def test_a_wrong_shutter_length_fails_the_sweep_check(glslppm):
    """The check above against a render whose shutter is 1% longer: its spread misses the
    analytic one of the true shutter by more than the bound."""
    g = glslppm
    film, _ = render(g, sweep_scene(g, "strip", shutter=1.01 * SHUTTER))
    measured = film[..., 0].astype(np.float64).mean(axis=0) / RADIANCE
    error = spread(measured) / spread(analytic_columns()) - 1
    print(f"  1% longer shutter: spread error {error:+.4%}")
    assert abs(error) > 0.003


def test_steps_that_do_not_move_render_bit_identically(glslppm):
    """Motion given with every step the frame's matrix (instances and camera) is no motion:
    the same image, bit for bit, the same variant, and nothing moves."""
    g = glslppm
    still, still_stats = render(g, sweep_scene(g, None), passes=4)
    scene = sweep_scene(g, None)
    frame = np.array([translation(strip_left(0.0))] * 3)
    scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                     instances=[(0, [-1.0, 0.0, 1.0], frame)], camera_times=[-1.0, 1.0],
                     camera_to_world=np.array([translation(0, 0, 4)] * 2),
                     camera_fov_x=[0.7, 0.7])
    assert scene.has_motion
    same, same_stats = render(g, scene, passes=4)
    assert same_stats["motion"] == still_stats["motion"] == "none"
    assert same_stats["variant"] == still_stats["variant"]
    assert same_stats["instancing"] == still_stats["instancing"]
    assert np.array_equal(same, still)
    # ... while a moving strip does change the image (the comparison can fail).
    moved, _ = render(g, sweep_scene(g, "strip"), passes=4)
    assert not np.array_equal(moved, still)


def test_pppm_farm_halves_and_two_workers_merge_to_the_whole_run(glslppm):
    """PPPM: a pass's time is a function of (seed, pass index), so interleaved halves merge
    into the one run within the farm merge's bound (tests/python/test_farm_merge.py: 1e-6,
    the sums' order and casts), and two workers give the one worker's image."""
    g = glslppm
    scene = sweep_scene(g, "strip")
    settings = dict(width=WIDTH, height=HEIGHT, photons_per_pass=1024, seed=5,
                    estimator="pppm")
    films = {}
    for name, indices in (("even", [0, 2, 4, 6]), ("odd", [1, 3, 5, 7]), ("all", range(8))):
        r = g.Renderer(scene, g.Settings(**settings))
        r.run_passes(list(indices))
        films[name] = r.film()
        r.close()
    merged = g.merge_films([films["even"], films["odd"]], [4, 4])
    scale = np.maximum(np.abs(merged), np.abs(films["all"]))
    difference = np.divide(np.abs(merged - films["all"]), scale, out=np.zeros_like(scale),
                           where=scale > 0)
    assert difference.max() <= 1e-6
    # The halves differ (each saw other times), so the bound is not loose.
    assert np.abs(films["even"] - films["odd"]).max() > 1e3 * 1e-6
    probe = g.Renderer(scene, g.Settings(**settings))
    device = probe.stats()["devices"][0]["device"]
    probe.close()
    r = g.Renderer(scene, g.Settings(**settings, devices=[device, device]))
    r.run(8)
    two = r.film()
    assert sum(d["passes"] for d in r.stats()["devices"]) == 8
    r.close()
    scale = np.maximum(np.abs(two), np.abs(films["all"]))
    difference = np.divide(np.abs(two - films["all"]), scale, out=np.zeros_like(scale),
                           where=scale > 0)
    assert difference.max() <= 1e-6


RAMP = [0.0, 1.0]  # a shutter that opens steadily: the time's density 2 s over the shutter


def ramp_squared_mean(a, b, c, d):
    """The mean over x in [a, b] of clip((x - c) / d, 0, 1)^2, in closed form: the chance that
    a time drawn with density 2 s (s in [0, 1]) has the edge past x."""
    def antiderivative(u):
        return np.where(u < 0, 0.0, np.where(u < 1, u ** 3 / 3, u - 2.0 / 3.0))
    return d * (antiderivative((b - c) / d) - antiderivative((a - c) / d)) / (b - a)


def analytic_ramp_columns(shutter=SHUTTER):
    """analytic_columns under the RAMP shutter curve: the strip covers x while its left edge
    c + D s is in [x - W, x], with s of density 2 s."""
    edges = np.linspace(-HALF, HALF, WIDTH + 1)
    c, d = strip_left(OPEN), SPEED * shutter
    return (ramp_squared_mean(edges[:-1], edges[1:], c, d) -
            ramp_squared_mean(edges[:-1], edges[1:], c + STRIP, d))


def centroid(profile):
    x = np.linspace(-HALF, HALF, WIDTH + 1)
    x = 0.5 * (x[:-1] + x[1:])
    return float((profile * x).sum() / profile.sum())


@pytest.mark.parametrize("curve, inverse", [
    ([1.0, 1.0], lambda u: u),
    ([0.0, 1.0], np.sqrt),
    ([2.0, 0.0], lambda u: 1.0 - np.sqrt(1.0 - u)),
    ([0.0, 1.0, 0.0], lambda u: np.where(u < 0.5, np.sqrt(u / 2), 1.0 - np.sqrt(np.maximum(1.0 - u, 0) / 2))),
    # A closed middle: no time falls in (1/3, 2/3).
    ([1.0, 0.0, 0.0, 1.0], lambda u: np.where(u < 0.5, (1 - np.sqrt(np.maximum(1 - 2 * u, 0))) / 3,
                                              1.0 - (1 - np.sqrt(np.maximum(2 * u - 1, 0))) / 3)),
])
def test_the_shutter_curve_is_inverted_exactly(glslppm, curve, inverse):
    """shutter_position(curve, u): the inverse of the piecewise-linear curve's cumulative
    distribution, against closed forms to 1e-12 over u in [0, 1)."""
    u = np.linspace(0.0, 1.0, 1001)[:-1]
    got = np.array([glslppm.shutter_position(curve, float(v)) for v in u])
    assert np.abs(got - inverse(u)).max() < 1e-12, np.abs(got - inverse(u)).max()


@pytest.mark.parametrize("curve, message", [
    ([1.0], "one point"),
    ([1.0, -0.5], "is not a shutter's openness"),
    ([1.0, float("nan")], "is not a shutter's openness"),
    ([0.0, 0.0, 0.0], "the shutter never opens"),
])
def test_a_bad_shutter_curve_is_an_error_naming_it(glslppm, curve, message):
    g = glslppm
    with pytest.raises(ValueError, match=message):
        sweep_scene(g, "strip", curve=curve)
    with pytest.raises(ValueError, match=message):
        g.shutter_position(curve, 0.5)


def test_moving_strip_under_a_shutter_curve_is_its_weighted_sweep(glslppm):
    """Blender's shutter curve weights the times: under a ramp (the shutter opening steadily
    to full at its close) the times' density is 2 s, and each pixel reads L times the chance
    that the strip covers it, in closed form (analytic_ramp_columns). Per pixel: the passes'
    samples u are a shifted lattice and the time is the curve's inverse CDF of u, so the
    coverage as a function of u still varies by <= 2: the same bound as the box's, 0.1 of L.
    The centroid is c + W/2 + D E[s] (E[s] = 2/3): 256 passes' lattice errs in E[s] = mean
    of sqrt(u) by at most its variation / 256 (Koksma), D / 256 = 0.0059 units, and the
    jitter's noise is below 0.001: bound 0.008 units. A box shutter's lies D/6 = 0.25 units
    (4 px) earlier, a shutter 1% longer's 0.01 units later (measured: +0.0122, failing).
    """
    g = glslppm
    film, stats = render(g, sweep_scene(g, "strip", curve=RAMP), passes=256)
    assert stats["motion"] == "instances"
    assert np.isfinite(film).all()
    rows = film[..., 0].astype(np.float64) / RADIANCE
    want = analytic_ramp_columns()
    assert np.abs(rows - want[None, :]).max() < 0.1, np.abs(rows - want[None, :]).max()
    measured = rows.mean(axis=0)
    assert measured.sum() * (2 * HALF / WIDTH) == pytest.approx(STRIP, rel=0.01)
    error = centroid(measured) - centroid(want)
    box = centroid(analytic_columns()) - centroid(want)
    print(f"  centroid {centroid(measured):.4f} analytic {centroid(want):.4f} ({error:+.4f}); "
          f"a box shutter's {centroid(analytic_columns()):.4f}")
    assert abs(error) < 0.008
    assert abs(box) > 0.2
    # A flat curve is the box: the same image as no curve, bit for bit.
    flat, _ = render(g, sweep_scene(g, "strip", curve=[0.5, 0.5, 0.5]), passes=4)
    box_film, _ = render(g, sweep_scene(g, "strip"), passes=4)
    assert np.array_equal(flat, box_film)


def test_the_pass_time_is_a_stratified_function_of_seed_and_pass(glslppm):
    """shutter_sample(seed, i): in [0, 1), the same for the same arguments, one per 1/2^k of
    the shutter (strata shifted by the seed's offset) over any 2^k passes from a multiple of
    2^k, and another offset per seed."""
    g = glslppm
    for seed in (0, 1, 12345):
        u = np.array([g.shutter_sample(seed, i) for i in range(256)])
        assert ((u >= 0) & (u < 1)).all()
        for k in range(9):
            n = 1 << k
            for first in range(0, 256, n):
                strata = np.floor(((u[first:first + n] - u[0]) % 1.0) * n + 1e-9).astype(int)
                assert sorted(strata) == list(range(n)), (seed, k, first)
        assert g.shutter_sample(seed, 77) == u[77]
    assert g.shutter_sample(0, 0) != g.shutter_sample(1, 0)
    # Index 1 is half a shutter from index 0, index 2 a quarter (radical inverse).
    assert (g.shutter_sample(3, 1) - g.shutter_sample(3, 0)) % 1.0 == pytest.approx(0.5)
    assert (g.shutter_sample(3, 2) - g.shutter_sample(3, 0)) % 1.0 == pytest.approx(0.25)


def rotation_z(angle, scale=1.0, move=(0.0, 0.0, 0.0)):
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4, dtype=np.float32)
    m[:2, :2] = [[c * scale, -s * scale], [s * scale, c * scale]]
    m[2, 2] = scale
    m[:3, 3] = move
    return m


def test_transforms_interpolate_as_cycles_does(glslppm):
    """Rotation by quaternion slerp (a quarter turn's middle is an eighth, not the shrunken
    mean of the matrices), scale and translation linearly; mirrors stay mirrors."""
    g = glslppm
    steps = np.array([rotation_z(0.0, 1.0, (0, 0, 0)), rotation_z(math.pi / 2, 3.0, (2, 4, 0))])
    mid = g.interpolate_transform([0.0, 1.0], steps, 0.5)
    np.testing.assert_allclose(mid, rotation_z(math.pi / 4, 2.0, (1, 2, 0)), atol=1e-6)
    np.testing.assert_allclose(g.interpolate_transform([0.0, 1.0], steps, 1.0), steps[1],
                               atol=1e-6)
    # Held at the ends outside the steps.
    np.testing.assert_allclose(g.interpolate_transform([0.0, 1.0], steps, -3.0), steps[0],
                               atol=1e-6)
    # A half turn and a bit goes the short way round (-170 degrees, not +190).
    far = np.array([rotation_z(0.0), rotation_z(math.radians(190))])
    np.testing.assert_allclose(g.interpolate_transform([0.0, 1.0], far, 0.5),
                               rotation_z(math.radians(-85)), atol=1e-6)
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0]).astype(np.float32)
    both = np.array([mirror, rotation_z(math.pi / 2) @ mirror])
    mid = g.interpolate_transform([0.0, 1.0], both, 0.5)
    np.testing.assert_allclose(mid, rotation_z(math.pi / 4) @ mirror, atol=1e-6)


@pytest.mark.parametrize("change,message", [
    (dict(shutter_length=0.0), r"motion.shutter_length is 0: the shutter must stay open > 0"),
    (dict(shutter_length=-0.5), r"motion.shutter_length is -0.5"),
    (dict(shutter_length=float("nan")), r"motion.shutter_length is nan"),
    (dict(times=[0.0, 0.0]), r"motion.instances\[0\] step 1: times are not increasing"),
    (dict(times=[1.0, 0.0]),
     r"motion.instances\[0\] step 1: times are not increasing \(1 then 0\)"),
    (dict(times=[0.0, float("inf")]), r"motion.instances\[0\] step 1: time is not finite"),
    (dict(bad="nan"), r"motion.instances\[0\] step 1: matrix is not finite"),
    (dict(bad="singular"), r"motion.instances\[0\] step 1: matrix is singular"),
    (dict(bad="mirror"), r"motion.instances\[0\] step 1: matrix mirrors where the step before"),
    (dict(bad="projective"), r"motion.instances\[0\] step 1: matrix is not affine"),
    (dict(instance=3), r"motion.instances\[0\].instance: 3 is out of range \(1 instances\)"),
    (dict(times=[0.0, 0.5, 1.0]), r"motion.instances\[0\]: 3 times for 2 matrices"),
    (dict(camera_fov_x=[0.5]), r"motion.camera_fov_x: 1 values for 2 camera steps"),
    (dict(camera_fov_x=[0.5, 4.0]), r"motion.camera_fov_x: 4 is not an angle of view"),
])
def test_bad_motion_is_an_error_naming_it(glslppm, change, message):
    g = glslppm
    scene = sweep_scene(g, None)
    mats = np.array([translation(0.0), translation(1.0)])
    if change.get("bad") == "nan":
        mats[1, 0, 3] = np.nan
    elif change.get("bad") == "singular":
        mats[1, :3, 0] = 0.0
    elif change.get("bad") == "mirror":
        mats[1, 0, 0] = -1.0
    elif change.get("bad") == "projective":
        mats[1, 3, 0] = 0.5
    kw = dict(shutter_open=0.0, shutter_length=change.get("shutter_length", 1.0),
              instances=[(change.get("instance", 0), change.get("times", [0.0, 1.0]), mats)])
    if "camera_fov_x" in change:
        kw.update(camera_times=[0.0, 1.0], camera_fov_x=change["camera_fov_x"],
                  camera_to_world=np.array([translation(0, 0, 4)] * 2))
    with pytest.raises(ValueError, match=message):
        scene.set_motion(**kw)
    assert not scene.has_motion  # the scene keeps no half-set motion


def spinning_scene(g, still=None):
    """A unit square turning a quarter turn about z over the frame (steps at -1, 0, +1, with
    growing scale and a drift), or standing still at `still`. Two black triangles outside
    the view fix the scene's box for both, so that the frames' constants (ray offsets, hash
    grid) are the same and only the instance's transform differs."""
    p, t = quad((-0.5, -0.5, 0), (0.5, -0.5, 0), (0.5, 0.5, 0), (-0.5, 0.5, 0))
    fence = np.array([(-12, -12, -5), (-10, 12, 3), (-11, 0, -5),
                      (12, -12, -5), (10, 12, 3), (11, 0, -5)], np.float32)
    steps = [-1.0, 0.0, 1.0]
    mats = np.array([rotation_z(a, s, (d, 0, 0)) for a, s, d in
                     zip((0.0, math.pi / 4, math.pi / 2), (1.0, 1.1, 1.3), (-0.3, 0.0, 0.4))])
    scene = g.Scene(fence, np.array([[0, 1, 2], [3, 4, 5]], np.uint32),
                    material_ids=np.array([1, 1], np.uint32),
                    materials=[g.Material("diffuse", color=(ALBEDO,) * 3),
                               g.Material("diffuse", color=(0, 0, 0))],
                    lights=[g.Light("sun", power=SUN, direction=(0, 0, -1))],
                    camera=g.Camera(translation(0, 0, 4), projection="orthographic",
                                    ortho_scale=2 * HALF),
                    instance_meshes=[{"positions": p, "indices": t}],
                    instances=np.array([mats[1] if still is None else still]),
                    instance_mesh=np.zeros(1, np.uint32))
    if still is None:
        scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER, instances=[(0, steps, mats)])
    return scene, steps, mats


def passes_equal_still_frames(g, scene, settings, motion, still_at, passes=8):
    """PPPM passes 0..passes-1 of the moving scene against the mean of the same passes of
    still scenes still_at(t_i), t_i = open + length shutter_sample(seed, i), each with a fresh
    tree: within the farm merge's 1e-6 relative, pixel by pixel. Returns the still films."""
    r = g.Renderer(scene, settings)
    r.run_passes(list(range(passes)))
    moving = r.film()
    assert r.stats()["motion"] == motion
    r.close()
    stills = []
    for i in range(passes):
        r = g.Renderer(still_at(OPEN + SHUTTER * g.shutter_sample(settings.seed, i)), settings)
        r.run_passes([i])
        stills.append(r.film())
        r.close()
    mean = g.merge_films(stills, [1] * passes)
    scale = np.maximum(np.abs(mean), np.abs(moving))
    difference = np.divide(np.abs(mean - moving), scale, out=np.zeros_like(scale),
                           where=scale > 0)
    print(f"  max relative difference {difference.max():.3g}")
    assert difference.max() <= 1e-6
    return stills


def test_a_spinning_instance_is_the_mean_of_still_frames_at_the_pass_times(glslppm):
    """Rotation, scale and drift together, through the refitted top level: PPPM pass i of
    the moving instance equals pass i of a still scene with the instance placed at
    interpolate_transform(steps, t_i), t_i = open + length shutter_sample(seed, i) (fresh
    two-level tree); their mean over 8 passes, within the farm merge's 1e-6."""
    g = glslppm
    settings = g.Settings(width=WIDTH, height=2 * HEIGHT, photons_per_pass=1024, seed=9,
                          estimator="pppm", instancing="two-level", initial_radius=0.05)
    scene, steps, mats = spinning_scene(g)
    stills = passes_equal_still_frames(
        g, scene, settings, "instances",
        lambda t: spinning_scene(g, g.interpolate_transform(steps, mats, t))[0])
    # The stills differ from each other: the square did turn.
    assert np.abs(stills[0] - stills[1]).max() > 0.1 * RADIANCE


def glass_ball_scene(g, still=None):
    """A glass ball (ior 1.5, r 0.4, centre 0.6 above a white floor: its focus on the floor)
    moving 1 unit along y per frame under a sun slanted along x, so that its caustic lands
    beside it at x = 0.45, seen from above by an orthographic camera; or standing still at
    `still`. Two small black fence triangles outside the view fix the scene's box (and so
    the frame's constants) for all of them."""
    from conftest import sphere
    bp, bt, bn = sphere((0, 0, 0), 0.4, 24, 48)
    fp, ft = quad((-1.5, -1.5, 0), (1.5, -1.5, 0), (1.5, 1.5, 0), (-1.5, 1.5, 0))
    fence = np.array([(-1.6, -1.6, -0.3), (-1.59, -1.6, -0.3), (-1.6, -1.59, -0.3),
                      (1.6, 1.6, 1.3), (1.59, 1.6, 1.3), (1.6, 1.59, 1.3)], np.float32)
    steps = [-1.0, 0.0, 1.0]
    mats = np.array([translation(0.0, y, 0.6) for y in (-1.0, 0.0, 1.0)])
    scene = g.Scene(np.concatenate([fp, fence]),
                    np.concatenate([ft, np.array([[4, 5, 6], [7, 8, 9]])]).astype(np.uint32),
                    material_ids=np.array([0, 0, 1, 1], np.uint32),
                    materials=[g.Material("diffuse", color=(ALBEDO,) * 3),
                               g.Material("diffuse", color=(0, 0, 0)),
                               g.Material("dielectric", ior=1.5)],
                    lights=[g.Light("sun", power=SUN, direction=(0.6, 0, -0.8))],
                    camera=g.Camera(translation(0.45, 0, 4), projection="orthographic",
                                    ortho_scale=2.0),
                    instance_meshes=[{"positions": bp, "indices": bt, "normals": bn}],
                    instances=np.array([mats[1] if still is None else still]),
                    instance_mesh=np.zeros(1, np.uint32),
                    instance_material_offset=np.array([2], np.uint32))
    if still is None:
        scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER, instances=[(0, steps, mats)])
    return scene, steps, mats


def test_a_moving_glass_balls_caustic_is_the_mean_of_still_frames(glslppm):
    """A caustic from a moving glass ball (photons through the ball's refractions, and light
    tracing's splats) smears as the ball moves: PPPM pass i equals pass i of the ball
    standing still where it is at pass i's time, so the moving render is the mean of still
    frames at the passes' times, within the farm merge's 1e-6. The smear: each still frame's
    caustic sits under the ball's place at its time (within 0.05 units, 1.2 px), the times
    span the sweep, and the moving image's peak falls below 0.7 of the still frame's."""
    g = glslppm
    settings = g.Settings(width=48, height=48, photons_per_pass=16384, seed=4,
                          estimator="pppm", instancing="two-level", initial_radius=0.03)
    passes = 8
    scene, steps, mats = glass_ball_scene(g)
    r = g.Renderer(scene, settings)
    r.run_passes(list(range(passes)))
    moving = r.film()
    stats = r.stats()
    r.close()
    assert stats["motion"] == "instances" and "light-tracing" in stats["variant"], stats
    stills = []
    for i in range(passes):
        t = OPEN + SHUTTER * g.shutter_sample(4, i)
        still, _, _ = glass_ball_scene(g, g.interpolate_transform(steps, mats, t))
        r = g.Renderer(still, settings)
        r.run_passes([i])
        stills.append(r.film())
        r.close()
    mean = g.merge_films(stills, [1] * passes)
    scale = np.maximum(np.abs(mean), np.abs(moving))
    difference = np.divide(np.abs(mean - moving), scale, out=np.zeros_like(scale),
                           where=scale > 0)
    # The ball standing at the frame's place, for the smear.
    frame, _, _ = glass_ball_scene(g, mats[1])
    r = g.Renderer(frame, settings)
    r.run_passes(list(range(passes)))
    still = r.film()
    r.close()

    def caustic_y(film):
        """The caustic's centre along y (units): the light above 1.0 (the lit floor reads
        0.41, the caustic 2 to 30) in the columns around x = 0.45, weighted by it."""
        w = np.maximum(film[:, 18:30, 0].astype(np.float64) - 1.0, 0.0).sum(axis=1)
        y = 1.0 - (np.arange(48) + 0.5) / 48 * 2.0  # row 0 at the top, y up
        return float((w * y).sum() / w.sum())

    times = [OPEN + SHUTTER * g.shutter_sample(4, i) for i in range(passes)]
    ball_y = [float(g.interpolate_transform(steps, mats, t)[1, 3]) for t in times]
    found = [caustic_y(f) for f in stills]
    print(f"  max relative difference {difference.max():.3g}; caustic y per pass "
          f"{np.round(found, 3).tolist()} (ball {np.round(ball_y, 3).tolist()}); peak "
          f"{still[..., 0].max():.2f} still -> {moving[..., 0].max():.2f} moving")
    assert np.isfinite(moving).all()
    assert difference.max() <= 1e-6
    # The caustic follows the ball (1 px = 0.042 units) over the passes, which span the
    # sweep; so the moving image spreads it, and its peak falls.
    assert np.abs(np.array(found) - np.array(ball_y)).max() < 0.05
    assert max(ball_y) - min(ball_y) > 0.4
    assert moving[..., 0].max() < 0.7 * still[..., 0].max()


def sweep_errors(film, radiance):
    """The worst pixel against L times its analytic coverage (in L) and the relative error of
    the profile's spread (test_moving_strip_is_the_box_filtered_sweep's bounds: 0.1, 0.3%)."""
    rows = film[..., 0].astype(np.float64) / radiance
    want = analytic_columns()
    return float(np.abs(rows - want[None, :]).max()), spread(rows.mean(axis=0)) / spread(want) - 1


def test_a_moving_emitting_strip_is_the_box_filtered_sweep(glslppm):
    """An instance that emits light moves: placed once with the other emitters (photons and
    light samples start from world-space triangles), its triangles, normals and emitter
    records rewritten at each pass's time (render/emitter_motion.cpp). The strip black and
    emitting L: the lit strip's closed form, every pixel within 0.1 L and the spread within
    0.3% (a 1% shutter error moves it 1.9%). Measured: 0.036 L, +0.09%."""
    g = glslppm
    film, stats = render(g, sweep_scene(g, "strip", emitter="strip"))
    assert stats["motion"] == "emitters" and stats["instancing"] == "flattened", stats
    assert "the 1 that emit light are placed once" in stats["instancing_reason"]
    assert not [w for w in stats["warnings"] if "motion blur" in w], stats["warnings"]
    assert np.isfinite(film).all()
    worst, error = sweep_errors(film, EMITTED)
    print(f"  emitting strip: worst pixel {worst:.3f} L, spread {error:+.4%}")
    assert worst < 0.1 and abs(error) < 0.003, (worst, error)


def test_instances_move_beside_an_instance_that_emits(glslppm):
    """An instance that emits light no longer stops the others' motion: the emitting one is
    placed once and the lit strip moves through the two levels, rendering its closed form
    (bounds as above; measured 0.050 L, -0.19%: the emitter, picked for some light samples and
    photons, adds noise). set_camera (the viewport's) makes a moving camera stand still while
    the instances keep moving."""
    g = glslppm
    scene = sweep_scene(g, "strip", emitter="aside")
    film, stats = render(g, scene)
    assert stats["motion"] == "instances" and stats["instancing"] == "two-level", stats
    assert "the 1 that emit light are placed once" in stats["instancing_reason"]
    worst, error = sweep_errors(film, RADIANCE)
    print(f"  strip beside an emitter: worst pixel {worst:.3f} L, spread {error:+.4%}")
    assert worst < 0.1 and abs(error) < 0.003, (worst, error)
    cams = np.array([translation(0, 0, 4), translation(1, 0, 4)])
    scene.set_motion(shutter_open=OPEN, shutter_length=SHUTTER,
                     instances=[(0, [-1.0, 1.0], np.array([translation(strip_left(-1.0)),
                                                          translation(strip_left(1.0))]))],
                     camera_times=[-1.0, 1.0], camera_to_world=cams)
    r = g.Renderer(scene, g.Settings(width=WIDTH, height=HEIGHT, photons_per_pass=1024))
    assert r.stats()["motion"] == "camera,instances"
    assert r.set_camera(g.Camera(translation(0, 0, 4), projection="orthographic",
                                 ortho_scale=2 * HALF))
    assert r.stats()["motion"] == "instances"
    r.close()
