"""Light linking and shadow linking through Blender (docs/light_linking.md; Blender 4.0+'s
Object > Shading > Light Linking / Shadow Linking): a light-linked scene against Cycles.
Blender 3.4 has no Object.light_linking: there the test checks that the add-on exports no
links and renders the scene as it is (it does not skip)."""

import bpy
import numpy as np

import helpers
from helpers import (BLENDER_4, add_camera, add_light, add_quad, diffuse_material,
                     emission_material, node_material)

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


PANEL_STRENGTH = 4.0


def mirror_under_a_blocked_panel():
    """A perfect mirror floor (Glossy, white, roughness 0) seen from above through two
    surfaces hidden from the camera: a black plane at z = 2 and an emissive panel (strength
    PANEL_STRENGTH, facing down) at z = 3 above it. The mirror shows the plane's underside
    where the panel is behind it. With Blender 4.0+ the panel's blocker collection excludes
    the plane. Returns whether the link was set."""
    scene = helpers.reset_scene(size=SIZE)
    add_quad("Mirror", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)],
             node_material("Mirror", "ShaderNodeBsdfGlossy", Color=(1.0, 1.0, 1.0, 1.0),
                           Roughness=0.0))
    plane = add_quad("Plane", [(-3, -3, 2), (-3, 3, 2), (3, 3, 2), (3, -3, 2)],
                     diffuse_material("Black", (0.0, 0.0, 0.0)))
    panel = add_quad("Panel", [(0.5, -1, 3), (0.5, 1, 3), (2.5, 1, 3), (2.5, -1, 3)],
                     emission_material("Panel", (1.0, 1.0, 1.0), PANEL_STRENGTH))
    for obj in (plane, panel):
        obj.visible_camera = False
    add_camera((0, 0, 8), (0, 0, 0))
    if not BLENDER_4:
        return scene, False
    collection = bpy.data.collections.new("panel_blockers")
    collection.objects.link(plane)
    collection.collection_objects[0].light_linking.link_state = 'EXCLUDE'
    panel.light_linking.blocker_collection = collection
    return scene, True


def test_a_mirror_shows_an_emitter_behind_a_blocker_excluded_from_its_shadow_as_cycles():
    """Cycles' shadow linking holds for emission met past a mirror too (a dedicated ray goes on
    past the surface the path meets, through blockers excluded from the emitter's shadow).
    Blender 4.0+: the mirror shows the panel through the plane in both engines: image mean
    within 2% of Cycles' (both 1-px box filters, 64 samples: the mirror is perfect, so the
    noise is the pixels' coverage of the panel's edge alone), every 3x3 region within 3% of
    the brightest, and the panel's reflection (the pixels wholly inside it) at PANEL_STRENGTH
    within 1e-3. Before session 19 GLSLPPM showed the plane black there (mean error 100%).
    Blender 3.4 (no links): the plane hides the panel in both engines: both images black."""
    scene, linked = mirror_under_a_blocked_panel()
    data = helpers.export()
    assert bool(data.shadow_link_blocks) == linked, data.shadow_link_blocks
    helpers.load_native()
    scene.glslppm.passes = 16
    ours = helpers.render_image("shadow_linked_mirror_glslppm", 'GLSLPPM')
    reference = helpers.render_cycles_box_filter("shadow_linked_mirror", samples=64)
    if not linked:
        assert np.abs(ours[..., :3]).max() < 1e-6 and np.abs(reference[..., :3]).max() < 1e-6
        return
    a, b, region_error, mean_error = helpers.region_comparison(ours, reference, grid=3)
    inside = reference[..., :3].min(axis=-1) > PANEL_STRENGTH * (1 - 1e-4)
    print(f"  mirror past an excluded blocker: mean error {mean_error:.4f}, worst region "
          f"{region_error:.4f}, {int(inside.sum())} pixels inside the panel's reflection, "
          f"there GLSLPPM {ours[..., :3][inside].min():.5f}..{ours[..., :3][inside].max():.5f}")
    assert inside.sum() >= 40
    assert np.allclose(ours[..., :3][inside], PANEL_STRENGTH, rtol=1e-3)
    assert mean_error <= 0.02, mean_error
    assert region_error <= 0.03, region_error


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
