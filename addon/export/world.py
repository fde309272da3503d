"""World converter: the Background shader's colour × strength as a constant
environment (environment maps come with the scene-breadth issue; until then an
Environment Texture stands in as its image's mean colour, with a warning)."""

from .material import socket_color, socket_value


def convert_world(world, warn):
    """Environment radiance (r, g, b) for a world (None: black)."""
    if world is None:
        return (0.0, 0.0, 0.0)
    if not world.use_nodes or world.node_tree is None:
        return tuple(max(0.0, float(c)) for c in world.color[:3])

    def world_warn(message):
        warn(f"world '{world.name}': {message}")

    tree = world.node_tree
    output = next((node for node in tree.nodes
                   if node.type == 'OUTPUT_WORLD' and node.is_active_output), None)
    if output is None:
        output = next((node for node in tree.nodes if node.type == 'OUTPUT_WORLD'), None)
    surface = output.inputs["Surface"] if output is not None else None
    if surface is None or not surface.is_linked:
        return (0.0, 0.0, 0.0)
    node = surface.links[0].from_node
    while node.type == 'REROUTE' and node.inputs[0].is_linked:
        node = node.inputs[0].links[0].from_node
    if node.type != 'BACKGROUND':
        world_warn(f"the {node.bl_label or node.type} node is not supported; "
                   "using the world's viewport colour")
        return tuple(max(0.0, float(c)) for c in world.color[:3])
    color = socket_color(node.inputs["Color"], world_warn, clamp=False)
    strength = socket_value(node.inputs["Strength"], world_warn)
    return tuple(max(0.0, c * strength) for c in color)
