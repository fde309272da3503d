"""Normal Map (tangent space) and Bump nodes on a material's BSDFs: one image per
material, which the renderer applies to the material's shading normal (all its Mix
leaves alike). A Normal Map's tangents come from the mesh (``mesh.calc_tangents``,
MikkTSpace, as Cycles takes them), read in ``mesh.py``; the Normal Map's UV Map is read
as the mesh's render UV map. A Bump's Height is an Image Texture's Color (its luminance,
as Blender converts a colour to a float); its Strength, Distance and Invert are kept.

What has no counterpart warns, naming the material and the node: other normal spaces
(object, world, Blender's object/world), a Normal Map or Bump fed by something other than
an Image Texture, a Bump over another normal (its Normal input), and BSDFs of one material
with different maps (the first found is used for all).
"""

from .node_inputs import image_texture_index, input_socket, linked_node, socket_value

# The shader nodes whose inputs lead to more shaders.
_SHADER_PASSTHROUGH = {'MIX_SHADER': (1, 2), 'ADD_SHADER': (0, 1)}


def shader_nodes(socket):
    """The shader nodes feeding a shader socket, through Mix and Add Shaders."""
    return _bsdfs(socket, set())


def _bsdfs(socket, seen):
    node = linked_node(socket)
    if node is None or node.as_pointer() in seen:
        return
    seen.add(node.as_pointer())
    inputs = _SHADER_PASSTHROUGH.get(node.type)
    if inputs is None:
        yield node
        return
    for k in inputs:
        yield from _bsdfs(node.inputs[k], seen)


def normal_map_of(surface_socket, warn, textures):
    """The MaterialData fields of the Normal Map or Bump feeding the BSDFs behind a
    material's Surface socket (a dict), or None."""
    found = None
    for bsdf in shader_nodes(surface_socket):
        socket = input_socket(bsdf, "Normal")
        node = linked_node(socket) if socket is not None else None
        if node is None:
            continue
        mapped = _tangent_normal_map(node, bsdf, warn, textures)
        if mapped is None:
            continue
        if found is None:
            found = mapped
        elif mapped != found:
            warn(f"{bsdf.bl_label} '{bsdf.name}' has a normal map other than the "
                 "material's first; the first is used for every BSDF of the material")
    return found


def _tangent_normal_map(node, bsdf, warn, textures):
    if node.type == 'BUMP':
        return _bump(node, warn, textures)
    if node.type != 'NORMAL_MAP':
        warn(f"the {node.bl_label} node '{node.name}' on the Normal of {bsdf.bl_label} "
             f"'{bsdf.name}' is not supported; the smooth normal is used")
        return None
    if node.space != 'TANGENT':
        warn(f"Normal Map '{node.name}': the {node.space.replace('_', ' ').title()} space "
             "is not supported (Tangent Space only); the smooth normal is used")
        return None
    image_node = linked_node(node.inputs["Color"])
    if textures is None or image_node is None or image_node.type != 'TEX_IMAGE':
        warn(f"Normal Map '{node.name}': its Color is not an Image Texture; the smooth "
             "normal is used")
        return None
    if linked_node(node.inputs["Strength"]) is not None:
        warn(f"Normal Map '{node.name}': a linked Strength is read as its default value")
    strength = max(0.0, socket_value(node.inputs["Strength"], warn))
    index = image_texture_index(image_node, warn, textures, uv_only=True)
    if index < 0:
        return None
    return {"normal_texture": index, "normal_strength": strength}


def _bump(node, warn, textures):
    source = node.inputs["Height"]
    image_node = linked_node(source)
    if (textures is None or image_node is None or image_node.type != 'TEX_IMAGE'
            or source.links[0].from_socket.name != "Color"):
        warn(f"Bump '{node.name}': its Height is not an Image Texture's Color; the smooth "
             "normal is used")
        return None
    if linked_node(node.inputs["Normal"]) is not None:
        warn(f"Bump '{node.name}': the normal under the bump (its Normal input) is ignored")
    for name in ("Strength", "Distance"):
        if linked_node(node.inputs[name]) is not None:
            warn(f"Bump '{node.name}': a linked {name} is read as its default value")
    index = image_texture_index(image_node, warn, textures, uv_only=True)
    if index < 0:
        return None
    distance = socket_value(node.inputs["Distance"], warn)
    return {"bump_texture": index,
            "bump_strength": min(max(socket_value(node.inputs["Strength"], warn), 0.0), 1.0),
            "bump_distance": -distance if node.invert else distance}
