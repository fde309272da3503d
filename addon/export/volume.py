"""What a material's Volume output becomes: Beer-Lambert absorption inside a glass object.

A Volume Absorption node on the Material Output's Volume of a material whose surface
refracts (Glass, Refraction, Principled BSDF with transmission) is the medium inside that
closed object: Cycles' absorption coefficient sigma_a = density x (1 - colour), per unit
of world length (Cycles integrates volumes along world-space rays, so the object's scale
makes a part thicker, not the medium denser). The renderer attenuates light that leaves
the object through its back faces by exp(-sigma_a t) (shaders/common/absorption.glsl).
Any other volume (scattering, emission, Principled Volume, a volume on an opaque
surface) is left out with a warning.
"""

from .node_inputs import linked_node, socket_color, socket_value


def volume_absorption(output, entries, warn):
    """sigma_a (r, g, b) of the Material Output `output`'s Volume, or None where it has
    none that the renderer models. entries: the material's converted surface, root first
    (the medium needs a refracting leaf: light enters the object only through one)."""
    socket = output.inputs.get("Volume")
    node = linked_node(socket) if socket is not None else None
    if node is None:
        return None
    if node.type != 'VOLUME_ABSORPTION':
        warn(f"the {node.bl_label or node.type} node '{node.name}' on the Volume output is "
             "not supported (only Volume Absorption inside glass); rendering without it")
        return None
    if not any(entry.kind == "dielectric" for entry in entries):
        warn(f"Volume Absorption '{node.name}' needs a refracting surface (Glass, Refraction, "
             "Principled BSDF with transmission) to be seen inside; rendering without it")
        return None
    # Cycles clamps the colour and the density at 0; a colour above 1 would add light.
    color = socket_color(node.inputs["Color"], warn, clamp=False)
    density = max(0.0, socket_value(node.inputs["Density"], warn))
    if max(color) > 1.0:
        warn(f"Volume Absorption '{node.name}': a colour above 1 would amplify light; "
             "clamped to 1")
    return tuple(density * (1.0 - min(max(c, 0.0), 1.0)) for c in color)
