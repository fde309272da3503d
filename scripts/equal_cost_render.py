"""One render of the equal-cost harness, inside Blender (scripts/equal_cost.py runs it as its
own process, one at a time; docs/equal_cost.md):

    GLSLPPM_MODULE_DIR=build blender -b --factory-startup --python \\
        scripts/equal_cost_render.py -- --scene caustic --method sppm --count 64 \\
        --seed 1 --size 128 --out DIR/name

builds the scene (scripts/equal_cost_scenes.py), renders it with the method at `count`
passes (glslppm) or samples per pixel (Cycles), and writes DIR/name.npy (linear RGB,
float32, row 0 at the top), DIR/name.png (display-referred, to look at) and DIR/name.json:
the CPU-seconds (user + sys, all threads) this process spent inside the render call and
before it (Blender's start-up, the add-on's registration, building the scene).

Methods: sppm, pppm, vcm (any estimator the add-on's enum holds: scene.glslppm.estimator;
an estimator missing from this build is an error that says so), cycles (caustics on, no
clamping, no filter glossy, 1-pixel box filter, no denoising, no adaptive sampling) and
cycles-mnee (the same plus shadow caustics on the scene's casters, receivers and lights).
A glslppm method may carry settings: "sppm:radius_scale=0.25,photons_per_pass=131072".
"""

import argparse
import importlib
import json
import os
import resource
import sys
import tempfile

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
BOUNCES = 16  # every kind, both engines (glslppm reads scene.cycles' Light Paths)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="equal_cost_render.py")
    parser.add_argument("--scene", required=True)
    parser.add_argument("--method", required=True)
    parser.add_argument("--count", type=int, required=True,
                        help="glslppm passes or Cycles samples per pixel")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--out", required=True, help="output path without extension")
    parser.add_argument("--build-only", action="store_true",
                        help="build the scene and stop (measures start-up alone)")
    return parser.parse_args(argv)


def cpu_seconds():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def register_addon():
    """The add-on from the source tree (as tests/blender/run.py --source does); the
    module comes from GLSLPPM_MODULE_DIR."""
    link_dir = tempfile.mkdtemp(prefix="glslppm-source-")
    os.symlink(os.path.join(REPO, "addon"), os.path.join(link_dir, "glslppm"))
    sys.path.insert(0, link_dir)
    package = importlib.import_module("glslppm")
    package.register()
    return package


def clear_scene(size):
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.lights,
                       bpy.data.cameras, bpy.data.materials, bpy.data.worlds):
        for item in list(collection):
            collection.remove(item)
    scene = bpy.context.scene
    render = scene.render
    render.resolution_x = render.resolution_y = size
    render.resolution_percentage = 100
    render.use_border = False
    render.film_transparent = False
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene.world = None  # black: no environment light in any scene
    cycles = scene.cycles
    for name in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                 "volume_bounces", "transparent_max_bounces"):
        setattr(cycles, name, BOUNCES)
    return scene


def setup_glslppm(scene, estimator, settings, count, seed):
    scene.render.engine = 'GLSLPPM'
    options = scene.glslppm
    estimators = [item.identifier for item in
                  options.bl_rna.properties["estimator"].enum_items]
    if estimator.upper() not in estimators:
        raise SystemExit(f"equal_cost_render: this add-on has no estimator {estimator.upper()} "
                         f"(it has {', '.join(estimators)})")
    options.estimator = estimator.upper()
    options.passes = count
    options.time_limit = 0.0
    options.seed = seed
    for key, value in settings.items():
        setattr(options, key, _setting_value(getattr(options, key), value))


def _setting_value(current, text):
    """A method's setting (--methods sppm:light_tracing=off) as the property's type: bool("off")
    would be True."""
    if isinstance(current, str):
        return text
    if isinstance(current, bool):
        if text.lower() not in ("1", "0", "true", "false", "on", "off", "yes", "no"):
            raise SystemExit(f"equal_cost_render: '{text}' is not on or off")
        return text.lower() in ("1", "true", "on", "yes")
    return type(current)(text)


def setup_cycles(scene, count, seed, mnee):
    scene.render.engine = 'CYCLES'
    cycles = scene.cycles
    cycles.device = 'CPU'
    cycles.samples = count
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    cycles.sample_clamp_direct = cycles.sample_clamp_indirect = 0.0
    cycles.light_sampling_threshold = 0.0
    cycles.caustics_reflective = cycles.caustics_refractive = True
    cycles.blur_glossy = 0.0
    cycles.seed = seed
    cycles.pixel_filter_type = 'BOX'
    cycles.filter_width = 1.0
    scene.render.threads_mode = 'AUTO'
    if mnee:
        for obj in scene.objects:
            role = obj.get("equal_cost_role")
            if role == "caster":
                obj.cycles.is_caustics_caster = True
            elif role == "receiver":
                obj.cycles.is_caustics_receiver = True
            elif obj.type == 'LIGHT' and obj.data.get("equal_cost_caustics_light"):
                obj.data.cycles.is_caustics_light = True


def write_outputs(scene, out):
    """The render as .npy (linear RGB) and .png (display-referred)."""
    settings = scene.render.image_settings
    settings.file_format = 'OPEN_EXR'
    settings.color_depth = '32'
    settings.exr_codec = 'ZIP'
    result = bpy.data.images["Render Result"]
    result.save_render(out + ".exr", scene=scene)
    settings.file_format = 'PNG'
    settings.color_depth = '8'
    result.save_render(out + ".png", scene=scene)
    image = bpy.data.images.load(out + ".exr", check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    os.remove(out + ".exr")
    rgb = pixels.reshape(height, width, 4)[::-1, :, :3]
    np.save(out + ".npy", np.ascontiguousarray(rgb))
    return rgb


def main():
    args = parse_args()
    sys.path.insert(0, HERE)
    import equal_cost_scenes
    name, _, extra = args.method.partition(":")
    settings = dict(item.split("=", 1) for item in extra.split(",") if item)
    glslppm = name not in ("cycles", "cycles-mnee")
    if glslppm:
        register_addon()
    scene = clear_scene(args.size)
    if args.scene not in equal_cost_scenes.SCENES:
        raise SystemExit(f"equal_cost_render: no scene {args.scene!r} "
                         f"({', '.join(equal_cost_scenes.SCENES)})")
    equal_cost_scenes.SCENES[args.scene]()
    if glslppm:
        setup_glslppm(scene, name, settings, args.count, args.seed)
    else:
        setup_cycles(scene, args.count, args.seed, mnee=name == "cycles-mnee")
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    before = cpu_seconds()
    render_seconds = 0.0
    if not args.build_only:
        bpy.ops.render.render()
        render_seconds = cpu_seconds() - before
        rgb = write_outputs(scene, args.out)
        if not np.isfinite(rgb).all():
            raise SystemExit("equal_cost_render: the render holds NaN or Inf")
    record = {"scene": args.scene, "method": args.method, "count": args.count,
              "seed": args.seed, "size": args.size, "render_cpu_s": render_seconds,
              "before_render_cpu_s": before, "blender": bpy.app.version_string}
    with open(args.out + ".json", "w") as f:
        json.dump(record, f, indent=1)
    print(f"equal_cost_render: {json.dumps(record)}", flush=True)


if __name__ == "__main__":
    main()
