"""The vector an Image Texture is looked up at, as an affine map of the mesh's UVs or of the
surface's world position.

Blender users tile, turn and shift images with a Mapping node (and Vector Math) between a
Texture Coordinate output (or a UV Map node) and the Image Texture's Vector. Each of these
nodes is affine in its vector input, so the chain is one affine map of its source:

- UV: (u, v, 0); the renderer's uv map is the first two rows of M (u, v, 0, 1) (Flat
  projection reads x and y; z is 0, so any rotation is exact): ``Texture(uv_map=...)``;
- Generated: the object's texture space, Cycles' orco (blender/util.h, mesh_texture_space):
  (p_object - texspace_location) / (2 texspace_size) + 1/2, a component 0 where the size is
  0, which maps the auto texture space (the bounding box) onto [0, 1]^3;
- Object: the position in the object's space, or in the space of the node's Object.

Generated and Object are affine in the world position p (through the object's inverse
transform), so their chain is one map M (p, 1) too, which the renderer applies to the world
position of the surface point: ``Texture(position_map=...)`` (docs/texture_coordinates.md).
The map depends on the object, so a material that reads them is converted once per object
(spaces below); on an instanced mesh (one mesh, many transforms) they are not followed.

Followed, as Cycles evaluates them (svm_mapping.h, svm_vector_math.h):

- Mapping: Point R (v S) + L, Texture R^T (v - L) / S, Vector R (v S), R the XYZ Euler
  rotation Rz Ry Rx; Normal type (it normalizes) is not affine;
- Vector Math: Add, Subtract, Multiply and Multiply Add with a constant factor, Divide by a
  constant (0 where a component is 0, as Cycles' safe_divide), Scale by a constant;
- unlinked sockets are constants; a socket driven by anything else (Value nodes, ...) is not
  followed: the texture is looked up at the mesh's UVs, with a warning naming the node.
"""

import math

import numpy as np

IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
_UV = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
COORDINATE_OUTPUTS = ("Generated", "Object")  # Texture Coordinate outputs read by position


class NotAffine(Exception):
    """A node of the chain that is not an affine map of its source (its message says
    which)."""


class ObjectSpaces:
    """The object a material is converted for: world -> object space and world ->
    Generated (texture space), as 4x4 arrays."""

    def __init__(self, matrix_world, texspace_location, texspace_size):
        self.world_to_object = np.linalg.inv(np.asarray(matrix_world, dtype=np.float64))
        size = np.asarray(texspace_size, dtype=np.float64)
        scale = np.array([0.0 if s == 0.0 else 0.5 / s for s in size])
        generated = np.eye(4)
        generated[:3, :3] = np.diag(scale)
        generated[:3, 3] = 0.5 - np.asarray(texspace_location, dtype=np.float64) * scale
        self.world_to_generated = generated @ self.world_to_object


def object_spaces(obj, matrix_world):
    """ObjectSpaces of a mesh object placed at matrix_world (its mesh's texture space)."""
    data = obj.data
    location = tuple(getattr(data, "texspace_location", (0.0, 0.0, 0.0)))
    size = tuple(getattr(data, "texspace_size", (1.0, 1.0, 1.0)))
    return ObjectSpaces(matrix_world, location, size)


def reads_object_coordinates(material):
    """True when a Texture Coordinate node of the material feeds something from its
    Generated or Object output: its textures' maps depend on the object."""
    tree = getattr(material, "node_tree", None) if material is not None else None
    if tree is None or not getattr(material, "use_nodes", True):
        return False
    return any(node.type == 'TEX_COORD' and any(
        node.outputs[name].is_linked for name in COORDINATE_OUTPUTS if name in node.outputs)
        for node in tree.nodes)


