"""Render passes through Blender (docs/passes.md): chosen in View Layer Properties as with
Cycles, written into the RenderResult, shown by the compositor's Render Layers node and
written by a File Output node; the light split sums to Combined, and a plane's Depth,
Normal and Denoising Albedo are its distance, normal and colour; the Denoising passes are
Cycles' (camera-space normal, noiseless albedo of a Principled face)."""

import os

import _cycles  # Blender's Cycles module: says whether Blender has OpenImageDenoise
import bpy
import numpy as np

import helpers
from helpers import add_camera, add_light, add_mesh_object, diffuse_material

SIZE = (40, 30)
LIGHT_SPLIT = ["Emission", "Environment", "Direct", "Indirect", "Caustics"]
# Blender 3.x names two of them shorter.
NAMES = {"Emission": "Emission", "Environment": "Environment"} if helpers.BLENDER_4 else \
    {"Emission": "Emit", "Environment": "Env"}


def plane_scene(every_pass=True):
    """A plane of colour (0.8, 0.4, 0.2) at z = 0 under a point light and a grey world, seen
    straight down by a camera 5 above it: Depth 5, Normal +z everywhere."""
    scene = helpers.reset_scene(size=SIZE)
    scene.glslppm.passes = 4
    scene.glslppm.photons_per_pass = 4096
    add_mesh_object("Plane", [(-20, -20, 0), (20, -20, 0), (20, 20, 0), (-20, 20, 0)],
                    [(0, 1, 2, 3)], material=diffuse_material("Orange", (0.8, 0.4, 0.2)))
    add_light('POINT', 300.0, location=(1, 1, 3))
    helpers.set_world((0.2, 0.2, 0.2))
    add_camera((0, 0, 5), (0, 0, 0))
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_normal = every_pass
    layer.use_pass_emit = layer.use_pass_environment = every_pass
    layer.glslppm.use_pass_denoising_data = every_pass
    layer.glslppm.use_pass_light_split = every_pass
    return scene


def test_passes_it_does_not_render_are_named_in_a_warning():
    """Vector and Mist on (as a Cycles user's view layer may have them): the render still
    writes Combined and the passes it renders, and one warning names the two it leaves out,
    so that the compositor's missing inputs are not a surprise. Without them, no such
    warning."""
    plane_scene(every_pass=False)
    layer = bpy.context.scene.view_layers[0]
    layer.use_pass_vector = layer.use_pass_mist = True
    layer.use_pass_z = True
    image, error, engine = helpers.render_recorded("passes_not_rendered")
    assert error is None, error
    assert image is not None and float(image[..., :3].mean()) > 0.01
    named = [w for w in helpers.warnings_of(engine) if "does not render" in w]
    assert len(named) == 1 and "Vector" in named[0] and "Mist" in named[0], named
    assert "Depth" not in named[0] and "Z" not in named[0].split(": ")[1], named
    layer.use_pass_vector = layer.use_pass_mist = False
    _, error, engine = helpers.render_recorded("passes_all_rendered")
    assert error is None, error
    assert not [w for w in helpers.warnings_of(engine) if "does not render" in w]


def assert_everywhere(array, value, tolerance, what):
    helpers.assert_close(array, np.full(np.shape(array), value), tolerance, what)


def render_multilayer(name, engine='GLSLPPM'):
    """Renders into OUT/name.exr as a multi-layer EXR; {channel: (H, W) array, row 0 at the
    top} read back with the module."""
    native = helpers.load_native()
    scene = bpy.context.scene
    scene.render.engine = engine
    settings = scene.render.image_settings
    helpers.compat().set_exr_format(settings, multilayer=True)
    settings.exr_codec = 'ZIP'
    path = os.path.join(helpers.OUT, f"{name}.exr")
    scene.render.filepath = path
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    # EXR rows run top to bottom, as the module's arrays do.
    return dict(native.read_exr_channels(path))


