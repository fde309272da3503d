"""Export from the evaluated depsgraph, checked against numbers worked out by hand:
triangle counts, world-space positions, normals, material mapping per node kind,
lights, camera angles of view and the world."""

import dataclasses
import math
import time

import bpy
import numpy as np

import helpers
from helpers import (CUBE_FACES, CUBE_VERTICES, add_camera, add_cube, add_light,
                     add_mesh_object, assert_close, diffuse_material, export, node_material,
                     set_world)

PRINCIPLED = "ShaderNodeBsdfPrincipled"
TRANSMISSION = "Transmission Weight" if helpers.BLENDER_4 else "Transmission"
EMISSION_COLOR = "Emission Color" if helpers.BLENDER_4 else "Emission"


def _camera():
    add_camera((0, -10, 0), (math.pi / 2, 0, 0))


def _triangles(data):
    return data.positions.reshape(-1, 3, 3)


def _geometric_normals(data):
    tri = _triangles(data)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return normals / np.linalg.norm(normals, axis=1, keepdims=True)


def test_cube_triangles_in_world_space():
    _camera()
    add_cube(location=(1, 2, 3), rotation=(0, 0, math.pi / 2), scale=(2, 1, 0.5))
    data = export()
    assert data.triangle_count == 12, data.triangle_count
    assert data.positions.dtype == np.float32 and data.positions.flags.c_contiguous
    assert data.indices.dtype == np.uint32 and data.indices.shape == (12, 3)
    assert data.material_ids.dtype == np.uint32 and data.material_ids.shape == (12,)
    # Scale (2, 1, 0.5) then 90 degrees about Z: x spans +-1, y +-2, z +-0.5, offset (1,2,3).
    assert_close(data.positions.min(axis=0), (0, 0, 2.5), 1e-5, "world min corner")
    assert_close(data.positions.max(axis=0), (2, 4, 3.5), 1e-5, "world max corner")
    # Local corner (1, -1, 1) -> scaled (2, -1, 0.5) -> rotated (1, 2, 0.5) -> (2, 4, 3.5).
    assert (np.abs(data.positions - (2, 4, 3.5)).max(axis=1) < 1e-5).sum() >= 3
    # Flat cube: no normals exported; every triangle faces away from the centre.
    assert data.normals is None
    outward = (_triangles(data).mean(axis=1) - (1, 2, 3))
    assert ((_geometric_normals(data) * outward).sum(axis=1) > 0).all()


def test_mirrored_object_keeps_outward_winding():
    _camera()
    add_cube(location=(0, 0, 0), scale=(-1, 1, 1))
    data = export()
    outward = _triangles(data).mean(axis=1)
    assert ((_geometric_normals(data) * outward).sum(axis=1) > 0).all(), \
        "negative scale flipped triangles inward"


def test_modifiers_and_instances():
    _camera()
    cube = add_cube(location=(0, 0, 0))
    array = cube.modifiers.new("Array", 'ARRAY')
    array.count = 3
    array.relative_offset_displace = (2, 0, 0)   # cubes at x = 0, 4, 8 (size 2, offset 2 sizes)
    collection = bpy.data.collections.new("Instanced")
    collection.objects.link(bpy.data.objects.new("Inner", add_cube("Inner").data))
    bpy.context.scene.collection.objects.unlink(bpy.data.objects["Inner"])
    for index, x in enumerate((20.0, 30.0)):
        empty = bpy.data.objects.new(f"Instance{index}", None)
        empty.instance_type = 'COLLECTION'
        empty.instance_collection = collection
        empty.location = (x, 0, 0)
        empty.scale = (0.5, 0.5, 0.5)
        bpy.context.scene.collection.objects.link(empty)
    data = export()
    # The array's cubes are the object's own triangles, in world space; the collection's
    # two instances are rows of the instance table over one mesh read once.
    assert data.triangle_count == 3 * 12, data.triangle_count
    assert_close(data.positions[:, 0].max(), 9.0, 1e-5, "array end")
    assert data.instance_count == 2 and len(data.instance_meshes) == 1, data.stats
    assert data.instance_meshes[0]["indices"].shape == (12, 3)
    assert_close(sorted(float(m[0, 3]) for m in data.instances), [20, 30], 1e-5,
                 "instance placement")
    for m in data.instances:
        assert_close(np.diag(m)[:3], (0.5, 0.5, 0.5), 1e-6, "instance scale")
    # Placed: x in 20 +- 0.5 and 30 +- 0.5, y in +-0.5.
    corners = data.instance_meshes[0]["positions"]
    placed = np.concatenate([corners @ m[:3, :3].T + m[:3, 3] for m in data.instances])
    assert_close(placed[:, 1].min(), -0.5, 1e-5, "instance scale")
    assert data.stats["meshes"] == 2, data.stats  # the instanced mesh was read once


def test_smooth_normals_follow_the_surface():
    _camera()
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=2,
                                         location=(1, 1, 1))
    sphere = bpy.context.active_object
    sphere.data.polygons.foreach_set("use_smooth", [True] * len(sphere.data.polygons))
    sphere.data.update()
    add_cube(location=(10, 0, 0))  # flat: its corners get face normals
    data = export()
    assert data.normals is not None and data.normals.shape == data.positions.shape
    lengths = np.linalg.norm(data.normals, axis=1)
    assert_close(lengths.min(), 1.0, 1e-4, "unit normals")
    sphere_corners = data.positions[:, 0] < 5
    radial = data.positions[sphere_corners] - (1, 1, 1)
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    cosine = (radial * data.normals[sphere_corners]).sum(axis=1)
    assert cosine.min() > 0.999, cosine.min()
    cube_normals = data.normals[~sphere_corners].reshape(-1, 3, 3)
    faces = _geometric_normals(data)[data.indices[:, 0] // 1 >= 0][
        (data.positions[::3, 0] >= 5)]
    assert_close(cube_normals[:, 0], faces, 1e-5, "flat faces use face normals")


def test_custom_normals():
    _camera()
    obj = add_mesh_object("Quad", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)],
                          [(0, 1, 2, 3)], rotation=(math.pi / 2, 0, 0))
    mesh = obj.data
    if not helpers.BLENDER_4_1:
        mesh.use_auto_smooth = True
    tilted = (0.0, 0.6, 0.8)
    mesh.normals_split_custom_set([tilted] * len(mesh.loops))
    data = export()
    assert data.normals is not None
    # Rotating 90 degrees about X maps local (0, 0.6, 0.8) to (0, -0.8, 0.6).
    assert_close(data.normals, np.tile((0.0, -0.8, 0.6), (6, 1)), 1e-4, "custom normals")


def test_nan_vertices_are_dropped_with_a_warning():
    _camera()
    add_mesh_object("Bad", [(0, 0, 0), (1, 0, 0), (0, 1, 0), (float("nan"), 0, 0)],
                    [(0, 1, 2), (1, 3, 2)])
    data = export()
    assert data.triangle_count == 1, data.triangle_count
    assert data.stats["dropped_triangles"] == 1
    assert any("NaN" in w for w in data.warnings), data.warnings
    assert np.isfinite(data.positions).all()


def _material_of(data, index=0):
    return data.materials[int(data.material_ids[index])]


