"""Blender's light linking and shadow linking (4.0+; docs/light_linking.md): each light's and
emissive object's Object > Shading > Light Linking (receiver_collection) and Shadow Linking
(blocker_collection), as the module's tables (Scene.light_link_receives,
Scene.shadow_link_blocks).

Every emitter object with a collection gets a link set (1, 2, ...; emitters that share their
two collections share one), every other emitter set 0, which reaches and is shadowed by
everything. Every object gets a row: for each set whether that set's light reaches it and
whether it shadows it; objects alike share a row, row 0 being "everything".

A collection's entries (objects and child collections, recursively) are each INCLUDE or
EXCLUDE (CollectionLightLinking.link_state). As Cycles reads them: with some INCLUDE, only
the included objects minus the excluded; with only EXCLUDE, every object but those.
Blender before 4.0 has no Object.light_linking: nothing to export, and no links."""

ALL = 0xFFFFFFFF
MAX_SETS = 32  # the module's MAX_LIGHT_LINK_SETS: bits of a mask


def _entries(collection):
    """{object name: included?} for a linking collection's entries, the child collections'
    objects taking their child's state (a direct entry wins over one inherited). The
    entries' states (CollectionObject, CollectionChild) run beside collection.objects and
    collection.children, in their order."""
    states = {}
    for child, entry in zip(collection.children, getattr(collection, "collection_children", ())):
        included = entry.light_linking.link_state == 'INCLUDE'
        for obj in child.all_objects:
            states.setdefault(obj.name_full, included)
    for obj, entry in zip(collection.objects, getattr(collection, "collection_objects", ())):
        states[obj.name_full] = entry.light_linking.link_state == 'INCLUDE'
    return states


class _Membership:
    """Who a linking collection lets the light reach (or lets shadow it)."""

    def __init__(self, collection):
        self.states = _entries(collection) if collection is not None else {}
        self.has_includes = any(self.states.values())

    def admits(self, name):
        state = self.states.get(name)
        if state is None:
            return not self.has_includes
        return state


def _collections(obj):
    linking = getattr(obj, "light_linking", None)  # Blender 4.0+
    if linking is None:
        return None, None
    return linking.receiver_collection, linking.blocker_collection


class LightLinks:
    """The scene's links: link_set(obj) for emitters, row(obj) for everything; the tables
    once every object has asked (receives, blocks; both empty without links)."""

    def __init__(self, objects, warn):
        self._sets = {}      # (receiver name, blocker name) -> (set, receivers, blockers)
        self._by_object = {}
        for obj in objects:
            receivers, blockers = _collections(obj)
            if receivers is None and blockers is None:
                continue
            key = (receivers.name_full if receivers else None,
                   blockers.name_full if blockers else None)
            if key not in self._sets:
                if len(self._sets) + 1 >= MAX_SETS:
                    warn(f"Light linking: more than {MAX_SETS - 1} different linking "
                         f"collections; '{obj.name}' is linked to everything")
                    continue
                self._sets[key] = (len(self._sets) + 1, _Membership(receivers),
                                   _Membership(blockers))
            self._by_object[obj.name_full] = self._sets[key][0]
        self._rows = {(ALL, ALL): 0}

    def __bool__(self):
        return bool(self._sets)

    def link_set(self, obj):
        """The link set of an emitter object (0: linked to everything)."""
        return self._by_object.get(obj.name_full, 0)

    def row(self, obj):
        """The row of a receiver or blocker object."""
        receives, blocks = ALL, ALL
        for link_set, receivers, blockers in self._sets.values():
            if not receivers.admits(obj.name_full):
                receives &= ~(1 << link_set)
            if not blockers.admits(obj.name_full):
                blocks &= ~(1 << link_set)
        return self._rows.setdefault((receives, blocks), len(self._rows))

    def tables(self):
        """(light_link_receives, shadow_link_blocks): [] and [] without links."""
        if not self._sets:
            return [], []
        rows = sorted(self._rows.items(), key=lambda item: item[1])
        return [r for (r, _), _ in rows], [b for (_, b), _ in rows]
