"""Material converter: a Blender material onto the renderer's lobes (diffuse, conductor,
dielectric, plastic, translucent, transparent) and Mix materials that choose between them.

A material's node tree becomes a small tree: leaves are MaterialData of one lobe, inner
nodes are ``Mix`` (the second part picked with probability equal to the factor, as
Blender's Mix Shader Fac). ``flatten`` turns it into a list, root first, with mix
indices into that list; the scene builder appends it to the material table and points
the faces at the root. One converter per shader node type (``SURFACE_CONVERTERS``);
Principled BSDF has its own file. A node without a counterpart renders as the material's
viewport display colour with one warning naming the material and the node; export never
fails over a material.

Image Texture nodes become textures on colours (a BSDF's Color, Principled Base Color),
on roughness, and on factors (Mix Shader Fac, Principled Metallic, Transmission, Alpha);
images on other inputs (emission) stand in as their mean colour, with a warning.

Add Shader: an Emission added to a BSDF is that BSDF emitting (exact). Two BSDFs added
become a Mix of factor 0.5 whose parts have their weights doubled (colours and emission
times 2), exact where a lobe is linear in its colour (Diffuse, Glossy, Glass,
Translucent, Transparent) and warned where it is not (Principled's parts).
"""

import math

from dataclasses import replace

from ..compat import DEFAULT_SURFACE_IS_PRINCIPLED, node_tree
from .image import image_mean_color
from .normal_map import normal_map_of, shader_nodes
from .node_inputs import (clamp01, image_texture_index, input_socket, linked_node,
                          linked_output, socket_color, socket_color_texture, socket_scalar,
                          vertex_color_input,
                          socket_value)
from .lobe_tree import (BLACK, Mix, distribution, emission, emission_image, ior_or_default, mix,
                        with_emission)
from .principled import convert_principled
from .scene_data import MaterialData
from .volume import volume_absorption

# An object without a material, as Cycles renders it: a diffuse 0.8 grey up to 4.x, from 5.0
# a new material's Principled BSDF (base 0.8, roughness 0.5, IOR 1.5, Multiscatter GGX).
DEFAULT_MATERIAL = (MaterialData("plastic", (0.8, 0.8, 0.8), ior=1.5, roughness=0.5)
                    if DEFAULT_SURFACE_IS_PRINCIPLED else MaterialData("diffuse", (0.8, 0.8, 0.8)))
# How deep Mix materials may nest (kMaxMixDepth in native/scene/scene.h).
MAX_MIX_DEPTH = 8


def convert_material(material, warn, textures=None):
    """The material's entries, root first (mix indices relative to the list); None is
    Blender's default grey. warn(message) collects a warning for the render report;
    textures is the scene's TextureTable (None: images stand in as their mean colour)."""
    if material is None:
        return [DEFAULT_MATERIAL]

    def material_warn(message):
        warn(f"material '{material.name}': {message}")

    if node_tree(material) is None:
        return [MaterialData("diffuse", clamp01(material.diffuse_color[:3]))]
    tree = material.node_tree
    output = tree.get_output_node('CYCLES') or tree.get_output_node('ALL')
    if output is None:
        material_warn("no Material Output node; using the viewport display colour")
        return [_viewport_fallback(material)]
    if linked_node(output.inputs["Surface"]) is None:
        material_warn("nothing connected to the Material Output's Surface; rendering black")
        return [BLACK]
    context = _Context(material_warn, textures, _viewport_fallback(material))
    root = context.shader(output.inputs["Surface"])
    if _depth(root) > MAX_MIX_DEPTH:
        root = _limit_depth(root, MAX_MIX_DEPTH, material_warn)
    entries = flatten(root)
    # The renderer reads the normal map and the emission image of the triangle's own
    # material, the root.
    mapped = normal_map_of(output.inputs["Surface"], material_warn, textures) or {}
    emission_texture = emission_texture_of(output.inputs["Surface"], context)
    if emission_texture >= 0:
        mapped["emission_texture"] = emission_texture
    # The medium inside (Volume Absorption) is the root's too: light leaving the object
    # through any face has run inside it.
    absorption = volume_absorption(output, entries, material_warn)
    if absorption is not None and max(absorption) > 0.0:
        mapped["absorption"] = absorption
    if mapped:
        entries[0] = replace(entries[0], **mapped)
    return entries