def _base_colour(data, index=0):
    """(colour, texture) of the base lobe of the first triangle's material: the first part
    of its mixes, a 0.5 mix's doubled weight undone."""
    material, scale = _material_of(data, index), 1.0
    while material.kind == "mix":
        if material.mix_mode == "constant" and material.mix_factor == 0.5:
            scale *= 0.5
        material = data.materials[material.mix_a]
    return tuple(scale * c for c in material.color), material.color_texture


def _single(material):
    """Exports one cube with the material (clearing earlier objects, keeping materials)."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    _camera()
    add_cube(material=material)
    return export()


def _check_plastic(materials, index, base, ior):
    """4.x: one plastic layer of index ior over base; 3.x: Cycles 3.x's sum of a diffuse
    and a Fresnel-weighted specular, as Mix(0.5, diffuse of 2 base, Mix(Fresnel(ior),
    black, reflector of colour 2))."""
    material = materials[index]
    if helpers.BLENDER_4:
        assert material.kind == "plastic", material
        assert_close(material.color, base, 1e-6, "plastic base colour")
        assert abs(material.ior - ior) < 1e-4, material
        return
    assert material.kind == "mix" and material.mix_factor == 0.5, material
    diffuse, specular = materials[material.mix_a], materials[material.mix_b]
    assert diffuse.kind == "diffuse", diffuse
    assert_close(diffuse.color, [2 * c for c in base], 1e-6, "doubled base colour")
    # The layer's Fresnel: index ior on both sides (never inverted behind, as Cycles 3.x).
    assert specular.mix_mode == "layer_fresnel" and abs(specular.mix_ior - ior) < 1e-4, specular
    assert materials[specular.mix_a].color == (0.0, 0.0, 0.0)
    reflector = materials[specular.mix_b]
    assert reflector.kind == "conductor" and reflector.color == (2.0, 2.0, 2.0), reflector


def test_principled_mappings():
    """Principled BSDF's parts: a plastic layer (index from Specular in 3.x, from IOR and
    Specular IOR Level in 4.x), a Schlick metal, glass, emission, and a rough metal kept
    rough."""
    base = (0.2, 0.4, 0.6, 1.0)
    data = _single(node_material("Plastic", PRINCIPLED, **{"Base Color": base, "IOR": 1.5}))
    # 3.x: Specular 0.5 is F0 = 0.04, index 1.5; 4.x: IOR 1.5 at level 0.5.
    _check_plastic(data.materials, int(data.material_ids[0]), base[:3], 1.5)
    assert not data.warnings, data.warnings

    metal = {"Base Color": base, "Metallic": 1.0, "Roughness": 0.0}
    data = _single(node_material("Metal", PRINCIPLED, **metal))
    material = _material_of(data)
    assert material.kind == "conductor" and material.schlick, material
    assert not data.warnings, data.warnings

    glass = {TRANSMISSION: 1.0, "IOR": 1.33, "Roughness": 0.0}
    data = _single(node_material("Glass", PRINCIPLED, **glass))
    material = _material_of(data)
    assert material.kind == "dielectric" and abs(material.ior - 1.33) < 1e-5, material
    # Neither version tints the glass's reflection by the base colour (v1 by Specular Tint
    # only, which is 0 here: Cycles 3.x's principled_v1_glass_refl); each refraction is
    # tinted by the base colour (0.8) in v1, by its square root in v2 (Cycles 4.x).
    assert not material.tint_reflection, material
    tint = math.sqrt(0.8) if helpers.BLENDER_4 else 0.8
    assert all(abs(c - tint) < 1e-6 for c in material.color), material

    glow = {EMISSION_COLOR: (1.0, 0.5, 0.25, 1), "Emission Strength": 4.0}
    data = _single(node_material("Glow", PRINCIPLED, **glow))
    assert_close(_material_of(data).emission, (4.0, 2.0, 1.0), 1e-6, "principled emission")
    assert data.emits_light()

    rough_metal = {"Metallic": 1.0, "Roughness": 0.8}
    data = _single(node_material("RoughMetal", PRINCIPLED, **rough_metal))
    material = _material_of(data)
    assert material.kind == "conductor" and abs(material.roughness - 0.8) < 1e-6, material
    assert not data.warnings, data.warnings


def test_principled_parts_become_mixes():
    """Metallic 0.3 and Transmission 0.4 with alpha 0.6: Mix(Transparent, Mix(metallic,
    Mix(transmission, plastic, glass), metal)), the mix indices pointing into the table."""
    inputs = {"Metallic": 0.3, TRANSMISSION: 0.4, "Alpha": 0.6, "Roughness": 0.35}
    data = _single(node_material("Parts", PRINCIPLED, **inputs))
    materials = data.materials
    root = _material_of(data)
    assert root.kind == "mix" and abs(root.mix_factor - 0.6) < 1e-6, root
    assert materials[root.mix_a].kind == "transparent", materials[root.mix_a]
    metallic = materials[root.mix_b]
    assert metallic.kind == "mix" and abs(metallic.mix_factor - 0.3) < 1e-6, metallic
    assert materials[metallic.mix_b].kind == "conductor"
    transmission = materials[metallic.mix_a]
    assert abs(transmission.mix_factor - 0.4) < 1e-6, transmission
    _check_plastic(materials, transmission.mix_a, (0.8, 0.8, 0.8), 1.5)
    assert materials[transmission.mix_b].kind == "dielectric"
    for leaf in materials:
        if leaf.kind in ("plastic", "dielectric", "conductor"):
            assert abs(leaf.roughness - 0.35) < 1e-6, leaf
    assert not data.warnings, data.warnings


def test_principled_v2_specular_level_sets_the_index():
    """4.x: Specular IOR Level 0.25 halves F0 = ((1.5 - 1) / 2.5)^2 = 0.04, so the layer's
    index is (1 + sqrt(0.02)) / (1 - sqrt(0.02)) = 1.32945; 3.x: Specular 0.25 gives F0
    0.02, the same index."""
    name = "Specular IOR Level" if helpers.BLENDER_4 else "Specular"
    data = _single(node_material("Half", PRINCIPLED, **{name: 0.25, "IOR": 1.5}))
    expected = (1 + math.sqrt(0.02)) / (1 - math.sqrt(0.02))
    _check_plastic(data.materials, int(data.material_ids[0]), (0.8, 0.8, 0.8), expected)


def test_principled_unmodelled_parts_warn_once_each():
    sheen = "Sheen Weight" if helpers.BLENDER_4 else "Sheen"
    coat = "Coat Weight" if helpers.BLENDER_4 else "Clearcoat"
    data = _single(node_material("Velvet", PRINCIPLED, **{sheen: 0.5, coat: 0.8}))
    assert len(data.warnings) == 2, data.warnings
    assert all(w.startswith("material 'Velvet': Principled BSDF 'Principled BSDF': ")
               for w in data.warnings), data.warnings
    assert "sheen" in data.warnings[1] and "coat" in data.warnings[0], data.warnings
    root = _material_of(data)
    # The coat: Fresnel of its index between the base and Mix(weight, base, white GGX).
    assert root.kind == "mix" and root.mix_mode == "layer_fresnel" and root.mix_ior == 1.5, root
    inner = data.materials[root.mix_b]
    assert inner.mix_a == root.mix_a, (inner, root)
    coat = data.materials[inner.mix_b]
    assert coat.kind == "conductor" and coat.color == (1.0, 1.0, 1.0), coat
    # 3.x's clearcoat reflects a quarter of 4.x's coat of the same weight.
    assert abs(inner.mix_factor - (0.8 if helpers.BLENDER_4 else 0.2)) < 1e-6, inner


def test_basic_node_mappings():
    data = _single(helpers.diffuse_material("Red", (0.8, 0.1, 0.1)))
    assert _material_of(data).kind == "diffuse"
    assert_close(_material_of(data).color, (0.8, 0.1, 0.1), 1e-6, "diffuse colour")

    data = _single(node_material("Mirror", "ShaderNodeBsdfGlossy", Roughness=0.0,
                                 Color=(0.9, 0.9, 0.9, 1)))
    assert _material_of(data).kind == "conductor" and not data.warnings, data.warnings

    satin = node_material("Satin", "ShaderNodeBsdfGlossy", Roughness=0.3)
    for node in satin.node_tree.nodes:
        if node.type == 'BSDF_GLOSSY':
            node.distribution = 'MULTI_GGX'
    data = _single(satin)
    material = _material_of(data)
    assert material.kind == "conductor" and not material.schlick, material
    assert abs(material.roughness - 0.3) < 1e-6 and material.multiscatter, material
    assert not data.warnings, data.warnings

    matte = node_material("Matte", "ShaderNodeBsdfGlossy", Roughness=0.9)
    for node in matte.node_tree.nodes:
        if node.type == 'BSDF_GLOSSY':
            node.distribution = 'BECKMANN'
    data = _single(matte)
    material = _material_of(data)
    assert material.kind == "conductor" and not material.multiscatter, material
    assert data.warnings == ["material 'Matte': Glossy BSDF 'Glossy BSDF': the Beckmann "
                             "distribution is rendered as GGX"], data.warnings

    data = _single(node_material("Glass", "ShaderNodeBsdfGlass", IOR=1.45, Roughness=0.2))
    material = _material_of(data)
    assert material.kind == "dielectric" and abs(material.ior - 1.45) < 1e-6, material
    assert material.tint_reflection and abs(material.roughness - 0.2) < 1e-6, material

    data = _single(node_material("Veil", "ShaderNodeBsdfTranslucent",
                                 Color=(0.5, 0.6, 0.7, 1)))
    assert _material_of(data).kind == "translucent" and not data.warnings, data.warnings
    data = _single(node_material("Clear", "ShaderNodeBsdfTransparent"))
    assert _material_of(data).kind == "transparent" and not data.warnings, data.warnings

    data = _single(helpers.emission_material("Lamp", (1.0, 0.8, 0.6), 10.0))
    material = _material_of(data)
    assert_close(material.emission, (10.0, 8.0, 6.0), 1e-5, "emission radiance")
    assert_close(material.color, (0, 0, 0), 0, "emitter reflects nothing")


def _shader_pair(name, combiner, first, second):
    """A material of combiner (Mix or Add Shader) over two shader nodes (type, inputs)."""
    material = node_material(name, combiner)
    tree = material.node_tree
    node = next(n for n in tree.nodes if n.type in ('MIX_SHADER', 'ADD_SHADER'))
    offset = 1 if node.type == 'MIX_SHADER' else 0
    for k, (node_type, inputs) in enumerate((first, second)):
        shader = tree.nodes.new(node_type)
        for key, value in inputs.items():
            shader.inputs[key].default_value = value
        tree.links.new(shader.outputs[0], node.inputs[offset + k])
    return material, tree, node


def test_mix_and_add_shaders():
    """Mix Shader's Fac is the probability of its second shader; Layer Weight's Fresnel
    is the Fresnel node's with IOR 1 / (1 - blend); Add of an Emission is the other
    shader emitting; Add of two BSDFs is Mix 0.5 with both weights doubled."""
    red = ("ShaderNodeBsdfDiffuse", {"Color": (0.8, 0.1, 0.1, 1)})
    glossy = ("ShaderNodeBsdfGlossy", {"Roughness": 0.25})
    material, tree, node = _shader_pair("Mixed", "ShaderNodeMixShader", red, glossy)
    node.inputs[0].default_value = 0.3
    data = _single(material)
    root = _material_of(data)
    assert root.kind == "mix" and abs(root.mix_factor - 0.3) < 1e-6, root
    assert data.materials[root.mix_a].kind == "diffuse"
    assert data.materials[root.mix_b].kind == "conductor"

    weight = tree.nodes.new("ShaderNodeLayerWeight")
    weight.inputs["Blend"].default_value = 0.2
    tree.links.new(weight.outputs["Fresnel"], node.inputs[0])
    root = _material_of(_single(material))
    assert root.mix_mode == "fresnel" and abs(root.mix_ior - 1.25) < 1e-5, root
    tree.links.new(weight.outputs["Facing"], node.inputs[0])
    root = _material_of(_single(material))
    assert root.mix_mode == "facing" and abs(root.mix_ior - 0.2) < 1e-6, root

    lamp = ("ShaderNodeEmission", {"Color": (1, 1, 1, 1), "Strength": 3.0})
    material, _, _ = _shader_pair("Glowing", "ShaderNodeAddShader", red, lamp)
    data = _single(material)
    leaf = _material_of(data)
    assert leaf.kind == "diffuse" and leaf.emission == (3.0, 3.0, 3.0), leaf

    blue = ("ShaderNodeBsdfDiffuse", {"Color": (0.1, 0.1, 0.4, 1)})
    material, _, _ = _shader_pair("Sum", "ShaderNodeAddShader", red, blue)
    data = _single(material)
    root = _material_of(data)
    assert root.kind == "mix" and root.mix_factor == 0.5, root
    assert_close(data.materials[root.mix_a].color, (1.6, 0.2, 0.2), 1e-6, "doubled red")
    assert_close(data.materials[root.mix_b].color, (0.2, 0.2, 0.8), 1e-6, "doubled blue")
    assert not data.warnings, data.warnings


def test_two_mixed_materials_keep_their_roots():
    """Two objects with tree materials: each face points at its own material's root and
    each root's mix indices at its own parts."""
    red = ("ShaderNodeBsdfDiffuse", {"Color": (0.8, 0.1, 0.1, 1)})
    glossy = ("ShaderNodeBsdfGlossy", {"Roughness": 0.25})
    first, _, _ = _shader_pair("First", "ShaderNodeMixShader", red, glossy)
    second, _, _ = _shader_pair("Second", "ShaderNodeMixShader", glossy, red)
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    _camera()
    add_cube("A", material=first)
    add_cube("B", location=(4, 0, 0), material=second)
    data = export()
    roots = sorted(set(int(k) for k in data.material_ids))
    assert roots == [0, 3], roots
    assert [m.kind for m in data.materials] == ["mix", "diffuse", "conductor",
                                                "mix", "conductor", "diffuse"]
    assert (data.materials[3].mix_a, data.materials[3].mix_b) == (4, 5)


