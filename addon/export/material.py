"""Material converter: a Blender material onto the renderer's closed material set
(diffuse, specular conductor, smooth dielectric, each with optional emission).

One converter per shader node type (``SURFACE_CONVERTERS``). A material that
cannot be mapped falls back to its viewport display colour with one warning;
export never fails over a material.

An Image Texture node feeding a BSDF's colour (Principled Base Color, Diffuse, Glossy,
Glass) becomes a texture: the material's colour is white and color_texture indexes
the scene's TextureTable (the renderer multiplies colour by the texel at the hit's
UV). Its Vector input is ignored (the mesh's render UV map is used) with a warning.
Images on other inputs (emission) stand in as their mean colour, with a warning.
"""

import math

from dataclasses import replace

from .image import image_mean_color
from .scene_data import MaterialData

# A glossy lobe this rough or rougher is nearer to diffuse than to a mirror.
ROUGH_AS_DIFFUSE = 0.5
# Roughness below this renders as a perfect mirror without a warning.
SMOOTH_ENOUGH = 0.05

DEFAULT_MATERIAL = MaterialData("diffuse", (0.8, 0.8, 0.8))


def convert_material(material, warn, textures=None):
    """MaterialData for a material (None: Blender's default grey).
    warn(message) collects a warning for the render report; textures is the scene's
    TextureTable (None: images stand in as their mean colour)."""
    if material is None:
        return DEFAULT_MATERIAL

    def material_warn(message):
        warn(f"material '{material.name}': {message}")

    if not material.use_nodes or material.node_tree is None:
        return MaterialData("diffuse", _clamp01(material.diffuse_color[:3]))
    tree = material.node_tree
    output = tree.get_output_node('CYCLES') or tree.get_output_node('ALL')
    if output is None:
        material_warn("no Material Output node; using the viewport display colour")
        return _viewport_fallback(material)
    surface = output.inputs["Surface"]
    node = _linked_node(surface)
    if node is None:
        material_warn("nothing connected to the Material Output's Surface; rendering black")
        return MaterialData("diffuse", (0.0, 0.0, 0.0))
    converter = SURFACE_CONVERTERS.get(node.type)
    if converter is None:
        material_warn(f"the {node.bl_label or node.type} node is not supported; "
                      "using the viewport display colour")
        return _viewport_fallback(material)
    return converter(node, _Inputs(material_warn, textures))


def volume_only(material):
    """True for a material whose output feeds only its Volume: a volume object, which
    has no surface to render."""
    if material is None or not material.use_nodes or material.node_tree is None:
        return False
    tree = material.node_tree
    output = tree.get_output_node('CYCLES') or tree.get_output_node('ALL')
    if output is None:
        return False
    volume = output.inputs.get("Volume")
    return (_linked_node(output.inputs["Surface"]) is None and volume is not None
            and _linked_node(volume) is not None)


def _viewport_fallback(material):
    return MaterialData("diffuse", _clamp01(material.diffuse_color[:3]))


# Node converters: each maps one shader node to MaterialData.

class _Inputs:
    """What a node converter needs besides the node: the warning sink and the textures.
    Calling it warns (converters read as before: warn(message))."""

    def __init__(self, warn, textures):
        self.warn = warn
        self.textures = textures

    def __call__(self, message):
        self.warn(message)

    def color(self, socket, clamp=True):
        """(rgb, texture index or -1) of a BSDF colour input."""
        return socket_color_texture(socket, self.warn, self.textures, clamp)


def _principled(node, warn):
    base, texture = warn.color(_input(node, "Base Color"))
    metallic = socket_value(_input(node, "Metallic"), warn)
    transmission = socket_value(_input(node, "Transmission Weight", "Transmission"), warn)
    roughness = socket_value(_input(node, "Roughness"), warn)
    ior = socket_value(_input(node, "IOR"), warn)
    emission = _emission(node, "Emission Color", "Emission", warn)
    alpha = socket_value(_input(node, "Alpha"), warn)
    if alpha < 1.0:
        warn(f"alpha {alpha:.2f} is not supported; rendering opaque")
    glass = transmission >= 0.5
    _warn_partial(warn, "transmission", transmission, "glass" if glass else "opaque")
    if glass:
        _warn_rough(warn, roughness, "smooth glass")
        return MaterialData("dielectric", base, _ior(ior), emission, texture)
    metal = metallic >= 0.5
    _warn_partial(warn, "metallic", metallic, "metal" if metal else "non-metal")
    if metal:
        return replace(_specular_reflector(base, roughness, emission, warn),
                       color_texture=texture)
    return MaterialData("diffuse", base, _ior(ior), emission, texture)


def _diffuse(node, warn):
    color, texture = warn.color(node.inputs["Color"])
    return MaterialData("diffuse", color, color_texture=texture)


