"""Render passes beside Combined (docs/passes.md): the light split sums to Combined, the
caustic pass holds exactly the photons that went through glass, and the data passes of a
known plane are its distance, normal and colour.
"""
import math

import numpy as np
import pytest

from conftest import look_at, merge, quad
from scene_builders import glass_ball_beam
from test_caustic_flux import floor_footprints, grow, pixel_of, sphere
from test_textures import stripes

LIGHT_SPLIT = ["emission", "environment", "direct", "indirect", "caustics"]
ALL = ["depth", "normal", "denoising_normal", "denoising_albedo"] + LIGHT_SPLIT


def render(g, scene, passes, **settings):
    options = dict(width=48, height=48, photons_per_pass=16384, seed=3)
    options.update(settings)
    r = g.Renderer(scene, g.Settings(passes=passes, **options))
    return r


def light_sum(r):
    return sum(r.render_pass(name).astype(np.float64) for name in LIGHT_SPLIT)


@pytest.mark.parametrize("scene_name,settings", [
    ("cornell", {}),
    ("caustic", {}),
    ("caustic", {"hash": "exact"}),
    ("caustic", {"direct_light": "photons"}),
    ("caustic", {"estimator": "pppm"}),
    ("mirror", {"estimator": "pppm", "direct_light": "photons", "hash": "exact"}),
])
def test_light_split_sums_to_combined(glslppm, scene_name, settings):
    """Emission + Environment + Direct + Indirect + Caustics is Combined in every pixel, to
    float rounding: the passes split Combined's own sums (the eye stage's compensated sum of
    light seen and sampled, the gather's tau), they do not estimate anything again. Rounding:
    the parts' compensated sums and the film's float products each round once, a few 1e-7 of
    the pixel (bound 4e-6 of the pixel plus 1e-6 of the image's mean, for pixels near 0)."""
    g = glslppm
    scene = {"cornell": lambda: g.cornell_box(False, False, 24),
             "caustic": lambda: g.caustic_scene(24),
             "mirror": lambda: g.cornell_box(True, True, 24)}[scene_name]()
    r = render(g, scene, ["all"], **settings)
    r.run(6)
    combined = r.film()[..., :3].astype(np.float64)
    parts = light_sum(r)
    bound = 4e-6 * np.abs(combined) + 1e-6 * combined.mean()
    assert combined.mean() > 0.01
    assert np.all(np.abs(parts - combined) <= bound), np.abs(parts - combined).max()
    # The passes leave Combined as it was: the same numbers as a render without them (the
    # exact hash's sums follow its atomics' order: equal to float rounding there). The light
    # split turns light tracing off (its Caustics pass would miss the splats:
    # docs/light_tracing.md), so the render without passes has it off too.
    assert "light-tracing" not in r.stats()["variant"].split(",")
    plain = g.Renderer(scene, g.Settings(width=48, height=48, photons_per_pass=16384, seed=3,
                                         light_tracing=False, **settings))
    plain.run(6)
    if settings.get("hash") == "exact":
        assert np.allclose(plain.film(), r.film(), rtol=1e-5, atol=1e-7)
    else:
        assert np.array_equal(plain.film(), r.film())
    assert "passes=" in r.stats()["variant"] and "passes=" not in plain.stats()["variant"]


def test_caustics_zero_without_glass_and_carry_the_glass_caustic(glslppm):
    """A diffuse-only Cornell box has no specular bounce, so no caustic photon: the pass is 0
    in every pixel while Indirect is not. The caustic scene's glass sphere focuses light onto
    the floor: its Caustics pass holds a bright spot, and no caustic light shows where photons
    cannot reach through glass (the diffuse box's passes are those of the same variant)."""
    g = glslppm
    r = render(g, g.cornell_box(False, False, 24), ["caustics", "indirect", "direct"])
    r.run(8)
    assert np.all(r.render_pass("caustics") == 0.0)
    assert r.render_pass("indirect").mean() > 0.01
    r = render(g, g.caustic_scene(24), ["caustics", "indirect"])
    r.run(8)
    caustics = r.render_pass("caustics")
    assert caustics.max() > 1.0 and caustics.mean() > 1e-3
    assert caustics.max() > 5.0 * r.render_pass("indirect").max()