def test_linked_colour_inputs():
    material = node_material("Tinted", "ShaderNodeBsdfDiffuse")
    tree = material.node_tree
    rgb = tree.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.3, 0.5, 0.7, 1.0)
    shader = next(node for node in tree.nodes if node.type == 'BSDF_DIFFUSE')
    tree.links.new(rgb.outputs[0], shader.inputs["Color"])
    data = _single(material)
    assert_close(_material_of(data).color, (0.3, 0.5, 0.7), 1e-6, "RGB node colour")


def save_image(name, pixels, float_buffer, file_format, extension):
    """Writes (H, W, 4) pixels (row 0 at the bottom) to OUT/name.extension through
    Blender's image API and loads the file back as a file image."""
    import os
    height, width = pixels.shape[:2]
    image = bpy.data.images.new(name, width, height, float_buffer=float_buffer)
    if float_buffer:
        image.colorspace_settings.name = "Non-Color"  # else save() writes sRGB-encoded
    image.pixels.foreach_set(np.asarray(pixels, dtype=np.float32).ravel())
    path = os.path.join(helpers.OUT, f"{name}.{extension}")
    image.filepath_raw = path
    image.file_format = file_format
    image.save()
    bpy.data.images.remove(image)
    return bpy.data.images.load(path, check_existing=False)


