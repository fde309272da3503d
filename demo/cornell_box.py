"""The demo scene: a Cornell box with a glass sphere, a mirror sphere and a ceiling
area light, built from scratch with bpy. The Blender tests import
``build_cornell_box`` for their diffuse box, scripts ``shader_material``.

Render it (what `make demo` does):

    blender -b --factory-startup --python demo/cornell_box.py -- \
        --out out/demo --size 512 --passes 256 [--save out/demo.blend]

writes out/demo.png (display-referred, through Blender's colour management) and
out/demo.exr (linear), using the GLSLPPM engine.
"""

import argparse
import math
import os
import sys

import bpy

WHITE = (0.75, 0.75, 0.75)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)


def _diffuse(name, color):
    material = shader_material(name, "ShaderNodeBsdfDiffuse", Color=tuple(color) + (1.0,))
    material.diffuse_color = tuple(color) + (1.0,)
    return material


def shader_material(name, node_type, **inputs):
    """A material whose Surface is one shader node with these inputs (Blender's names);
    scripts/passes_compositor_image.py builds its materials with it too."""
    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # 5.x gives every material a tree, use_nodes deprecated
        material.use_nodes = True
    tree = material.node_tree
    for node in list(tree.nodes):
        if node.type != 'OUTPUT_MATERIAL':
            tree.nodes.remove(node)
    shader = tree.nodes.new(node_type)
    for key, value in inputs.items():
        shader.inputs[key].default_value = value
    output = next(node for node in tree.nodes if node.type == 'OUTPUT_MATERIAL')
    tree.links.new(shader.outputs[0], output.inputs["Surface"])
    return material


def quad(name, corners, material):
    """One quad object, corners counter-clockwise seen from its front (inside the box);
    demo/showcase.py builds its table with it too."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(c) for c in corners], [], [(0, 1, 2, 3)])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def sphere(name, location, radius, material, segments=48):
    """A smooth-shaded UV sphere of `segments` x segments/2 (demo/showcase.py's balls too)."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=segments // 2,
                                         radius=radius, location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.polygons.foreach_set("use_smooth", [True] * len(obj.data.polygons))
    obj.data.materials.append(material)
    return obj


def build_cornell_box(glass=True, mirror=True, light_power=40.0, lens=38.0):
    """The box spans x -1..1, y -1..1 (back wall at y = 1), z 0..2; the camera looks
    in along +y through the open front. Returns the scene."""
    scene = bpy.context.scene
    white, red, green = _diffuse("White", WHITE), _diffuse("Red", RED), _diffuse("Green", GREEN)
    quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    quad("Ceiling", [(-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)], white)
    quad("Back", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    quad("Left", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    quad("Right", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)

    light = bpy.data.lights.new("CeilingLight", 'AREA')
    light.shape = 'SQUARE'
    light.size = 0.5
    light.energy = light_power
    light_object = bpy.data.objects.new("CeilingLight", light)
    light_object.location = (0, 0, 1.98)
    light_object.visible_camera = True  # lights are hidden from the camera by default
    scene.collection.objects.link(light_object)

    if glass:
        sphere("GlassSphere", (0.45, -0.25, 0.35), 0.35,
                shader_material("Glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.0))
    if mirror:
        sphere("MirrorSphere", (-0.45, 0.35, 0.4), 0.4,
                shader_material("Mirror", "ShaderNodeBsdfGlossy", Roughness=0.0,
                                Color=(0.95, 0.95, 0.95, 1.0)))

    camera = bpy.data.cameras.new("Camera")
    camera.lens = lens
    camera_object = bpy.data.objects.new("Camera", camera)
    camera_object.location = (0, -3.6, 1.0)
    camera_object.rotation_euler = (math.pi / 2, 0, 0)
    scene.collection.objects.link(camera_object)
    scene.camera = camera_object
    scene.world = None
    return scene


def _clear():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.lights, bpy.data.cameras,
                       bpy.data.materials):
        for item in list(collection):
            collection.remove(item)


def enable_addon():
    """The GLSLPPM engine, unless registered already: the legacy add-on (3.x) or the
    extension (4.2+); demo/showcase.py uses it too."""
    import addon_utils
    registered = {getattr(engine, "bl_idname", "")
                  for engine in bpy.types.RenderEngine.__subclasses__()
                  if getattr(engine, "is_registered", False)}
    if 'GLSLPPM' not in registered:
        for name in ("glslppm", "bl_ext.user_default.glslppm"):
            if addon_utils.enable(name, default_set=True) is not None:
                break


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="cornell_box.py")
    parser.add_argument("--out", default="out/demo")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--passes", type=int, default=256)
    parser.add_argument("--photons", type=int, default=65536)
    parser.add_argument("--time-limit", type=float, default=0.0)
    parser.add_argument("--save", default=None, help="also save the scene as .blend")
    args = parser.parse_args(argv)

    enable_addon()
    _clear()
    scene = build_cornell_box()
    scene.render.engine = 'GLSLPPM'
    scene.render.resolution_x = scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    scene.glslppm.passes = args.passes
    scene.glslppm.photons_per_pass = args.photons
    scene.glslppm.time_limit = args.time_limit
    scene.view_settings.view_transform = 'Standard'
    out = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    if args.save:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save), copy=True)

    bpy.ops.render.render()
    result = bpy.data.images["Render Result"]
    png = scene.render.image_settings
    png.file_format = 'PNG'
    png.color_depth = '8'
    result.save_render(out + ".png", scene=scene)
    exr = scene.render.image_settings
    exr.file_format = 'OPEN_EXR'
    exr.color_depth = '32'
    result.save_render(out + ".exr", scene=scene)
    print(f"demo: wrote {out}.png and {out}.exr")


if __name__ == "__main__":
    main()