SCATTERED = 1 << 21  # shaders/common/bounces.glsl's BOUNCES_SCATTERED


def photon_class(ph):
    """The path class of photon records (Renderer.photons(): column 7 is class + 4 x the
    bounce word)."""
    return ph[:, 7].astype(np.uint32) & 3


def photon_bounces(ph):
    return ph[:, 7].astype(np.uint32) >> 2


def kind_count(words, kind):
    """A kind's count in bounce words: 0 diffuse, 1 glossy, 2 transmission (7 bits each)."""
    return (words >> (7 * kind)) & 127


def test_photon_classes_follow_the_glass(glslppm):
    """A parallel beam falls onto a glass ball above a black floor (test_caustic_flux's beam),
    photons alone: a photon that comes straight down beside the ball is direct light (class
    0), every other photon on the floor went through the ball and is a caustic (class 2);
    nothing scatters diffusely, so there is no class 1. The class in the photon record
    must match this geometric count photon for photon."""
    g = glslppm
    faces = [quad((-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3))]
    ball_p, ball_t, ball_n = sphere((0.0, 1.0, 0.0), 0.5, 32, 64)
    positions, indices, ids = merge((*faces[0], 0), (ball_p, ball_t, 1))
    normals = np.concatenate([np.tile([0.0, 1.0, 0.0], (4, 1)), ball_n]).astype(np.float32)
    materials = [g.Material("diffuse", color=(0.0, 0.0, 0.0)),
                 g.Material("dielectric", color=(1.0, 1.0, 1.0), ior=1.5)]
    light = g.Light("spot", power=1000.0, position=(0.0, 3.5, 0.0), direction=(0.0, -1.0, 0.0),
                    spot_size=0.002, spot_blend=0.0, radius=0.7)
    camera = g.Camera(look_at((0.0, 0.3, 0.0), (0.0, 0.0, 0.0), up=(0, 0, -1)),
                      projection="orthographic", ortho_scale=2.0)
    scene = g.Scene(positions, indices, normals=normals, material_ids=ids, materials=materials,
                    lights=[light], camera=camera)
    r = g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=65536, seed=1,
                                     direct_light="photons", passes=["caustics", "direct"]))
    counted = {0: 0, 2: 0}
    in_and_out = 0  # caustic photons in and out of the ball, not reflected inside
    for _ in range(8):
        r.run(1)
        ph = r.photons()
        ph = ph[(ph[:, 11] > 0.0) & (np.abs(ph[:, 1]) < 1e-5)]
        # Beside the ball: straight down, outside its silhouette (the tessellated ball's lies
        # between 0.4985 and 0.5 from the axis). Light through the ball near its axis comes
        # out straight too, but lands near the axis. Left out: a band about the silhouette,
        # where light grazing the ball's steep facets is reflected by less than the cone
        # (a caustic, but straight, within 0.002 of the silhouette).
        rho = np.hypot(ph[:, 0], ph[:, 2])
        straight = ph[:, 5] > math.cos(2e-3)
        clear = (rho < 0.495) | (rho > 0.503)
        beside = straight & clear & (rho > 0.503)
        classes, bounces = photon_class(ph), photon_bounces(ph)
        assert np.all(classes[beside] == 0)
        assert np.all(classes[clear & ~beside] == 2)
        assert np.all(np.isin(classes, [0, 2]))
        # The bounce words (shaders/common/bounces.glsl, docs/bounces.md): none beside the
        # ball. Off the ball, the first scatter (a reflection off its outside, or the way in)
        # only marks the word; the way out is one transmission, after any glossy internal
        # reflections; nothing is diffuse, and nothing enters the convex ball twice.
        assert np.all(bounces[beside] == 0)
        through = bounces[clear & ~beside]
        glossy, transmission = kind_count(through, 1), kind_count(through, 2)
        assert np.all(through & SCATTERED != 0)
        assert np.all(kind_count(through, 0) == 0)
        assert np.all((transmission == 1) | ((transmission == 0) & (glossy == 0)))
        in_and_out += int(((glossy == 0) & (transmission == 1)).sum())
        counted[0] += int(beside.sum())
        counted[2] += int((clear & ~beside).sum())
    assert counted[0] > 1000 and counted[2] > 1000, counted
    assert in_and_out > 0.5 * counted[2], (in_and_out, counted)


