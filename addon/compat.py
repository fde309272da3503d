"""Every difference between the Blender versions the add-on supports (3.4 and 4.x) in
one place: the rest of the add-on asks here instead of testing bpy.app.version."""

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


def set_equirectangular(camera):
    """A panoramic camera with the equirectangular projection: 4.0 moved panorama_type
    from Cycles' camera settings onto the camera."""
    camera.type = 'PANO'
    if BLENDER_4:
        camera.panorama_type = 'EQUIRECTANGULAR'
    else:
        camera.cycles.panorama_type = 'EQUIRECTANGULAR'
