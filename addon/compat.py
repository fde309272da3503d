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
