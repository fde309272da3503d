"""Issue 30's first scene (a Cornell box built in Blender) rendered by Cycles and by GLSLPPM
through the add-on, one variant at a time, for bisecting their difference
(docs/cornell_vs_cycles.md holds the measured table):

    GLSLPPM_MODULE_DIR=build GLSLPPM_SHADER_DIR=shaders nice blender -b --factory-startup \
        --python scripts/cornell_vs_cycles.py -- --variant base [--variant gap0.05 ...] \
        [--passes 400] [--samples 1024] [--cache /tmp/cornell30] [--gltf FILE.glb]

A variant is a '+'-joined list of changes to the base scene: gapG (the light G below the
ceiling instead of 1 mm), white (white emission instead of warm), area (a square area light
of the same power instead of the emissive quad), photons (direct light from photons),
radiusR (radius scale R), pppm (the PPPM estimator), hidden (the light hidden from the
camera), principled (Principled BSDF walls of roughness 1, which Blender's glTF exporter
keeps; it writes a Diffuse BSDF as its default material: white, metallic 1, roughness 1),
spec0 (with principled: Specular 0), balls (a mirror and a glass ball for the boxes),
glossy (the issue's glossy variant: glossy_objects), and with glossy: frost0 (its frosted
ball smooth), frostglass (the ball a Glass BSDF), frostonly (the frosted ball alone).

Cycles renders twice at half the samples with seeds 1 and 2 (cached under --cache by
variant): their mean is the reference, half their difference the reference's noise. Prints
one line per variant: the image mean ratio GLSLPPM / Cycles, the worst 16x16 region's
relative difference, and Cycles' noise on both. With --gltf, also writes the base and
principled scenes as glTF (Blender's exporter, FILE_<variant>.glb) for `glslppm-render
--scene`; --image compares such a render (an EXR) with the variant's reference.
"""

import argparse
import math
import os
import sys

import bpy
import numpy as np

WHITE = (0.73, 0.73, 0.73)
RED = (0.65, 0.05, 0.05)
GREEN = (0.12, 0.45, 0.15)
WARM = (1.0, 0.78, 0.55)
# The changes that make another scene (and another Cycles reference); the rest are settings.
SCENE_CHANGES = ("white", "area", "hidden", "principled", "spec0", "balls", "glossy",
                 "frost0", "frostglass", "frostonly")


def enable_source_addon():
    """The add-on from this checkout's addon/ (as tests/blender/run.py --source does)."""
    import importlib
    import tempfile
    here = os.path.dirname(os.path.abspath(__file__))
    link_dir = tempfile.mkdtemp(prefix="glslppm-source-")
    os.symlink(os.path.join(here, "..", "addon"), os.path.join(link_dir, "glslppm"))
    sys.path.insert(0, link_dir)
    package = importlib.import_module("glslppm")
    package.register()
    return package


def clear():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.lights, bpy.data.cameras,
                       bpy.data.materials, bpy.data.worlds):
        for item in list(collection):
            collection.remove(item)


def diffuse(name, color, principled=False):
    """A Diffuse BSDF material, or a Principled BSDF of roughness 1 (what glTF can hold)."""
    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # 5.x gives every material a tree, use_nodes deprecated
        material.use_nodes = True
    tree = material.node_tree
    for node in list(tree.nodes):
        if node.type != 'OUTPUT_MATERIAL':
            tree.nodes.remove(node)
    if principled:
        node = tree.nodes.new("ShaderNodeBsdfPrincipled")
        node.inputs["Base Color"].default_value = tuple(color) + (1.0,)
        node.inputs["Roughness"].default_value = 1.0
        node.inputs["Metallic"].default_value = 0.0
        if principled == "spec0":  # 4.x: Specular IOR Level
            name = "Specular" if "Specular" in node.inputs else "Specular IOR Level"
            node.inputs[name].default_value = 0.0
    else:
        node = tree.nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Color"].default_value = tuple(color) + (1.0,)
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def emission(name, color, strength):
    material = diffuse(name, (0, 0, 0))
    tree = material.node_tree
    tree.nodes.remove(next(n for n in tree.nodes if n.type == 'BSDF_DIFFUSE'))
    node = tree.nodes.new("ShaderNodeEmission")
    node.inputs["Color"].default_value = tuple(color) + (1.0,)
    node.inputs["Strength"].default_value = strength
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def mesh_object(name, vertices, faces, material, location=(0, 0, 0), angle=0.0):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in vertices], [], [tuple(f) for f in faces])
    mesh.update()
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    obj.rotation_euler = (0, 0, math.radians(angle))
    bpy.context.scene.collection.objects.link(obj)
    return obj