def test_caustic_pass_flux_equals_the_photons_through_glass(glslppm):
    """test_caustic_flux's rendered-caustic scene (a beam through a glass ball onto a white
    floor beside a wall), light sampled: photons on the floor came through the ball
    (caustic) or off the wall and floor (indirect). The Caustics pass's flux over the caustic
    and 12 pixels around it, sum of pi L / albedo times each pixel's floor area, must equal
    the flux of the caustic photons stored there, counted at their positions from the photon
    records. Bound: as test_caustic_flux's (blur only moves flux outwards, <= 1.005; 12
    pixels hold it all within 0.5%, so a 1% bias fails)."""
    g = glslppm
    size = 256
    scene, to_world, fov_x, centre, radius, albedo = glass_ball_beam(g)
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=65536,
                                     hash="exact", seed=1, passes=["caustics", "indirect"]))
    photon_flux = np.zeros(size * size)
    for _ in range(40):
        r.run(1)
        ph = r.photons()
        ph = ph[(ph[:, 11] > 0.0) & (np.abs(ph[:, 1]) < 1e-5) & (photon_class(ph) == 2)]
        ph = ph.astype(np.float64)
        pixel = pixel_of(ph[:, :3], to_world, fov_x, size)
        inside = pixel >= 0
        photon_flux += np.bincount(pixel[inside], weights=ph[inside, 8], minlength=size * size)
    photon_flux = photon_flux.reshape(size, size) / r.stats()["photons_emitted"]
    area, visible = floor_footprints(to_world, fov_x, size, centre, radius)
    rendered = r.render_pass("caustics")[..., 0].astype(np.float64) * (math.pi / albedo) * area
    irradiance = np.where(visible, photon_flux / area, 0.0)
    caustic = visible & (irradiance > 0.05 * irradiance.max())
    region = grow(caustic, 12) & visible
    ratio = rendered[region].sum() / photon_flux[region].sum()
    assert 0.995 <= ratio <= 1.005, ratio
    # The caustic is most of the floor's photon light there: the indirect light off the
    # wall is a few percent of it.
    indirect = r.render_pass("indirect")[..., 0].astype(np.float64) * (math.pi / albedo) * area
    assert indirect[caustic].sum() < 0.1 * rendered[caustic].sum()


def plane_scene(g, textured):
    """A square plane 3 units in front of a perspective camera turned away from the axes,
    facing it: every pixel sees the plane at z-depth exactly 3 (its distance grows towards the
    corners, its depth along the view axis does not)."""
    to_world = look_at((0.5, 1.0, 2.0), (-1.0, 0.2, -0.5))
    eye, forward = to_world[:3, 3], -to_world[:3, 2]
    right, up = to_world[:3, 0], to_world[:3, 1]
    centre = eye + 3.0 * forward
    corners = [centre + sx * 4.0 * right + sy * 4.0 * up for sx, sy in
               [(-1, -1), (1, -1), (1, 1), (-1, 1)]]
    p = np.array(corners, dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=np.float32)
    colour = (1.0, 1.0, 1.0) if textured else (0.8, 0.4, 0.2)
    material = g.Material("diffuse", color=colour, color_texture=0 if textured else -1)
    textures = ([g.Texture(stripes([0.2, 0.9], texels_each=64, dtype=np.float32))]
                if textured else [])
    scene = g.Scene(p, t, uvs=uv if textured else None, materials=[material],
                    camera=g.Camera(to_world, fov_x=0.9), environment=(1.0, 1.0, 1.0),
                    textures=textures)
    return scene, forward


