"""A Cycles render of glslppm's built-in Cornell box, as an independent reference for
`glslppm-bench converge --cross-check` (or --reference).

    PYTHONPATH=build blender -b --factory-startup --python scripts/cycles_reference.py -- \\
        --out X.exr --size 64 --samples 4096 [--mirror] [--glass]

(Blender 4.x and 5.x read PYTHONPATH only with --python-use-system-env before --python;
checked in Blender 3.4.1 and 5.2.2.)

The scene comes from the module's cornell_box(...).arrays(), so both renderers see the same
triangles, materials and camera: diffuse -> Diffuse BSDF, conductor -> sharp Glossy, dielectric
-> sharp Glass, emission -> one-sided Emission (front faces only, as glslppm's emitters; the
light stays visible to the camera in both). Cycles runs on the CPU, unclamped, without
denoising or adaptive sampling, with a 1-pixel box filter (glslppm jitters uniformly within
each pixel) and glslppm's bounce limit (16). The EXR gets glslppm/ attributes (source=cycles,
scene, samples) that converge reports.
"""

import argparse
import math
import os
import sys
import time

import bpy
import mathutils

import _glslppm

# The add-on's one place for Blender's version differences (it needs only bpy).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "addon"))
import compat  # noqa: E402 - found through the path above


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="cycles_reference.py")
    parser.add_argument("--out", required=True, help="EXR file to write")
    parser.add_argument("--size", type=int, default=64, help="width and height in pixels")
    parser.add_argument("--samples", type=int, default=1024)
    parser.add_argument("--mirror", action="store_true", help="keep the mirror sphere")
    parser.add_argument("--glass", action="store_true", help="keep the glass sphere")
    parser.add_argument("--bounces", type=int, default=16)
    args = parser.parse_args(argv)
    if args.size < 1 or args.samples < 1:
        parser.error("--size and --samples must be positive")
    return args


def make_material(index, spec):
    material = bpy.data.materials.new(f"glslppm_{index}_{spec['kind']}")
    tree = compat.use_nodes(material)
    nodes, links = tree.nodes, tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    color = (*spec["color"], 1.0)
    emission = max(spec["emission"])
    if emission > 0.0:
        # One-sided: front faces emit, back faces are black.
        emit = nodes.new("ShaderNodeEmission")
        emit.inputs["Color"].default_value = (*[c / emission for c in spec["emission"]], 1.0)
        emit.inputs["Strength"].default_value = emission
        black = nodes.new("ShaderNodeBsdfDiffuse")
        black.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        mix = nodes.new("ShaderNodeMixShader")
        geometry = nodes.new("ShaderNodeNewGeometry")
        links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
        links.new(emit.outputs[0], mix.inputs[1])
        links.new(black.outputs[0], mix.inputs[2])
        shader = mix
    elif spec["kind"] == "conductor":
        shader = nodes.new("ShaderNodeBsdfGlossy")
        shader.inputs["Color"].default_value = color
        shader.inputs["Roughness"].default_value = 0.0
    elif spec["kind"] == "dielectric":
        shader = nodes.new("ShaderNodeBsdfGlass")
        shader.inputs["Color"].default_value = color
        shader.inputs["Roughness"].default_value = 0.0
        shader.inputs["IOR"].default_value = spec["ior"]
    else:
        shader = nodes.new("ShaderNodeBsdfDiffuse")
        shader.inputs["Color"].default_value = color
    links.new(shader.outputs[0], output.inputs["Surface"])
    return material


def build_scene(arrays, size):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    positions = [tuple(map(float, p)) for p in arrays["positions"]]
    faces = [tuple(map(int, t)) for t in arrays["indices"]]
    mesh = bpy.data.meshes.new("cornell")
    mesh.from_pydata(positions, [], faces)
    for i, spec in enumerate(arrays["materials"]):
        mesh.materials.append(make_material(i, spec))
    ids = arrays["material_ids"]
    kinds = [arrays["materials"][int(m)]["kind"] for m in ids] if len(ids) else []
    for polygon in mesh.polygons:
        polygon.material_index = int(ids[polygon.index]) if len(ids) else 0
        # Spheres are shaded smooth (glslppm interpolates their vertex normals).
        polygon.use_smooth = bool(kinds) and kinds[polygon.index] != "diffuse"
    mesh.update()
    scene.collection.objects.link(bpy.data.objects.new("cornell", mesh))

    camera = bpy.data.cameras.new("camera")
    camera.sensor_fit = 'HORIZONTAL'
    camera.angle = float(arrays["camera_fov_x"])
    camera.clip_start, camera.clip_end = 1e-3, 1e4
    camera_object = bpy.data.objects.new("camera", camera)
    camera_object.matrix_world = mathutils.Matrix([list(map(float, row))
                                                   for row in arrays["camera_to_world"]])
    scene.collection.objects.link(camera_object)
    scene.camera = camera_object

    world = bpy.data.worlds.new("black")
    compat.use_nodes(world).nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    render = scene.render
    render.resolution_x = render.resolution_y = size
    render.resolution_percentage = 100
    scene.view_settings.view_transform = 'Standard'
    settings = render.image_settings
    settings.file_format = 'OPEN_EXR'
    settings.color_depth = '32'
    settings.exr_codec = 'ZIP'
    return scene


def setup_cycles(scene, samples, bounces):
    scene.render.engine = 'CYCLES'
    cycles = scene.cycles
    cycles.device = 'CPU'
    cycles.samples = samples
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    for name in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces"):
        setattr(cycles, name, bounces)
    cycles.sample_clamp_direct = cycles.sample_clamp_indirect = 0.0
    cycles.light_sampling_threshold = 0.0
    cycles.caustics_reflective = cycles.caustics_refractive = True
    cycles.blur_glossy = 0.0
    cycles.seed = 1
    if hasattr(cycles, "pixel_filter_type"):
        cycles.pixel_filter_type = 'BOX'
    cycles.filter_width = 1.0
    scene.render.threads_mode = 'AUTO'


def main():
    args = parse_args()
    arrays = _glslppm.cornell_box(mirror_sphere=args.mirror, glass_sphere=args.glass).arrays()
    scene = build_scene(arrays, args.size)
    setup_cycles(scene, args.samples, args.bounces)
    out = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    scene.render.filepath = out
    scene.render.use_file_extension = False
    start = time.monotonic()
    bpy.ops.render.render(write_still=True)
    seconds = time.monotonic() - start
    # Rewritten with the module, so that converge finds where the image came from.
    rgba, _ = _glslppm.read_exr(out)
    name = "cornell" if args.mirror and args.glass else \
        "cornell-diffuse" if not (args.mirror or args.glass) else "cornell-partial"
    _glslppm.write_exr(out, rgba, {
        "source": "cycles", "scene": name, "samples": str(args.samples),
        "bounces": str(args.bounces), "seconds": f"{seconds:.2f}",
        "blender": bpy.app.version_string})
    mean = float(rgba[..., :3].mean())
    print(f"cycles_reference: {out}: {args.size}x{args.size}, {args.samples} samples, "
          f"{seconds:.1f} s, mean {mean:.5f}")
    if not math.isfinite(mean):
        sys.exit("cycles_reference: the render holds NaN or Inf")


if __name__ == "__main__":
    main()