def box(name, size, height, location, angle, material):
    """A box of size x size x height standing on z = 0, turned angle degrees about z."""
    s = size / 2
    vertices = [(x, y, z) for z in (0, height) for (x, y) in ((-s, -s), (s, -s), (s, s), (-s, s))]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return mesh_object(name, vertices, faces, material, location, angle)


def node_material(name, node_type, **inputs):
    material = diffuse(name, (0, 0, 0))
    tree = material.node_tree
    tree.nodes.remove(next(n for n in tree.nodes if n.type == 'BSDF_DIFFUSE'))
    node = tree.nodes.new(node_type)
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    output = next(n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL')
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def ball(name, location, material, radius=0.15):
    """A smooth-shaded UV sphere of 64 x 32."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=radius,
                                         location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.polygons.foreach_set("use_smooth", [True] * len(obj.data.polygons))
    obj.data.materials.append(material)
    return obj


def frosted_material(changes):
    """The glossy variant's frosted glass: Principled, transmission 1, roughness 0.15 (IOR
    1.45, the node's default); frost0 makes it smooth, frostglass a Glass BSDF of the same
    roughness and IOR."""
    roughness = 0.0 if "frost0" in changes else 0.15
    if "frostglass" in changes:
        return node_material("Frosted", "ShaderNodeBsdfGlass", IOR=1.45, Roughness=roughness)
    transmission = "Transmission" if bpy.app.version < (4, 0, 0) else "Transmission Weight"
    return node_material("Frosted", "ShaderNodeBsdfPrincipled",
                         **{transmission: 1.0, "Roughness": roughness})


def glossy_objects(white, changes=()):
    """The issue's glossy variant: a gold Principled ball (metallic 1, roughness 0.3), a
    frosted glass one (transmission 1, roughness 0.15), a blue plastic Principled box
    (roughness 0.4); the floor a Mix of the white Diffuse and a Glossy 0.2 at factor 0.3.
    frostonly keeps the frosted ball alone on the white floor."""
    ball("Frosted", (0.2, -0.1, 0.15), frosted_material(changes))
    if "frostonly" in changes:
        return
    ball("Gold", (-0.2, 0.15, 0.15), node_material(
        "Gold", "ShaderNodeBsdfPrincipled", **{"Base Color": (1.0, 0.77, 0.34, 1.0),
                                               "Metallic": 1.0, "Roughness": 0.3}))
    box("Plastic", 0.2, 0.2, (0.25, 0.25, 0), 20.0, node_material(
        "Plastic", "ShaderNodeBsdfPrincipled", **{"Base Color": (0.1, 0.2, 0.8, 1.0),
                                                  "Roughness": 0.4}))
    floor = bpy.data.objects["Floor"]
    mixed = node_material("FloorMix", "ShaderNodeMixShader", Fac=0.3)
    tree = mixed.node_tree
    mix = next(n for n in tree.nodes if n.type == 'MIX_SHADER')
    lambert = tree.nodes.new("ShaderNodeBsdfDiffuse")
    lambert.inputs["Color"].default_value = WHITE + (1.0,)
    gloss = tree.nodes.new("ShaderNodeBsdfGlossy")
    gloss.inputs["Roughness"].default_value = 0.2
    tree.links.new(lambert.outputs[0], mix.inputs[1])
    tree.links.new(gloss.outputs[0], mix.inputs[2])
    floor.data.materials[0] = mixed


def build(changes):
    """The unit box open at the front (x, y in [-0.5, 0.5], z in [0, 1], back wall at
    y = 0.5): Diffuse walls, a 0.2 x 0.2 emissive quad of strength 40 facing down 1 mm
    below the ceiling, two turned white boxes; the camera looks in along +y."""
    scene = bpy.context.scene
    p = "spec0" if "spec0" in changes else "principled" in changes
    white, red, green = (diffuse(name, color, p) for name, color in
                         (("White", WHITE), ("Red", RED), ("Green", GREEN)))
    quad = [(0, 1, 2, 3)]
    mesh_object("Floor", [(-.5, -.5, 0), (.5, -.5, 0), (.5, .5, 0), (-.5, .5, 0)], quad, white)
    mesh_object("Ceiling", [(-.5, -.5, 1), (-.5, .5, 1), (.5, .5, 1), (.5, -.5, 1)], quad, white)
    mesh_object("Back", [(-.5, .5, 0), (.5, .5, 0), (.5, .5, 1), (-.5, .5, 1)], quad, white)
    mesh_object("Left", [(-.5, -.5, 0), (-.5, .5, 0), (-.5, .5, 1), (-.5, -.5, 1)], quad, red)
    mesh_object("Right", [(.5, -.5, 0), (.5, -.5, 1), (.5, .5, 1), (.5, .5, 0)], quad, green)
    if "balls" in changes:
        ball("Mirror", (-0.2, 0.15, 0.15), node_material("Mirror", "ShaderNodeBsdfGlossy",
                                                         Roughness=0.0))
        ball("Glass", (0.2, -0.1, 0.15), node_material("Glass", "ShaderNodeBsdfGlass",
                                                       IOR=1.5, Roughness=0.0))
    elif "glossy" in changes:
        glossy_objects(white, changes)
    else:
        box("ShortBox", 0.3, 0.3, (-0.17, -0.1, 0), -17.0, white)
        box("TallBox", 0.3, 0.6, (0.17, 0.15, 0), 17.0, white)

    gap = next((float(c[3:]) for c in changes if c.startswith("gap")), 0.001)
    color = (1.0, 1.0, 1.0) if "white" in changes else WARM
    z = 1.0 - gap
    if "area" in changes:
        # Emission strength 40 W/m^2/sr over 0.04 m^2 from one side: pi L A watts.
        light = bpy.data.lights.new("Light", 'AREA')
        light.shape = 'SQUARE'
        light.size = 0.2
        light.energy = math.pi * 40.0 * 0.04
        light.color = color
        obj = bpy.data.objects.new("Light", light)
        obj.location = (0, 0, z)
        scene.collection.objects.link(obj)
        obj.visible_camera = "hidden" not in changes
    else:
        s = 0.1
        obj = mesh_object("Light", [(-s, -s, z), (-s, s, z), (s, s, z), (s, -s, z)], quad,
                          emission("Emitter", color, 40.0))
        obj.visible_camera = "hidden" not in changes

    camera = bpy.data.cameras.new("Camera")
    camera.lens = 50.0
    camera_object = bpy.data.objects.new("Camera", camera)
    camera_object.location = (0, -1.9, 0.5)
    camera_object.rotation_euler = (math.pi / 2, 0, 0)
    scene.collection.objects.link(camera_object)
    scene.camera = camera_object
    scene.world = None
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    for owner in (scene.cycles, scene.glslppm):
        owner.max_bounces = owner.diffuse_bounces = 64
        owner.glossy_bounces = owner.transmission_bounces = 64
    return scene


def render(path, engine):
    scene = bpy.context.scene
    scene.render.engine = engine
    settings = scene.render.image_settings
    settings.file_format = 'OPEN_EXR'
    settings.color_depth = '32'
    settings.exr_codec = 'ZIP'
    scene.render.filepath = path
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path, check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)[::-1, :, :3].astype(np.float64)


def cycles_reference(key, samples, cache):
    """Mean and half difference of two Cycles renders (seeds 1, 2) of samples / 2 each."""
    images = []
    for seed in (1, 2):
        path = os.path.join(cache, f"{key}_cycles{samples}_seed{seed}.exr")
        if not os.path.exists(path):
            cycles = bpy.context.scene.cycles
            cycles.device = 'CPU'
            cycles.samples = samples // 2
            cycles.use_denoising = False
            cycles.use_adaptive_sampling = False
            cycles.sample_clamp_direct = cycles.sample_clamp_indirect = 0.0
            cycles.light_sampling_threshold = 0.0
            cycles.caustics_reflective = cycles.caustics_refractive = True
            cycles.blur_glossy = 0.0
            cycles.pixel_filter_type = 'BOX'
            cycles.filter_width = 1.0
            cycles.seed = seed
            render(path, 'CYCLES')
        image = bpy.data.images.load(path, check_existing=False)
        pixels = np.empty(64 * 64 * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
        images.append(pixels.reshape(64, 64, 4)[::-1, :, :3].astype(np.float64))
    return (images[0] + images[1]) / 2, (images[0] - images[1]) / 2


def regions(image, size=16):
    h, w = image.shape[:2]
    return image.reshape(h // size, size, w // size, size, 3).mean(axis=(1, 3, 4))


def compare(name, ours, reference, noise):
    """The image means' ratio, that of the light's own pixels (Cycles above 1: the emitter
    seen by the camera) and of the rest, and the worst 16x16 region's relative difference."""
    ratio = ours.mean() / reference.mean()
    a, b, n = regions(ours), regions(reference), regions(noise)
    worst = float(np.abs(a / b - 1).max())
    light = reference.mean(axis=2) > 1.0
    split = ours[light].sum() / reference[light].sum() if light.any() else float("nan")
    rest = ours[~light].mean() / reference[~light].mean()
    print(f"RESULT {name}: mean ratio {ratio:.4f} (Cycles noise "
          f"{abs(noise.mean()) / reference.mean():.4f}; light's pixels {split:.4f}, "
          f"rest {rest:.4f}), worst 16x16 region {worst:.4f} "
          f"(Cycles noise {float(np.abs(n / b).max()):.4f}); "
          f"regions ratio {np.round(a / b, 3).tolist()}", flush=True)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="cornell_vs_cycles.py")
    parser.add_argument("--variant", action="append", default=[])
    parser.add_argument("--passes", type=int, default=400)
    parser.add_argument("--photons", type=int, default=65536)
    parser.add_argument("--samples", type=int, default=1024)
    parser.add_argument("--seed", type=int, action="append", default=[],
                        help="GLSLPPM's seed (repeatable: one render per seed)")
    parser.add_argument("--cache", default="/tmp/cornell30")
    parser.add_argument("--gltf", default=None)
    parser.add_argument("--no-glslppm", action="store_true")
    parser.add_argument("--image", action="append", default=[],
                        help="an EXR (glslppm-render's) to compare with the variant's reference "
                             "instead of rendering")
    args = parser.parse_args(argv)
    os.makedirs(args.cache, exist_ok=True)
    enable_source_addon()
    for variant in args.variant or ["base"]:
        changes = [c for c in variant.split("+") if c != "base"]
        clear()
        scene = build(changes)
        cycles_changes = sorted(c for c in changes if c.startswith("gap") or c in SCENE_CHANGES)
        key = "+".join(cycles_changes) or "base"
        reference, noise = cycles_reference(key, args.samples, args.cache)
        if args.gltf and changes in ([], ["principled"], ["principled", "spec0"]):
            gltf = args.gltf.replace(".glb", f"_{key}.glb")
            bpy.ops.export_scene.gltf(filepath=gltf, export_format='GLB',
                                      export_cameras=True, export_lights=True)
        for path in args.image:
            image = bpy.data.images.load(os.path.abspath(path), check_existing=False)
            pixels = np.empty(64 * 64 * 4, dtype=np.float32)
            image.pixels.foreach_get(pixels)
            bpy.data.images.remove(image)
            compare(f"{variant} {os.path.basename(path)}",
                    pixels.reshape(64, 64, 4)[::-1, :, :3].astype(np.float64), reference, noise)
        if args.no_glslppm or args.image:
            continue
        scene.glslppm.passes = args.passes
        scene.glslppm.photons_per_pass = args.photons
        scene.glslppm.direct_light = 'PHOTONS' if "photons" in changes else 'SAMPLED'
        radius = next((float(c[6:]) for c in changes if c.startswith("radius")), 1.0)
        scene.glslppm.radius_scale = radius
        scene.glslppm.estimator = 'PPPM' if "pppm" in changes else 'SPPM'
        for seed in args.seed or [None]:
            suffix = "" if seed is None else f"_seed{seed}"
            if seed is not None:
                scene.glslppm.seed = seed
            name = f"{variant}_glslppm{args.passes}_{args.photons}{suffix}.exr"
            ours = render(os.path.join(args.cache, name), 'GLSLPPM')
            compare(variant + suffix, ours, reference, noise)


if __name__ == "__main__":
    main()