@pytest.mark.parametrize("estimator", ["sppm", "pppm", "vcm"])
def test_depth_normal_albedo_of_a_plane(glslppm, estimator):
    g = glslppm
    scene, forward = plane_scene(g, textured=False)
    r = render(g, scene, ["depth", "normal", "denoising_normal", "denoising_albedo"],
               estimator=estimator)
    r.run(4)
    depth = r.render_pass("depth")
    assert depth.shape == (48, 48, 1)
    # Float rounding of the hit point (a few ulps of 3) and of the mean over 4 passes.
    assert np.allclose(depth, 3.0, rtol=0, atol=2e-5), np.abs(depth - 3.0).max()
    # Normal in world space; Denoising Normal in Cycles' camera space (x right, y up, z along
    # the view), where a plane facing the camera is (0, 0, -1).
    facing = -forward / np.linalg.norm(forward)
    for name, want in [("normal", facing), ("denoising_normal", (0.0, 0.0, -1.0))]:
        n = r.render_pass(name)
        assert np.allclose(n, want, rtol=0, atol=1e-5), (name, np.abs(n - want).max())
    albedo = r.render_pass("denoising_albedo")
    assert np.allclose(albedo, (0.8, 0.4, 0.2), rtol=0, atol=1e-6)


@pytest.mark.parametrize("estimator", ["sppm", "vcm"])
def test_depth_of_background_and_textured_albedo(glslppm, estimator):
    """The textured plane's Denoising Albedo is the texel's colour (float stripes 0.2 and 0.9,
    compared in each stripe's central half, away from the bilinear blend); where the camera
    sees no surface, Depth is Cycles' 1e10, the normals 0 and the albedo the world's
    radiance (1 here), as Cycles writes the background into Denoising Albedo. VCM's eye
    paths write them as SPPM's."""
    g = glslppm
    scene, _ = plane_scene(g, textured=True)
    r = render(g, scene, ["depth", "normal", "denoising_albedo"], estimator=estimator)
    r.run(4)
    albedo = r.render_pass("denoising_albedo")[..., 0]
    near = {v: np.abs(albedo - v) < 1e-6 for v in (0.2, 0.9)}
    assert near[0.2].sum() > 200 and near[0.9].sum() > 200
    # Blends only in the pixels along the stripes' edges.
    assert (near[0.2] | near[0.9]).mean() > 0.9, (near[0.2] | near[0.9]).mean()
    # A triangle in the image's right half leaves the left half empty.
    empty = g.Scene(np.array([(0, -1, -5), (1, -1, -5), (1, 1, -5)], dtype=np.float32),
                    np.array([[0, 1, 2]], dtype=np.uint32),
                    materials=[g.Material("diffuse", color=(0.5, 0.5, 0.5))],
                    camera=g.Camera(np.eye(4, dtype=np.float32), fov_x=0.5),
                    environment=(1.0, 1.0, 1.0))
    r = render(g, empty, ["depth", "normal", "denoising_normal", "denoising_albedo"],
               estimator=estimator)
    r.run(2)
    depth = r.render_pass("depth")[..., 0]
    assert depth[24, 4] == 1e10 and abs(depth[24, 40] - 5.0) < 1e-5
    assert np.all(r.render_pass("normal")[24, 4] == 0.0)
    assert np.all(r.render_pass("denoising_normal")[24, 4] == 0.0)
    assert np.all(r.render_pass("denoising_albedo")[24, 4] == 1.0)


def test_pass_names_and_errors(glslppm):
    g = glslppm
    names = [p["name"] for p in g.render_passes()]
    assert names == ALL
    blender = {p["name"]: (p["blender"], p["blender_3x"]) for p in g.render_passes()}
    assert blender["emission"] == ("Emission", "Emit")
    assert blender["denoising_albedo"] == ("Denoising Albedo", "Denoising Albedo")
    assert g.Settings(passes=["all"]).passes == ALL
    assert g.Settings(passes=["combined"]).passes == []
    with pytest.raises(ValueError, match="'shadow' is not a render pass"):
        g.Settings(passes=["shadow"])
    r = render(g, g.cornell_box(False, False, 8), ["depth"], width=8, height=8)
    r.run(1)
    with pytest.raises(ValueError, match="'normal' was not enabled"):
        r.render_pass("normal")