def test_passes_sum_to_combined_and_describe_the_plane():
    plane_scene()
    channels = render_multilayer("passes_plane")
    layer = "ViewLayer."
    expected = {layer + "Combined." + c for c in "RGBA"} | {layer + "Depth.Z"}
    for name in ["Normal", "Denoising Normal"]:
        expected |= {layer + name + "." + c for c in "XYZ"}
    for name in ["Denoising Albedo", "Direct", "Indirect", "Caustics",
                 NAMES["Emission"], NAMES["Environment"]]:
        expected |= {layer + name + "." + c for c in "RGB"}
    assert expected <= set(channels), sorted(set(expected) - set(channels))
    for c in "RGB":
        combined = channels[layer + "Combined." + c].astype(np.float64)
        parts = sum(channels[layer + NAMES.get(n, n) + "." + c].astype(np.float64)
                    for n in LIGHT_SPLIT)
        bound = 4e-6 * np.abs(combined) + 1e-6 * combined.mean()
        assert combined.mean() > 0.01
        assert np.all(np.abs(parts - combined) <= bound), np.abs(parts - combined).max()
    # The plane fills the image: no caustic (nothing specular), Depth 5, normal +z.
    assert np.all(channels[layer + "Caustics.R"] == 0.0)
    assert_everywhere(channels[layer + "Depth.Z"], 5.0, 1e-4, "depth")
    # Normal in world space; Denoising Normal in Cycles' camera space (the camera looks
    # straight down: the plane faces it, -z).
    for name, normal in [("Normal", (0.0, 0.0, 1.0)), ("Denoising Normal", (0.0, 0.0, -1.0))]:
        for c, value in zip("XYZ", normal):
            assert_everywhere(channels[layer + name + "." + c], value, 1e-5, name)
    for c, value in zip("RGB", (0.8, 0.4, 0.2)):
        assert_everywhere(channels[layer + "Denoising Albedo." + c], value, 1e-6, "albedo")


def compositor_tree(scene):
    """An empty compositor tree with a Render Layers node and the composite output (the
    Composite node up to 4.x, the tree's Group Output in 5.x)."""
    tree, composite = helpers.compat().compositor_tree(scene)
    layers = tree.nodes.new("CompositorNodeRLayers")
    return tree, layers, composite


def test_compositor_shows_the_passes_and_file_output_writes_them():
    """The Render Layers node has a socket per enabled pass (and none for a disabled one); a
    File Output node fed Caustics, Depth and Denoising Albedo writes them; a Denoise node fed
    Image, Denoising Normal and Denoising Albedo runs where Blender has OpenImageDenoise."""
    scene = plane_scene()
    tree, layers, composite = compositor_tree(scene)
    sockets = {socket.name for socket in layers.outputs if socket.enabled}
    wanted = {"Image", "Depth", "Normal", "Denoising Normal", "Denoising Albedo", "Direct",
              "Indirect", "Caustics", NAMES["Emission"], NAMES["Environment"]}
    assert wanted <= sockets, sorted(wanted - sockets)
    scene.view_layers[0].glslppm.use_pass_light_split = False
    sockets = {socket.name for socket in layers.outputs if socket.enabled}
    assert "Caustics" not in sockets and "Depth" in sockets, sorted(sockets)
    scene.view_layers[0].glslppm.use_pass_light_split = True

    directory = os.path.join(helpers.OUT, "file_output")
    names = ["Caustics", "Depth", "Denoising Albedo"]
    output = helpers.compat().file_output_node(tree, directory, names)
    for name in names:
        tree.links.new(layers.outputs[name], output.inputs[name])
    # The Denoise node fed Image, Denoising Normal and Denoising Albedo, into the Composite.
    denoise = tree.nodes.new("CompositorNodeDenoise")
    tree.links.new(layers.outputs["Image"], denoise.inputs["Image"])
    tree.links.new(layers.outputs["Denoising Normal"], denoise.inputs["Normal"])
    tree.links.new(layers.outputs["Denoising Albedo"], denoise.inputs["Albedo"])
    tree.links.new(denoise.outputs["Image"], composite.inputs["Image"])
    channels = render_multilayer("passes_compositor")
    written = sorted(os.listdir(directory))
    native = helpers.load_native()
    for name, channel in [("Caustics", "R"), ("Depth", "Z"), ("Denoising Albedo", "R")]:
        files = [f for f in written if f.startswith(name)]
        assert len(files) == 1, written
        image = native.read_exr_channels(os.path.join(directory, files[0]))
        # A single-layer EXR of a value pass holds it in V (3.x) or in R, G, B.
        values = image.get("V", image.get("R"))
        reference = channels["ViewLayer." + name + "." + channel]
        helpers.assert_close(values, reference, 1e-6, f"{name} written by File Output")
    # Blender's Denoise node runs OpenImageDenoise where Blender was built with it (as
    # Cycles reports); Debian's 3.4 and 4.3 builds were not, and the node then passes its
    # image through: the composite is Combined exactly. Where it runs, it must smooth the
    # noisy floor (the pixel-to-pixel spread of the lit plane drops).
    composite_rgb = np.stack([channels["Composite.Combined." + c] for c in "RGB"], axis=-1)
    combined_rgb = np.stack([channels["ViewLayer.Combined." + c] for c in "RGB"], axis=-1)
    if not _cycles.with_openimagedenoise:
        print("test_passes: this Blender has no OpenImageDenoise: the Denoise node passes the "
              "image through")
        assert np.array_equal(composite_rgb, combined_rgb)
    else:
        assert np.isfinite(composite_rgb).all()
        spread = [np.abs(np.diff(image[..., 0], axis=1)).mean()
                  for image in (composite_rgb, combined_rgb)]
        assert spread[0] < 0.7 * spread[1], spread


