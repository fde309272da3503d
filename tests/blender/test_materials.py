"""Materials as Blender users build them, against Cycles in the same Blender: rough
metal, frosted glass, plastic, Mix Shader, a roughness map, a normal map, an emission
image, an alpha cut-out and a glossy caustic. Each scene is small (48x48 pixels) and
compared on a grid of regions; the tolerance is stated in each test and the measured
errors are printed and put in the failure message.

Cycles renders unclamped and undenoised with a 1-pixel box filter (as GLSLPPM's jittered
pixels). Its noise at the sample counts below is what limits the bounds: a region of
16x16 pixels holds 65k-260k of its paths, about 0.5-1% standard error on diffuse regions
and 1-3% where glossy or caustic paths dominate (measured by rendering twice with two
seeds where stated).
"""

import numpy as np

import bpy

import helpers
from helpers import add_camera, add_light, add_quad, node_material

SIZE = (48, 48)
PRINCIPLED = "ShaderNodeBsdfPrincipled"


def _render_both(name, passes, photons, samples, glossy_threshold=None):
    """Renders the scene with GLSLPPM and with Cycles (`samples`); fails on any export
    warning."""
    helpers.load_native()
    scene = bpy.context.scene
    if glossy_threshold is not None:
        scene.glslppm.glossy_threshold = glossy_threshold
    scene.glslppm.passes = passes
    scene.glslppm.photons_per_pass = photons
    ours, error, engine = helpers.render_recorded(name)
    assert error is None, error
    warnings = helpers.warnings_of(engine)
    assert not warnings, warnings
    reference = helpers.render_cycles_box_filter(name, samples)
    return ours, reference


def _compare(name, ours, reference, grid, region_tolerance, mean_tolerance, mask=None):
    """Region means of both images (pixels where mask is False left out); fails when the
    worst region differs by more than region_tolerance of the brightest reference region
    or the image means by more than mean_tolerance."""
    if mask is not None:
        ours, reference = ours.copy(), reference.copy()
        ours[~mask] = reference[~mask] = np.nan
    a, b, region_error, mean_error = helpers.region_comparison(ours, reference, grid)
    message = (f"{name}: worst region {region_error:.4f} (tolerance {region_tolerance}), "
               f"mean {mean_error:.4f} (tolerance {mean_tolerance}); GLSLPPM "
               f"{a.round(4).tolist()} Cycles {b.round(4).tolist()}")
    print("  " + message)
    assert region_error < region_tolerance and mean_error < mean_tolerance, message
    return region_error, mean_error


def _floor(material, size=4.0, z=0.0):
    s = size
    return add_quad("Floor", [(-s, -s, z), (s, -s, z), (s, s, z), (-s, s, z)],
                    material=material)


def _sphere(name, material, radius=1.0, location=(0, 0, 1.0), segments=48):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=segments // 2,
                                         radius=radius, location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.materials.append(material)
    obj.data.polygons.foreach_set("use_smooth", [True] * len(obj.data.polygons))
    obj.data.update()
    return obj


def _principled(name, **inputs):
    """A Principled BSDF material; inputs keyed by the 4.x names, translated for 3.x."""
    if not helpers.BLENDER_4:
        renamed = {"Transmission Weight": "Transmission", "Emission Color": "Emission",
                   "Coat Weight": "Clearcoat", "Coat Roughness": "Clearcoat Roughness"}
        inputs = {renamed.get(k, k): v for k, v in inputs.items()}
    return node_material(name, PRINCIPLED, **inputs)


def _set_distribution(material, distribution):
    for node in material.node_tree.nodes:
        if hasattr(node, "distribution"):
            node.distribution = distribution


def _look_from(eye, target, **camera):
    """The scene's camera at eye, looking at target (add_camera's other settings)."""
    return add_camera(eye, helpers.look_at_rotation(eye, target), **camera)


def _grey_room(eye, target, lens):
    """A grey floor under a large square area light and a dim world; the camera at eye looks
    at target through a `lens` mm lens."""
    _floor(helpers.diffuse_material("Grey", (0.5, 0.5, 0.5)))
    add_light('AREA', 400.0, location=(1.0, -1.5, 4.0), rotation=(0.35, 0.2, 0.0), size=2.0)
    helpers.set_world((0.2, 0.2, 0.2))
    _look_from(eye, target, lens=lens)


