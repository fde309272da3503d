"""Hair (particle hair on meshes), Curves objects and point clouds as triangles: each
curve segment a six-sided tube of the curve's radius, each point an icosahedron, with
smooth (radial) normals so they shade as the round tubes and spheres Cycles renders.

The tube's and icosahedron's sizes are chosen so that their mean projected area (a
convex body's surface area / 4, Cauchy's formula) equals the round shape's: a six-sided
tube of circumradius R has mean width 6R/pi, so R = (pi/3) r; an icosahedron of
circumradius R has area 9.574 R^2, so R = sqrt(pi / 2.3936) r. Coverage and the light
caught then match Cycles' on average over directions.

Positions arrive in world space; every strand and point counts against a triangle
budget (Render Properties > Photons > Curve Triangle Limit), warned once when reached.
"""

import math

import numpy as np

SIDES = 6
TUBE_SCALE = math.pi / 3.0
SPHERE_SCALE = math.sqrt(math.pi / (5.0 * math.sqrt(3.0) * (1.0 / math.sin(0.4 * math.pi)) ** 2
                                    / 4.0))
TRIANGLES_PER_SEGMENT = 2 * SIDES
# Radius when a Curves object or point cloud has no radius attribute.
DEFAULT_RADIUS = 0.01


class TriangleBudget:
    def __init__(self, limit, warn):
        self.left = limit
        self.limit = limit
        self._warn = warn
        self.dropped = 0

    def take(self, wanted, name):
        """How many of `wanted` triangles may be added (all, some or none)."""
        granted = max(0, min(wanted, self.left))
        self.left -= granted
        if granted < wanted:
            self.dropped += wanted - granted
            self._warn(f"hair, curves and points reached the Curve Triangle Limit "
                       f"({self.limit:,} triangles) at object '{name}'; the rest are left "
                       "out (Render Properties > Photons > Curve Triangle Limit)")
        return granted


