"""The Mix tree of lobes that every shader node's converter builds (material.py's for the
plain BSDFs, principled.py's for Principled BSDF), and the inputs they all read the same
way: a node's microfacet distribution, its emission and its IOR. Its leaves are
scene_data.MaterialData; material.py flattens the tree into the module's list."""

import math

from dataclasses import dataclass, replace

from .node_inputs import input_socket, linked_node, socket_color, socket_value
from .scene_data import MaterialData

BLACK = MaterialData("diffuse", (0.0, 0.0, 0.0))


@dataclass(eq=False)
class Mix:
    """A Mix material under construction: b is picked with probability factor
    (times the texture's channel), a otherwise."""
    a: object
    b: object
    factor: float = 0.5
    texture: int = -1
    channel: str = "luminance"
    mode: str = "constant"      # "constant", "fresnel" or "layer_fresnel" (IOR ior),
                                # "facing" (blend ior)
    ior: float = 1.5
    mean_texel: float = 0.5     # the texture's mean channel value (for the mean emission)


def mix(a, b, factor, texture=-1, channel="luminance", mean_texel=0.5):
    """Mix(a, b) with a constant or textured factor, or a or b alone where the factor
    is 0 or a constant 1."""
    if factor <= 0.0:
        return a
    if texture < 0 and factor >= 1.0:
        return b
    return Mix(a, b, min(max(factor, 0.0), 1.0), texture, channel, mean_texel=mean_texel)


def with_emission(tree, radiance):
    """tree with radiance added to each of its leaves (a new tree)."""
    if isinstance(tree, Mix):
        return replace(tree, a=with_emission(tree.a, radiance),
                       b=with_emission(tree.b, radiance))
    return replace(tree, emission=tuple(e + r for e, r in zip(tree.emission, radiance)))


_DISTRIBUTIONS = {'SHARP': (False, False), 'GGX': (False, False),
                  'MULTI_GGX': (True, False), 'BECKMANN': (False, True),
                  'ASHIKHMIN_SHIRLEY': (False, True)}


def distribution(node, context):
    """multiscatter for a node's distribution, warning where it is not GGX and the two
    differ: not at roughness 0, where every distribution is the same perfect mirror or
    refraction (Blender 3.x's Glass BSDF defaults to Beckmann there)."""
    name = getattr(node, "distribution", 'GGX')
    multiscatter, approximated = _DISTRIBUTIONS.get(name, (False, True))
    roughness = input_socket(node, "Roughness")
    smooth = roughness is not None and not roughness.is_linked and roughness.default_value <= 0.0
    if approximated and not smooth:
        context(f"{node.bl_label} '{node.name}': the {name.replace('_', '-').title()} "
                "distribution is rendered as GGX")
    return multiscatter


def emission(node, color_name, old_color_name, warn, strength_name="Emission Strength"):
    """Radiance = colour × strength. Principled's colour input is "Emission" in 3.x and
    "Emission Color" in 4.x (where it defaults to white with strength 0)."""
    color_socket = input_socket(node, color_name, old_color_name)
    strength_socket = input_socket(node, strength_name)
    strength = socket_value(strength_socket, warn) if strength_socket is not None else 1.0
    if strength <= 0.0 or color_socket is None:
        return (0.0, 0.0, 0.0)
    if emission_image(color_socket, warn) is not None:
        return (strength, strength, strength)  # times the texel: emission_texture_of
    color = socket_color(color_socket, warn, clamp=False)
    return tuple(max(0.0, c * strength) for c in color)


def emission_image(socket, context):
    """The Image Texture node on an emission colour input, where the export has a texture
    table (context.textures), else None."""
    node = linked_node(socket)
    if getattr(context, "textures", None) is None or node is None or node.type != 'TEX_IMAGE':
        return None
    return node


def ior_or_default(ior):
    """A node's IOR where it is a positive number, else glass's 1.5."""
    return float(ior) if math.isfinite(ior) and ior > 0.0 else 1.5
