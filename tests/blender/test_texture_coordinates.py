"""Image textures on Texture Coordinate's Generated and Object outputs through a Mapping,
against Cycles: an emissive object whose emission is a checker image, seen directly with no
other light, so both engines' pixels are the mean of the texture over the pixel and differ
only in where their samples fall (the renderer's lookup is
addon/export/texture_mapping.py's position map, docs/texture_coordinates.md).

Per pixel, over pixels whose 3x3 neighbourhood lies on the object in both images (the
silhouette's pixels depend on the engines' pixel filters): bounds stated at each test with
the measured numbers."""

import math

import bpy
import numpy as np

import helpers

SIZE = 64
SAMPLES = 1024


def _checker_image(name):
    """A 4x4 float checker of two colours (Linear), bilinear filtered by both engines."""
    pixels = np.ones((4, 4, 4), dtype=np.float32)
    cells = (np.add.outer(np.arange(4), np.arange(4)) % 2).astype(bool)
    pixels[cells, :3] = (0.9, 0.6, 0.2)
    pixels[~cells, :3] = (0.1, 0.3, 0.8)
    pixels[0, 0, :3] = (0.5, 0.9, 0.4)  # one odd cell: a turned or mirrored image shows
    return helpers.linear_image(name, pixels)


def _emissive_checker(name, coordinate, coordinate_object=None):
    """Texture Coordinate (coordinate) -> Mapping (Point: moved, turned about all three
    axes, scaled) -> Image Texture (checker, Repeat) -> Emission 1 -> Material Output."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    coordinates.object = coordinate_object
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = 'POINT'
    mapping.inputs["Location"].default_value = (0.1, -0.2, 0.3)
    mapping.inputs["Rotation"].default_value = (0.2, -0.3, math.radians(35.0))
    mapping.inputs["Scale"].default_value = (1.6, 2.2, 1.3)
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = _checker_image(f"checker_{name.lower()}")
    tree.links.new(coordinates.outputs[coordinate], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    tree.links.new(texture.outputs["Color"], emission.inputs["Color"])
    tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    return material


def _scene(make_material):
    """A box off-centre in its own space (its auto texture space is not the unit cube),
    moved, turned and scaled, under an orthographic camera, the world black; its material
    make_material()."""
    scene = helpers.reset_scene(size=(SIZE, SIZE))
    material = make_material()
    helpers.set_world((0.0, 0.0, 0.0))
    vertices = [(0.5 + 1.5 * x, -0.25 + 0.75 * y, 0.1 + 0.4 * z)
                for x, y, z in helpers.CUBE_VERTICES]
    obj = helpers.add_mesh_object("Box", vertices, helpers.CUBE_FACES, location=(-0.4, 0.2, 0.0),
                                  rotation=(0.5, 0.3, 0.7), scale=(1.1, 1.4, 1.2),
                                  material=material)
    helpers.add_camera((0, 0, 6), (0, 0, 0), type='ORTHO', ortho_scale=5.0)
    scene.glslppm.passes = SAMPLES
    scene.glslppm.photons_per_pass = 1024
    return obj


def _compare(name):
    """Ours against Cycles over the box's inner pixels: (mean |difference|, largest
    |difference|, largest |mean signed difference| of a channel, pixel count)."""
    helpers.load_native()
    ours = helpers.render_image(f"{name}_glslppm", 'GLSLPPM')
    reference = helpers.render_cycles_box_filter(name, samples=SAMPLES)
    # The box's pixels: every texel is brighter than 0.5 in sum, the black world 0.
    covered = (ours[..., :3].sum(axis=2) > 0.05) & (reference[..., :3].sum(axis=2) > 0.05)
    inside = covered.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            inside &= np.roll(np.roll(covered, dy, axis=0), dx, axis=1)
    difference = ours[..., :3].astype(np.float64)[inside] - reference[..., :3][inside]
    mean = float(np.abs(difference).mean())
    largest = float(np.abs(difference).max())
    bias = float(np.abs(difference.mean(axis=0)).max())
    print(f"  {name}: over {int(inside.sum())} inner pixels mean |difference| {mean:.5f}, "
          f"largest {largest:.5f}, mean signed difference {bias:.6f} (largest channel); "
          f"image means {ours[..., :3][inside].mean():.4f} "
          f"{reference[..., :3][inside].mean():.4f}")
    return mean, largest, bias, int(inside.sum())


# Bounds: both engines' pixels average SAMPLES samples of a texture that varies across the
# pixel, which leaves 0.6-1.2e-3 mean |difference| and up to 9.6e-3 at a pixel (measured
# under 3.4; at 256 samples twice that, as sampling noise goes) with no bias (mean signed
# difference at most 9.5e-5 in a channel); a texture space 1% off (Generated's offset 0.49
# for 0.5, tried once) gives 1.5e-2 mean |difference| and 1.4e-3 bias.
MEAN_BOUND, PIXEL_BOUND, BIAS_BOUND = 2e-3, 2e-2, 3e-4


def _check(name):
    mean, largest, bias, count = _compare(name)
    assert count > 1000, count
    assert mean < MEAN_BOUND and largest < PIXEL_BOUND and bias < BIAS_BOUND, \
        (name, mean, largest, bias)


def test_generated_coordinates_through_mapping_match_cycles():
    """Generated -> Mapping -> checker on a moved, turned, scaled box whose texture space is
    its off-centre bounds."""
    _scene(lambda: _emissive_checker("Generated", "Generated"))
    _check("generated")


def test_object_coordinates_through_mapping_match_cycles():
    """Object -> Mapping -> checker on the same box; then the node's Object set to a moved,
    turned, scaled Empty (that object's space)."""
    material = _scene(lambda: _emissive_checker("Object", "Object")).active_material
    _check("object")
    empty = bpy.data.objects.new("Frame", None)
    empty.location, empty.rotation_euler = (0.7, -0.3, 0.2), (0.0, 0.4, -0.6)
    empty.scale = (1.3, 0.8, 1.0)
    bpy.context.scene.collection.objects.link(empty)
    next(n for n in material.node_tree.nodes if n.type == 'TEX_COORD').object = empty
    _check("object_of_empty")


def test_what_is_not_followed_is_warned_by_name():
    """Generated on an instanced mesh (a collection instance), a bump map on Generated and
    Box projection each warn naming the node; the box on Generated alone, without a UV
    map, warns of nothing (it needs no UVs) and gets a position map."""
    helpers.reset_scene(size=(16, 16))
    helpers.add_camera((0, 0, 6), (0, 0, 0), type='ORTHO', ortho_scale=5.0)
    plain = _emissive_checker("Plain", "Generated")
    helpers.add_cube("Plain", material=plain)
    boxed = _emissive_checker("Boxed", "Generated")
    boxed_node = next(n for n in boxed.node_tree.nodes if n.type == 'TEX_IMAGE')
    boxed_node.name = "Boxed Image"
    boxed_node.projection = 'BOX'
    helpers.add_cube("BoxProjected", location=(3, 0, 0), material=boxed)
    bumped = _emissive_checker("Bumped", "Generated")
    tree = bumped.node_tree
    bump = tree.nodes.new("ShaderNodeBump")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    image = next(n for n in tree.nodes if n.type == 'TEX_IMAGE')
    image.name = "Bump Image"
    tree.links.new(image.outputs["Color"], bump.inputs["Height"])
    tree.links.new(bump.outputs["Normal"], diffuse.inputs["Normal"])
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])
    helpers.add_cube("Bumped", location=(-3, 0, 0), material=bumped)
    instanced = _emissive_checker("Instanced", "Generated")
    next(n for n in instanced.node_tree.nodes if n.type == 'TEX_COORD').name = "Inst Coords"
    collection = bpy.data.collections.new("Parts")
    part = bpy.data.objects.new("Part", helpers.add_cube("PartMesh", material=instanced).data)
    bpy.data.objects.remove(bpy.data.objects["PartMesh"])
    collection.objects.link(part)
    holder = bpy.data.objects.new("Holder", None)
    holder.instance_type = 'COLLECTION'
    holder.instance_collection = collection
    holder.location = (0, 3, 0)
    bpy.context.scene.collection.objects.link(holder)
    data = helpers.export()
    print("  warnings:", data.warnings)
    expect = (("Boxed Image", "Box projection"), ("Bump Image", "bump map on Generated"),
              ("Inst Coords", "instanced meshes"))
    for name, what in expect:
        assert any(name in w and what in w for w in data.warnings), (name, data.warnings)
    assert not [w for w in data.warnings if "Plain" in w or "UV map" in w and "'Plain'" in w], \
        data.warnings
    assert data.stats["instance_table"] == 1, data.stats
    assert sum(t.position_map is not None for t in data.textures) >= 2, data.textures