def volume_only(material):
    """True for a material whose output feeds only its Volume: a volume object, which
    has no surface to render."""
    if material is None or node_tree(material) is None:
        return False
    tree = material.node_tree
    output = tree.get_output_node('CYCLES') or tree.get_output_node('ALL')
    if output is None:
        return False
    volume = output.inputs.get("Volume")
    return (linked_node(output.inputs["Surface"]) is None and volume is not None
            and linked_node(volume) is not None)


def _viewport_fallback(material):
    return MaterialData("diffuse", clamp01(material.diffuse_color[:3]))


class _Context:
    """What a node converter needs besides the node: the warning sink, the textures and
    the fallback. Calling it warns (converters read as before: warn(message))."""

    def __init__(self, warn, textures, fallback):
        self.warn = warn
        self.textures = textures
        self.fallback = fallback

    def __call__(self, message):
        self.warn(message)

    def color(self, socket, clamp=True):
        """(rgb, texture index or -1) of a BSDF colour input."""
        return socket_color_texture(socket, self.warn, self.textures, clamp)

    def vertex_color(self, socket):
        """The colour attribute a BSDF colour input multiplies in ("" the mesh's default),
        or None (node_inputs.vertex_color_input)."""
        found = vertex_color_input(socket)
        return None if found is None else found[1]

    def value(self, socket):
        return socket_value(socket, self.warn)

    def value_color(self, node, name):
        """The RGB of node's colour input name (white where the node has none)."""
        socket = input_socket(node, name)
        return (1.0, 1.0, 1.0) if socket is None else socket_color(socket, self.warn,
                                                                   clamp=False)

    def scalar(self, socket):
        """(value, texture index or -1, channel) of a float input."""
        return socket_scalar(socket, self.warn, self.textures)

    def factor(self, socket):
        """(value, texture, channel, mean texel) of a factor input in [0, 1]."""
        value, texture, channel = self.scalar(socket)
        mean = 0.5
        if texture >= 0:
            node = linked_node(socket)
            while node is not None and node.type != 'TEX_IMAGE':
                node = linked_node(node.inputs[0])
            if node is not None:
                mean = _mean_channel(node.image, channel, self.warn)
        return min(max(value, 0.0), 1.0), texture, channel, mean

    def roughness(self, socket):
        """Keyword arguments of a roughness input: roughness and its texture."""
        value, texture, channel = self.scalar(socket)
        return {"roughness": min(max(value, 0.0), 1.0), "roughness_texture": texture,
                "roughness_channel": channel}

    def shader(self, socket):
        """The tree of the shader node feeding socket (an unlinked shader input is
        black, as in Cycles)."""
        node = linked_node(socket)
        if node is None:
            return BLACK
        converter = SURFACE_CONVERTERS.get(node.type)
        if converter is None:
            self.warn(f"the {node.bl_label or node.type} node '{node.name}' is not "
                      "supported; using the viewport display colour")
            return self.fallback
        return converter(node, self)


def _mean_channel(image, channel, warn):
    r, g, b = image_mean_color(image, (0.5, 0.5, 0.5), lambda message: None)
    return {"red": r, "green": g, "blue": b, "alpha": 1.0}.get(
        channel, 0.2126 * r + 0.7152 * g + 0.0722 * b)


# Node converters: each maps one shader node to a tree.

def _diffuse(node, context):
    color, texture = context.color(node.inputs["Color"])
    roughness = socket_value(input_socket(node, "Roughness"), context)
    if roughness > 0.0:
        context(f"Diffuse BSDF '{node.name}': Oren-Nayar roughness {roughness:.2f} is "
                "rendered as Lambert")
    return MaterialData("diffuse", color, color_texture=texture,
                        vertex_color=context.vertex_color(node.inputs["Color"]))


# Blender's microfacet distributions: (multiscatter, mapped onto GGX with a warning).
def _roughness_of(node, context):
    if getattr(node, "distribution", None) == 'SHARP':
        return {"roughness": 0.0}
    return context.roughness(node.inputs["Roughness"])


def _warn_anisotropy(node, context, name="Anisotropy"):
    socket = input_socket(node, name)
    if socket is not None and (socket.is_linked or socket.default_value != 0.0):
        context(f"{node.bl_label} '{node.name}': anisotropy is not supported; "
                "rendering isotropic")


