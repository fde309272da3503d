"""Values of shader node inputs: unlinked defaults, constants (RGB and Value nodes) and
Image Texture nodes, which become textures of the scene's TextureTable where the
renderer reads one (colours; scalars through one channel of a texel).

Blender converts a colour plugged into a float input to its luminance; an Image Texture's
Alpha output is the texel's alpha. A Separate RGB / Separate Color node between an image
and a float input picks one channel (glTF imports wire metallic and roughness so).
"""

import math

from .image import image_mean_color


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


def image_texture_index(node, warn, textures):
    """The TextureTable index of an Image Texture node's image (-1: none), warning about
    what of the node is not followed."""
    if node.inputs["Vector"].is_linked:
        warn(f"the Vector input of image texture '{node.name}' is ignored; "
             "using the mesh's render UV map")
    if node.projection != 'FLAT':
        warn(f"image texture '{node.name}': {node.projection.title()} projection is "
             "rendered as Flat (UV)")
    return textures.index(node.image, node.extension, warn)


def socket_color_texture(socket, warn, textures, clamp=True):
    """(rgb, texture index) of a colour input: an Image Texture node becomes a texture
    (rgb white, since the renderer multiplies them); anything else is socket_color."""
    node = linked_node(socket)
    if textures is None or node is None or node.type != 'TEX_IMAGE':
        return socket_color(socket, warn, clamp), -1
    index = image_texture_index(node, warn, textures)
    if index < 0:
        return socket_color(socket, warn, clamp, linked=False), -1
    return (1.0, 1.0, 1.0), index


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