class _Affine:
    """vector = matrix (x, y, z, 1), matrix 3x4, x y z the source's: None (a constant), "uv"
    ((u, v, 0)) or "position" (the world position)."""

    def __init__(self, source, matrix):
        self.source = source
        self.matrix = matrix

    def combine(self, other, matrix):
        if self.source and other.source and self.source != other.source:
            raise NotAffine("its vector mixes UV with Generated or Object coordinates")
        return _Affine(self.source or other.source, matrix)


def texture_map(image_node, warn, render_uv_map=None, spaces=None):
    """("uv", ((a, b, c), (d, e, f))): looked up at (a u + b v + c, d u + e v + f) for mesh
    uv (u, v); or ("position", ((a, b, c, d), (e, f, g, h))): at (a x + b y + c z + d, ...)
    for world position (x, y, z). spaces (ObjectSpaces) is the object the material is
    converted for, None for an instanced mesh. ("uv", IDENTITY) when the Vector is unlinked
    or the chain cannot be followed (warned, naming the node)."""
    socket = image_node.inputs["Vector"]
    if _source(socket)[0] is None:
        return "uv", IDENTITY
    try:
        vector = _vector_of(socket, warn, render_uv_map, spaces)
    except NotAffine as error:
        warn(f"image texture '{image_node.name}': {error}; using the mesh's render UV map")
        return "uv", IDENTITY
    matrix = vector.matrix
    if not np.all(np.isfinite(matrix)):
        warn(f"image texture '{image_node.name}': its Vector is not finite; using the mesh's "
             "render UV map")
        return "uv", IDENTITY
    if vector.source == "position":
        return "position", tuple(tuple(float(x) for x in row) for row in matrix[:2])
    # A constant vector is one texel everywhere: as a uv map it is the constant column.
    return "uv", tuple((float(row[0]), float(row[1]), float(row[3])) for row in matrix[:2])


def _source(socket):
    """(node, output socket) feeding socket through reroutes; a muted node passes its first
    vector input on, as Blender's internal links do. (None, None) when unlinked."""
    while socket is not None and socket.is_linked:
        link = socket.links[0]
        if not link.is_valid or link.is_muted:
            return None, None
        node = link.from_node
        if node.type == 'REROUTE':
            socket = node.inputs[0]
        elif node.mute:
            links = [li for li in node.internal_links if li.to_socket == link.from_socket]
            if not links:
                return None, None
            socket = links[0].from_socket
        else:
            return node, link.from_socket
    return None, None


def _constant(vector):
    matrix = np.zeros((3, 4))
    matrix[:, 3] = [float(c) for c in vector]
    return _Affine(None, matrix)


def _position(node, output, spaces):
    """Texture Coordinate's Generated or Object output as a map of the world position."""
    if output.name == "Object" and getattr(node, "object", None) is not None:
        to_space = np.linalg.inv(np.array(node.object.matrix_world, dtype=np.float64))
    elif spaces is None:
        raise NotAffine(f"Texture Coordinate '{node.name}' {output.name} is not followed on "
                        "instanced meshes, hair, curves and point clouds (UV is)")
    elif output.name == "Object":
        to_space = spaces.world_to_object
    else:
        to_space = spaces.world_to_generated
    return _Affine("position", to_space[:3].copy())


def _vector_of(socket, warn, render_uv_map, spaces):
    """The socket's vector as an _Affine of its source."""
    node, output = _source(socket)
    if node is None:
        value = socket.default_value
        return _constant(tuple(value) if hasattr(value, "__len__") else (value,) * 3)
    if node.type == 'TEX_COORD':
        if output.name == "UV":
            return _Affine("uv", _UV.copy())
        if output.name in COORDINATE_OUTPUTS:
            if getattr(node, "from_instancer", False):
                warn(f"Texture Coordinate '{node.name}': From Instancer is not followed")
            return _position(node, output, spaces)
        raise NotAffine(f"Texture Coordinate '{node.name}' {output.name} is not followed "
                        "(UV, Generated and Object are)")
    if node.type == 'UVMAP':
        if node.uv_map and render_uv_map is not None and node.uv_map != render_uv_map:
            warn(f"UV Map node '{node.name}' reads '{node.uv_map}'; the mesh's render UV map "
                 f"'{render_uv_map}' is used")
        return _Affine("uv", _UV.copy())
    if node.type == 'MAPPING':
        return _mapping(node, _vector_of(node.inputs["Vector"], warn, render_uv_map, spaces))
    if node.type == 'VECT_MATH' and output.name == "Vector":
        return _vector_math(node, warn, render_uv_map, spaces)
    raise NotAffine(f"the {node.bl_label or node.type} node '{node.name}' on its Vector is not "
                    "followed")


