"""Every difference between the Blender versions the add-on supports (3.4, 4.x and 5.x) in
one place: the rest of the add-on (and its tests) asks here instead of testing
bpy.app.version."""

import bpy

VERSION = bpy.app.version

# 4.0: RenderPass.rect.foreach_set wants a flat buffer (3.x: (pixels, 4)); Cycles' area
# light and spot light conventions changed (export/light.py).
BLENDER_4 = VERSION >= (4, 0, 0)
FLAT_RECT = BLENDER_4

# 4.0 spelled the render passes out: "Emit" -> "Emission", "Env" -> "Environment" (the
# module's render_passes() gives both names).
PASS_NAME_KEY = "blender" if BLENDER_4 else "blender_3x"

# 4.1 replaced calc_normals_split() and MeshLoop.normal with Mesh.corner_normals.
HAS_CORNER_NORMALS = VERSION >= (4, 1, 0)

# An object without a material: Cycles renders Blender's default surface, a diffuse 0.8 grey
# up to 4.x and from 5.0 what a new material is, a default Principled BSDF (measured: the same
# pixels in Cycles 5.2; 5% darker than the diffuse grey seen at 60 degrees).
DEFAULT_SURFACE_IS_PRINCIPLED = VERSION >= (5, 0, 0)

# Cycles' shadow terminator term for bump and normal maps: Chiang 2019 up to 4.x, Conty
# Estevez 2021 from 5.0 (the module's Settings bump_shadowing; shaders/common/lobes.glsl).
BUMP_SHADOWING = "conty2021" if VERSION >= (5, 0, 0) else "chiang2019"

# 5.0 deprecated use_nodes on materials, lights, worlds and scenes (it always reads True
# and 6.0 removes it): a datablock with a node tree renders with it.
BLENDER_5 = VERSION >= (5, 0, 0)
USE_NODES_DEPRECATED = BLENDER_5


def node_tree(datablock):
    """The node tree a material, light or world renders with, or None: 3.x and 4.x use it
    only while use_nodes is on; 5.x always (use_nodes is not read there)."""
    tree = getattr(datablock, "node_tree", None)
    if tree is None or USE_NODES_DEPRECATED:
        return tree
    return tree if getattr(datablock, "use_nodes", False) else None


def set_equirectangular(camera):
    """A panoramic camera with the equirectangular projection: 4.0 moved panorama_type
    from Cycles' camera settings onto the camera."""
    camera.type = 'PANO'
    if BLENDER_4:
        camera.panorama_type = 'EQUIRECTANGULAR'
    else:
        camera.cycles.panorama_type = 'EQUIRECTANGULAR'


# The sky type a new Sky Texture gets: 5.0 split Nishita into 'SINGLE_SCATTERING' and
# 'MULTIPLE_SCATTERING' (the default) and renamed its dust_density to aerosol_density.
DEFAULT_SKY_TYPE = 'MULTIPLE_SCATTERING' if BLENDER_5 else 'NISHITA'
PHYSICAL_SKY_TYPES = ('SINGLE_SCATTERING', 'MULTIPLE_SCATTERING') if BLENDER_5 else ('NISHITA',)


def set_exr_format(image_settings, multilayer=False):
    """32-bit OpenEXR, one layer or every pass (multi-layer): 5.x chooses the kind by
    media_type first ('OPEN_EXR_MULTILAYER' is refused while it is 'IMAGE')."""
    if BLENDER_5:
        image_settings.media_type = 'MULTI_LAYER_IMAGE' if multilayer else 'IMAGE'
    image_settings.file_format = 'OPEN_EXR_MULTILAYER' if multilayer else 'OPEN_EXR'
    image_settings.color_depth = '32'


def compositor_tree(scene):
    """(tree, output): an empty compositor node tree of the scene and the node whose
    "Image" input is the composited image. 3.x/4.x: scene.node_tree (use_nodes) and a
    Composite node; 5.x: a new tree in scene.compositing_node_group and its Group Output
    with an Image socket (the Composite node is gone)."""
    scene.render.use_compositing = True
    if BLENDER_5:
        tree = bpy.data.node_groups.new("Compositor", "CompositorNodeTree")
        scene.compositing_node_group = tree
        tree.interface.new_socket("Image", in_out='OUTPUT', socket_type='NodeSocketColor')
        return tree, tree.nodes.new("NodeGroupOutput")
    scene.use_nodes = True
    tree = scene.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    return tree, tree.nodes.new("CompositorNodeComposite")


def color_mix_node(tree, blend_type):
    """(node, a, b, result): a compositor node that mixes colour a with b by blend_type
    ('ADD', 'SUBTRACT', 'MULTIPLY', ...) at factor 1. 3.x/4.x: a MixRGB node; 5.x removed
    it from the compositor for the shared Mix node, whose colour sockets are its 'A' and 'B'
    of type RGBA (its Factor defaults to 0.5)."""
    if BLENDER_5:
        node = tree.nodes.new("ShaderNodeMix")
        node.data_type = 'RGBA'
        node.blend_type = blend_type
        node.inputs["Factor"].default_value = 1.0
        a, b = (next(s for s in node.inputs if s.name == name and s.type == 'RGBA')
                for name in ("A", "B"))
        result = next(s for s in node.outputs if s.type == 'RGBA')
        return node, a, b, result
    node = tree.nodes.new("CompositorNodeMixRGB")
    node.blend_type = blend_type
    return node, node.inputs[1], node.inputs[2], node.outputs[0]


def file_output_node(tree, directory, names):
    """A File Output node that writes one single-layer 32-bit EXR per name into directory,
    each file's name starting with its input's name; its inputs are named as `names`.
    5.x replaced base_path and file_slots with directory, file_name and
    file_output_items."""
    node = tree.nodes.new("CompositorNodeOutputFile")
    set_exr_format(node.format)
    if BLENDER_5:
        node.directory = directory
        node.file_name = ""
        node.file_output_items.clear()
        for name in names:
            node.file_output_items.new('RGBA', name)
    else:
        node.base_path = directory
        node.file_slots.clear()
        for name in names:
            node.file_slots.new(name)
    return node


def use_nodes(datablock):
    """Makes a new material, light or world render with its node tree: 3.x/4.x turn
    use_nodes on (creating the tree); 5.x gives every one a tree and deprecates the
    switch."""
    if not USE_NODES_DEPRECATED:
        datablock.use_nodes = True
    return datablock.node_tree


# Motion blur's settings (docs/motion_blur.md): the shutter's position is Cycles'
# (scene.cycles.motion_blur_position) on 3.4, and scene.render's where a version has it there;
# the per-object switch and steps are the object's own where it has them, else Cycles'
# (object.cycles, 3.4). Looked up by name rather than version: only 3.4 is measured here
# (tests/blender/test_motion_blur.py), 4.x and 5.x not yet.
def motion_blur_position(scene):
    """'START', 'CENTER' or 'END': where the shutter sits around the frame."""
    for owner in (scene.render, getattr(scene, "cycles", None)):
        position = getattr(owner, "motion_blur_position", None)
        if position is not None:
            return position
    return 'CENTER'


def object_motion_blur(obj):
    """(use motion blur, Blender's motion steps) for an object; (True, 1) where unset."""
    for owner in (obj, getattr(obj, "cycles", None)):
        if owner is not None and hasattr(owner, "use_motion_blur"):
            return bool(owner.use_motion_blur), max(1, int(getattr(owner, "motion_steps", 1)))
    return True, 1
