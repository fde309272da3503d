"""Mesh converter: an evaluated object's triangles read with ``foreach_get`` into numpy.

Triangles keep their three corners unshared (corner = Blender loop), so split and
custom normals and UV seams need no vertex splitting logic: a corner's position,
normal and UV are gathered by its loop index. Geometry stays in object space here;
``transform_geometry`` places it in the world per instance.
"""

from dataclasses import dataclass

import bpy
import numpy as np

# Blender 4.1 replaced calc_normals_split() and MeshLoop.normal with corner_normals.
HAS_CORNER_NORMALS = bpy.app.version >= (4, 1, 0)


@dataclass
class MeshGeometry:
    """One mesh in object space; corners 3i, 3i+1, 3i+2 make triangle i."""
    positions: np.ndarray        # float32 (3T, 3)
    normals: object              # float32 (3T, 3), or None when every face is flat
    uvs: object                  # float32 (3T, 2) or None
    slot_indices: np.ndarray     # int32 (T,): material slot of each triangle

    @property
    def triangle_count(self):
        return len(self.slot_indices)

    def subset(self, keep):
        """The triangles where keep (T,) is True, or None when none is."""
        if not keep.any():
            return None
        corners = np.repeat(keep, 3)
        return MeshGeometry(self.positions[corners],
                            None if self.normals is None else self.normals[corners],
                            None if self.uvs is None else self.uvs[corners],
                            self.slot_indices[keep])


def mesh_geometry(mesh, need_uvs=False):
    """Reads an (evaluated) mesh; returns None for a mesh without faces."""
    mesh.calc_loop_triangles()
    triangles = mesh.loop_triangles
    count = len(triangles)
    if count == 0:
        return None
    corner_loops = np.empty(3 * count, dtype=np.int32)
    triangles.foreach_get("loops", corner_loops)
    corner_vertices = np.empty(3 * count, dtype=np.int32)
    triangles.foreach_get("vertices", corner_vertices)
    slot_indices = np.empty(count, dtype=np.int32)
    triangles.foreach_get("material_index", slot_indices)

    vertex_positions = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", vertex_positions)
    positions = vertex_positions.reshape(-1, 3)[corner_vertices]

    normals = None
    if _needs_normals(mesh):
        normals = _corner_normals(mesh)[corner_loops]

    uvs = None
    if need_uvs and mesh.uv_layers.active is not None:
        layer = _render_uv_layer(mesh)
        loop_uvs = np.empty(2 * len(mesh.loops), dtype=np.float32)
        layer.data.foreach_get("uv", loop_uvs)
        uvs = loop_uvs.reshape(-1, 2)[corner_loops]
    return MeshGeometry(positions, normals, uvs, slot_indices)


def _needs_normals(mesh):
    """False when every face is flat: the renderer then uses geometric normals."""
    if HAS_CORNER_NORMALS:
        return mesh.normals_domain != 'FACE'
    if mesh.has_custom_normals:
        return True
    smooth = np.empty(len(mesh.polygons), dtype=bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    return bool(smooth.any())


def _corner_normals(mesh):
    """Per-loop normals: split, auto-smooth and custom normals included."""
    normals = np.empty(3 * len(mesh.loops), dtype=np.float32)
    if HAS_CORNER_NORMALS:
        mesh.corner_normals.foreach_get("vector", normals)
    else:
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", normals)
    return normals.reshape(-1, 3)


def _render_uv_layer(mesh):
    for layer in mesh.uv_layers:
        if layer.active_render:
            return layer
    return mesh.uv_layers.active


def transform_geometry(geometry, matrix):
    """World-space copies of positions and normals under a 4x4 object-to-world matrix.

    Normals transform by the inverse transpose. A mirroring matrix (negative
    determinant) reverses the winding, so corners 1 and 2 swap to keep each
    triangle's geometric normal (counter-clockwise front) facing the same side.
    Returns a world-space MeshGeometry.
    """
    matrix = np.asarray(matrix, dtype=np.float64)
    linear = matrix[:3, :3]
    positions = geometry.positions @ linear.T.astype(np.float32)
    positions += matrix[:3, 3].astype(np.float32)
    normals = None
    if geometry.normals is not None:
        try:
            normal_matrix = np.linalg.inv(linear).T
        except np.linalg.LinAlgError:
            normal_matrix = linear
        normals = geometry.normals @ normal_matrix.T.astype(np.float32)
        lengths = np.linalg.norm(normals, axis=1, keepdims=True)
        np.divide(normals, lengths, out=normals, where=lengths > 0.0)
    uvs = geometry.uvs
    if np.linalg.det(linear) < 0.0:
        positions, normals, uvs = (
            None if corners is None else _swap_corners(corners)
            for corners in (positions, normals, uvs))
    return MeshGeometry(positions, normals, uvs, geometry.slot_indices)


def _swap_corners(corners):
    triangles = corners.reshape(-1, 3, corners.shape[1])
    return np.ascontiguousarray(triangles[:, (0, 2, 1)]).reshape(corners.shape)


def face_normals(positions):
    """Geometric normal of each triangle repeated at its three corners (for meshes
    without smooth normals when another mesh in the scene has them)."""
    triangles = positions.reshape(-1, 3, 3)
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    np.divide(normals, lengths, out=normals, where=lengths > 0.0)
    return np.repeat(normals.astype(np.float32), 3, axis=0)
