"""Blender's light groups (3.2+; docs/light_groups.md): View Layer > Light Groups, each
light's, emissive object's and the world's "Light Group" field, as indices into the view
layer's list (-1: none, or a name the list does not hold, as Cycles ignores it)."""


def group_indices(view_layer):
    """{group name: index} of the view layer's light groups ({} before Blender 3.2)."""
    groups = getattr(view_layer, "lightgroups", None) or ()
    return {group.name: index for index, group in enumerate(groups)}


def group_of(datablock, indices):
    """The light group index of an object or world, -1 for none."""
    return indices.get(getattr(datablock, "lightgroup", "") or "", -1)