def test_caustics_pass_holds_the_glass_balls_caustic():
    """A Glass BSDF ball above the plane focuses the point light into a spot below it: the
    Caustics pass is bright there and holds no light where the ball cannot send any (the
    image's corners, far outside its shadow), while the diffuse-only plane of the test above
    had none at all."""
    scene = plane_scene()
    scene.glslppm.passes = 16
    scene.glslppm.photons_per_pass = 65536
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(0, 0, 1.0), segments=48,
                                         ring_count=24)
    bpy.ops.object.shade_smooth()
    glass = helpers.node_material("Glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.0)
    bpy.context.object.data.materials.append(glass)
    light = next(o for o in scene.objects if o.type == 'LIGHT')
    light.location = (0, 0, 4)
    channels = render_multilayer("passes_caustic")
    caustics = channels["ViewLayer.Caustics.R"]
    height, width = caustics.shape
    centre = caustics[height // 2 - 3:height // 2 + 3, width // 2 - 3:width // 2 + 3]
    corners = np.concatenate([caustics[:4, :4].ravel(), caustics[-4:, -4:].ravel()])
    assert centre.max() > 0.5 and centre.mean() > 10.0 * max(corners.mean(), 1e-6), \
        (centre.mean(), corners.mean())


# Denoising Albedo against Cycles on a Principled face: rms of the per-pixel difference and
# the relative difference of the face's mean. Measured: 3.4 rms 1e-4 to 7e-4, means within
# 0.03%; 4.3 rms 3e-4 to 8e-4, means within 0.1% (the GGX albedo tables differ slightly).
# An albedo 1% off is 8e-3 rms and 1% in the mean; the sampled lobe (before) was 0.22 rms.
ALBEDO_RMS = 0.004
ALBEDO_MEAN = 0.005


def principled_cube_scene():
    """Blender's default cube (default Principled BSDF, base colour 0.8) seen from the
    default camera's place, under a point light and a grey world: three faces in view."""
    scene = helpers.reset_scene(size=(64, 64))
    scene.glslppm.passes = 16
    scene.glslppm.photons_per_pass = 4096
    material = helpers.node_material("Principled", "ShaderNodeBsdfPrincipled")
    helpers.add_cube("Cube", material=material)
    add_light('POINT', 1000.0, location=(4.1, 1.0, 5.9))
    helpers.set_world((0.05, 0.05, 0.05))
    location = (7.36, -6.93, 4.96)
    add_camera(location, helpers.look_at_rotation(location, (0, 0, 0)))
    layer = scene.view_layers[0]
    layer.glslppm.use_pass_denoising_data = True
    layer.cycles.denoising_store_passes = True
    return scene


def _stack(channels, name, components):
    return np.stack([channels["ViewLayer." + name + "." + c] for c in components], axis=-1)


def test_denoising_passes_match_cycles_on_a_principled_cube():
    """Denoising Albedo and Normal of the default cube against Cycles' (16 samples each).
    Normals: Cycles' camera space, per pixel wherever a pixel and its 8 neighbours see one
    face (Cycles' 1.5-pixel filter blends across edges), within 2e-3 (the 45-degree turn
    of a world-space normal was 1.44 off). Albedo: on each face's inner pixels the spread
    is below 0.01 (Cycles 0.0004-0.006, from the view angle's Fresnel; the sampled lobe gave
    0.22 at 16 passes), per pixel within ALBEDO_RMS of Cycles' and each channel's mean within
    ALBEDO_MEAN (both are base colour plus the specular layer's expected albedo: Cycles 3.4
    takes Fresnel at the view angle, 4.x its GGX albedo table, as here)."""
    _denoising_cube_against_cycles('SPPM', "denoising_cube")


def test_denoising_passes_under_vcm_match_cycles_on_a_principled_cube():
    """The same passes under the VCM estimator (docs/vcm.md: its eye paths write the
    denoising features as SPPM's eye stage does), with the same bounds against Cycles."""
    _denoising_cube_against_cycles('VCM', "denoising_cube_vcm")


def _denoising_cube_against_cycles(estimator, name):
    principled_cube_scene()
    bpy.context.scene.glslppm.estimator = estimator
    ours = render_multilayer(name, helpers.recording_engine().bl_idname)
    assert helpers.last_render_stats()["estimator"] == estimator.lower()
    helpers.setup_cycles(samples=16)
    reference = render_multilayer("denoising_cube_cycles", 'CYCLES')
    bpy.context.scene.render.engine = 'GLSLPPM'
    n_ours, n_ref = (_stack(c, "Denoising Normal", "XYZ") for c in (ours, reference))
    a_ours, a_ref = (_stack(c, "Denoising Albedo", "RGB") for c in (ours, reference))
    # Faces by Cycles' normal; a pixel counts where its 3x3 neighbourhood is all that face.
    faces = []
    lengths = np.linalg.norm(n_ref, axis=-1)
    for normal in {tuple(np.round(v, 2)) for v in n_ref[lengths > 0.99].reshape(-1, 3)}:
        on = np.all(np.round(n_ref, 2) == np.array(normal), axis=-1)
        inner = on.copy()
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                inner &= np.roll(np.roll(on, dy, axis=0), dx, axis=1)
        if inner.sum() >= 20:
            faces.append(inner)
    assert len(faces) == 3, [f.sum() for f in faces]  # the top face is the smallest
    every = np.any(faces, axis=0)
    normal_error = float(np.abs(n_ours - n_ref)[every].max())
    print(f"  denoising normal: {every.sum()} pixels, largest difference {normal_error:.2e}")
    assert normal_error < 2e-3, normal_error
    for face in faces:
        spread = a_ours[face].std(axis=0)
        mean, want = a_ours[face].mean(axis=0), a_ref[face].mean(axis=0)
        rms = np.sqrt(np.mean((a_ours[face] - a_ref[face]) ** 2, axis=0))
        print(f"  denoising albedo: {face.sum()} pixels, std {spread.max():.4f} "
              f"(Cycles {a_ref[face].std(axis=0).max():.4f}), rms difference {rms.max():.4f}, "
              f"mean {mean.round(4).tolist()} Cycles {want.round(4).tolist()}")
        assert spread.max() < 0.01, spread
        assert rms.max() < ALBEDO_RMS, rms
        assert np.all(np.abs(mean / want - 1.0) < ALBEDO_MEAN), (mean, want)