def test_cli_writes_the_passes_as_one_multilayer_exr(glslppm, tmp_path):
    """glslppm-render --passes-out: one EXR whose channels Blender reads as the view layer's
    passes ("ViewLayer.<pass>.<channel>"), the light split summing to Combined there too."""
    import subprocess

    from test_cli import RENDER
    g = glslppm
    out = tmp_path / "passes.exr"
    base = [RENDER, "--width", "32", "--height", "24", "--passes", "4", "--photons", "4096",
            "--out", str(out)]
    result = subprocess.run(base + ["--passes-out", "all"], capture_output=True, text=True,
                            timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    channels = g.read_exr_channels(str(out))
    expected = {"ViewLayer.Combined." + c for c in "RGBA"}
    for p in g.render_passes():
        expected |= {"ViewLayer.%s.%s" % (p["blender"], c) for c in p["channel_names"]}
    assert set(channels) == expected
    for c in "RGB":
        combined = channels["ViewLayer.Combined." + c].astype(np.float64)
        parts = sum(channels["ViewLayer.%s.%s" % (name, c)].astype(np.float64)
                    for name in ["Emission", "Environment", "Direct", "Indirect", "Caustics"])
        assert np.all(np.abs(parts - combined) <= 4e-6 * np.abs(combined) + 1e-6 * combined.mean())
    # The built-in box's back wall faces the camera: Normal (0, 0, 1) at the image centre.
    assert abs(channels["ViewLayer.Normal.Z"][12, 16] - 1.0) < 1e-4
    assert 0.0 < channels["ViewLayer.Depth.Z"][12, 16] < 1e3

    # The same frame in bands of 8 rows (the per-pixel buffers capped; the pass films, 288
    # bytes a pixel, are the largest): its layers are the untiled frame's, Depth to float
    # rounding, the light split as test_tiles' films: within 4e-6 of the pixel's Combined
    # (a band's shifted film rounds hit points differently by an ulp; each part moves by
    # no more than its sum does).
    tiled_out = tmp_path / "tiled.exr"
    tiled = [a if a != str(out) else str(tiled_out) for a in base]
    result = subprocess.run(tiled + ["--passes-out", "all", "--max-block-bytes",
                                     str(32 * 8 * 288)], capture_output=True, text=True,
                            timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    assert "tile 3/3 done" in result.stderr
    bands = g.read_exr_channels(str(tiled_out))
    assert set(bands) == expected
    assert np.allclose(bands["ViewLayer.Depth.Z"], channels["ViewLayer.Depth.Z"], rtol=5e-7,
                       atol=0)
    for name in ["Combined.R", "Caustics.G", "Indirect.B", "Direct.R", "Emission.G"]:
        a, b = bands["ViewLayer." + name], channels["ViewLayer." + name]
        scale = channels["ViewLayer.Combined." + name[-1]]
        assert np.all(np.abs(a - b) <= 4e-6 * scale + 1e-7), (name, np.abs(a - b).max())

    result = subprocess.run(base + ["--passes-out", "combined"], capture_output=True, text=True,
                            timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    assert set(g.read_exr_channels(str(out))) == {"ViewLayer.Combined." + c for c in "RGBA"}
    result = subprocess.run(base + ["--passes-out", "depth,shadow"], capture_output=True,
                            text=True, timeout=60, cwd="/")
    assert result.returncode == 1 and "'shadow' is not a render pass" in result.stderr


def test_a_tiles_passes_are_the_frames_rows(glslppm):
    """The add-on renders a frame larger than one storage buffer as bands of rows, each its
    own renderer (tile_render_inputs) whose passes go into its part of the result: a band's
    passes equal those rows of the whole frame's. Depth comes from the eye stage alone, whose
    random streams the band shares with the frame: equal but for the rounding of the band's
    shifted film (an ulp or two of the depth). Caustics goes through the photons' hash and
    radii: within test_tiles' 4e-6 of the pixel."""
    g = glslppm
    scene = g.caustic_scene(24)
    settings = g.Settings(width=48, height=48, photons_per_pass=16384, seed=3,
                          passes=["depth", "caustics"])
    whole = g.Renderer(scene, settings)
    whole.run(4)
    band_scene, band_settings = g.tile_render_inputs(scene, settings, (0, 16, 48, 16))
    assert band_settings.passes == ["depth", "caustics"]
    band = g.Renderer(band_scene, band_settings)
    band.run(4)
    assert np.allclose(band.render_pass("depth"), whole.render_pass("depth")[16:32], rtol=5e-7,
                       atol=0.0)
    frame, part = whole.render_pass("caustics")[16:32], band.render_pass("caustics")
    assert frame.max() > 0.1
    assert np.all(np.abs(part - frame) <= 4e-6 * frame + 1e-7), np.abs(part - frame).max()


def test_a_restart_starts_the_passes_again(glslppm):
    """reset_film (the viewport's restarts) clears the pass films with Combined: the passes
    after a restart are those of a new renderer (same passes, same generator states: equal to
    float rounding, as test_restart's films)."""
    g = glslppm
    scene = g.caustic_scene(24)
    settings = g.Settings(width=32, height=32, photons_per_pass=8192, seed=7, passes=["all"])
    restarted = g.Renderer(scene, settings)
    restarted.run(5)
    restarted.reset_film()
    restarted.run(3)
    fresh = g.Renderer(scene, settings)
    fresh.run(3)
    together = restarted.render_passes(ALL)  # one read back: the same arrays
    for name in ALL:
        a, b = restarted.render_pass(name), fresh.render_pass(name)
        assert np.array_equal(together[name], a)
        assert np.abs(a - b).max() <= 1e-5 * max(1.0, float(np.abs(b).max())), name


def test_two_pppm_workers_merge_their_passes_as_their_films(glslppm):
    """PPPM on two workers (two contexts on this device): each worker's passes are the mean of
    its pass indices, merged by their counts as Combined is: the merged light split still
    sums to the merged Combined, and Depth and Caustics equal one worker's render of the same
    pass indices to float rounding (the merge sums float means in double)."""
    g = glslppm
    scene = g.caustic_scene(24)
    probe = g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=64))
    device = probe.stats()["devices"][0]["device"]
    probe.close()
    options = dict(width=32, height=32, photons_per_pass=8192, seed=5, estimator="pppm",
                   passes=["depth"] + LIGHT_SPLIT)
    two = g.Renderer(scene, g.Settings(devices=[device, device], **options))
    assert two.run(6) == 6
    assert len(two.stats()["devices"]) == 2
    combined = two.film()[..., :3].astype(np.float64)
    parts = light_sum(two)
    assert np.all(np.abs(parts - combined) <= 1e-5 * np.abs(combined) + 1e-6 * combined.mean())
    one = g.Renderer(scene, g.Settings(**options))
    one.run(6)
    # Merged in double from float means: equal to float rounding.
    assert np.allclose(two.render_pass("depth"), one.render_pass("depth"), rtol=1e-6, atol=0)
    assert np.allclose(two.render_pass("caustics"), one.render_pass("caustics"), rtol=1e-5,
                       atol=1e-6)


@pytest.mark.parametrize("estimator", ["sppm", "vcm"])
@pytest.mark.parametrize("wall", ["diffuse", "rough_conductor"])
def test_denoising_features_pass_through_a_mirror_as_cycles(glslppm, wall, estimator):
    """Cycles' rule (kernel/film/denoising_passes.h): a specular surface multiplies the
    feature throughput by its albedo and the features come from the next surface. A mirror
    of colour (0.9, 0.8, 0.7) at 45 degrees fills an orthographic view and shows a wall of
    colour (0.8, 0.4, 0.2): Denoising Albedo is their product in every pixel, noiselessly
    (bound 1e-5: a 1% error is 3e-3), and Denoising Normal the wall's normal (-1, 0, 0) in
    camera space (x right, y up, z along the view; the mirror's own would be (0.71, 0,
    -0.71)). The wall is a Lambert or a GGX conductor of roughness 0.5,
    which Cycles counts as diffuse-like (alpha 0.25 > 0.075)."""
    g = glslppm
    p = np.array([(-1, -1, 1), (1, -1, -1), (1, 1, -1), (-1, 1, 1),
                  (3, -5, -5), (3, 5, -5), (3, 5, 5), (3, -5, 5)], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]], dtype=np.uint32)
    colour = (0.8, 0.4, 0.2)
    materials = [g.Material("conductor", color=(0.9, 0.8, 0.7)),
                 g.Material("diffuse", color=colour) if wall == "diffuse" else
                 g.Material("conductor", color=colour, roughness=0.5)]
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 2.0
    scene = g.Scene(p, t, material_ids=np.array([0, 0, 1, 1], dtype=np.uint32),
                    materials=materials, environment=(1.0, 1.0, 1.0),
                    camera=g.Camera(to_world, projection="orthographic", ortho_scale=1.9))
    r = render(g, scene, ["denoising_normal", "denoising_albedo"], estimator=estimator)
    r.run(4)
    albedo = r.render_pass("denoising_albedo")
    want = np.array([0.9 * 0.8, 0.8 * 0.4, 0.7 * 0.2])
    assert np.abs(albedo - want).max() < 1e-5, np.abs(albedo - want).max()
    normal = r.render_pass("denoising_normal")
    assert np.abs(normal - (-1.0, 0.0, 0.0)).max() < 1e-5, np.abs(normal - (-1, 0, 0)).max()


