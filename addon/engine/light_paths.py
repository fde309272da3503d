"""The bounce limits a render follows: Blender's Light Paths settings, as Cycles reads them.

Cycles keeps them on scene.cycles (Total, Diffuse, Glossy, Transmission; docs/bounces.md says
how the renderer counts a photon-mapped path against them). Where the Cycles add-on is off,
scene.glslppm holds the same four under Cycles' names and defaults. Cycles' Transparent and
Volume limits have no counterpart: cut-outs and hidden surfaces count against the surfaces a
path may meet (Total + 1), and the renderer has no volumes yet.
"""

# The module's Settings keywords, by Cycles' property names.
_KEYWORDS = {"max_bounces": "max_bounces", "diffuse_bounces": "max_diffuse_bounces",
             "glossy_bounces": "max_glossy_bounces",
             "transmission_bounces": "max_transmission_bounces"}


def light_paths_owner(scene):
    """scene.cycles where the Cycles add-on is registered, else scene.glslppm."""
    cycles = getattr(scene, "cycles", None)
    if cycles is not None and hasattr(cycles, "diffuse_bounces"):
        return cycles
    return scene.glslppm


def bounce_limits(settings):
    """The module Settings' keywords for the limits of the scene that owns settings
    (scene.glslppm, or a view of it that reads through)."""
    owner = light_paths_owner(settings.id_data)
    return {keyword: int(getattr(owner, name)) for name, keyword in _KEYWORDS.items()}


def old_max_bounces_warning(scene):
    """A file saved before the add-on followed Cycles' Light Paths may have set GLSLPPM's own
    Max Bounces; with Cycles on, that value is no longer read. None if nothing to say."""
    owner = light_paths_owner(scene)
    settings = scene.glslppm
    if owner is settings or not settings.is_property_set("max_bounces"):
        return None
    if settings.max_bounces == owner.max_bounces:
        return None
    return (f"GLSLPPM's own Max Bounces ({settings.max_bounces}) is no longer read: the render "
            f"follows the Light Paths panel as Cycles does (Total {owner.max_bounces}, "
            f"Diffuse {owner.diffuse_bounces}, Glossy {owner.glossy_bounces}, Transmission "
            f"{owner.transmission_bounces})")
