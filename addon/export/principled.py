"""Principled BSDF onto the renderer's lobes, for both of Blender's versions of the node:
v1 (Blender 3.x: Specular, Transmission Roughness, Clearcoat, Sheen) and v2 (4.x:
Specular IOR Level, Transmission Weight, Coat, Sheen Weight).

The node is a tree of Mix materials, as Cycles composes its closures:

    Mix(Transparent, ...)                          alpha (when below 1 or textured)
      Mix(Fresnel(coat IOR), base,                 the coat (when its weight is > 0)
          Mix(coat weight, base, white GGX of the coat's roughness))
        base = Mix(metallic, Mix(transmission, plastic, glass), metal)

- metal: a GGX conductor with Schlick Fresnel from the base colour, and v2's F82 tint from
  its Specular Tint (as Cycles 4.x: reflectance at about 82 degrees is Schlick's times the
  tint); v2's tint of the dielectric reflection is not modelled (warned);
- glass: a GGX dielectric tinting its transmission, and not its reflection: v2 by the
  square root of the base colour at each refraction (Cycles 4.x), v1 by the base colour;
  v1's glass reflection starts at lerp(white, base colour, Specular Tint), white at the
  default tint 0 (Cycles 3.x's principled_v1_glass_refl); Specular Tint is warned about;
- plastic, v2: a white GGX dielectric layer over a Lambert base of the base colour,
  energy conserving (as 4.x layers them), its index from IOR scaled by Specular IOR
  Level (F0 times 2 level, as Cycles 4.x does);
- plastic, v1: Cycles 3.x adds a Fresnel-weighted white specular to a diffuse it does
  not attenuate, so v1 is that sum: Mix(0.5, Lambert of twice the base colour,
  Mix(Fresnel, nothing, GGX reflector of colour 2)), both weights doubled, the index from
  Specular (F0 = 0.08 specular). Its Disney diffuse's retro-reflection is Lambert here;
- coat: approximated by a Fresnel-weighted choice of a white GGX reflector (Fresnel of
  the coat's IOR at the view direction, times its weight: v1's clearcoat weight is a
  quarter of Clearcoat at IOR 1.5, as Cycles 3.x scales it). Tint and the coat's
  darkening of the base are not modelled: a warning says so.

The Fresnel weights of the v1 specular and of the coat are "layer_fresnel": their index seen
from the front on both sides, as Cycles sets up those closures, where a Fresnel node inverts it
behind. Inverted, the inside of a closed mesh reflected totally beyond 42 degrees, and v1's
doubled specular made it a furnace of albedo near 1.8 (tests/python/test_layer_fresnel.py).

Sheen, subsurface, anisotropy, thin film and the coat's own normal have no counterpart yet:
each is left out with a warning naming the material and the node (the Normal input is read by
normal_map.py). Emission is added to every lobe below the alpha (Principled's emission is
covered by its alpha, as in Cycles).
"""

import math

from dataclasses import replace

from .lobe_tree import (BLACK, Mix, distribution, emission, ior_or_default, mix,
                        with_emission)
from .node_inputs import input_socket
from .scene_data import MaterialData

TRANSPARENT = MaterialData("transparent", (1.0, 1.0, 1.0))


def convert_principled(node, context):
    v2 = "Specular IOR Level" in node.inputs
    label = f"Principled BSDF '{node.name}'"

    def warn(message):
        context(f"{label}: {message}")

    base_color, base_texture = context.color(node.inputs["Base Color"])
    base_vertex = context.vertex_color(node.inputs["Base Color"])
    roughness = context.roughness(node.inputs["Roughness"])
    multiscatter = distribution(node, context)
    ior = ior_or_default(context.value(node.inputs["IOR"]))
    if v2:
        level = max(context.value(node.inputs["Specular IOR Level"]), 0.0)
        layer_ior = _ior_from_f0(min(_f0(ior) * 2.0 * level, 0.999), ior < 1.0)
        glass_ior = layer_ior
        specular_tint = tuple(min(max(c, 0.0), 1.0)
                              for c in context.value_color(node, "Specular Tint"))
        metallic_only = (not node.inputs["Metallic"].is_linked
                         and node.inputs["Metallic"].default_value >= 1.0)
        if _non_white(specular_tint) and not metallic_only:
            warn("Specular Tint of the dielectric reflection is not rendered (the metal's "
                 "F82 tint is)")
    else:
        specular = max(context.value(node.inputs["Specular"]), 0.0)
        layer_ior = _ior_from_f0(min(0.08 * specular, 0.999), False)
        glass_ior = ior
        if context.value(node.inputs["Specular Tint"]) > 0.0:
            warn("Specular Tint is not rendered")

    def lobe(kind, **kwargs):
        return MaterialData(kind, base_color, color_texture=base_texture,
                            vertex_color=base_vertex, multiscatter=multiscatter,
                            **{**roughness, **kwargs})

    metal = lobe("conductor", schlick=True)
    if v2 and _non_white(specular_tint):
        metal = replace(metal, f82_tint=specular_tint)
    if abs(layer_ior - 1.0) < 1e-6:
        # No specular (Specular or Specular IOR Level 0): the diffuse base alone.
        plastic = MaterialData("diffuse", base_color, color_texture=base_texture,
                               vertex_color=base_vertex)
    elif v2:
        plastic = lobe("plastic", ior=layer_ior)
    else:
        diffuse = MaterialData("diffuse", tuple(2.0 * c for c in base_color),
                               color_texture=base_texture, vertex_color=base_vertex)
        specular = MaterialData("conductor", (2.0, 2.0, 2.0), multiscatter=multiscatter,
                                **roughness)
        plastic = Mix(diffuse, Mix(BLACK, specular, mode="layer_fresnel", ior=layer_ior))
    transmission = context.factor(input_socket(node, "Transmission Weight", "Transmission"))
    glass = lobe("dielectric", ior=glass_ior)
    if v2:
        # Warned only where the glass is used (a Transmission of 0 leaves it out).
        glass = _v2_glass_tint(glass, warn if transmission[0] > 0.0 else None)
    else:
        glass = _v1_transmission_roughness(node, context, glass, multiscatter, warn)

    metallic = context.factor(node.inputs["Metallic"])
    tree = mix(mix(plastic, glass, *transmission), metal, *metallic)
    tree = _coat(node, context, v2, tree, multiscatter, warn)

    _warn_unmodelled(node, context, v2, warn)
    radiance = emission(node, "Emission Color", "Emission", context)
    if max(radiance) > 0.0:
        tree = with_emission(tree, radiance)
    alpha = context.factor(node.inputs["Alpha"])
    return mix(TRANSPARENT, tree, *alpha)