BALL_EYE, BALL_TARGET = (0.0, -4.5, 2.2), (0, 0, 0.9)


def _metal_ball_matches_cycles(name, label, metal):
    """A metal ball (Multiscatter GGX) on the grey floor against Cycles: worst region of 3x3
    within 4% of the brightest, image mean within 2%."""
    _set_distribution(metal, 'MULTI_GGX')
    _sphere("Ball", metal)
    _grey_room(BALL_EYE, BALL_TARGET, lens=50.0)
    ours, reference = _render_both(name, 192, 32768, 512)
    _compare(label, ours, reference, 3, 0.04, 0.02)


def test_rough_gold_sphere_matches_cycles():
    """Principled metallic gold, roughness 0.4, Multiscatter GGX, on a grey floor: worst
    region of 3x3 within 4% of the brightest, image mean within 2% (measured 3.0% and 0.7%
    under 3.4, 3.4% and 1.2% under 4.3: the worst is the noise of the photons gathered on
    the rough metal)."""
    helpers.reset_scene(size=SIZE)
    gold = _principled("Gold", **{"Base Color": (1.0, 0.766, 0.336, 1.0), "Metallic": 1.0,
                                  "Roughness": 0.4})
    _metal_ball_matches_cycles("gold", "rough gold sphere", gold)


def test_f82_tinted_metal_matches_cycles():
    """Blender 4.x's Principled metal with a Specular Tint (F82 tint, Cycles'
    fresnel_f82tint): a rough silver-white sphere tinted (1, 0.45, 0.2) towards grazing
    angles, on the grey floor, against Cycles; worst region of 3x3 within 4%, mean within 2%
    as the gold sphere's (measured: see the printed line). Blender 3.x's Principled has no
    F82 tint (its Specular Tint, a factor, tints the dielectric's reflection): there the
    test checks that a metal with Specular Tint 1 exports an untinted Schlick metal, whose
    Cycles comparison is the gold sphere's."""
    helpers.reset_scene(size=SIZE)
    if not helpers.BLENDER_4:
        metal = _principled("Tinted", **{"Base Color": (0.95, 0.95, 0.95, 1.0),
                                         "Metallic": 1.0, "Roughness": 0.35,
                                         "Specular Tint": 1.0})
        _sphere("Ball", metal)
        _look_from(BALL_EYE, BALL_TARGET)
        tints = {m.f82_tint for m in helpers.export().materials if m.kind == "conductor"}
        assert tints == {(1.0, 1.0, 1.0)}, tints
        return
    metal = _principled("Tinted", **{"Base Color": (0.95, 0.95, 0.95, 1.0), "Metallic": 1.0,
                                     "Roughness": 0.35, "Specular Tint": (1.0, 0.45, 0.2, 1.0)})
    _metal_ball_matches_cycles("f82", "F82-tinted metal", metal)


def test_frosted_glass_matches_cycles():
    """A Glass BSDF sphere (IOR 1.5, roughness 0.3, GGX) in front of a
    bright two-tone backdrop: the backdrop blurred through it, and its caustic on the
    floor. Worst region of 3x3 within 3%, mean within 1.5%.

    GGX: with Multiscatter GGX the sphere's region is 6.7% darker than Cycles 4.3's (as
    the roughness map's Glossy, 4.x's compensation keeps the lobe's shape) and within 2%
    of Cycles 3.4's. Default settings: the eye path follows rough glass by sampling
    (visible points on frosted glass gathered a far noisier estimate and are not made);
    measured 1.8% worst / 0.14% mean under 3.4, 2.2% / 0.96% under 4.3.
    """
    helpers.reset_scene(size=SIZE)
    glass = node_material("Frosted", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.3)
    _set_distribution(glass, 'GGX')
    _sphere("Ball", glass, radius=0.8, location=(0, 0, 0.8))
    _grey_room((0.0, -4.0, 1.5), (0, 0, 0.8), lens=45.0)
    add_quad("Backdrop", [(-3, 2, 0), (0, 2, 0), (0, 2, 3), (-3, 2, 3)],
             material=helpers.diffuse_material("Blue", (0.1, 0.2, 0.8)))
    add_quad("Backdrop2", [(0, 2, 0), (3, 2, 0), (3, 2, 3), (0, 2, 3)],
             material=helpers.diffuse_material("Orange", (0.9, 0.5, 0.1)))
    ours, reference = _render_both("frosted", 192, 32768, 1024)
    _compare("frosted glass", ours, reference, 3, 0.03, 0.015)


