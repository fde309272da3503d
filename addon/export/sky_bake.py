"""Run by a second Blender (``blender -b --factory-startup --python sky_bake.py --
REQUEST.json``): renders one Sky Texture with Cycles, as export/sky.py asks.

Writes REQUEST's "map" (an equirectangular EXR of the sky without its sun disc, in
the mapping the renderer's environment maps use) and, for a sky with a sun disc,
REQUEST's "sun" (JSON: the disc's irradiance, RGB, measured through a narrow camera
aimed at it as the difference of renders with and without the disc).
"""

import importlib.util
import json
import math
import sys

import bpy
import numpy as np
from mathutils import Vector


def _compat(path):
    spec = importlib.util.spec_from_file_location("glslppm_compat", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _scene(request, compat):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = 'CYCLES'
    cycles = scene.cycles
    cycles.device = 'CPU'
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    cycles.pixel_filter_type = 'BOX'
    cycles.filter_width = 1.0
    scene.view_settings.view_transform = 'Standard'
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.image_settings.color_depth = '32'
    scene.render.use_file_extension = False
    world = bpy.data.worlds.new("Sky")
    tree = compat.use_nodes(world)
    background = next(node for node in tree.nodes if node.type == 'BACKGROUND')
    background.inputs["Strength"].default_value = 1.0
    sky = tree.nodes.new("ShaderNodeTexSky")
    for name, value in request["settings"].items():
        setattr(sky, name, value)
    tree.links.new(sky.outputs["Color"], background.inputs["Color"])
    scene.world = world
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene, sky, camera


def _render(scene, path, width, height, samples):
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.cycles.samples = samples
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path, check_existing=False)
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def main():
    request = json.load(open(sys.argv[sys.argv.index("--") + 1]))
    compat = _compat(request["compat"])
    scene, sky, camera = _scene(request, compat)
    has_disc = request["sun_disc"]
    if has_disc:
        sky.sun_disc = False
    # This rotation makes Cycles' equirectangular camera write the renderer's mapping
    # (u = 0.5 - atan2(y, x) / 2 pi, v up), checked against the Generated coordinates.
    compat.set_equirectangular(camera.data)
    camera.rotation_euler = (math.pi / 2, 0.0, -math.pi / 2)
    width, height = request["size"]
    _render(scene, request["map"], width, height, request["samples"])
    if not has_disc:
        return
    elevation, rotation = sky.sun_elevation, sky.sun_rotation
    to_sun = Vector((math.cos(elevation) * math.sin(rotation),
                     math.cos(elevation) * math.cos(rotation), math.sin(elevation)))
    camera.data.type = 'PERSP'
    camera.data.sensor_fit = 'HORIZONTAL'
    fov = max(3.0 * sky.sun_size, math.radians(0.05))
    camera.data.angle = fov
    camera.rotation_euler = to_sun.to_track_quat('-Z', 'Y').to_euler()
    side = 48
    without = _render(scene, request["map"] + ".off.exr", side, side, 4)
    sky.sun_disc = True
    with_disc = _render(scene, request["map"] + ".on.exr", side, side, 16)
    # Each pixel's solid angle (a small field: the cos^3 falloff is below 1e-4).
    pixel = (2.0 * math.tan(0.5 * fov) / side) ** 2
    irradiance = ((with_disc - without)[..., :3].astype(np.float64).sum(axis=(0, 1)) * pixel)
    json.dump({"irradiance": [max(0.0, float(v)) for v in irradiance],
               "direction": list(to_sun), "angle": float(sky.sun_size)},
              open(request["sun"], "w"))


main()