def image_material(name, image, shader=PRINCIPLED, extension='REPEAT'):
    """A material whose BSDF colour comes from an Image Texture node."""
    material = node_material(name, shader)
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    texture.extension = extension
    bsdf = next(node for node in tree.nodes if node.type.startswith('BSDF'))
    tree.links.new(texture.outputs["Color"], bsdf.inputs[0])
    return material


def _mapped_image_material(name, image, vector_type, location, rotation, scale,
                           coordinate="UV", between=None):
    """Texture Coordinate (coordinate output) -> [between node] -> Mapping -> Image Texture."""
    material = image_material(name, image)
    tree = material.node_tree
    texture = next(node for node in tree.nodes if node.type == 'TEX_IMAGE')
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = vector_type
    for socket, value in (("Location", location), ("Rotation", rotation), ("Scale", scale)):
        if socket in mapping.inputs:
            mapping.inputs[socket].default_value = value
    source = coordinates.outputs[coordinate]
    if between is not None:
        node = tree.nodes.new("ShaderNodeVectorMath")
        node.operation = between
        node.name = "Odd Vector Math"
        tree.links.new(source, node.inputs[0])
        source = node.outputs["Vector"]
    tree.links.new(source, mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    return material


def test_mapping_node_on_uvs_becomes_the_textures_uv_map():
    """Texture Coordinate UV -> Mapping -> Image Texture: the texture's uv map is the
    Mapping of (u, v, 0), checked at three uvs against Blender's own Euler matrix
    (mathutils) for the Point, Texture and Vector types, within 1e-6; no warning. Generated
    through the Mapping becomes the texture's position map, checked at three world points
    of a moved, turned and scaled cube whose mesh is off-centre (its auto texture space
    not the unit cube) against Cycles' orco (mesh_texture_space) within 1e-5. A chain
    that is not affine (a Normalize) keeps the mesh's UVs and a warning naming the node."""
    from mathutils import Euler, Vector
    pixels = np.full((2, 2, 4), 0.5, dtype=np.float32)
    image = save_image("Mapped", pixels, False, 'PNG', "png")
    location, rotation, scale = (0.25, -0.5, 0.75), (0.3, -0.2, 0.6), (2.0, 3.0, 0.5)
    matrix = Euler(rotation, 'XYZ').to_matrix()
    loc, size = Vector(location), Vector(scale)
    closed_forms = {
        'POINT': lambda p: matrix @ (p * size) + loc,
        'TEXTURE': lambda p: Vector(x / s for x, s in zip(matrix.transposed() @ (p - loc),
                                                          size)),
        'VECTOR': lambda p: matrix @ (p * size),
    }
    for kind, closed_form in closed_forms.items():
        data = _single(_mapped_image_material(f"Mapped {kind}", image, kind, location,
                                              rotation, scale))
        (a, b, c), (d, e, f) = data.textures[0].uv_map
        for u, v in ((0.0, 0.0), (1.0, 0.0), (0.3, 0.8)):
            want = closed_form(Vector((u, v, 0.0)))
            got = (a * u + b * v + c, d * u + e * v + f)
            assert_close(got, tuple(want)[:2], 1e-6, f"{kind} mapping of uv ({u}, {v})")
        assert not [w for w in data.warnings if "Mapped" in w or "image texture" in w], \
            data.warnings
    material = _mapped_image_material("Generated", image, 'POINT', location, rotation, scale,
                                      "Generated")
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    _camera()
    cube = add_mesh_object("Off", [(0.5 + 1.5 * x, -0.25 + 0.75 * y, 0.1 + 0.4 * z)
                                   for x, y, z in CUBE_VERTICES], CUBE_FACES,
                           location=(0.3, -0.2, 0.5), rotation=(0.4, -0.3, 0.9),
                           scale=(1.5, 0.7, 1.2), material=material)
    data = export()
    assert not [w for w in data.warnings if "Generated" in w or "image texture" in w], \
        data.warnings
    texture = data.textures[0]
    assert texture.position_map is not None, texture
    to_object = cube.matrix_world.inverted()
    for corner in ((0.5, -0.25, 0.1), (2.0, 0.5, 0.5), (-1.0, -1.0, -0.3)):
        world = cube.matrix_world @ Vector(corner)
        p = to_object @ world
        generated = Vector(((p.x - 0.5) / 3.0 + 0.5, (p.y + 0.25) / 1.5 + 0.5,
                            (p.z - 0.1) / 0.8 + 0.5))  # bounds (-1, -1, -0.3)..(2, 0.5, 0.5)
        want = closed_forms['POINT'](generated)
        got = [sum(r[k] * world[k] for k in range(3)) + r[3] for r in texture.position_map]
        assert_close(got, tuple(want)[:2], 1e-5, f"Generated mapping at {corner}")
    for coordinate, between, named in (("UV", 'NORMALIZE', "Odd Vector Math"),):
        data = _single(_mapped_image_material(f"Odd {coordinate}", image, 'POINT', location,
                                              rotation, scale, coordinate, between))
        assert data.textures[0].uv_map == ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
        assert any(named in w and "render UV map" in w for w in data.warnings), data.warnings


def test_image_texture_becomes_a_texture():
    """An sRGB 8-bit PNG crosses as its exact bytes (uint8), a float EXR as float32
    linear; one Texture per image however many materials use it; UVs are exported."""
    rows = np.linspace(0.0, 1.0, 4 * 3 * 4).reshape(4, 3, 4).astype(np.float32)
    rows[..., 3] = 1.0
    png = save_image("Ramp8", rows, False, 'PNG', "png")
    assert png.colorspace_settings.name == "sRGB" and not png.is_float
    _camera()
    for name, x, shader in (("A", 0, PRINCIPLED), ("B", 3, "ShaderNodeBsdfDiffuse")):
        cube = add_cube(name, location=(x, 0, 0), material=image_material(name, png, shader))
        cube.data.uv_layers.new()  # Blender's default: every face covers [0, 1]^2
    add_cube("NoUVs", location=(-3, 0, 0), material=bpy.data.materials["A"])
    data = export()
    assert any("NoUVs" in w and "no UV map" in w for w in data.warnings), data.warnings
    assert len(data.textures) == 1, data.textures
    texture = data.textures[0]
    assert texture.pixels.dtype == np.uint8 and texture.pixels.shape == (4, 3, 4)
    assert_close(texture.pixels, np.rint(rows * 255), 0, "sRGB bytes")
    assert texture.wrap == "repeat"
    # The Diffuse BSDF's material and the Principled BSDF's base, each white times the
    # texture (3.x's Principled base at twice its weight, as Cycles 3.x sums it).
    textured = [m for m in data.materials if m.color_texture >= 0]
    assert len(textured) == 2, data.materials
    for material in textured:
        assert material.color_texture == 0 and len(set(material.color)) == 1, material
        assert material.color[0] in (1.0, 2.0), material
    assert data.uvs is not None and data.uvs.shape == (len(data.positions), 2)
    corners = data.uvs.reshape(-1, 3, 2)
    assert_close(np.sort(np.unique(data.uvs)), (0.0, 1.0), 0, "unit-square UVs")
    doubled_areas = np.abs(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    # Textured triangles cover half the square each; the cube without UVs gets (0, 0).
    assert_close(np.sort(doubled_areas), [0.0] * 12 + [1.0] * 24, 0, "UV triangle areas")

    helpers.reset_scene()
    hdr = np.full((2, 5, 4), 1.0, dtype=np.float32)
    hdr[..., 0] = 4.0  # beyond 1: kept, as float32 linear
    exr = save_image("Bright", hdr, True, 'OPEN_EXR', "exr")
    material = image_material("Lit", exr, extension='CLIP')
    data = _single(material)
    assert data.textures[0].pixels.dtype == np.float32
    assert_close(data.textures[0].pixels, hdr, 1e-6, "float texels")
    assert data.textures[0].wrap == "clip"


def test_image_texture_interpolation_crosses_to_the_texture():
    """The Image Texture's interpolation: Linear and Closest cross as they are, unwarned;
    Cubic and Smart render as Linear with one warning naming the image, however many nodes
    read it (two cubes of one Cubic material, and a second Cubic material)."""
    pixels = np.full((2, 2, 4), 0.5, dtype=np.float32)
    png = save_image("Texels", pixels, False, 'PNG', "png")
    for interpolation, want in (('Linear', "linear"), ('Closest', "closest")):
        material = image_material(f"Filter {interpolation}", png)
        material.node_tree.nodes["Image Texture"].interpolation = interpolation
        data = _single(material)
        assert [t.interpolation for t in data.textures] == [want], data.textures
        assert not any("interpolation" in w for w in data.warnings), data.warnings
    for interpolation in ('Cubic', 'Smart'):
        for obj in list(bpy.data.objects):
            bpy.data.objects.remove(obj)
        _camera()
        for k in range(2):
            material = image_material(f"Filter {interpolation} {k}", png)
            material.node_tree.nodes["Image Texture"].interpolation = interpolation
            add_cube(f"Cube {k}", location=(3 * k, 0, 0), material=material)
            add_cube(f"Twin {k}", location=(3 * k, 3, 0), material=material)
        data = export()
        assert [t.interpolation for t in data.textures] == ["linear"], data.textures
        warned = [w for w in data.warnings if "interpolation" in w]
        assert len(warned) == 1 and f"image '{png.name}': {interpolation} interpolation " \
            "is rendered as Linear" in warned[0], data.warnings


def test_image_texture_colour_spaces_and_fallbacks():
    pixels = np.full((2, 2, 4), 0.5, dtype=np.float32)
    pixels[..., 3] = 1.0
    png = save_image("Data", pixels, False, 'PNG', "png")
    png.colorspace_settings.name = "Non-Color"
    data = _single(image_material("Data", png, extension='EXTEND'))
    texture = data.textures[0]
    assert texture.pixels.dtype == np.float32, texture.pixels.dtype
    assert_close(texture.pixels[..., :3], np.full((2, 2, 3), 128 / 255), 1e-6, "raw values")
    # Extend is rendered as Cycles renders it (edge texels outside the image), unwarned.
    assert texture.wrap == "extend"
    assert not any("Extend" in w for w in data.warnings), data.warnings

    # A missing file: magenta (1, 0, 1), as Cycles renders it, and a warning naming it.
    missing = node_material("Missing", PRINCIPLED, **{"Base Color": (0.1, 0.2, 0.3, 1)})
    tree = missing.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = missing_image()
    principled = next(node for node in tree.nodes if node.type == 'BSDF_PRINCIPLED')
    tree.links.new(texture.outputs["Color"], principled.inputs["Base Color"])
    data = _single(missing)
    color, texture = _base_colour(data)
    assert_close(color, (1.0, 1.0, 1.0), 1e-6, "colour under the texture")
    assert texture == 0 and len(data.textures) == 1
    assert_close(data.textures[0].pixels, np.float32([[[1, 0, 1, 1]]]), 0.0, "magenta texel")
    name = tree.nodes["Image Texture"].image.name
    assert any(f"image '{name}' is missing" in w and "magenta" in w
               for w in data.warnings), data.warnings

    # An image on an emission colour: the emission is the strength, times the image's
    # texel (emission_texture, the material's root), with no warning.
    glow = node_material("Glow", "ShaderNodeEmission", Strength=2.0)
    tree = glow.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = png
    emission = next(node for node in tree.nodes if node.type == 'EMISSION')
    tree.links.new(texture.outputs["Color"], emission.inputs["Color"])
    data = _single(glow)
    glowing = _material_of(data)
    assert_close(glowing.emission, [2.0] * 3, 1e-6, "emission strength")
    assert glowing.emission_texture >= 0, glowing
    assert_close(data.textures[glowing.emission_texture].pixels[..., :3],
                 np.full((2, 2, 3), 128 / 255), 1e-6, "emission image")
    assert not any("mean colour" in w for w in data.warnings), data.warnings


def missing_image():
    """An image datablock whose file has gone (as after moving a .blend)."""
    image = bpy.data.images.new("Gone", 2, 2)
    image.source = 'FILE'
    image.filepath = "/nonexistent/texture.png"
    return image


def test_unsupported_material_falls_back_once():
    _camera()
    material = node_material("Toon", "ShaderNodeBsdfToon")
    material.diffuse_color = (0.1, 0.7, 0.2, 1.0)
    add_cube("A", material=material)
    add_cube("B", location=(5, 0, 0), material=material)
    data = export()
    assert_close(_material_of(data).color, (0.1, 0.7, 0.2), 1e-6, "viewport colour")
    assert len(data.warnings) == 1 and "Toon" in data.warnings[0], data.warnings


def test_material_slots_map_per_triangle():
    _camera()
    red = diffuse_material("Red", (1, 0, 0))
    blue = diffuse_material("Blue", (0, 0, 1))
    cube = add_cube(material=red)
    cube.data.materials.append(blue)
    cube.data.polygons.foreach_set("material_index", [0, 1, 0, 1, 0, 1])
    cube.data.update()
    data = export()
    colors = np.array([data.materials[i].color for i in data.material_ids])
    centers = _triangles(data).mean(axis=1)
    # Faces -X, -Y, -Z (indices 0, 2, 4) red; +X, +Y, +Z blue.
    blue_side = centers.sum(axis=1) > 0
    assert_close(colors[blue_side], np.tile((0, 0, 1), (6, 1)), 0, "blue faces")
    assert_close(colors[~blue_side], np.tile((1, 0, 0), (6, 1)), 0, "red faces")


def test_point_spot_sun_lights():
    _camera()
    add_light('POINT', 100.0, location=(1, 2, 3), color=(1, 0.5, 0.25), shadow_soft_size=0.1)
    add_light('SPOT', 50.0, location=(0, 0, 5), rotation=(math.pi / 2, 0, 0),
              spot_size=math.radians(60), spot_blend=0.25)
    add_light('SUN', 3.0, rotation=(0, math.pi / 4, 0), angle=math.radians(2))
    data = export()
    lights = {light.kind: light for light in data.lights}
    point, spot, sun = lights["point"], lights["spot"], lights["sun"]
    assert_close(point.position, (1, 2, 3), 1e-6, "point position")
    assert_close(point.color, (1, 0.5, 0.25), 1e-6, "point colour")
    assert point.power == 100.0 and abs(point.radius - 0.1) < 1e-6
    # Rotating -Z by 90 degrees about X points the spot along +Y.
    assert_close(spot.direction, (0, 1, 0), 1e-6, "spot direction")
    assert abs(spot.spot_size - math.radians(60)) < 1e-6 and abs(spot.spot_blend - 0.25) < 1e-6
    # Rotating -Z by 45 degrees about Y: (-sin 45, 0, -cos 45).
    assert_close(sun.direction, (-math.sqrt(0.5), 0, -math.sqrt(0.5)), 1e-6, "sun direction")
    assert sun.power == 3.0 and abs(sun.angle - math.radians(2)) < 1e-6


def test_area_lights_are_native():
    """Every shape crosses as an area light with the object's matrix and sizes; power
    is Blender's, times pi/4 under 3.x (Cycles 3.x's radiance P / (4A) against the
    module's P / (pi A)); camera visibility is the object's."""
    _camera()
    factor = 1.0 if helpers.BLENDER_4 else math.pi / 4
    shapes = {'SQUARE': (2.0, 2.0), 'RECTANGLE': (2.0, 0.5), 'DISK': (1.5, 1.5),
              'ELLIPSE': (1.0, 3.0)}
    for index, (shape, (size_x, size_y)) in enumerate(shapes.items()):
        obj = add_light('AREA', 100.0 + index, location=(index, 0, 4),
                        rotation=(math.pi / 2, 0, 0), shape=shape, size=size_x, size_y=size_y)
        obj.visible_camera = index % 2 == 0
    data = export()
    assert data.triangle_count == 0 and len(data.lights) == 4, data.lights
    for index, light in enumerate(sorted(data.lights, key=lambda light: light.power)):
        shape, (size_x, size_y) = list(shapes.items())[index]
        assert light.kind == "area" and light.shape == shape.lower(), light
        assert abs(light.power - (100.0 + index) * factor) < 1e-4, light.power
        assert_close((light.size_x, light.size_y), (size_x, size_y), 1e-6, f"{shape} size")
        assert light.to_world.dtype == np.float32 and light.to_world.shape == (4, 4)
        assert_close(light.to_world[:3, 3], (index, 0, 4), 1e-6, "light position")
        # Rotating -Z by 90 degrees about X: the light shines along +Y.
        assert_close(light.direction, (0, 1, 0), 1e-6, "direction")
        assert light.visible_to_camera == (index % 2 == 0)


def test_light_options_per_blender_version():
    """Spot lights get 3.x's cosine factor only under 3.x; an un-normalized 4.x area
    light passes power x area (Cycles: L = P / pi regardless of size)."""
    _camera()
    add_light('SPOT', 10.0, spot_size=1.0)
    spot = export().lights[0]
    assert spot.spot_cosine == (not helpers.BLENDER_4), spot
    helpers.reset_scene()
    _camera()
    obj = add_light('AREA', 10.0, shape='RECTANGLE', size=2.0, size_y=3.0)
    if hasattr(obj.data, "normalize"):
        obj.data.normalize = False
        obj.scale = (2.0, 1.0, 1.0)
        light = export().lights[0]
        assert abs(light.power - 10.0 * 2.0 * 3.0 * 2.0) < 1e-4, light.power


def _fov(sensor_fit, size, **camera):
    helpers.reset_scene(size=size)
    add_camera((0, 0, 0), (0, 0, 0), lens=50.0, sensor_fit=sensor_fit, sensor_width=36.0,
               sensor_height=24.0, **camera)
    add_cube(location=(0, 0, -5))
    return export().camera


def test_camera_fov_for_each_sensor_fit():
    wide, tall = (128, 64), (64, 128)
    assert_close(_fov('AUTO', wide).fov_x, 2 * math.atan(18 / 50), 1e-6, "AUTO landscape")
    assert_close(_fov('AUTO', tall).fov_x, 2 * math.atan(18 / 50 * 0.5), 1e-6, "AUTO portrait")
    assert_close(_fov('HORIZONTAL', tall).fov_x, 2 * math.atan(18 / 50), 1e-6, "HORIZONTAL")
    assert_close(_fov('VERTICAL', wide).fov_x, 2 * math.atan(12 / 50 * 2), 1e-6, "VERTICAL")
    camera = _fov('VERTICAL', wide, shift_x=0.1, shift_y=-0.2)
    # Shift is in units of the fit side (height 64); the module wants the larger (128).
    assert_close((camera.shift_x, camera.shift_y), (0.05, -0.1), 1e-6, "shift")
    camera = _fov('AUTO', wide, shift_x=0.1)
    assert_close(camera.shift_x, 0.1, 1e-6, "AUTO shift unchanged")


def test_camera_transform_ortho_and_depth_of_field():
    helpers.reset_scene()
    camera = add_camera((1, 2, 3), (0.3, 0.2, 0.1), type='ORTHO', ortho_scale=7.0)
    camera.scale = (2, 2, 2)
    add_cube(location=(0, 0, -5))
    data = export()
    expected = np.array(camera.matrix_world.normalized())
    assert_close(data.camera.to_world, expected, 1e-5, "camera matrix without scale")
    assert data.camera.to_world.dtype == np.float32 and data.camera.to_world.shape == (4, 4)
    assert data.camera.projection == "orthographic" and abs(data.camera.ortho_scale - 7) < 1e-6

    helpers.reset_scene()
    camera = add_camera((0, 0, 0), (0, 0, 0), lens=50.0)
    camera.data.dof.use_dof = True
    camera.data.dof.aperture_fstop = 2.0
    target = bpy.data.objects.new("Target", None)
    target.location = (1, 0, -4)
    bpy.context.scene.collection.objects.link(target)
    camera.data.dof.focus_object = target
    add_cube(location=(0, 0, -5))
    data = export()
    assert_close(data.camera.aperture_radius, 0.05 / 4, 1e-7, "aperture radius")
    assert_close(data.camera.focus_distance, 4.0, 1e-5, "focus distance along the view axis")


def test_object_without_material_exports_as_a_new_material():
    """Cycles renders an object without a material as a new material of that Blender: a
    diffuse 0.8 grey up to 4.x (whose new materials have no nodes), a default Principled BSDF
    in 5.x (measured the same pixels in Cycles 5.2). The export of both is the same."""
    _camera()
    add_cube()
    without = export()
    assert len(without.materials) == 1 and not without.warnings, without.warnings
    add_cube("Other", location=(3, 0, 0), material=bpy.data.materials.new("New"))
    with_new = export()
    assert not with_new.warnings, with_new.warnings
    default, new = _material_of(without), _material_of(with_new, 12)
    for field in dataclasses.fields(default):
        a, b = getattr(default, field.name), getattr(new, field.name)
        if isinstance(a, (float, tuple)) and a is not None and b is not None:
            assert_close(a, b, 1e-6, field.name)  # float32 colours, an IOR through F0
        else:
            assert a == b, (field.name, default, new)
    kind = "plastic" if helpers.BLENDER_5 else "diffuse"
    assert _material_of(without).kind == kind, _material_of(without)


def test_world_background():
    _camera()
    add_cube()
    set_world((0.5, 0.25, 1.0), 2.0)
    assert_close(export().environment, (1.0, 0.5, 2.0), 1e-6, "background colour x strength")
    world = bpy.context.scene.world
    world.color = (0.1, 0.2, 0.3)
    if helpers.BLENDER_5:
        # 5.x has no world without nodes (use_nodes is deprecated and always on): the
        # viewport colour is never the background, and an unlinked World Output is black.
        assert_close(export().environment, (1.0, 0.5, 2.0), 1e-6, "nodes, whatever the colour")
        world.node_tree.links.clear()
        assert_close(export().environment, (0, 0, 0), 0, "nothing linked to the World Output")
    else:
        world.use_nodes = False
        assert_close(export().environment, (0.1, 0.2, 0.3), 1e-6, "world colour without nodes")
    bpy.context.scene.world = None
    data = export()
    assert_close(data.environment, (0, 0, 0), 0, "no world")
    assert not data.emits_light()


def environment_world(image, strength=1.0):
    """A world whose Background colour is an Environment Texture of image."""
    world = set_world((0.2, 0.3, 0.4), strength)
    tree = world.node_tree
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image = image
    background = next(node for node in tree.nodes if node.type == 'BACKGROUND')
    tree.links.new(texture.outputs["Color"], background.inputs["Color"])
    return world


def test_world_environment_texture():
    _camera()
    add_cube()
    sky = np.ones((4, 8, 4), dtype=np.float32)
    sky[2:, :, :3] = (2.0, 3.0, 5.0)   # the upper half (rows from the bottom) brighter
    environment_world(save_image("Sky", sky, True, 'OPEN_EXR', "exr"), strength=1.5)
    data = export()
    assert data.environment_texture == 0 and len(data.textures) == 1
    assert_close(data.environment, (1.5, 1.5, 1.5), 1e-6, "strength multiplies the map")
    assert_close(data.textures[0].pixels, sky, 1e-6, "environment texels")
    assert data.emits_light()

    assert_close(data.environment_to_world, np.eye(4), 1e-6,
                 "Blender's map is the module's: no rotation")

    # A Mapping node (Point) rotating the lookup by R: the module looks up at M^T d,
    # which must be R d.
    tree = bpy.context.scene.world.node_tree
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.pi / 2)
    texture = next(node for node in tree.nodes if node.type == 'TEX_ENVIRONMENT')
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    lookup = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]])  # 90 degrees about Z
    assert_close(export().environment_to_world[:3, :3].T, lookup, 1e-6, "rotated lookup")
    mapping.vector_type = 'TEXTURE'  # the inverse transform
    assert_close(export().environment_to_world[:3, :3].T, lookup.T, 1e-6, "inverse lookup")

    # A missing image: magenta x strength, as Cycles renders it, and a warning.
    environment_world(missing_image(), strength=2.0)
    data = export()
    assert data.environment_texture == 0 and len(data.textures) == 1
    assert_close(data.textures[0].pixels, np.float32([[[1, 0, 1, 1]]]), 0.0, "magenta texel")
    assert any("missing" in w and "magenta" in w for w in data.warnings), data.warnings


