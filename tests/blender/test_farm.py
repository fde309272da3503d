"""A frame split over farm jobs in Blender: the PPPM estimator with a pass offset per job,
the farm attributes in each EXR Blender writes, and the files merged (the module's
merge_farm_files, glslppm-merge's code) into the image of one job running every pass, its
render passes too."""

import os

import bpy
import numpy as np

import helpers
from test_passes import plane_scene, render_multilayer
from test_render import small_lit_scene

# Each pass renders bit-identically in any job; the sums' order, the divisions and the
# merge's cast to float leave a few 2^-24 (tests/python/test_pppm.py).
MERGE_BOUND = 1e-6


def render_job(name, passes, offset):
    scene = small_lit_scene(passes=passes)
    scene.glslppm.estimator = 'PPPM'
    scene.glslppm.first_pass = offset
    helpers.render_image(name)
    return os.path.join(helpers.OUT, f"{name}.exr")


def relative_difference(a, b):
    scale = np.maximum(np.abs(a), np.abs(b))
    d = np.divide(np.abs(a - b), scale, out=np.zeros_like(scale), where=scale > 0)
    return float(d.max())


def test_farm_jobs_merge_into_the_whole_frame():
    native = helpers.load_native()
    first = render_job("farm_0", 3, 0)
    second = render_job("farm_1", 3, 3)
    whole = render_job("farm_whole", 6, 0)
    headers = {path: native.read_exr(path)[1] for path in (first, second, whole)}
    assert headers[first].get("glslppm.pass_ranges") == "0-3", headers[first]
    assert headers[second]["glslppm.pass_ranges"] == "3-6"
    assert headers[whole]["glslppm.pass_ranges"] == "0-6"
    assert headers[first]["glslppm.estimator"] == "pppm"
    assert headers[first]["glslppm.scene_hash"] == headers[whole]["glslppm.scene_hash"]
    merged_path = os.path.join(helpers.OUT, "farm_merged.exr")
    attributes = native.merge_farm_files([second, first], merged_path)
    assert attributes["glslppm.pass_ranges"] == "0-6"
    merged = native.read_exr(merged_path)[0]
    expected = native.read_exr(whole)[0]
    assert merged[..., :3].mean() > 1e-3, "black farm frame"
    assert relative_difference(merged, expected) <= MERGE_BOUND
    # The same job twice overlaps: refused, naming the file and the field.
    try:
        native.merge_farm_files([first, first], merged_path)
    except ValueError as error:
        assert "glslppm.pass_ranges overlaps" in str(error) and first in str(error), error
    else:
        raise AssertionError("overlapping farm jobs were merged")


def test_farm_jobs_with_every_pass_merge_every_layer():
    """Jobs that write every render pass (a multi-layer EXR, as `-F OPEN_EXR_MULTILAYER`
    writes it) merge layer by layer into the job running every pass, under Blender's layer
    names, each channel within MERGE_BOUND as Combined is (the module's test_merge_passes
    measures the same for the glass ball's caustic)."""
    native = helpers.load_native()
    paths = {}
    for name, passes, offset in (("farm_passes_0", 3, 0), ("farm_passes_1", 3, 3),
                                 ("farm_passes_whole", 6, 0)):
        scene = plane_scene()
        scene.glslppm.estimator = 'PPPM'
        scene.glslppm.passes = passes
        scene.glslppm.first_pass = offset
        render_multilayer(name)
        paths[name] = os.path.join(helpers.OUT, f"{name}.exr")
    merged_path = os.path.join(helpers.OUT, "farm_passes_merged.exr")
    attributes = native.merge_farm_files([paths["farm_passes_1"], paths["farm_passes_0"]],
                                         merged_path)
    assert attributes["glslppm.pass_ranges"] == "0-6"
    merged = native.read_exr_channels(merged_path)
    whole = native.read_exr_channels(paths["farm_passes_whole"])
    assert set(merged) == set(whole) and "ViewLayer.Caustics.R" in merged, sorted(merged)
    worst = {name: relative_difference(merged[name], whole[name]) for name in whole}
    print(f"  worst relative difference {max(worst.values()):.2e} ({max(worst, key=worst.get)})")
    assert max(worst.values()) <= MERGE_BOUND, worst
    assert merged["ViewLayer.Direct.R"].mean() > 1e-3, "no direct light in the merged frame"


def test_device_list_in_preferences():
    """Detect Devices lists every EGL device with its vendor and a checkbox; the software
    renderer starts checked only where there is no GPU; several checked devices are used
    by PPPM scenes, the first alone by SPPM ones."""
    preferences_module = helpers.ADDON.properties.preferences
    assert preferences_module.default_use(
        [{"software": False}, {"software": True}, {"software": False}]) == [True, False, True]
    assert preferences_module.default_use([{"software": True}]) == [True]
    if helpers.SOURCE_MODE:
        raise helpers.Skip("the preferences exist for the installed add-on only")
    native = helpers.load_native()
    assert bpy.ops.glslppm.detect_devices() == {'FINISHED'}
    preferences = bpy.context.preferences.addons[helpers.ADDON_NAME].preferences
    listed = native.describe_devices()
    assert [entry.index for entry in preferences.devices] == [d["index"] for d in listed]
    for entry, device in zip(preferences.devices, listed):
        assert entry.software == device["software"]
        assert entry.vendor, f"no vendor for {entry.name}"
        assert entry.use == preferences_module.default_use(listed)[device["index"]]
    scene = small_lit_scene()
    first = preferences.devices[0]
    extra = preferences.devices.add()  # a second worker on the same device
    extra.name, extra.index, extra.use = first.name, first.index, True
    first.use = True
    try:
        assert preferences_module.render_devices(scene.glslppm) == [first.index]  # SPPM
        scene.glslppm.estimator = 'PPPM'
        assert preferences_module.render_devices(scene.glslppm) == [first.index] * 2
        helpers.render_image("two_workers")
    finally:
        preferences.devices.remove(len(preferences.devices) - 1)