def _glossy(node, context):
    color, texture = context.color(node.inputs["Color"])
    _warn_anisotropy(node, context)
    return MaterialData("conductor", color, color_texture=texture,
                        vertex_color=context.vertex_color(node.inputs["Color"]),
                        multiscatter=distribution(node, context),
                        **_roughness_of(node, context))


def _glass(node, context):
    color, texture = context.color(node.inputs["Color"])
    return MaterialData("dielectric", color, ior_or_default(context.value(node.inputs["IOR"])),
                        color_texture=texture, tint_reflection=True,
                        vertex_color=context.vertex_color(node.inputs["Color"]),
                        multiscatter=distribution(node, context),
                        **_roughness_of(node, context))


def _refraction(node, context):
    context(f"Refraction BSDF '{node.name}' is rendered as glass (with Fresnel reflection)")
    return _glass(node, context)


def _translucent(node, context):
    color, texture = context.color(node.inputs["Color"])
    return MaterialData("translucent", color, color_texture=texture,
                        vertex_color=context.vertex_color(node.inputs["Color"]))


def _transparent(node, context):
    return MaterialData("transparent", context.color(node.inputs["Color"])[0])


def _emission_node(node, context):
    return MaterialData("diffuse", (0.0, 0.0, 0.0), 1.5,
                        emission(node, "Color", None, context, strength_name="Strength"))


def _mix_shader(node, context):
    a = context.shader(node.inputs[1])
    b = context.shader(node.inputs[2])
    fac = node.inputs[0]
    source, output = linked_output(fac)
    if source is not None and source.type == 'FRESNEL':
        _warn_normal(source, context)
        return Mix(a, b, mode="fresnel", ior=ior_or_default(context.value(source.inputs["IOR"])))
    if source is not None and source.type == 'LAYER_WEIGHT':
        _warn_normal(source, context)
        blend = min(max(context.value(source.inputs["Blend"]), 0.0), 1.0)
        if output.name == "Facing":
            return Mix(a, b, mode="facing", ior=blend)
        # Layer Weight's Fresnel is the Fresnel node's with IOR 1 / (1 - blend).
        return Mix(a, b, mode="fresnel", ior=1.0 / max(1.0 - blend, 1e-5))
    value, texture, channel, mean = context.factor(fac)
    return mix(a, b, value, texture, channel, mean)


def _warn_normal(node, context):
    socket = input_socket(node, "Normal")
    if socket is not None and socket.is_linked:
        context(f"the Normal input of {node.bl_label} '{node.name}' is ignored")


def _add_shader(node, context):
    a = context.shader(node.inputs[0])
    b = context.shader(node.inputs[1])
    for emitter, other in ((a, b), (b, a)):
        if _emission_only(emitter):
            return with_emission(other, emitter.emission)

    def approximate():
        context(f"Add Shader '{node.name}': a Principled BSDF's weight doubled is "
                "approximated (its specular layer is not scaled)")

    return Mix(_scaled(a, 2.0, approximate), _scaled(b, 2.0, approximate), 0.5)


def _emission_only(tree):
    return (isinstance(tree, MaterialData) and tree.kind == "diffuse" and
            max(tree.color) == 0.0 and tree.color_texture < 0)


def _scaled(tree, k, approximate):
    """tree with its weight times k: colours and emission scaled."""
    if isinstance(tree, Mix):
        return replace(tree, a=_scaled(tree.a, k, approximate),
                       b=_scaled(tree.b, k, approximate))
    linear = (tree.kind in ("diffuse", "translucent", "transparent") or
              (tree.kind == "conductor" and not tree.schlick) or
              (tree.kind == "dielectric" and tree.tint_reflection))
    if not linear:
        approximate()
    return replace(tree, color=tuple(k * c for c in tree.color),
                   emission=tuple(k * e for e in tree.emission))