def _glossy(node, warn):
    color, texture = warn.color(node.inputs["Color"])
    roughness = socket_value(node.inputs["Roughness"], warn)
    return replace(_specular_reflector(color, roughness, (0.0, 0.0, 0.0), warn),
                   color_texture=texture)


def _glass(node, warn):
    color, texture = warn.color(node.inputs["Color"])
    _warn_rough(warn, socket_value(node.inputs["Roughness"], warn), "smooth glass")
    return MaterialData("dielectric", color, _ior(socket_value(node.inputs["IOR"], warn)),
                        color_texture=texture)


def _refraction(node, warn):
    warn("Refraction BSDF rendered as glass (with Fresnel reflection)")
    return _glass(node, warn)


def _emission_node(node, warn):
    emission = _emission(node, "Color", None, warn, strength_name="Strength")
    return MaterialData("diffuse", (0.0, 0.0, 0.0), 1.5, emission)


SURFACE_CONVERTERS = {
    'BSDF_PRINCIPLED': _principled,
    'BSDF_DIFFUSE': _diffuse,
    'BSDF_GLOSSY': _glossy,          # 4.0+ merged Anisotropic into Glossy
    'BSDF_ANISOTROPIC': _glossy,     # 3.x
    'BSDF_GLASS': _glass,
    'BSDF_REFRACTION': _refraction,
    'EMISSION': _emission_node,
}


def _specular_reflector(color, roughness, emission, warn):
    """Glossy reflection: a mirror when smooth; the nearest supported lobe when rough."""
    if roughness >= ROUGH_AS_DIFFUSE:
        warn(f"roughness {roughness:.2f} is not supported; rendering as diffuse")
        return MaterialData("diffuse", color, 1.5, emission)
    _warn_rough(warn, roughness, "a mirror")
    return MaterialData("conductor", color, 1.5, emission)


def _emission(node, color_name, old_color_name, warn, strength_name="Emission Strength"):
    """Radiance = colour × strength. Principled's colour input is "Emission" in 3.x and
    "Emission Color" in 4.x (where it defaults to white with strength 0)."""
    color_socket = _input(node, color_name, old_color_name)
    strength_socket = _input(node, strength_name)
    strength = socket_value(strength_socket, warn) if strength_socket is not None else 1.0
    if strength <= 0.0 or color_socket is None:
        return (0.0, 0.0, 0.0)
    color = socket_color(color_socket, warn, clamp=False)
    return tuple(max(0.0, c * strength) for c in color)


def _warn_partial(warn, name, value, rendered_as):
    if 0.01 < value < 0.99:
        warn(f"{name} {value:.2f} rendered as {rendered_as}")


def _warn_rough(warn, roughness, rendered_as):
    if roughness > SMOOTH_ENOUGH:
        warn(f"roughness {roughness:.2f} rendered as {rendered_as}")


def _ior(ior):
    return float(ior) if math.isfinite(ior) and ior > 0.0 else 1.5


# Socket values: unlinked defaults, constants and (for colours) image textures.

def _input(node, *names):
    for name in names:
        if name is not None and name in node.inputs:
            return node.inputs[name]
    return None


def _linked_node(socket):
    """The node feeding a socket, through reroutes; None when unlinked or muted."""
    while socket is not None and socket.is_linked:
        link = socket.links[0]
        if not link.is_valid or link.is_muted:
            return None
        node = link.from_node
        if node.type != 'REROUTE':
            return None if node.mute else node
        socket = node.inputs[0]
    return None


def socket_color_texture(socket, warn, textures, clamp=True):
    """(rgb, texture index) of a colour input: an Image Texture node becomes a texture
    (rgb white, since the renderer multiplies them); anything else is socket_color."""
    node = _linked_node(socket)
    if textures is None or node is None or node.type != 'TEX_IMAGE':
        return socket_color(socket, warn, clamp), -1
    if node.inputs["Vector"].is_linked:
        warn(f"the Vector input of image texture '{node.name}' is ignored; "
             "using the mesh's render UV map")
    if node.projection != 'FLAT':
        warn(f"image texture '{node.name}': {node.projection.title()} projection is "
             "rendered as Flat (UV)")
    index = textures.index(node.image, node.extension, warn)
    if index < 0:
        return socket_color(socket, warn, clamp, linked=False), -1
    return (1.0, 1.0, 1.0), index


def socket_color(socket, warn, clamp=True, linked=True):
    """A colour input's RGB: its default, an RGB node's colour, or an image's mean."""
    color = tuple(socket.default_value[:3])
    node = _linked_node(socket) if linked else None
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
    return _clamp01(color) if clamp else tuple(_finite(c) for c in color)


def socket_value(socket, warn):
    """A float input's value: its default or a Value node's output."""
    if socket is None:
        return 0.0
    value = socket.default_value
    node = _linked_node(socket)
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


def _clamp01(color):
    return tuple(min(1.0, max(0.0, _finite(c))) for c in color)