def test_presets_set_the_settings_they_name():
    presets = helpers.ADDON.properties.presets.PRESETS
    settings = bpy.context.scene.glslppm
    assert {"PREVIEW", "FINAL", "CAUSTICS"} <= set(presets)
    for key, preset in presets.items():
        settings.passes, settings.radius_scale = 3, 7.0
        result = bpy.ops.glslppm.apply_preset(preset=key)
        assert result == {'FINISHED'}, result
        assert preset["description"], key
        for name, value in preset["settings"].items():
            actual = getattr(settings, name)
            if isinstance(value, float):
                assert abs(actual - value) < 1e-6 * max(1.0, abs(value)), (key, name, actual)
            else:
                assert actual == value, (key, name, actual, value)
    # What the names promise, whatever the measured numbers: a preview is cheaper than a
    # final render, caustics keep every photon and start from a smaller radius.
    table = {key: preset["settings"] for key, preset in presets.items()}
    preview, final, caustics = table["PREVIEW"], table["FINAL"], table["CAUSTICS"]
    sizing = {key: preset["photons"] for key, preset in presets.items()}
    assert preview["passes"] < final["passes"]
    assert sizing["PREVIEW"]["photon_to_eye"] <= sizing["FINAL"]["photon_to_eye"]
    assert sizing["PREVIEW"]["highest"] <= sizing["FINAL"]["highest"]
    assert caustics["hash_mode"] == 'EXACT' and caustics["radius_scale"] < 1.0