def test_plastic_cube_matches_cycles():
    """The default Principled BSDF (non-metallic, roughness 0.5) on a red cube: the white
    specular layer over a diffuse base. Worst region of 3x3 within 3%, mean within 1.5%
    (measured 1.5% and 0.05% under 3.4, 1.6% and 0.6% under 4.3). Blender 3.x's Principled
    adds a Disney diffuse and an unattenuated specular, exported as that sum; exported as
    4.x's energy-conserving layer instead, 3.4 measured 5.9% and 3.2%."""
    helpers.reset_scene(size=SIZE)
    plastic = _principled("Plastic", **{"Base Color": (0.8, 0.1, 0.05, 1.0),
                                        "Roughness": 0.5})
    helpers.add_cube("Cube", material=plastic, location=(0, 0, 0.7), scale=(0.7,) * 3,
                     rotation=(0, 0, 0.6))
    _grey_room((2.5, -3.5, 2.5), (0, 0, 0.6), lens=50.0)
    ours, reference = _render_both("plastic", 96, 32768, 256)
    _compare("plastic cube", ours, reference, 3, 0.03, 0.015)


def test_rough_metal_floor_under_a_near_area_light_matches_cycles():
    """A Principled metal floor (roughness 0.2, Multiscatter GGX) holding visible points
    (glossy threshold 0.1) with a 2 m area light 1.5 m above it reflected in it: the
    highlight's direct light is a light sample and a BSDF sample combined by MIS
    (docs/direct_light.md), checked compiled. Worst region of 3x3 within 2.5%, mean within
    2% (measured 0.8% and 0.8% under 3.4, 0.6% and 0.6% under 4.3)."""
    helpers.reset_scene(size=SIZE)
    metal = _principled("Metal", **{"Base Color": (0.8, 0.8, 0.8, 1.0), "Metallic": 1.0,
                                    "Roughness": 0.2})
    _set_distribution(metal, 'MULTI_GGX')
    _floor(metal)
    add_light('AREA', 200.0, location=(0.0, 1.0, 1.5), size=2.0)
    helpers.set_world((0.05, 0.05, 0.05))
    add_camera((0.0, -3.0, 1.5), helpers.look_at_rotation((0.0, -3.0, 1.5), (0, 0, 0)),
               lens=35.0)
    ours, reference = _render_both("metal_floor", 128, 16384, 512, glossy_threshold=0.1)
    assert "emitter-mis" in helpers.last_render_stats().get("variant", ""), \
        helpers.last_render_stats()
    _compare("rough metal floor", ours, reference, 3, 0.025, 0.02)


def _mix_material():
    """Mix Shader of a red Diffuse and a rough (0.3) white Glossy by a Fresnel node
    (IOR 1.45)."""
    material = node_material("MixFloor", "ShaderNodeMixShader")
    tree = material.node_tree
    mixer = next(node for node in tree.nodes if node.type == 'MIX_SHADER')
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.7, 0.15, 0.1, 1.0)
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = 'GGX'
    glossy.inputs["Roughness"].default_value = 0.3
    glossy.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    fresnel = tree.nodes.new("ShaderNodeFresnel")
    fresnel.inputs["IOR"].default_value = 1.45
    tree.links.new(fresnel.outputs[0], mixer.inputs[0])
    tree.links.new(diffuse.outputs[0], mixer.inputs[1])
    tree.links.new(glossy.outputs[0], mixer.inputs[2])
    return material


