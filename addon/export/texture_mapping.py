"""The vector an Image Texture is looked up at, as an affine map of the mesh's UVs.

Blender users tile, turn and shift images with a Mapping node (and Vector Math) between
Texture Coordinate's UV output (or a UV Map node) and the Image Texture's Vector. UV is
(u, v, 0), and each of these nodes is affine in its vector input, so the chain is one affine
map of (u, v): evaluated here as a 3x3 matrix M with vector = M (u, v, 1), whose first two
rows (Flat projection reads x and y) are the renderer's per-texture uv map
(``_glslppm.Texture(uv_map=...)``, applied in shaders/common/textures.glsl). W never mixes
in: it is 0 for UVs, so any rotation is exact.

Followed, as Cycles evaluates them (svm_mapping.h, svm_vector_math.h):

- Mapping: Point R (v S) + L, Texture R^T (v - L) / S, Vector R (v S), R the XYZ Euler
  rotation Rz Ry Rx; Normal type (it normalizes) is not affine;
- Vector Math: Add, Subtract, Multiply and Multiply Add with a constant factor, Divide by a
  constant (0 where a component is 0, as Cycles' safe_divide), Scale by a constant;
- unlinked sockets are constants; a socket driven by anything else (Generated, Object,
  Value nodes, ...) is not followed: the texture is looked up at the mesh's UVs, with a
  warning naming the node.
"""

import math

import numpy as np

IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
_UV = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])


class NotAffine(Exception):
    """A node of the chain that is not an affine map of the UVs (its message says which)."""


def texture_uv_map(image_node, warn, render_uv_map=None):
    """((a, b, c), (d, e, f)): the Image Texture node is looked up at (a u + b v + c,
    d u + e v + f) for mesh uv (u, v). IDENTITY when its Vector is unlinked or the chain
    cannot be followed (warned, naming the node)."""
    socket = image_node.inputs["Vector"]
    if _source(socket)[0] is None:
        return IDENTITY
    try:
        matrix = _vector_of(socket, warn, render_uv_map)
    except NotAffine as error:
        warn(f"image texture '{image_node.name}': {error}; using the mesh's render UV map")
        return IDENTITY
    if not np.all(np.isfinite(matrix)):
        warn(f"image texture '{image_node.name}': its Vector is not finite; using the mesh's "
             "render UV map")
        return IDENTITY
    return tuple(tuple(float(x) for x in row) for row in matrix[:2])


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
    matrix = np.zeros((3, 3))
    matrix[:, 2] = [float(c) for c in vector]
    return matrix


def _is_constant(matrix):
    return not np.any(matrix[:, :2])


def _vector_of(socket, warn, render_uv_map):
    """M (3x3) with socket's vector = M (u, v, 1)."""
    node, output = _source(socket)
    if node is None:
        value = socket.default_value
        return _constant(tuple(value) if hasattr(value, "__len__") else (value,) * 3)
    if node.type == 'TEX_COORD':
        if output.name == "UV":
            return _UV.copy()
        raise NotAffine(f"Texture Coordinate '{node.name}' {output.name} is not followed "
                        "(UV is)")
    if node.type == 'UVMAP':
        if node.uv_map and render_uv_map is not None and node.uv_map != render_uv_map:
            warn(f"UV Map node '{node.name}' reads '{node.uv_map}'; the mesh's render UV map "
                 f"'{render_uv_map}' is used")
        return _UV.copy()
    if node.type == 'MAPPING':
        return _mapping(node, _vector_of(node.inputs["Vector"], warn, render_uv_map))
    if node.type == 'VECT_MATH' and output.name == "Vector":
        return _vector_math(node, warn, render_uv_map)
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
        location = np.array(_constant_input(node, "Location"))
        shifted = vector - _constant(location)
        return np.diag(_safe_inverse(scale)) @ rotation.T @ shifted
    result = rotation @ np.diag(scale) @ vector
    if kind == 'POINT':
        result = result + _constant(_constant_input(node, "Location"))
    return result


def _vector_math(node, warn, render_uv_map):
    operation = node.operation

    def vector(k):  # the k-th Vector input (Scale is the fourth socket)
        return _vector_of(node.inputs[k], warn, render_uv_map)

    if operation == 'ADD':
        return vector(0) + vector(1)
    if operation == 'SUBTRACT':
        return vector(0) - vector(1)
    if operation in ('MULTIPLY', 'MULTIPLY_ADD'):
        a, b = vector(0), vector(1)
        if _is_constant(a):
            a, b = b, a
        if not _is_constant(b):
            raise NotAffine(f"Vector Math node '{node.name}' multiplies two vectors that both "
                            "vary")
        result = np.diag(b[:, 2]) @ a
        return result + vector(2) if operation == 'MULTIPLY_ADD' else result
    if operation == 'DIVIDE':
        b = vector(1)
        if not _is_constant(b):
            raise NotAffine(f"Vector Math node '{node.name}' divides by a vector that varies")
        return np.diag(_safe_inverse(b[:, 2])) @ vector(0)
    if operation == 'SCALE':
        scale = node.inputs["Scale"]
        if _source(scale)[0] is not None:
            raise NotAffine(f"Vector Math node '{node.name}': a linked Scale is not followed")
        return float(scale.default_value) * vector(0)
    raise NotAffine(f"Vector Math node '{node.name}' ({operation.replace('_', ' ').title()}) "
                    "is not affine")
