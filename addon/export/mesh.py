"""Mesh converter: an evaluated object's triangles read with ``foreach_get`` into numpy.

Triangles keep their three corners unshared (corner = Blender loop), so split and
custom normals and UV seams need no vertex splitting logic: a corner's position,
normal and UV are gathered by its loop index. Geometry stays in object space here;
``transform_geometry`` places it in the world per instance.
"""

from dataclasses import dataclass

import numpy as np

from ..compat import HAS_CORNER_NORMALS


@dataclass
class MeshGeometry:
    """One mesh in object space; corners 3i, 3i+1, 3i+2 make triangle i."""
    positions: np.ndarray        # float32 (3T, 3)
    normals: object              # float32 (3T, 3), or None when every face is flat
    uvs: object                  # float32 (3T, 2) or None
    slot_indices: np.ndarray     # int32 (T,): material slot of each triangle
    tangents: object = None      # float32 (3T, 4): MikkTSpace tangent, bitangent sign; or None
    colors: object = None        # float32 (3T, 3): a colour attribute, linear; or None

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
                            self.slot_indices[keep],
                            None if self.tangents is None else self.tangents[corners],
                            None if self.colors is None else self.colors[corners])


def mesh_geometry(mesh, need_uvs=False, check_cancel=None, need_tangents=False,
                  color_attribute=None):
    """Reads an (evaluated) mesh; returns None for a mesh without faces. check_cancel()
    runs between the steps (each a few tenths of a second for millions of triangles)
    and may raise to stop. need_tangents (normal maps): the render UV map's MikkTSpace
    tangents, as Cycles reads them. color_attribute: the name of a colour attribute to
    read per corner ("" the default one; colors stays None where the mesh has no such
    point or corner colour attribute)."""
    check_cancel = check_cancel or (lambda: None)
    mesh.calc_loop_triangles()
    check_cancel()
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
    check_cancel()

    vertex_positions = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", vertex_positions)
    positions = vertex_positions.reshape(-1, 3)[corner_vertices]
    check_cancel()

    normals = None
    if _needs_normals(mesh):
        normals = _corner_normals(mesh)[corner_loops]
        check_cancel()

    uvs = None
    if need_uvs and mesh.uv_layers.active is not None:
        layer = _render_uv_layer(mesh)
        loop_uvs = np.empty(2 * len(mesh.loops), dtype=np.float32)
        layer.data.foreach_get("uv", loop_uvs)
        uvs = loop_uvs.reshape(-1, 2)[corner_loops]
    tangents = None
    if need_tangents and uvs is not None:
        tangents = _corner_tangents(mesh, _render_uv_layer(mesh), corner_loops)
        made = uv_tangents(positions, normals, uvs)
        if tangents is None:
            tangents = made
        else:
            # Corners whose uvs span nothing get no tangent from Blender (zero or NaN): the
            # renderer refuses those, so they take the made ones.
            bad = ~(np.linalg.norm(tangents[:, :3], axis=1) > 1e-12)
            tangents[bad] = made[bad]
    colors = None
    if color_attribute is not None:
        colors = corner_colors(mesh, color_attribute, corner_loops, corner_vertices)
    return MeshGeometry(positions, normals, uvs, slot_indices, tangents, colors)


def color_attribute_of(mesh, name):
    """The mesh's colour attribute called name ("": the default one, which Cycles renders
    for a Color Attribute node without a name), or None. mesh.color_attributes holds the
    point and corner colours, byte and float, in 3.4 and 4.x alike."""
    colors = mesh.color_attributes
    if name == "":
        name = colors.default_color_name
    attribute = colors.get(name) if name else None
    if attribute is None or attribute.domain not in ('POINT', 'CORNER'):
        return None
    return attribute