def test_bottom_up_passes_are_the_rows_reversed(glslppm):
    """The add-on asks for its passes bottom row first, as Blender stores them, and the module
    flips them in the copy it makes anyway (one flip, as film(bottom_up=True) for Combined):
    exactly the top-down image's rows reversed, for 1- and 3-channel passes and Combined."""
    g = glslppm
    r = render(g, g.caustic_scene(24), ["depth", "direct", "normal"], width=40, height=24)
    r.run(2)
    top_down = r.render_passes(["depth", "direct", "normal"])
    bottom_up = r.render_passes(["depth", "direct", "normal"], bottom_up=True)
    for name in top_down:
        assert top_down[name].shape == bottom_up[name].shape
        assert top_down[name].std() > 0.0  # rows that differ: a flip that did nothing fails
        assert np.array_equal(bottom_up[name], top_down[name][::-1]), name
    assert np.array_equal(r.render_pass("direct", bottom_up=True), top_down["direct"][::-1])
    assert np.array_equal(r.film(bottom_up=True), r.film()[::-1])


def test_passes_and_combined_share_one_orientation(glslppm):
    """One flip, the module's: a lit square in the image's upper left, against a black world.
    The pixels Depth sees it in (depth below 1e10) and those Combined sees lit are the same
    pixels, row by row, top-down and bottom-up; the square is far from symmetric, so a pass
    flipped against Combined (or mirrored) would disagree in about half its pixels."""
    g = glslppm
    p, t = quad((-2.0, 0.2, -4.0), (-0.3, 0.2, -4.0), (-0.3, 1.9, -4.0), (-2.0, 1.9, -4.0))
    scene = g.Scene(p, t, materials=[g.Material("diffuse", color=(0.8,) * 3)],
                    lights=[g.Light("point", power=200.0, position=(-1.0, 1.0, -2.0))],
                    camera=g.Camera(np.eye(4, dtype=np.float32), fov_x=math.radians(60)))
    r = render(g, scene, ["depth", "normal"], width=40, height=24, photons_per_pass=4096)
    r.run(2)
    for bottom_up in (False, True):
        combined = r.film(bottom_up=bottom_up)[..., :3].sum(axis=2) > 0.0
        passes = r.render_passes(["depth", "normal"], bottom_up=bottom_up)
        seen = passes["depth"][..., 0] < 1e9
        facing = passes["normal"][..., 2] > 0.5  # the square faces the camera (+z)
        # Upper left (top-down) or lower left (bottom up): the square's place in each.
        rows = slice(0, 12) if not bottom_up else slice(12, 24)
        assert seen[rows, :20].mean() > 0.5 and seen[:, 20:].sum() == 0, bottom_up
        assert 0.1 < seen.mean() < 0.4
        assert (seen != seen[::-1]).mean() > 0.2  # a flipped pass would be caught
        # Edge pixels are partly covered (the pixel filter's jitter): at most one in 20.
        assert (seen != combined).mean() < 0.05, (seen != combined).mean()
        assert (seen != facing).mean() < 0.05, (seen != facing).mean()
    r.close()


