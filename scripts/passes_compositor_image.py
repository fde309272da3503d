"""docs/passes-compositor.png: a glass ball's caustic tinted in the compositor from the
Caustics pass, without rendering again (docs/passes.md). Run from the repository root:

    GLSLPPM_MODULE_DIR=$PWD/build blender -b --factory-startup \
        --python scripts/passes_compositor_image.py

Left: Combined as rendered. Right: the composite (Combined - Caustics) + Caustics x tint.
"""

import os
import sys
import tempfile

import bpy
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "scenes"))
from demo_cornell import shader_material  # noqa: E402 - found through the path above
TINT = (1.0, 0.35, 0.08, 1.0)
SIZE = (320, 240)


def enable_addon():
    link_dir = tempfile.mkdtemp(prefix="glslppm-source-")
    os.symlink(os.path.join(REPO, "addon"), os.path.join(link_dir, "glslppm"))
    sys.path.insert(0, link_dir)
    import glslppm
    glslppm.register()


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
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.02, 0.02, 0.025, 1)
    scene.world = world
    scene.view_layers[0].glslppm.use_pass_light_split = True
    scene.view_layers[0].use_pass_emit = True
    scene.view_layers[0].use_pass_environment = True
    return scene


def tint_caustics(scene):
    """Render Layers -> (Image - Caustics) + Caustics x TINT -> Composite."""
    scene.use_nodes = True
    tree = scene.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    layers = tree.nodes.new("CompositorNodeRLayers")
    rest = tree.nodes.new("CompositorNodeMixRGB")
    rest.blend_type = 'SUBTRACT'
    tree.links.new(layers.outputs["Image"], rest.inputs[1])
    tree.links.new(layers.outputs["Caustics"], rest.inputs[2])
    tinted = tree.nodes.new("CompositorNodeMixRGB")
    tinted.blend_type = 'MULTIPLY'
    tree.links.new(layers.outputs["Caustics"], tinted.inputs[1])
    tinted.inputs[2].default_value = TINT
    total = tree.nodes.new("CompositorNodeMixRGB")
    total.blend_type = 'ADD'
    tree.links.new(rest.outputs[0], total.inputs[1])
    tree.links.new(tinted.outputs[0], total.inputs[2])
    composite = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(total.outputs[0], composite.inputs["Image"])


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
    enable_addon()
    scene = build_scene()
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
    out.filepath_raw = os.path.join(REPO, "docs", "passes-compositor.png")
    out.file_format = 'PNG'
    out.save()
    print("wrote", out.filepath_raw)


main()
