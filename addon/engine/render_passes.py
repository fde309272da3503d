"""Render passes beside Combined (docs/passes.md): which ones the view layer asks for, their
registration with Blender (RenderEngine.update_render_passes) and their pixels in the
RenderResult. The module's render_passes() is the one list of names, Blender's included."""

from ..compat import PASS_NAME_KEY

# Blender's type for a pass of 1 (Depth) or 3 channels, by its channel letters.
_PASS_TYPES = {"Z": 'VALUE', "XYZ": 'VECTOR', "RGB": 'COLOR'}


# The light split's passes (View Layer > Passes > GLSLPPM Light Split).
LIGHT_SPLIT = frozenset({"direct", "indirect", "caustics"})


def requested(view_layer):
    """The module's names of the passes the view layer enables, in the module's order."""
    own = view_layer.glslppm
    wanted = set()
    if view_layer.use_pass_z:
        wanted.add("depth")
    if view_layer.use_pass_normal:
        wanted.add("normal")
    if own.use_pass_denoising_data:
        wanted |= {"denoising_normal", "denoising_albedo"}
    if view_layer.use_pass_emit:
        wanted.add("emission")
    if view_layer.use_pass_environment:
        wanted.add("environment")
    if own.use_pass_light_split:
        wanted |= LIGHT_SPLIT
    return wanted


# Blender's view-layer passes that GLSLPPM does not render (Cycles' and EEVEE's), by the
# property that asks for each: a user who comes with them on is told, not left to find them
# missing in the compositor. getattr: each Blender has its own set.
_NOT_RENDERED = (
    ("use_pass_vector", "Vector"), ("use_pass_mist", "Mist"),
    ("use_pass_position", "Position"), ("use_pass_uv", "UV"),
    ("use_pass_object_index", "Object Index"), ("use_pass_material_index", "Material Index"),
    ("use_pass_diffuse_direct", "Diffuse Direct"),
    ("use_pass_diffuse_indirect", "Diffuse Indirect"),
    ("use_pass_diffuse_color", "Diffuse Color"), ("use_pass_glossy_direct", "Glossy Direct"),
    ("use_pass_glossy_indirect", "Glossy Indirect"), ("use_pass_glossy_color", "Glossy Color"),
    ("use_pass_transmission_direct", "Transmission Direct"),
    ("use_pass_transmission_indirect", "Transmission Indirect"),
    ("use_pass_transmission_color", "Transmission Color"),
    ("use_pass_ambient_occlusion", "Ambient Occlusion"), ("use_pass_shadow", "Shadow"),
    ("use_pass_cryptomatte_object", "Cryptomatte Object"),
    ("use_pass_cryptomatte_material", "Cryptomatte Material"),
    ("use_pass_cryptomatte_asset", "Cryptomatte Asset"),
)


def not_rendered(view_layer):
    """Blender's names of the passes the view layer enables that GLSLPPM does not render."""
    return [name for prop, name in _NOT_RENDERED if getattr(view_layer, prop, False)]


def catalog(native, view_layer):
    """(module name, Blender's name, channels, channel letters) of each requested pass."""
    wanted = requested(view_layer)
    return [(p["name"], p[PASS_NAME_KEY], p["channels"], p["channel_names"])
            for p in native.render_passes() if p["name"] in wanted]


def register(engine, native, scene, view_layer):
    """What update_render_passes registers: Combined, then the requested passes (without
    the module, Combined alone)."""
    if view_layer.use_pass_combined:
        engine.register_pass(scene, view_layer, "Combined", 4, "RGBA", 'COLOR')
    if native is None:
        return
    for _, blender_name, channels, letters in catalog(native, view_layer):
        engine.register_pass(scene, view_layer, blender_name, channels, letters,
                             _PASS_TYPES[letters])
    for name in light_group_names(view_layer):
        engine.register_pass(scene, view_layer, light_group_pass(name), 3, "RGB", 'COLOR')


def light_group_names(view_layer):
    """The view layer's Light Groups (Blender 3.2+; docs/light_groups.md), in order."""
    return [group.name for group in getattr(view_layer, "lightgroups", None) or ()]


def light_group_pass(name):
    """Cycles' name of a light group's pass."""
    return "Combined_" + name


def result_group_passes(result, view_layer):
    """{light group name: the result's RenderPass} for the groups a result has."""
    by_name = {p.name: p for p in result.layers[0].passes}
    return {name: by_name[light_group_pass(name)] for name in light_group_names(view_layer)
            if light_group_pass(name) in by_name}


def result_passes(result, native, view_layer, leave_out=frozenset()):
    """{module name: the result's RenderPass} for the requested passes a result has, but
    those left out (the module does not render them: they stay empty)."""
    by_name = {p.name: p for p in result.layers[0].passes}
    return {name: by_name[blender_name]
            for name, blender_name, _, _ in catalog(native, view_layer)
            if blender_name in by_name and name not in leave_out}
