"""Values of shader node inputs: unlinked defaults, constants (RGB and Value nodes) and
Image Texture nodes, which become textures of the scene's TextureTable where the
renderer reads one (colours; scalars through one channel of a texel).

Blender converts a colour plugged into a float input to its luminance; an Image Texture's
Alpha output is the texel's alpha. A Separate RGB / Separate Color node between an image
and a float input picks one channel (glTF imports wire metallic and roughness so).

A colour input fed by a mesh's colour attribute (the Color Attribute node, 3.x's Vertex
Color node, or an Attribute node's Color output), directly or through a Mix set to Multiply
at factor 1 with a constant colour, is that constant times the vertex colour, which the
renderer interpolates per corner (vertex_color_input).
"""

import math

from .image import image_mean_color
from .texture_mapping import IDENTITY, texture_map


def input_socket(node, *names):
    """The first of names that node has as an input (names differ across Blender
    versions); None when it has none of them."""
    for name in names:
        if name is not None and name in node.inputs:
            return node.inputs[name]
    return None


def linked_node(socket):
    """The node feeding a socket, through reroutes; None when unlinked or muted."""
    node, _ = linked_output(socket)
    return node


def linked_output(socket):
    """(node, output socket) feeding a socket, through reroutes; (None, None) when
    unlinked or muted."""
    while socket is not None and socket.is_linked:
        link = socket.links[0]
        if not link.is_valid or link.is_muted:
            return None, None
        node = link.from_node
        if node.type != 'REROUTE':
            return (None, None) if node.mute else (node, link.from_socket)
        socket = node.inputs[0]
    return None, None


def image_texture_index(node, warn, textures, uv_only=False):
    """The TextureTable index of an Image Texture node's image under its extension,
    interpolation and the uv or position map of its Vector input (texture_mapping.py), -1
    for none, warning about what of the node is not followed. uv_only: normal and bump maps,
    whose tangent frame the renderer takes from the uvs, are looked up at the uvs."""
    source, rows = texture_map(node, warn, spaces=getattr(textures, "spaces", None))
    if source == "position" and uv_only:
        warn(f"image texture '{node.name}': a normal or bump map on Generated or Object "
             "coordinates is not followed; using the mesh's render UV map")
        source, rows = "uv", IDENTITY
    if node.projection != 'FLAT':
        warn(f"image texture '{node.name}': {node.projection.title()} projection is "
             "rendered as Flat")
    if source == "position":
        return textures.index(node.image, node.extension, warn, position_map=rows,
                              interpolation=node.interpolation)
    return textures.index(node.image, node.extension, warn, rows,
                          interpolation=node.interpolation)


def socket_color_texture(socket, warn, textures, clamp=True):
    """(rgb, texture index) of a colour input: an Image Texture node becomes a texture
    (rgb white, since the renderer multiplies them); a colour attribute the constant it is
    multiplied by (vertex_color_input); anything else is socket_color."""
    vertex = vertex_color_input(socket)
    if vertex is not None:
        rgb = vertex[0]
        return (clamp01(rgb) if clamp else tuple(_finite(c) for c in rgb)), -1
    node = linked_node(socket)
    if textures is None or node is None or node.type != 'TEX_IMAGE':
        return socket_color(socket, warn, clamp), -1
    index = image_texture_index(node, warn, textures)
    if index < 0:
        return socket_color(socket, warn, clamp, linked=False), -1
    return (1.0, 1.0, 1.0), index


def vertex_color_input(socket):
    """(constant rgb, attribute name) when socket's colour is a mesh colour attribute times
    a constant, else None. The name is "" for the mesh's default (render) colour attribute,
    as the Color Attribute node's empty Layer means."""
    node, output = linked_output(socket)
    constant = (1.0, 1.0, 1.0)
    operands = _multiply_operands(node)
    if operands is not None:
        first, second = operands
        for attribute_socket, other in ((first, second), (second, first)):
            if other.is_linked and linked_node(other) is not None:
                other_node = linked_node(other)
                if other_node.type != 'RGB':
                    continue
                color = tuple(other_node.outputs[0].default_value[:3])
            else:
                color = tuple(other.default_value[:3])
            name = _color_attribute_name(*linked_output(attribute_socket))
            if name is not None:
                return tuple(_finite(c) for c in color), name
        return None
    name = _color_attribute_name(node, output)
    return None if name is None else (constant, name)


