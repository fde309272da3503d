"""Light groups as artists use them (issue 33, docs/light_groups.md): the compositor
re-balances two lights from their group passes, and the group passes are Cycles' own.

The scene is test_light_groups' plane under a warm "key" and a cool "fill" point light."""

import os

import bpy
import numpy as np

import helpers
from test_light_groups import two_light_scene
from test_passes import compositor_tree, render_multilayer

SIZE = (48, 36)
KEY, FILL = 300.0, 200.0         # the lights' watts
KEY_GAIN, FILL_GAIN = 0.5, 0.25  # the compositor's weights (colour inputs stay within [0, 1])


def plane_scene(key_energy=KEY, fill_energy=FILL, groups=True):
    """test_light_groups' plane under the two point lights at these powers."""
    return two_light_scene(groups=groups, key_energy=key_energy, fill_energy=fill_energy)


def stop_compositing(scene):
    """Back to no compositor (the next tests render the plain Combined)."""
    scene.render.use_compositing = False
    if hasattr(scene, "compositing_node_group"):
        scene.compositing_node_group = None
    else:
        scene.use_nodes = False


def render_rgb(name):
    """The image a render saves (the composite where the compositor is on), as (H, W, 3)."""
    native = helpers.load_native()
    scene = bpy.context.scene
    helpers.compat().set_exr_format(scene.render.image_settings, multilayer=False)
    path = os.path.join(helpers.OUT, f"{name}.exr")
    scene.render.filepath = path
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    channels = native.read_exr_channels(path)
    return np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)


def group_rgb(channels, name):
    return np.stack([channels[f"ViewLayer.{name}.{c}"] for c in "RGB"],
                    axis=-1).astype(np.float64)


def test_compositor_rebalances_two_light_groups_as_a_render_with_those_strengths():
    """Render Layers' Combined_key x 0.5 + Combined_fill x 0.25 (Mix nodes, into the
    composite) against a render whose lights are 150 W and 50 W: the same image within the
    renders' own noise. Each group's mean is its light alone's within 0.2% at 64 passes
    (test_light_groups): the means within 0.6% (measured 0.12% / 0.19% / 0.30% per channel
    on 3.4.1, 4.3.2 and 5.2.2 alike), so a 1% bias fails; every 3x3 region within 3% of the
    brightest (measured 1.05%; a 16 x 12 px region's noise is about 1%)."""
    scene = plane_scene()
    tree, layers, composite = compositor_tree(scene)
    compat = helpers.compat()
    parts = []
    for name, gain in (("key", KEY_GAIN), ("fill", FILL_GAIN)):
        node, a, b, result = compat.color_mix_node(tree, 'MULTIPLY')
        tree.links.new(layers.outputs[f"Combined_{name}"], a)
        b.default_value = (gain, gain, gain, 1.0)
        parts.append(result)
    node, a, b, total = compat.color_mix_node(tree, 'ADD')
    tree.links.new(parts[0], a)
    tree.links.new(parts[1], b)
    tree.links.new(total, composite.inputs["Image"])
    try:
        mixed = render_rgb("light_groups_composited")
    finally:
        stop_compositing(scene)
    plane_scene(KEY * KEY_GAIN, FILL * FILL_GAIN, groups=False)
    relit = render_rgb("light_groups_relit")
    _, _, region_error, mean_error = helpers.region_comparison(mixed, relit)
    ratio = mixed.mean(axis=(0, 1)) / relit.mean(axis=(0, 1))
    print(f"  composited / relit: mean per channel {np.round(ratio, 4).tolist()}, worst "
          f"region {region_error:.4f}")
    assert relit.mean() > 0.01
    assert mean_error < 0.006, mean_error
    assert np.all(np.abs(ratio - 1.0) < 0.006), ratio
    assert region_error < 0.03, region_error
    # The weights did act: the composite is not the plain Combined (0.5 and 0.25 of it).
    plane_scene()
    plain = render_rgb("light_groups_plain")
    assert mixed.mean() < 0.5 * plain.mean()


def test_light_group_passes_match_cycles():
    """Combined_key and Combined_fill against Cycles' passes of the same names (Cycles, 256
    samples, light paths at 16, no clamping): each group's mean within 0.8% per channel
    (the issue asks 2%; measured under 3.4: 0.9985 and 1.0019, each render's noise about
    0.2% on the mean, so a 1% bias fails) and every 3x3 region within 4% of the brightest
    (Cycles' noise at 256 samples and ours at 64 passes, each about 1% on a region).
    The lights have Blender's radius 0.25, 2 and 3 m above the plane: Cycles lights them
    from a disc facing the lit point (3.x; 4.x and 5.x with Soft Falloff on, the default),
    1.3% darker under the fill light than the sphere the module had (Light.facing_disc)."""
    plane_scene()
    ours = render_multilayer("light_groups_ours")
    helpers.setup_cycles(samples=256)
    theirs = render_multilayer("light_groups_cycles", engine='CYCLES')
    for name in ("key", "fill"):
        a, b = group_rgb(ours, f"Combined_{name}"), group_rgb(theirs, f"Combined_{name}")
        ratio = a.mean(axis=(0, 1)) / b.mean(axis=(0, 1))
        _, _, region_error, _ = helpers.region_comparison(a, b)
        print(f"  {name}: ours / Cycles per channel {np.round(ratio, 4).tolist()}, worst "
              f"region {region_error:.4f}")
        assert b.mean() > 0.005, name
        assert np.all(np.abs(ratio - 1.0) < 0.008), (name, ratio)
        assert region_error < 0.04, (name, region_error)