def test_mix_shader_floor_matches_cycles():
    """A floor of Mix(Diffuse, Glossy) by Fresnel, seen at a grazing angle with an area
    light reflected in it: worst region of 3x3 within 4%, mean within 2% (measured 2.2% and
    0.8% under 3.4, 2.5% and 1.0% under 4.3).

    The light is small (1 m) and the glossy rough (0.3) because GLSLPPM's direct light at
    a rough visible point is light sampling alone (no BSDF sampling to weigh against), so
    a narrow highlight of a large light converges slowly: with roughness 0.2 and a 2 m
    light the highlight's region still moved by +-6% between two seeds at 512 passes,
    while Cycles' moved by 0.1% at 2048 samples.

    Rendered at glossy threshold 0.2, so that the glossy leaf holds the visible point as this
    test was written for. At the default 0.5 the eye paths follow it instead and the highlight
    comes from light samples weighed by MIS: three seeds gave worst regions 4.9%, 3.2% and
    2.4% (means 1.2%, 0.3%, 0.4%), the highlight's region 1.207, 1.305 and 1.238 against
    Cycles' 1.269: unbiased, but too noisy at 256 passes for this bound."""
    helpers.reset_scene(size=SIZE)
    _floor(_mix_material(), size=6.0)
    add_light('AREA', 300.0, location=(0.0, 4.0, 2.5), rotation=(-1.1, 0.0, 0.0), size=1.0)
    helpers.set_world((0.1, 0.1, 0.1))
    _look_from((0.0, -4.0, 1.2), (0, 1.0, 0),
               lens=50.0)
    ours, reference = _render_both("mix_floor", 256, 16384, 1024, glossy_threshold=0.2)
    _compare("mix shader floor", ours, reference, 3, 0.04, 0.02)


def _image(name, pixels):
    """A float image (Non-Color) of (H, W, 4) pixels, row 0 at the bottom, packed into
    the .blend (no file)."""
    height, width = pixels.shape[:2]
    image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    image.pixels.foreach_set(np.asarray(pixels, dtype=np.float32).ravel())
    image.pack()
    return image


def _uv_quad(name, corners, material, uvs=(0, 0, 1, 0, 1, 1, 0, 1)):
    quad = add_quad(name, corners, material=material)
    layer = quad.data.uv_layers.new()
    layer.data.foreach_set("uv", uvs)
    return quad


def _plane_under_sun(material, uvs, sun_rotation):
    """A 4 x 4 plane (its corners' UVs `uvs`) under a sun of strength 3 and a dim world,
    seen straight down by an orthographic camera."""
    _uv_quad("Plane", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], material, uvs)
    add_light('SUN', 3.0, rotation=sun_rotation)
    helpers.set_world((0.1, 0.1, 0.1))
    add_camera((0, 0, 6.0), (0, 0, 0), type='ORTHO', ortho_scale=3.6)


def test_roughness_mapped_plane_matches_cycles():
    """A Glossy plane (GGX) whose roughness comes from an image, 0.1 on its left half
    and 0.5 on its right (Non-Color, luminance), reflecting an area light: the two
    halves compared on a 2x2 grid, worst region within 2%, mean within 1% (measured 0.4% and
    0.3%).

    GGX, not Multiscatter GGX: with Multiscatter GGX the rough half matches Cycles 3.4
    within 2% but is 6-7% darker than Cycles 4.3, whose compensation scales the
    single-scatter lobe (keeping its shape, so the highlight gains) where the renderer's
    adds a diffuse-like lobe (Kulla-Conty); measured with single-scatter GGX the two
    agree within 2% in both versions."""
    helpers.reset_scene(size=SIZE)
    pixels = np.ones((64, 64, 4), dtype=np.float32)
    pixels[:, :32, :3] = 0.1
    pixels[:, 32:, :3] = 0.5
    material = node_material("Brushed", "ShaderNodeBsdfGlossy")
    _set_distribution(material, 'GGX')
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _image("Roughness", pixels)
    glossy = next(node for node in tree.nodes if node.type == 'BSDF_GLOSSY')
    glossy.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    tree.links.new(texture.outputs["Color"], glossy.inputs["Roughness"])
    _uv_quad("Plane", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], material)
    add_light('AREA', 500.0, location=(0.0, 3.0, 2.5), rotation=(-0.9, 0.0, 0.0), size=3.0,
              shape='RECTANGLE', size_y=1.0)
    helpers.set_world((0.05, 0.05, 0.05))
    _look_from((0.0, -3.0, 2.5), (0, 0.3, 0),
               lens=40.0)
    ours, reference = _render_both("roughness_map", 256, 16384, 1024)
    columns = np.zeros(ours.shape[:2], dtype=bool)
    columns[:, :22] = columns[:, 26:] = True   # the halves, without the seam
    _compare("roughness-mapped plane", ours, reference, 2, 0.02, 0.01, mask=columns)