SURFACE_CONVERTERS = {
    'BSDF_PRINCIPLED': convert_principled,
    'BSDF_DIFFUSE': _diffuse,
    'BSDF_GLOSSY': _glossy,          # 4.0+ merged Anisotropic into Glossy
    'BSDF_ANISOTROPIC': _glossy,     # 3.x
    'BSDF_GLASS': _glass,
    'BSDF_REFRACTION': _refraction,
    'BSDF_TRANSLUCENT': _translucent,
    'BSDF_TRANSPARENT': _transparent,
    'EMISSION': _emission_node,
    'MIX_SHADER': _mix_shader,
    'ADD_SHADER': _add_shader,
}


_EMISSION_COLORS = {'EMISSION': ("Color",), 'BSDF_PRINCIPLED': ("Emission Color", "Emission")}


def emission_texture_of(surface_socket, context):
    """The texture index of the image on an Emission node's or a Principled BSDF's emission
    colour behind a material's Surface (the renderer applies it to the whole material, as
    the normal map), or -1; a second, different image warns and is left out."""
    found = -1
    for node in shader_nodes(surface_socket):
        socket = input_socket(node, *_EMISSION_COLORS.get(node.type, ()))
        image_node = emission_image(socket, context) if socket is not None else None
        if image_node is None:
            continue
        index = image_texture_index(image_node, context, context.textures)
        if found < 0:
            found = index
        elif index != found:
            context(f"{node.bl_label} '{node.name}' has an emission image other than the "
                    "material's first; the first is used for the whole material")
    return found


# The tree as the module's list.

def _expected_factor(node):
    """The factor's mean: the constant times the texture's mean, or Fresnel / Layer
    Weight's facing averaged over cosine-weighted directions (for the emission a mix
    starts photons with; what the eye sees is the leaf's own)."""
    if node.mode == "constant":
        return node.factor * (node.mean_texel if node.texture >= 0 else 1.0)
    if node.mode == "facing":
        blend = min(node.ior, 1.0 - 1e-5)
        b = 2.0 * blend if blend < 0.5 else 0.5 / (1.0 - blend)
        return 1.0 - 2.0 / (b + 2.0)
    steps = 64
    return sum(2.0 * c * _fresnel(c, node.ior) / steps
               for c in ((i + 0.5) / steps for i in range(steps)))


def _fresnel(cos_i, ior):
    """Unpolarized Fresnel reflectance of a dielectric of relative index ior."""
    sin2_t = (1.0 - cos_i * cos_i) / (ior * ior)
    if sin2_t >= 1.0:
        return 1.0
    cos_t = math.sqrt(1.0 - sin2_t)
    rs = (cos_i - ior * cos_t) / (cos_i + ior * cos_t)
    rp = (ior * cos_i - cos_t) / (ior * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def _expected_emission(tree):
    if isinstance(tree, Mix):
        f = _expected_factor(tree)
        ea, eb = _expected_emission(tree.a), _expected_emission(tree.b)
        return tuple((1.0 - f) * x + f * y for x, y in zip(ea, eb))
    return tree.emission


def _depth(tree):
    if isinstance(tree, Mix):
        return 1 + max(_depth(tree.a), _depth(tree.b))
    return 0


def _limit_depth(tree, levels, warn):
    """tree with at most `levels` Mix levels: deeper mixes become their more likely
    part, with a warning."""
    if not isinstance(tree, Mix):
        return tree
    if levels == 0:
        warn(f"Mix shaders nest deeper than {MAX_MIX_DEPTH} levels; the deepest render "
             "as their more likely shader")
        likely = tree.b if _expected_factor(tree) >= 0.5 else tree.a
        return _limit_depth(likely, 0, warn)
    return replace(tree, a=_limit_depth(tree.a, levels - 1, warn),
                   b=_limit_depth(tree.b, levels - 1, warn))


def flatten(tree):
    """The tree as MaterialData entries, root first; shared parts appear once."""
    entries, index = [], {}

    def visit(node):
        key = id(node)
        if key in index:
            return index[key]
        k = index[key] = len(entries)
        entries.append(None)
        if isinstance(node, Mix):
            a, b = visit(node.a), visit(node.b)
            entries[k] = MaterialData(
                "mix", (0.0, 0.0, 0.0), emission=_expected_emission(node), mix_a=a, mix_b=b,
                mix_factor=node.factor, mix_texture=node.texture, mix_channel=node.channel,
                mix_mode=node.mode, mix_ior=node.ior)
        else:
            entries[k] = node
        return k

    visit(tree)
    return entries