def _color_attribute_name(node, output):
    """The attribute a Color Attribute / Vertex Color / Attribute node's Color output reads,
    or None for any other node or output."""
    if node is None or output is None or output.name != "Color":
        return None
    if node.type == 'VERTEX_COLOR':  # 3.2+'s Color Attribute, 3.x's Vertex Color
        return node.layer_name
    if node.type == 'ATTRIBUTE' and node.attribute_type == 'GEOMETRY':
        return node.attribute_name
    return None


def _multiply_operands(node):
    """The two colour sockets of a Mix (Color) node set to Multiply at factor 1 (unlinked),
    whose result is their product; None for anything else. 3.x's MixRGB names them
    Color1 / Color2, 4.x's Mix node A_Color / B_Color (identifiers: its float and vector
    sockets share the names A and B)."""
    if node is None or node.type not in ('MIX_RGB', 'MIX') or node.blend_type != 'MULTIPLY':
        return None
    if node.type == 'MIX':
        if node.data_type != 'RGBA' or getattr(node, "clamp_result", False):
            return None
        sockets = {s.identifier: s for s in node.inputs}
        factor, first, second = sockets["Factor_Float"], sockets["A_Color"], sockets["B_Color"]
    else:
        if node.use_clamp:
            return None
        factor, first, second = node.inputs["Fac"], node.inputs["Color1"], node.inputs["Color2"]
    if factor.is_linked or factor.default_value != 1.0:
        return None
    return first, second


_SEPARATE_CHANNELS = {"R": "red", "G": "green", "B": "blue",
                      "Red": "red", "Green": "green", "Blue": "blue"}


def socket_scalar(socket, warn, textures):
    """(value, texture index or -1, channel) of a float input: an Image Texture (directly
    or through Separate RGB / Separate Color) gives value 1 times the texel's channel."""
    node, output = linked_output(socket)
    channel = "luminance"
    if node is not None and node.type in ('SEPRGB', 'SEPARATE_COLOR') and \
            output.name in _SEPARATE_CHANNELS and \
            getattr(node, "mode", 'RGB') == 'RGB':
        channel = _SEPARATE_CHANNELS[output.name]
        node, output = linked_output(node.inputs[0])
        if node is None or node.type != 'TEX_IMAGE':
            warn(f"'{socket.name}' is driven by a Separate node whose input is not an "
                 "image texture; using the input's own value")
            return _finite(socket.default_value), -1, "luminance"
    if textures is not None and node is not None and node.type == 'TEX_IMAGE':
        index = image_texture_index(node, warn, textures)
        if index >= 0:
            if output.name == "Alpha":
                channel = "alpha"
            return 1.0, index, channel
        return _finite(socket.default_value), -1, "luminance"
    return socket_value(socket, warn), -1, "luminance"


def socket_color(socket, warn, clamp=True, linked=True):
    """A colour input's RGB: its default, an RGB node's colour, or an image's mean."""
    color = tuple(socket.default_value[:3])
    node = linked_node(socket) if linked else None
    if node is not None:
        if node.type == 'RGB':
            color = tuple(node.outputs[0].default_value[:3])
        elif node.type in ('TEX_IMAGE', 'TEX_ENVIRONMENT'):
            color = image_mean_color(node.image, color, warn)
        else:
            warn(f"'{socket.name}' is driven by a {node.bl_label or node.type} node, which "
                 "is not supported; using the input's own value")
    if not all(math.isfinite(c) for c in color):
        warn(f"'{socket.name}' is ({', '.join(f'{c:g}' for c in color)}); "
             "using 0 for what is not a finite number")
    return clamp01(color) if clamp else tuple(_finite(c) for c in color)


def socket_value(socket, warn):
    """A float input's value: its default or a Value node's output."""
    if socket is None:
        return 0.0
    value = socket.default_value
    node = linked_node(socket)
    if node is not None:
        if node.type == 'VALUE':
            value = node.outputs[0].default_value
        else:
            warn(f"'{socket.name}' is driven by a {node.bl_label or node.type} node, which "
                 "is not supported; using the input's own value")
    if not math.isfinite(value):
        warn(f"'{socket.name}' is {value:g}; using 0")
    return _finite(value)


def _finite(value):
    value = float(value)
    return value if math.isfinite(value) else 0.0


def clamp01(color):
    return tuple(min(1.0, max(0.0, _finite(c))) for c in color)