def _tilt_texels(size, tilt_u, tilt_v):
    """A Non-Color tangent-space normal map: its left half (u < 0.5) tilts the normal by
    tilt_u towards +tangent, its right half by tilt_v towards +bitangent."""
    pixels = np.ones((size, size, 4), dtype=np.float32)
    left = np.array([np.sin(tilt_u), 0.0, np.cos(tilt_u)])
    right = np.array([0.0, np.sin(tilt_v), np.cos(tilt_v)])
    pixels[:, :size // 2, :3] = (left + 1.0) / 2.0
    pixels[:, size // 2:, :3] = (right + 1.0) / 2.0
    return pixels


def test_normal_mapped_plane_matches_cycles():
    """A white Diffuse plane whose Normal comes from a Normal Map node (tangent space,
    strength 1) reading an image that tilts the normal 35 degrees towards +tangent on one
    half and 25 degrees towards +bitangent on the other, under a sun and a dim world. The
    UV map is turned a quarter (u along +y, v along -x), so tangents that did not follow
    the UVs (MikkTSpace, from mesh.calc_tangents) would tilt the wrong way. Cycles reads
    0.780 and 0.739 on the halves, where the flat plane reads 0.698: a map left out fails by
    6-12%, and leaving out Cycles' shadow terminator term for bumped normals (Chiang et al.
    2019; common/lobes.glsl bump_shadowing) reads 1.1% and 1.3% too bright. Worst region of
    4x4 within 1%, mean within 0.5% (measured: Blender 3.4 0.36% / 0.05%, 4.3 0.37% /
    0.05%)."""
    helpers.reset_scene(size=SIZE)
    material = node_material("Bumpy", "ShaderNodeBsdfDiffuse",
                             Color=(0.8, 0.8, 0.8, 1.0))
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _image("TiltMap", _tilt_texels(64, np.radians(35.0), np.radians(25.0)))
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(texture.outputs["Color"], normal_map.inputs["Color"])
    diffuse = next(node for node in tree.nodes if node.type == 'BSDF_DIFFUSE')
    tree.links.new(normal_map.outputs["Normal"], diffuse.inputs["Normal"])
    _plane_under_sun(material, [0, 1, 0, 0, 1, 0, 1, 1], sun_rotation=(-0.5, -0.4, 0.0))
    ours, reference = _render_both("normal_map", 512, 16384, 256)
    seam = np.ones(ours.shape[:2], dtype=bool)
    seam[23:25, :] = False   # the map's two halves meet at y = 0 (bilinear texels)
    _compare("normal-mapped plane", ours, reference, 4, 0.01, 0.005, mask=seam)


def test_bump_mapped_plane_matches_cycles():
    """A white Diffuse plane under a Bump node (strength 1, distance 2) whose Height is an
    image's Color: a ramp along u on the left half of the plane (u from 0.1 to 0.5 over 2
    units: the normal tilts by atan(0.4)) and flat on the right half, under a sun and a dim
    world. Cycles differentiates the height in screen space, the renderer in uv: for a ramp
    both give its gradient. The halves read 0.826 and 0.750 (Cycles 3.4 and 4.3; 0.832 and
    0.750 in Cycles 5.2, whose bumped diffuse fades by Conty Estevez 2021's shadowing term
    instead of Chiang 2019's: the add-on asks the module for the term of its Blender): a
    bump left out fails by 10%. Worst region of 4x4 within 1%, mean within 0.5% against the
    Cycles of the same Blender (measured: Blender 3.4 0.37% / 0.03%, 4.3 0.37% / 0.03%, 5.2
    0.38% / 0.03%; with 4.x's term 5.2 read 1.03% / 0.42%)."""
    helpers.reset_scene(size=SIZE)
    n = 64
    c = (np.arange(n) + 0.5) / n
    pixels = np.ones((n, n, 4), dtype=np.float32)
    pixels[..., :3] = np.minimum(c, 0.5)[None, :, None]
    material = node_material("Bumped", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _image("Height", pixels)
    bump = tree.nodes.new("ShaderNodeBump")
    bump.inputs["Distance"].default_value = 2.0
    tree.links.new(texture.outputs["Color"], bump.inputs["Height"])
    diffuse = next(node for node in tree.nodes if node.type == 'BSDF_DIFFUSE')
    tree.links.new(bump.outputs["Normal"], diffuse.inputs["Normal"])
    _plane_under_sun(material, [0.1, 0.1, 0.9, 0.1, 0.9, 0.9, 0.1, 0.9],
                     sun_rotation=(0.0, -0.5, 0.0))
    ours, reference = _render_both("bump", 512, 16384, 256)
    seam = np.ones(ours.shape[:2], dtype=bool)
    seam[:, 22:26] = False   # the ramp's end (bilinear texels)
    _compare("bump-mapped plane", ours, reference, 4, 0.01, 0.005, mask=seam)


def test_emission_texture_matches_cycles():
    """An Emission shader (strength 3) whose Color is an image (Non-Color float: red rising
    along u, green falling along v, 64x64 texels) on a quad tilted over a white floor:
    the quad seen directly and the coloured light it throws, each texel's radiance carried
    by photons and light samples weighted by their texel (the quad's two triangles are
    picked by their mean texel). Worst region of 4x4 within 1%, mean within 0.5% (measured:
    Blender 3.4 0.23% / 0.09%, 4.3 0.21% / 0.07%; the floor's own regions agree within 0.5%
    of theirs)."""
    helpers.reset_scene(size=SIZE)
    n = 64
    c = (np.arange(n) + 0.5) / n
    pixels = np.ones((n, n, 4), dtype=np.float32)
    pixels[..., 0] = 0.1 + 1.9 * c[None, :]
    pixels[..., 1] = 2.0 - 1.9 * c[:, None]
    pixels[..., 2] = 0.3
    material = helpers.emission_material("Screen", (1.0, 1.0, 1.0), 3.0)
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _image("ScreenImage", pixels)
    emitter = next(node for node in tree.nodes if node.type == 'EMISSION')
    tree.links.new(texture.outputs["Color"], emitter.inputs["Color"])
    _uv_quad("Screen", [(-1.0, 0.6, 0.3), (1.0, 0.6, 0.3), (1.0, 1.0, 1.8), (-1.0, 1.0, 1.8)],
             material)
    _floor(helpers.diffuse_material("White", (0.8, 0.8, 0.8)), size=3.0)
    helpers.set_world((0.0, 0.0, 0.0))
    _look_from((0.0, -3.5, 3.0), (0, 0.2, 0.4),
               lens=35.0)
    ours, reference = _render_both("emission_texture", 256, 65536, 1024)
    _compare("emission texture", ours, reference, 4, 0.01, 0.005)


def test_alpha_cut_out_leaf_matches_cycles():
    """A green Principled leaf whose Alpha is an image's alpha (a disc cut from a
    square, 64x64 texels), over a white floor under a sun: the leaf and its shadow with
    holes. Worst region of 4x4 within 2.5%, mean within 1.5%.

    Default settings: shadow rays cross the leaf's transparent part where its alpha mix
    picks the Transparent leaf (measured 0.8% worst, 0.4% mean under 3.4 and 4.3; photons alone,
    which blur the edges by the gather radius, 3.4% and 0.4%)."""
    helpers.reset_scene(size=SIZE)
    n = 64
    y, x = np.mgrid[0:n, 0:n] + 0.5
    pixels = np.ones((n, n, 4), dtype=np.float32)
    pixels[..., 3] = ((x - n / 2) ** 2 + (y - n / 2) ** 2 < (0.45 * n) ** 2)
    pixels[..., 3] *= ((x - n / 2) ** 2 + (y - n / 2) ** 2 > (0.2 * n) ** 2)
    leaf = _principled("Leaf", **{"Base Color": (0.2, 0.6, 0.1, 1.0), "Roughness": 1.0})
    tree = leaf.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _image("LeafMask", pixels)
    principled = next(node for node in tree.nodes if node.type == 'BSDF_PRINCIPLED')
    tree.links.new(texture.outputs["Alpha"], principled.inputs["Alpha"])
    specular = "Specular IOR Level" if helpers.BLENDER_4 else "Specular"
    principled.inputs[specular].default_value = 0.0
    _uv_quad("Leaf", [(-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], leaf)
    _floor(helpers.diffuse_material("White", (0.8, 0.8, 0.8)))
    add_light('SUN', 3.0, rotation=(0.3, 0.0, 0.0))
    helpers.set_world((0.1, 0.1, 0.1))
    _look_from((0, -1.0, 6.0), (0, -0.3, 0.5),
               type='ORTHO', ortho_scale=3.2)
    ours, reference = _render_both("leaf", 128, 16384, 256)
    _compare("alpha cut-out leaf", ours, reference, 4, 0.025, 0.015)


def test_glossy_caustic_matches_cycles():
    """A small spot light below a rough (0.15) metal reflector, pointing up at it: the
    reflector (hidden from the camera) throws a blurred caustic onto a diffuse floor the
    spot cannot reach directly; the camera sees only the floor. Worst region of 3x3
    within 6%, mean within 3% (measured 2.4% and 0.7% under 3.4, 3.1% and 2.0% under 4.3):
    Cycles finds this light only through its glossy bounce, so it is the noisier
    reference (its two mirror-symmetric regions differed by 15% at 2048 samples)."""
    helpers.reset_scene(size=SIZE)
    metal = node_material("Reflector", "ShaderNodeBsdfGlossy", Roughness=0.15,
                          Color=(0.95, 0.95, 0.95, 1.0))
    _set_distribution(metal, 'GGX')
    # Wound to face down (-Z).
    reflector = add_quad("Reflector", [(-0.5, -0.5, 2.5), (-0.5, 0.5, 2.5), (0.5, 0.5, 2.5),
                                       (0.5, -0.5, 2.5)], material=metal)
    reflector.visible_camera = False
    _floor(helpers.diffuse_material("Floor", (0.8, 0.8, 0.8)), size=4.0)
    location = (1.5, 0.0, 0.5)
    add_light('SPOT', 300.0, location=location,
              rotation=helpers.look_at_rotation(location, (0.0, 0.0, 2.5)),
              spot_size=0.5, spot_blend=0.0, shadow_soft_size=0.05)
    add_camera((-1.0, 0.0, 5.0), (0.0, 0.0, 0.0), type='ORTHO', ortho_scale=3.0)
    ours, reference = _render_both("glossy_caustic", 128, 65536, 6144)
    _compare("glossy caustic", ours, reference, 3, 0.06, 0.03)


def test_color_attribute_gradient_matches_cycles():
    """Two planes under a sun with colour attribute gradients along x: a Diffuse BSDF fed by
    a Color Attribute node (sRGB bytes per corner) and one fed by an Attribute node (float
    colours per point) times a constant through a Mix set to Multiply. Cycles interpolates
    the corners' colours across each triangle as the renderer does; 4x4 regions, worst
    within 2%, mean within 1%, as the other diffuse planes here."""
    helpers.reset_scene(size=SIZE)
    left = add_quad("Bytes", [(-2, -2, 0), (0, -2, 0), (0, 2, 0), (-2, 2, 0)],
                    material=helpers.color_attribute_material("Bytes"))
    helpers.set_corner_colors(left, "Col", [(0.9, 0.2, 0.1), (0.1, 0.5, 0.9),
                                            (0.1, 0.5, 0.9), (0.9, 0.2, 0.1)], srgb=True)
    right = add_quad("Floats", [(0, -2, 0), (2, -2, 0), (2, 2, 0), (0, 2, 0)],
                     material=helpers.color_attribute_material("Floats", "Paint",
                                                               multiply=(0.9, 0.8, 0.6)))
    helpers.set_corner_colors(right, "Paint", [(0.05, 0.9, 0.3), (0.8, 0.1, 0.7),
                                               (0.8, 0.1, 0.7), (0.05, 0.9, 0.3)],
                              domain='POINT', data_type='FLOAT_COLOR')
    add_light('SUN', 3.0, rotation=(0.3, 0.2, 0.0))
    helpers.set_world((0.1, 0.1, 0.1))
    add_camera((0, 0, 6.0), (0, 0, 0), type='ORTHO', ortho_scale=3.6)
    ours, reference = _render_both("color_attribute", 128, 16384, 1024)
    _compare("colour attribute gradient", ours, reference, 4, 0.02, 0.01)
    # The comparison above is grey: each channel's regions too, within the same 2%.
    a, b = (helpers.region_means(image, 4) for image in (ours, reference))
    channel_error = np.abs(a - b).max(axis=(0, 1)) / b.max(axis=(0, 1))
    print(f"  per channel: worst region {channel_error.round(4).tolist()}")
    assert np.all(channel_error < 0.02), (channel_error, a, b)