def tube_triangles(points, radii, first, counts):
    """Triangles of the polylines points[first[i] : first[i] + counts[i]] (world space,
    (N, 3)) with per-point radii (N,): (positions (3T, 3), normals (3T, 3)) float32."""
    starts = []
    for begin, count in zip(first, counts):
        if count >= 2:
            starts.append(np.arange(begin, begin + count - 1))
    if not starts:
        return None
    a = np.concatenate(starts)
    p0, p1 = points[a].astype(np.float64), points[a + 1].astype(np.float64)
    r0, r1 = radii[a] * TUBE_SCALE, radii[a + 1] * TUBE_SCALE
    axis = p1 - p0
    length = np.linalg.norm(axis, axis=1)
    keep = length > 0.0
    p0, p1, r0, r1, axis, length = p0[keep], p1[keep], r0[keep], r1[keep], axis[keep], \
        length[keep]
    if len(p0) == 0:
        return None
    t = axis / length[:, None]
    # A perpendicular from whichever world axis is least aligned with the segment.
    helper = np.zeros_like(t)
    helper[np.arange(len(t)), np.argmin(np.abs(t), axis=1)] = 1.0
    u = np.cross(t, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(t, u)
    angles = 2.0 * math.pi * np.arange(SIDES + 1) / SIDES
    # (S, K+1, 3): the outward direction at each angle around each segment.
    out = (np.cos(angles)[None, :, None] * u[:, None, :] +
           np.sin(angles)[None, :, None] * v[:, None, :])
    ring0 = p0[:, None, :] + r0[:, None, None] * out
    ring1 = p1[:, None, :] + r1[:, None, None] * out
    k = np.arange(SIDES)
    corners = np.stack([ring0[:, k], ring0[:, k + 1], ring1[:, k + 1],
                        ring0[:, k], ring1[:, k + 1], ring1[:, k]], axis=2)
    normals = np.stack([out[:, k], out[:, k + 1], out[:, k + 1],
                        out[:, k], out[:, k + 1], out[:, k]], axis=2)
    return (np.ascontiguousarray(corners.reshape(-1, 3), dtype=np.float32),
            np.ascontiguousarray(normals.reshape(-1, 3), dtype=np.float32))


def _icosahedron():
    g = (1.0 + math.sqrt(5.0)) / 2.0
    vertices = np.array([(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g),
                         (0, -1, -g), (0, 1, -g), (g, 0, -1), (g, 0, 1), (-g, 0, -1),
                         (-g, 0, 1)], dtype=np.float64)
    vertices /= np.linalg.norm(vertices, axis=1, keepdims=True)
    faces = np.array([(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9),
                      (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2),
                      (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
                      (8, 6, 7), (9, 8, 1)])
    return vertices[faces.ravel()]  # (60, 3) unit directions, counter-clockwise outside


ICOSAHEDRON = _icosahedron()
TRIANGLES_PER_POINT = len(ICOSAHEDRON) // 3


def sphere_triangles(centres, radii):
    """Triangles of spheres at centres (N, 3) with radii (N,): (positions, normals)."""
    if len(centres) == 0:
        return None
    directions = np.broadcast_to(ICOSAHEDRON, (len(centres),) + ICOSAHEDRON.shape)
    positions = centres[:, None, :] + (radii * SPHERE_SCALE)[:, None, None] * directions
    return (np.ascontiguousarray(positions.reshape(-1, 3), dtype=np.float32),
            np.ascontiguousarray(directions.reshape(-1, 3), dtype=np.float32))


def _attribute(data, name, width, count):
    attribute = data.attributes.get(name)
    if attribute is None or len(attribute.data) != count:
        return None
    values = np.empty(count * width, dtype=np.float32)
    attribute.data.foreach_get("vector" if width == 3 else "value", values)
    return values.reshape(count, width) if width > 1 else values


def _world(points, matrix):
    matrix = np.asarray(matrix, dtype=np.float64)
    scale = abs(np.linalg.det(matrix[:3, :3])) ** (1.0 / 3.0)
    return points @ matrix[:3, :3].T + matrix[:3, 3], scale


def curves_object(obj, matrix, budget, warn):
    """Triangles (positions, normals) of a Curves object's strands (control points as a
    polyline) under matrix_world, or None."""
    data = obj.data
    count = len(data.points)
    if count == 0 or len(data.curves) == 0:
        return None
    positions = _attribute(data, "position", 3, count)
    radii = _attribute(data, "radius", 1, count)
    if radii is None:
        radii = np.full(count, DEFAULT_RADIUS, dtype=np.float32)
    first = np.empty(len(data.curves), dtype=np.int32)
    data.curves.foreach_get("first_point_index", first)
    counts = np.empty(len(data.curves), dtype=np.int32)
    data.curves.foreach_get("points_length", counts)
    points, scale = _world(positions.astype(np.float64), matrix)
    return _budgeted_tubes(points, radii * scale, first, counts, budget, obj.name)


def _budgeted_tubes(points, radii, first, counts, budget, name):
    segments = np.maximum(counts - 1, 0)
    wanted = int(segments.sum()) * TRIANGLES_PER_SEGMENT
    granted = budget.take(wanted, name)
    if granted < wanted:
        keep = np.cumsum(segments) * TRIANGLES_PER_SEGMENT <= granted
        first, counts = first[keep], counts[keep]
    return tube_triangles(points, radii, first, counts)


def point_cloud(obj, matrix, budget, warn):
    """Triangles of a point cloud's points as spheres under matrix_world, or None."""
    data = obj.data
    count = len(data.points)
    if count == 0:
        return None
    positions = _attribute(data, "position", 3, count)
    radii = _attribute(data, "radius", 1, count)
    if radii is None:
        radii = np.full(count, DEFAULT_RADIUS, dtype=np.float32)
    centres, scale = _world(positions.astype(np.float64), matrix)
    granted = budget.take(count * TRIANGLES_PER_POINT, obj.name) // TRIANGLES_PER_POINT
    return sphere_triangles(centres[:granted], radii[:granted].astype(np.float64) * scale)


def hair_systems(obj, depsgraph_mode, budget, warn):
    """[(material slot index, (positions, normals))] for the particle hair systems of an
    evaluated mesh object: each strand's cached path (world space) as tubes, its width
    going from root to tip diameter (times Diameter Scale) as Cycles' hair does."""
    out = []
    for system in obj.particle_systems:
        settings = system.settings
        if settings.type != 'HAIR' or settings.render_type != 'PATH':
            continue
        steps = 2 ** (settings.render_step if depsgraph_mode == 'RENDER'
                      else settings.display_step)
        parents = len(system.particles)
        children = len(system.child_particles)
        if children and settings.child_type != 'NONE':
            strands = list(range(parents, parents + children))
            if getattr(settings, "use_parent_particles", False):
                strands = list(range(parents)) + strands
        else:
            strands = list(range(parents))
        if not strands:
            continue
        wanted = len(strands) * steps * TRIANGLES_PER_SEGMENT
        granted = budget.take(wanted, obj.name)
        strands = strands[:granted // (steps * TRIANGLES_PER_SEGMENT)]
        points = np.array([tuple(system.co_hair(obj, particle_no=i, step=k))
                           for i in strands for k in range(steps + 1)], dtype=np.float64)
        if len(points) == 0:
            continue
        fraction = np.tile(np.linspace(0.0, 1.0, steps + 1), len(strands))
        # Blender names these diameters (Root Diameter, Tip Diameter, Diameter Scale).
        scale = 0.5 * settings.radius_scale
        radii = scale * (settings.root_radius +
                         (settings.tip_radius - settings.root_radius) * fraction)
        first = np.arange(len(strands), dtype=np.int32) * (steps + 1)
        counts = np.full(len(strands), steps + 1, dtype=np.int32)
        triangles = tube_triangles(points, radii, first, counts)
        if triangles is not None:
            out.append((max(0, settings.material - 1), triangles))
    return out