def test_vcm_emission_and_environment_are_the_light_seen_before_a_rough_scatter(glslppm):
    """VCM (docs/vcm.md) writes Emission and Environment as SPPM's eye stage does: the light
    of emitters and the world the camera sees directly or through mirrors, none of what its
    paths meet past a rough scatter (that light is Combined's, whose split VCM does not write
    yet). A grey floor under a world of radiance (0.2, 0.3, 0.4), an emissive panel of
    radiance 5 above it in view, a mirror beside it showing the sky: where the camera sees
    the panel, Emission is 5 and Combined equals it (the panel is black, lit or not); where
    it sees the sky directly or in the mirror, Environment is the sky's radiance (times the
    mirror's colour, 0.9) and equals Combined; on the floor both are 0 while Combined is
    lit. Exact to float rounding (bound 1e-5: a 1% error is 3e-3 or more). Light tracing
    and merging add nothing to these passes' pixels (the panel and the sky hold no photon)."""
    g = glslppm
    sky = np.array([0.2, 0.3, 0.4])
    floor = quad((-4, 0, -4), (-4, 0, 4), (4, 0, 4), (4, 0, -4))
    panel = quad((-1.5, 1.0, -2.0), (-0.5, 1.0, -2.0), (-0.5, 2.0, -2.0), (-1.5, 2.0, -2.0))
    mirror = quad((0.5, 1.0, -2.0), (1.5, 1.0, -2.5), (1.5, 2.0, -2.5), (0.5, 2.0, -2.0))
    p, t, ids = merge((*floor, 0), (*panel, 1), (*mirror, 2))
    materials = [g.Material("diffuse", color=(0.5, 0.5, 0.5)),
                 g.Material("diffuse", color=(0.0, 0.0, 0.0), emission=(5.0, 5.0, 5.0)),
                 g.Material("conductor", color=(0.9, 0.9, 0.9))]
    scene = g.Scene(p, t, material_ids=ids, materials=materials, environment=tuple(sky),
                    camera=g.Camera(look_at((0, 1.5, 3), (0, 1.0, -2)), fov_x=1.2))
    r = render(g, scene, ["emission", "environment", "depth"], estimator="vcm")
    r.run(8)
    combined = r.film()[..., :3].astype(np.float64)
    emission = r.render_pass("emission").astype(np.float64)
    environment = r.render_pass("environment").astype(np.float64)
    depth = r.render_pass("depth")[..., 0]
    r.close()
    on_panel = np.all(np.abs(emission - 5.0) < 1e-5, axis=-1)
    sky_seen = np.all(np.abs(environment - sky) < 1e-5, axis=-1)
    mirrored = np.all(np.abs(environment - 0.9 * sky) < 1e-5, axis=-1)
    floor_seen = (depth < 1e9) & np.all(emission == 0.0, axis=-1) & \
        np.all(environment == 0.0, axis=-1)
    assert on_panel.sum() > 20 and sky_seen.sum() > 50 and mirrored.sum() > 20, \
        (on_panel.sum(), sky_seen.sum(), mirrored.sum())
    assert floor_seen.sum() > 300 and combined[floor_seen].mean() > 0.05
    assert np.abs(combined[on_panel] - emission[on_panel]).max() < 1e-5
    for seen in (sky_seen, mirrored):
        assert np.abs(combined[seen] - environment[seen]).max() < 1e-5