def test_no_camera_is_an_export_error():
    add_cube()
    try:
        export()
    except helpers.ADDON.export.ExportError as error:
        assert "camera" in str(error)
    else:
        raise AssertionError("export without a camera should fail")


def _tables_export():
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    return depsgraph


def test_material_edit_exports_tables_without_reading_meshes():
    """The viewport's material, light and world edits (export_tables): the new tables equal
    a whole export's, the geometry arrays are the last export's own (no mesh read), and an
    edit that reaches the geometry's side of the table asks for a whole export (None)."""
    _camera()
    grid = helpers.add_bumpy_grid(300)  # 180,000 triangles
    red = diffuse_material("Red", (0.8, 0.1, 0.1))
    grid.data.materials.append(red)
    add_cube(location=(0, 0, 3)).data.materials.append(diffuse_material("Grey", (0.5,) * 3))
    add_light('POINT', 100.0, location=(0, -2, 4))
    set_world((0.1, 0.2, 0.3))
    start = time.perf_counter()
    before = export()
    whole_seconds = time.perf_counter() - start

    red.node_tree.nodes["Diffuse BSDF"].inputs["Color"].default_value = (0.1, 0.1, 0.8, 1.0)
    bpy.data.lights[0].energy = 250.0
    bpy.context.scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 2.0
    depsgraph = _tables_export()
    start = time.perf_counter()
    tables = helpers.ADDON.export.export_tables(depsgraph, before)
    tables_seconds = time.perf_counter() - start
    whole = export()
    print(f"whole export {whole_seconds * 1e3:.0f} ms, tables only {tables_seconds * 1e3:.1f} ms "
          f"({before.triangle_count} triangles)")
    assert tables is not None
    # The geometry is the last export's own arrays: nothing was read again.
    assert tables.positions is before.positions and tables.material_ids is before.material_ids
    # The tables are what a whole export of the edited scene gives.
    assert tables.materials == whole.materials, (tables.materials, whole.materials)
    assert repr(tables.lights) == repr(whole.lights), (tables.lights, whole.lights)
    assert repr(tables.environment) == repr(whole.environment), (tables.environment,
                                                                 whole.environment)
    assert tables.lights[0].power == 250.0, tables.lights[0]
    # The grid's triangles now point at the edited colour.
    grid_material = tables.materials[int(tables.material_ids[0])]
    assert_close(grid_material.color, (0.1, 0.1, 0.8), 1e-6, "edited colour")
    assert np.array_equal(tables.material_ids, whole.material_ids)
    # Far cheaper than reading 180k triangles again (measured 0.1-1 ms against 60-150 ms).
    assert tables_seconds < 0.25 * whole_seconds, (tables_seconds, whole_seconds)

    # A Mix Shader adds entries to the table: the triangles' ids would move, so a whole
    # export is asked for.
    tree = red.node_tree
    mix = tree.nodes.new("ShaderNodeMixShader")
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
    tree.links.new(tree.nodes["Diffuse BSDF"].outputs[0], mix.inputs[1])
    tree.links.new(glossy.outputs[0], mix.inputs[2])
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    assert helpers.ADDON.export.export_tables(_tables_export(), before) is None

