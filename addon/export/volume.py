"""What a material's Volume output becomes: Beer-Lambert absorption inside a glass object.

A Volume Absorption node on the Material Output's Volume of a material whose surface
refracts (Glass, Refraction, Principled BSDF with transmission) is the medium inside that
closed object: Cycles' absorption coefficient sigma_a = density x (1 - colour), per unit
of world length (Cycles integrates volumes along world-space rays, so the object's scale
makes a part thicker, not the medium denser). The renderer attenuates light that leaves
the object through its back faces by exp(-sigma_a t) (shaders/common/absorption.glsl).
A Principled Volume that only absorbs (black Color, no emission) is the same medium, of
sigma_a = density x (1 - sqrt(Absorption Color)) as Cycles has it. Any other volume
(scattering, emission, a volume behind an opaque surface) is left out with a warning.
"""

import math

from .node_inputs import input_socket, linked_node, socket_color, socket_value


def volume_absorption(output, entries, warn):
    """sigma_a (r, g, b) of the Material Output `output`'s Volume, or None where it has
    none that the renderer models. entries: the material's converted surface, root first
    (the medium needs a refracting leaf: light enters the object only through one)."""
    socket = output.inputs.get("Volume")
    node = linked_node(socket) if socket is not None else None
    if node is None:
        return None
    converter = _ABSORBING_NODES.get(node.type)
    if converter is None:
        warn(f"the {node.bl_label or node.type} node '{node.name}' on the Volume output is "
             "not supported (only Volume Absorption inside glass); rendering without it")
        return None
    if not any(entry.kind == "dielectric" for entry in entries):
        warn(f"{node.bl_label} '{node.name}' needs a refracting surface (Glass, Refraction, "
             "Principled BSDF with transmission) to be seen inside; rendering without it")
        return None
    return converter(node, warn)


def _volume_absorption_node(node, warn):
    """Cycles' Volume Absorption: density x (1 - colour), both clamped at 0."""
    color = socket_color(node.inputs["Color"], warn, clamp=False)
    density = max(0.0, socket_value(node.inputs["Density"], warn))
    if max(color) > 1.0:
        warn(f"Volume Absorption '{node.name}': a colour above 1 would amplify light; "
             "clamped to 1")
    return tuple(density * (1.0 - min(max(c, 0.0), 1.0)) for c in color)


def _principled_volume(node, warn):
    """Cycles' Principled Volume where it only absorbs (black Color: no scattering; no
    emission, no blackbody): its extinction density x (1 - sqrt(Absorption Color)). Anything
    else of it scatters or emits, which is not modelled: left out with a warning."""
    def color_of(name, absent):
        socket = input_socket(node, name)
        return absent if socket is None else socket_color(socket, warn, clamp=False)

    scatter = color_of("Color", (0.0, 0.0, 0.0))
    emits = (socket_value(input_socket(node, "Emission Strength"), warn) > 0.0 or
             socket_value(input_socket(node, "Blackbody Intensity"), warn) > 0.0)
    if max(scatter) > 0.0 or emits:
        warn(f"Principled Volume '{node.name}' scatters or emits (only its absorption with a "
             "black Color is rendered); rendering without it")
        return None
    density = max(0.0, socket_value(input_socket(node, "Density"), warn))
    color = color_of("Absorption Color", (1.0, 1.0, 1.0))
    return tuple(density * max(0.0, 1.0 - math.sqrt(max(c, 0.0))) for c in color)


_ABSORBING_NODES = {'VOLUME_ABSORPTION': _volume_absorption_node,
                    'PRINCIPLED_VOLUME': _principled_volume}