def _v2_glass_tint(glass, warn):
    """Cycles 4.x tints each refraction of the Principled glass by the square root of the
    base colour (so that light passing into and out of an object keeps the base colour);
    a textured or vertex base colour is read as it is and tints each refraction by itself
    (`warn`, unless None, says so)."""
    if glass.color_texture >= 0 or glass.vertex_color:
        if warn:
            warn("the glass's transmission is tinted by the textured Base Color at each "
                 "refraction, where Blender 4.x tints by its square root")
        return glass
    return replace(glass, color=tuple(math.sqrt(max(c, 0.0)) for c in glass.color))


def _v1_transmission_roughness(node, context, glass, multiscatter, warn):
    """Blender 3.x refracts with roughness 1 - (1 - roughness)(1 - transmission
    roughness), except with Multiscatter GGX above roughness 0.05, where its glass
    ignores Transmission Roughness."""
    socket = node.inputs["Transmission Roughness"]
    t = min(max(context.value(socket), 0.0), 1.0)
    if t <= 0.0 or (multiscatter and glass.roughness > 0.05):
        return glass
    warn("Transmission Roughness also roughens the glass's reflection here")
    r = glass.roughness if glass.roughness_texture < 0 else 0.5
    if glass.roughness_texture >= 0:
        warn("a textured Roughness with Transmission Roughness: the glass uses a constant "
             "roughness")
    return replace(glass, roughness=1.0 - (1.0 - r) * (1.0 - t), roughness_texture=-1)


def _coat(node, context, v2, tree, multiscatter, warn):
    if v2:
        weight = context.value(node.inputs["Coat Weight"])
        coat_roughness = context.roughness(node.inputs["Coat Roughness"])
        coat_ior = ior_or_default(context.value(node.inputs["Coat IOR"]))
        tinted = _non_white(context.value_color(node, "Coat Tint"))
    else:
        weight = 0.25 * context.value(node.inputs["Clearcoat"])
        coat_roughness = context.roughness(node.inputs["Clearcoat Roughness"])
        coat_ior = 1.5
        tinted = False
    if weight <= 0.0:
        return tree
    warn("the coat is approximated by a Fresnel-weighted white reflection; its darkening "
         "of the layers below" + (" and its tint are" if tinted else " is") + " not rendered")
    coat = MaterialData("conductor", (1.0, 1.0, 1.0), multiscatter=multiscatter,
                        **coat_roughness)
    return Mix(tree, mix(tree, coat, min(weight, 1.0)), mode="layer_fresnel", ior=coat_ior)


def _warn_unmodelled(node, context, v2, warn):
    def active(*names):
        socket = input_socket(node, *names)
        return socket is not None and (socket.is_linked or socket.default_value > 0.0)

    if active("Sheen Weight", "Sheen"):
        warn("sheen is not rendered")
    if active("Subsurface Weight", "Subsurface"):
        warn("subsurface scattering is rendered as diffuse reflection")
    if active("Anisotropic"):
        warn("anisotropy is not supported; rendering isotropic")
    if active("Thin Film Thickness"):
        warn("thin film is not rendered")
    # Its Normal input is read by normal_map.py with every BSDF's.
    for name in ("Coat Normal", "Clearcoat Normal"):
        socket = input_socket(node, name)
        if socket is not None and socket.is_linked:
            warn(f"its {name} input is ignored (the coat shares the base's normal)")


def _f0(ior):
    return ((ior - 1.0) / (ior + 1.0)) ** 2


def _ior_from_f0(f0, inverted):
    """The index whose normal-incidence reflectance is f0 (its inverse for v2's IOR
    below 1, as Cycles inverts it)."""
    s = math.sqrt(max(f0, 0.0))
    ior = (1.0 + s) / (1.0 - s)
    return 1.0 / ior if inverted else ior


def _non_white(color):
    return any(abs(c - 1.0) > 1e-4 for c in color)