def corner_colors(mesh, name, corner_loops, corner_vertices):
    """(3T, 3) float32 linear rgb of a colour attribute at each triangle corner, or None.
    Blender's "color" property is scene linear for byte colours too (their sRGB bytes
    decoded as Blender decodes them); alpha is not read."""
    attribute = color_attribute_of(mesh, name)
    if attribute is None:
        return None
    values = np.empty(4 * len(attribute.data), dtype=np.float32)
    attribute.data.foreach_get("color", values)
    rgb = values.reshape(-1, 4)[:, :3]
    index = corner_loops if attribute.domain == 'CORNER' else corner_vertices
    return np.ascontiguousarray(rgb[index])


def _corner_tangents(mesh, layer, corner_loops):
    """Blender's MikkTSpace tangents per corner (loop.tangent, loop.bitangent_sign; the same
    calls in 3.x and 4.x), or None where Blender cannot make them (faces of more than four
    corners: "Tangent space can only be computed for tris/quads")."""
    try:
        mesh.calc_tangents(uvmap=layer.name)
    except RuntimeError:
        return None
    loop_tangents = np.empty(3 * len(mesh.loops), dtype=np.float32)
    mesh.loops.foreach_get("tangent", loop_tangents)
    signs = np.empty(len(mesh.loops), dtype=np.float32)
    mesh.loops.foreach_get("bitangent_sign", signs)
    mesh.free_tangents()
    tangents = np.concatenate([loop_tangents.reshape(-1, 3), signs[:, None]], axis=1)
    return np.ascontiguousarray(tangents[corner_loops])


def uv_tangents(positions, normals, uvs):
    """Per-triangle tangents (dp/du made orthogonal to each corner's normal, the sign of
    dp/dv against n x t) for corners Blender gave none: what the renderer makes itself from
    the uvs (native/scene/tangent_space.h), here for unshared corners."""
    p = positions.reshape(-1, 3, 3).astype(np.float64)
    w = uvs.reshape(-1, 3, 2).astype(np.float64)
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = w[:, 1] - w[:, 0], w[:, 2] - w[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    safe = np.where(det == 0.0, 1.0, det)[:, None]
    dpdu = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) / safe
    dpdv = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) / safe
    n = (np.repeat(np.cross(e1, e2), 3, axis=0) if normals is None
         else normals.astype(np.float64))
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    dpdu, dpdv = np.repeat(dpdu, 3, axis=0), np.repeat(dpdv, 3, axis=0)
    t = dpdu - n * np.sum(n * dpdu, axis=1, keepdims=True)
    length = np.linalg.norm(t, axis=1, keepdims=True)
    # A corner whose uvs span nothing gets any tangent orthogonal to its normal.
    other = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    fallback = np.cross(n, other)
    fallback /= np.linalg.norm(fallback, axis=1, keepdims=True)
    t = np.where(length > 1e-12, t / np.maximum(length, 1e-30), fallback)
    sign = np.where(np.sum(np.cross(n, t) * dpdv, axis=1) < 0.0, -1.0, 1.0)
    return np.concatenate([t, sign[:, None]], axis=1).astype(np.float32)


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

    Normals transform by the inverse transpose, tangents by the matrix. A mirroring matrix
    (negative determinant) reverses the winding, so corners 1 and 2 swap to keep each
    triangle's geometric normal (counter-clockwise front) facing the same side, and the
    bitangent's sign flips (as Cycles flips it for negatively scaled objects).
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
    uvs, colors = geometry.uvs, geometry.colors
    tangents = None
    if geometry.tangents is not None:
        tangents = geometry.tangents.copy()
        turned = geometry.tangents[:, :3] @ linear.T.astype(np.float32)
        lengths = np.linalg.norm(turned, axis=1, keepdims=True)
        np.divide(turned, lengths, out=turned, where=lengths > 0.0)
        tangents[:, :3] = turned
    if np.linalg.det(linear) < 0.0:
        positions, normals, uvs, tangents, colors = (
            None if corners is None else _swap_corners(corners)
            for corners in (positions, normals, uvs, tangents, colors))
        if tangents is not None:
            tangents[:, 3] = -tangents[:, 3]
    return MeshGeometry(positions, normals, uvs, geometry.slot_indices, tangents, colors)


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