def test_denoising_albedo_of_a_generated_texture_matches_cycles():
    """A Diffuse BSDF coloured by Generated -> Mapping -> checker on the box under a white
    world: Denoising Albedo (the texel) per inner pixel against Cycles'. Bounds those of the
    emission tests (measured under 3.4: mean |difference| 5.9e-4, largest 5.4e-3, bias
    1.4e-5)."""
    scene = helpers.reset_scene(size=(SIZE, SIZE))
    material = _emissive_checker("Albedo", "Generated")
    tree = material.node_tree
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    image = next(n for n in tree.nodes if n.type == 'TEX_IMAGE')
    tree.links.new(image.outputs["Color"], diffuse.inputs["Color"])
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])
    vertices = [(0.5 + 1.5 * x, -0.25 + 0.75 * y, 0.1 + 0.4 * z)
                for x, y, z in helpers.CUBE_VERTICES]
    helpers.add_mesh_object("Box", vertices, helpers.CUBE_FACES, location=(-0.4, 0.2, 0.0),
                            rotation=(0.5, 0.3, 0.7), scale=(1.1, 1.4, 1.2), material=material)
    helpers.add_camera((0, 0, 6), (0, 0, 0), type='ORTHO', ortho_scale=5.0)
    helpers.set_world((1.0, 1.0, 1.0))
    layer = scene.view_layers[0]
    layer.glslppm.use_pass_denoising_data = True
    layer.cycles.denoising_store_passes = True
    scene.glslppm.passes = SAMPLES
    scene.glslppm.photons_per_pass = 1024
    from test_passes import render_multilayer
    ours = render_multilayer("albedo_generated")
    helpers.setup_cycles(samples=SAMPLES)
    scene.cycles.pixel_filter_type = 'BOX'
    scene.cycles.filter_width = 1.0
    reference = render_multilayer("albedo_generated_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    a = np.stack([ours[f"ViewLayer.Denoising Albedo.{c}"] for c in "RGB"], axis=-1)
    b = np.stack([reference[f"ViewLayer.Denoising Albedo.{c}"] for c in "RGB"], axis=-1)
    # The box's pixels: the white world's albedo is 1 in both, no texel is near white.
    covered = (np.abs(a - 1.0).sum(axis=2) > 0.1) & (np.abs(b - 1.0).sum(axis=2) > 0.1)
    inside = covered.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            inside &= np.roll(np.roll(covered, dy, axis=0), dx, axis=1)
    difference = a.astype(np.float64)[inside] - b[inside]
    mean = float(np.abs(difference).mean())
    largest = float(np.abs(difference).max())
    bias = float(np.abs(difference.mean(axis=0)).max())
    print(f"  albedo: over {int(inside.sum())} inner pixels mean |difference| {mean:.5f}, "
          f"largest {largest:.5f}, bias {bias:.6f}")
    assert inside.sum() > 1000
    assert mean < MEAN_BOUND and largest < PIXEL_BOUND and bias < BIAS_BOUND, \
        (mean, largest, bias)
