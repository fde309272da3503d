"""Light linking and shadow linking through Blender (docs/light_linking.md; Blender 4.0+'s
Object > Shading > Light Linking / Shadow Linking): a light-linked scene against Cycles.
Blender 3.4 has no Object.light_linking: there the test checks that the add-on exports no
links and renders the scene as it is (it does not skip)."""

import bpy
import numpy as np

import helpers
from helpers import BLENDER_4, add_camera, add_light, add_quad, diffuse_material

SIZE = (48, 36)


def linked_scene():
    """Two grey panels side by side on the ground seen from above, a small dark square
    floating over the right one, a warm point light "key" and a cool one "fill". With
    Blender 4.0+, the key's receiver collection excludes the left panel and its blocker
    collection excludes the square: the left panel is lit by the fill alone, and the square
    shadows only the fill. Returns whether the links were set."""
    scene = helpers.reset_scene(size=SIZE)
    grey = diffuse_material("Grey", (0.6, 0.6, 0.6))
    left = add_quad("Left", [(-4, -3, 0), (-0.1, -3, 0), (-0.1, 3, 0), (-4, 3, 0)], grey)
    add_quad("Right", [(0.1, -3, 0), (4, -3, 0), (4, 3, 0), (0.1, 3, 0)], grey)
    square = add_quad("Square", [(1.2, -0.4, 1.0), (2.0, -0.4, 1.0), (2.0, 0.4, 1.0),
                                 (1.2, 0.4, 1.0)], diffuse_material("Dark", (0.1, 0.1, 0.1)))
    key = add_light('POINT', 300.0, location=(0.0, 0.5, 3.0), color=(1.0, 0.7, 0.4))
    add_light('POINT', 200.0, location=(3.0, -0.5, 2.5), color=(0.4, 0.7, 1.0))
    add_camera((0, 0, 9), (0, 0, 0))
    if not BLENDER_4:
        return scene, False
    for kind, obj in (("receiver", left), ("blocker", square)):
        collection = bpy.data.collections.new(f"key_{kind}s")
        collection.objects.link(obj)
        collection.collection_objects[0].light_linking.link_state = 'EXCLUDE'
        setattr(key.light_linking, f"{kind}_collection", collection)
    return scene, True


def test_light_linked_scene_matches_cycles():
    """Blender 4.0+: the add-on exports one link set and the tables, and the render matches
    Cycles' (128 samples): the image mean within 2%, every region of a 3x3 grid within 5% of
    the brightest region (noise: both engines' at these sizes; the regions hold 192 pixels).
    The left third, lit by the fill alone, must be darker than the right third by more than
    the bound, so that ignoring the links fails. Blender 3.4: no links are exported (it has no
    light_linking) and the render is the unlinked scene's, checked against Cycles alike."""
    scene, linked = linked_scene()
    data = helpers.export()
    if linked:
        assert data.light_link_receives and len(data.light_link_receives) == 3, \
            data.light_link_receives
        assert [light.light_link_set for light in data.lights] == [1, 0]
    else:
        assert data.light_link_receives == [] and data.shadow_link_blocks == []
    helpers.load_native()
    scene.glslppm.passes = 48
    scene.glslppm.photons_per_pass = 32768
    ours = helpers.render_image("light_linking_glslppm", 'GLSLPPM')
    helpers.setup_cycles(samples=128)
    reference = helpers.render_image("light_linking_cycles", 'CYCLES')
    scene.render.engine = 'GLSLPPM'
    a, b, region_error, mean_error = helpers.region_comparison(ours, reference, grid=3)
    print(f"  light linking (links {linked}): mean error {mean_error:.4f}, worst region "
          f"{region_error:.4f}; regions GLSLPPM {np.round(a, 4).tolist()} Cycles "
          f"{np.round(b, 4).tolist()}")
    assert mean_error <= 0.02, mean_error
    assert region_error <= 0.05, region_error
    if linked:
        left, right = b[:, 0].mean(), b[:, 2].mean()
        assert left < 0.8 * right, (left, right)


def test_blender_before_4_says_light_linking_needs_4():
    """Blender 3.4 has no light linking (its files' links are dropped): for GLSLPPM the Object
    tab has a Light Linking panel saying that it needs Blender 4.0, and no other engine shows
    it. From 4.0 the panel is not registered: Blender's own Light Linking and Shadow Linking
    panels draw the links, which GLSLPPM renders (test_light_linked_scene_matches_cycles)."""
    from types import SimpleNamespace
    panel = getattr(bpy.types, "OBJECT_PT_glslppm_light_linking", None)
    if BLENDER_4:
        assert panel is None
        return
    assert panel is not None
    scene, _ = linked_scene()
    obj = scene.objects["Left"]
    assert panel.poll(SimpleNamespace(engine='GLSLPPM', object=obj))
    assert not panel.poll(SimpleNamespace(engine='CYCLES', object=obj))
    assert not panel.poll(SimpleNamespace(engine='GLSLPPM', object=None))
    module = __import__(panel.__module__, fromlist=["MESSAGE"])
    assert "Blender 4.0" in module.MESSAGE
