"""World converter: the Background shader's colour x strength as a constant
environment, or, with an Environment Texture node on its Color, strength x an
equirectangular map (Blender's mapping: Z up, which is the renderer's too), turned
by a Mapping node on its Vector input if there is one (rotation only).

A missing image, or a projection other than equirectangular, falls back to the
node's own colour with a warning; the render goes on.
"""

import numpy as np

from ..compat import node_tree
from .node_inputs import linked_node as _linked_node, socket_color, socket_value
from .sky import bake_sky

BLACK = (0.0, 0.0, 0.0)

# The module's equirectangular mapping is Blender's (Cycles'), u = 0.5 - atan2(y, x) / 2 pi,
# in the frame it is given; test_cycles.test_environment_texture_matches_cycles checks it.
MODULE_FROM_BLENDER_MAP = np.eye(3)


def convert_world(world, warn, textures=None, add_light=None):
    """(environment rgb, environment texture index or -1, environment_to_world float32
    4x4 or None) for a world (None: black). textures is the scene's TextureTable (None:
    an Environment Texture counts as its mean colour); add_light(LightData) takes a Sky
    Texture's sun disc."""
    rgb, texture, to_world = _convert_world(world, warn, textures, add_light)
    return rgb, texture, to_world if texture >= 0 else None


def _convert_world(world, warn, textures, add_light):
    if world is None:
        return BLACK, -1, None
    tree = node_tree(world)
    if tree is None:
        return tuple(max(0.0, float(c)) for c in world.color[:3]), -1, None

    def world_warn(message):
        warn(f"world '{world.name}': {message}")

    output = next((node for node in tree.nodes
                   if node.type == 'OUTPUT_WORLD' and node.is_active_output), None)
    if output is None:
        output = next((node for node in tree.nodes if node.type == 'OUTPUT_WORLD'), None)
    volume = output.inputs.get("Volume") if output is not None else None
    if volume is not None and _linked_node(volume) is not None:
        world_warn("world volumes are not supported; rendering without it")
    surface = output.inputs["Surface"] if output is not None else None
    node = _linked_node(surface) if surface is not None else None
    if node is None:
        return BLACK, -1, None
    if node.type != 'BACKGROUND':
        world_warn(f"the {node.bl_label or node.type} node is not supported; "
                   "using the world's viewport colour")
        return tuple(max(0.0, float(c)) for c in world.color[:3]), -1, None
    strength = socket_value(node.inputs["Strength"], world_warn)
    color_socket = node.inputs["Color"]
    source = _linked_node(color_socket)
    if textures is not None and source is not None and source.type == 'TEX_ENVIRONMENT':
        texture = _environment_texture(source, world_warn, textures)
        if texture >= 0:
            lookup = _lookup_rotation(source.inputs["Vector"], world_warn)
            return (max(0.0, strength),) * 3, texture, _to_world(lookup)
        color = socket_color(color_socket, world_warn, clamp=False, linked=False)
    elif textures is not None and source is not None and source.type == 'TEX_SKY':
        vector = source.inputs.get("Vector")  # 4.x's Nishita sky has none
        if vector is not None and _linked_node(vector) is not None:
            world_warn("the Sky Texture's Vector input is ignored; the sky is unturned")
        texture = bake_sky(source, max(0.0, strength), world_warn, textures,
                           add_light or (lambda light: None))
        if texture >= 0:
            return (max(0.0, strength),) * 3, texture, np.eye(4, dtype=np.float32)
        color = (0.5, 0.5, 0.5)
    else:
        color = socket_color(color_socket, world_warn, clamp=False)
    return tuple(max(0.0, c * strength) for c in color), -1, None


def _environment_texture(node, warn, textures):
    """The texture index of an Environment Texture node, or -1 (warned)."""
    if node.projection != 'EQUIRECTANGULAR':
        warn(f"environment texture '{node.name}': {node.projection.title()} projection "
             "is not supported; using the Background colour")
        return -1
    return textures.index(node.image, 'REPEAT', warn, interpolation=node.interpolation)


def _to_world(lookup):
    """The module's environment_to_world M for a map Blender looks up at lookup @ d: the
    module looks up at M^T d in its own mapping, so M^T = MODULE_FROM_BLENDER_MAP lookup."""
    matrix = np.eye(4, dtype=np.float32)
    matrix[:3, :3] = (MODULE_FROM_BLENDER_MAP @ lookup).T
    return matrix


def _lookup_rotation(vector_socket, warn):
    """R such that Blender looks the map up at R d for a world direction d: the identity,
    or a Mapping node's rotation (Point and Vector: R; Texture: R^-1). Scale and location
    do not turn directions and are left out, with a warning."""
    node = _linked_node(vector_socket)
    if node is None or (node.type == 'TEX_COORD' and _generated(vector_socket)):
        return np.eye(3)
    if node.type != 'MAPPING' or node.vector_type == 'NORMAL' or not _direction_input(node):
        warn(f"the {node.bl_label or node.type} node on the environment texture's Vector "
             "is not supported; using the map unturned")
        return np.eye(3)
    from mathutils import Euler
    rotation = np.array(Euler(_vector(node, "Rotation"), 'XYZ').to_matrix())
    scale = _vector(node, "Scale")
    if max(scale) - min(scale) > 1e-6 * max(abs(s) for s in scale) or min(scale) <= 0.0:
        warn("the environment Mapping node's non-uniform or negative scale is ignored")
    if node.vector_type in ('POINT', 'TEXTURE') and any(_vector(node, "Location")):
        warn("the environment Mapping node's location is ignored (directions only)")
    return rotation.T if node.vector_type == 'TEXTURE' else rotation


def _direction_input(mapping):
    """True when the Mapping node's own Vector is the world direction (unlinked or the
    Texture Coordinate node's Generated output, which for a world is the direction)."""
    node = _linked_node(mapping.inputs["Vector"])
    return node is None or (node.type == 'TEX_COORD' and _generated(mapping.inputs["Vector"]))


def _generated(socket):
    return socket.links[0].from_socket.name == "Generated"


def _vector(node, name):
    """A Mapping node input's value (Vector 3.x+ sockets; a linked one reads its default)."""
    socket = node.inputs.get(name)
    return tuple(float(v) for v in socket.default_value) if socket is not None else (0, 0, 0)
