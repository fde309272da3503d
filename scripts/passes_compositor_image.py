"""docs/passes-compositor.png: a glass ball's caustic tinted in the compositor from the
Caustics pass, without rendering again (docs/passes.md). Run from the repository root:

    GLSLPPM_MODULE_DIR=$PWD/build blender -b --factory-startup \
        --python scripts/passes_compositor_image.py [-- --out PNG --passes N]

It runs in every Blender of the test matrix (the compositor through the add-on's compat).

Left: Combined as rendered. Right: the composite (Combined - Caustics) + Caustics x tint.
"""

import argparse
import os
import sys
import tempfile

import bpy
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "demo"))
from cornell_box import shader_material  # noqa: E402 - found through the path above
TINT = (1.0, 0.35, 0.08, 1.0)
compat = None  # the add-on's version differences, once enable_addon() has imported it
SIZE = (320, 240)


def enable_addon():
    link_dir = tempfile.mkdtemp(prefix="glslppm-source-")
    os.symlink(os.path.join(REPO, "addon"), os.path.join(link_dir, "glslppm"))
    sys.path.insert(0, link_dir)
    import glslppm
    glslppm.register()
    global compat
    from glslppm import compat


def build_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = 'GLSLPPM'
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = 'Standard'
    scene.glslppm.passes = 96
    scene.glslppm.photons_per_pass = 131072
    bpy.ops.mesh.primitive_plane_add(size=12)
    bpy.context.object.data.materials.append(
        shader_material("Floor", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0, 0, 0.6), segments=64,
                                         ring_count=32)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(
        shader_material("Glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.0))
    light = bpy.data.lights.new("Spot", 'SPOT')
    light.energy = 3000.0
    light.spot_size = 0.6
    light.shadow_soft_size = 0.05
    spot = bpy.data.objects.new("Spot", light)
    spot.location = (-2.5, 0.0, 3.0)
    spot.rotation_euler = (0.0, -0.69, 0.0)
    scene.collection.objects.link(spot)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (3.2, -3.2, 2.6)
    camera.rotation_euler = (1.08, 0.0, 0.785)
    scene.collection.objects.link(camera)
    scene.camera = camera
    world = bpy.data.worlds.new("World")
    compat.use_nodes(world).nodes["Background"].inputs["Color"].default_value = (0.02, 0.02, 0.025, 1)
    scene.world = world
    scene.view_layers[0].glslppm.use_pass_light_split = True
    scene.view_layers[0].use_pass_emit = True
    scene.view_layers[0].use_pass_environment = True
    return scene


def tint_caustics(scene):
    """Render Layers -> (Image - Caustics) + Caustics x TINT -> the composite."""
    tree, composite = compat.compositor_tree(scene)
    layers = tree.nodes.new("CompositorNodeRLayers")
    _, image, caustics, rest = compat.color_mix_node(tree, 'SUBTRACT')
    tree.links.new(layers.outputs["Image"], image)
    tree.links.new(layers.outputs["Caustics"], caustics)
    _, caustics, tint, tinted = compat.color_mix_node(tree, 'MULTIPLY')
    tree.links.new(layers.outputs["Caustics"], caustics)
    tint.default_value = TINT
    _, first, second, total = compat.color_mix_node(tree, 'ADD')
    tree.links.new(rest, first)
    tree.links.new(tinted, second)
    tree.links.new(total, composite.inputs["Image"])


def render_png(scene, path):
    scene.render.image_settings.file_format = 'PNG'
    scene.render.filepath = path
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(SIZE[1], SIZE[0], 4)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="passes_compositor_image.py")
    parser.add_argument("--out", default=os.path.join(REPO, "docs", "passes-compositor.png"))
    parser.add_argument("--passes", type=int, default=96)
    args = parser.parse_args(argv)
    enable_addon()
    scene = build_scene()
    scene.glslppm.passes = args.passes
    work = tempfile.mkdtemp(prefix="glslppm-passes-doc-")
    scene.render.use_compositing = False
    plain = render_png(scene, os.path.join(work, "combined.png"))
    tint_caustics(scene)
    scene.render.use_compositing = True
    tinted = render_png(scene, os.path.join(work, "tinted.png"))
    gap = np.ones((SIZE[1], 4, 4), dtype=np.float32)
    joined = np.concatenate([plain, gap, tinted], axis=1)
    out = bpy.data.images.new("passes-compositor", joined.shape[1], joined.shape[0])
    out.pixels.foreach_set(joined.ravel())
    out.filepath_raw = os.path.abspath(args.out)
    out.file_format = 'PNG'
    out.save()
    print("wrote", out.filepath_raw)


main()