def test_normal_map_and_bump_export():
    """A Normal Map (tangent space) on a BSDF's Normal: the material's normal texture and
    strength, the mesh's MikkTSpace tangents (unit, orthogonal to the normals, sign +-1)
    beside its uvs; a Bump from an image's Color: texture, strength, distance, Invert as a
    negative distance; neither warns."""
    image = bpy.data.images.new("Tilt", 2, 2, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    image.pixels.foreach_set([0.75, 0.5, 0.9, 1.0] * 4)
    for kind in ("normal", "bump"):
        material = node_material(f"Mapped-{kind}", "ShaderNodeBsdfDiffuse")
        tree = material.node_tree
        texture = tree.nodes.new("ShaderNodeTexImage")
        texture.image = image
        diffuse = next(node for node in tree.nodes if node.type == 'BSDF_DIFFUSE')
        if kind == "normal":
            node = tree.nodes.new("ShaderNodeNormalMap")
            node.inputs["Strength"].default_value = 0.7
            tree.links.new(texture.outputs["Color"], node.inputs["Color"])
        else:
            node = tree.nodes.new("ShaderNodeBump")
            node.inputs["Strength"].default_value = 0.4
            node.inputs["Distance"].default_value = 0.2
            node.invert = True
            tree.links.new(texture.outputs["Color"], node.inputs["Height"])
        tree.links.new(node.outputs["Normal"], diffuse.inputs["Normal"])
        for obj in list(bpy.data.objects):
            bpy.data.objects.remove(obj)
        _camera()
        cube = add_cube(material=material)
        layer = cube.data.uv_layers.new()
        layer.data.foreach_set("uv", [0, 0, 1, 0, 1, 1, 0, 1] * len(cube.data.polygons))
        data = export()
        assert not data.warnings, data.warnings
        root = _material_of(data)
        if kind == "normal":
            assert root.normal_texture >= 0 and abs(root.normal_strength - 0.7) < 1e-6, root
            t = data.tangents
            assert t is not None and t.shape == (len(data.positions), 4), t
            assert_close(np.linalg.norm(t[:, :3], axis=1), np.ones(len(t)), 1e-5, "unit")
            assert_close(np.sum(t[:, :3] * data.normals, axis=1) if data.normals is not None
                         else np.zeros(len(t)), np.zeros(len(t)), 1e-5, "orthogonal")
            assert set(np.unique(t[:, 3])) <= {-1.0, 1.0}, np.unique(t[:, 3])
        else:
            assert root.bump_texture >= 0 and root.normal_texture < 0, root
            assert abs(root.bump_strength - 0.4) < 1e-6, root
            assert abs(root.bump_distance + 0.2) < 1e-6, root
            assert data.tangents is None


def test_color_attribute_export():
    """A Color Attribute node (the default attribute: sRGB bytes per corner) and an
    Attribute node naming a float point attribute through Multiply with a constant: each
    material flags its attribute (the constant its colour), the corners carry the linear
    colours (sRGB byte 128 is 0.2158605 linear, as Blender decodes it), a mesh without the
    attribute its material reads is black with a warning (as Cycles renders it), and a Mix
    at factor 0.5 falls back with the one warning."""
    _camera()
    painted = add_mesh_object("Painted", [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)],
                              [(0, 1, 2, 3)], material=helpers.color_attribute_material("Col"))
    bytes_ = np.array([[128, 0, 255], [255, 128, 0], [0, 255, 128], [64, 64, 64]]) / 255.0
    helpers.set_corner_colors(painted, "Col", bytes_, srgb=True)
    tinted = add_mesh_object("Tinted", [(2, 0, -1), (4, 0, -1), (4, 0, 1), (2, 0, 1)],
                             [(0, 1, 2, 3)], material=helpers.color_attribute_material(
                                 "Tint", "Paint", multiply=(0.5, 0.25, 1.0)))
    points = np.array([[0.1, 0.2, 0.3], [1.5, 0.5, 0.0], [0.7, 0.8, 0.9], [0.0, 0.0, 2.0]])
    helpers.set_corner_colors(tinted, "Paint", points, domain='POINT', data_type='FLOAT_COLOR')
    data = export()
    assert not data.warnings, data.warnings
    colors = data.colors
    assert colors is not None and colors.shape == (len(data.positions), 3), colors
    by_name = {m.vertex_color: m for m in data.materials if m.vertex_color is not None}
    assert set(by_name) == {"", "Paint"}, data.materials
    assert_close(np.array(by_name["Paint"].color), np.array([0.5, 0.25, 1.0]), 1e-6, "constant")
    assert_close(np.array(by_name[""].color), np.ones(3), 1e-6, "white")

    def srgb_to_linear(c):
        return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)

    # Each corner's colour by its position: corners of the quads' vertices, any triangulation.
    corners = {"Painted": (painted, srgb_to_linear(bytes_)), "Tinted": (tinted, points)}
    for name, (obj, expected) in corners.items():
        vertices = np.array([v.co for v in obj.data.vertices]) + np.array(obj.location)
        # Painted's corners are its loops, which from_pydata numbers as its vertices.
        for corner, position in enumerate(data.positions):
            distances = np.linalg.norm(vertices - position, axis=1)
            if distances.min() < 1e-6:
                assert_close(colors[corner], expected[int(distances.argmin())], 1e-5,
                             f"{name} corner {corner}")
    assert_close(srgb_to_linear(np.array([128 / 255])), np.array([0.2158605]), 1e-6, "decode")

    # The attribute missing: black, with a warning; a half-factor Mix: the fallback warning.
    bpy.data.objects.remove(tinted)
    add_mesh_object("Bare", [(2, 0, -1), (4, 0, -1), (4, 0, 1), (2, 0, 1)], [(0, 1, 2, 3)],
                    material=bpy.data.materials["Tint"])
    add_mesh_object("Half", [(5, 0, -1), (7, 0, -1), (7, 0, 1), (5, 0, 1)], [(0, 1, 2, 3)],
                    material=helpers.color_attribute_material("Half", "", (0.5,) * 3, 0.5))
    data = export()
    assert any("'Bare' has no 'Paint'" in w and "black" in w for w in data.warnings), \
        data.warnings
    assert any("material 'Half'" in w and "Mix" in w for w in data.warnings), data.warnings
    bare = data.positions[:, 0] > 1.5
    bare &= data.positions[:, 0] < 4.5
    assert bare.any() and np.all(data.colors[bare] == 0.0)


def test_beckmann_glass_warns_only_where_it_differs_from_ggx():
    """At roughness 0 every distribution is the same perfect refraction: Blender 3.x's Glass
    BSDF (Beckmann by default) exports without a warning there, and warns once rough."""
    for roughness, warned in ((0.0, False), (0.2, True)):
        glass = node_material(f"Glass{roughness}", "ShaderNodeBsdfGlass", Roughness=roughness)
        for node in glass.node_tree.nodes:
            if node.type == 'BSDF_GLASS':
                node.distribution = 'BECKMANN'
        data = _single(glass)
        expected = [f"material 'Glass{roughness}': Glass BSDF 'Glass BSDF': the Beckmann "
                    "distribution is rendered as GGX"] if warned else []
        assert data.warnings == expected, (roughness, data.warnings)