def _constant_input(node, name):
    socket = node.inputs.get(name)
    if socket is None:
        return (0.0, 0.0, 0.0)
    if _source(socket)[0] is not None:
        raise NotAffine(f"Mapping node '{node.name}': a linked {name} is not followed")
    return tuple(float(c) for c in socket.default_value)


def euler_xyz(rotation):
    """Blender's XYZ Euler rotation matrix Rz Ry Rx (Cycles' euler_to_transform)."""
    x, y, z = rotation
    cx, sx, cy, sy, cz, sz = (math.cos(x), math.sin(x), math.cos(y), math.sin(y),
                              math.cos(z), math.sin(z))
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def _safe_inverse(values):
    return np.array([0.0 if v == 0.0 else 1.0 / v for v in values])


def _mapping(node, vector):
    """Cycles' svm_mapping of an affine vector."""
    kind = node.vector_type
    if kind == 'NORMAL':
        raise NotAffine(f"Mapping node '{node.name}' of type Normal (it normalizes) is not "
                        "followed")
    rotation = euler_xyz(_constant_input(node, "Rotation"))
    scale = np.array(_constant_input(node, "Scale"))
    if kind == 'TEXTURE':
        location = _constant(_constant_input(node, "Location")).matrix
        return _Affine(vector.source, np.diag(_safe_inverse(scale)) @ rotation.T @
                       (vector.matrix - location))
    result = rotation @ np.diag(scale) @ vector.matrix
    if kind == 'POINT':
        result = result + _constant(_constant_input(node, "Location")).matrix
    return _Affine(vector.source, result)


def _vector_math(node, warn, render_uv_map, spaces):
    operation = node.operation

    def vector(k):  # the k-th Vector input (Scale is the fourth socket)
        return _vector_of(node.inputs[k], warn, render_uv_map, spaces)

    if operation in ('ADD', 'SUBTRACT'):
        a, b = vector(0), vector(1)
        return a.combine(b, a.matrix + b.matrix if operation == 'ADD' else a.matrix - b.matrix)
    if operation in ('MULTIPLY', 'MULTIPLY_ADD'):
        a, b = vector(0), vector(1)
        if a.source is None:
            a, b = b, a
        if b.source is not None:
            raise NotAffine(f"Vector Math node '{node.name}' multiplies two vectors that both "
                            "vary")
        result = _Affine(a.source, np.diag(b.matrix[:, 3]) @ a.matrix)
        if operation == 'MULTIPLY_ADD':
            c = vector(2)
            return result.combine(c, result.matrix + c.matrix)
        return result
    if operation == 'DIVIDE':
        a, b = vector(0), vector(1)
        if b.source is not None:
            raise NotAffine(f"Vector Math node '{node.name}' divides by a vector that varies")
        return _Affine(a.source, np.diag(_safe_inverse(b.matrix[:, 3])) @ a.matrix)
    if operation == 'SCALE':
        scale = node.inputs["Scale"]
        if _source(scale)[0] is not None:
            raise NotAffine(f"Vector Math node '{node.name}': a linked Scale is not followed")
        a = vector(0)
        return _Affine(a.source, float(scale.default_value) * a.matrix)
    raise NotAffine(f"Vector Math node '{node.name}' ({operation.replace('_', ' ').title()}) "
                    "is not affine")
