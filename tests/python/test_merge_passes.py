"""glslppm-merge merges the render passes (docs/passes.md) as it merges Combined: two farm
halves of a PPPM frame, each written with every pass, merge into the frame one process
renders over all the passes, every layer of it; frames with other passes are refused by name.

Each layer of a file is a mean over the file's passes (Depth and the Normals too: the eye
stage sums them per pass as it sums light), so the merge weights every layer by the files'
pass counts, as Renderer.film and render_passes weight their workers'.
"""
import os
import subprocess

import numpy as np
import pytest

from conftest import BUILD
from scene_builders import glass_ball_beam

RENDER = os.path.join(BUILD, "glslppm-render")
MERGE = os.path.join(BUILD, "glslppm-merge")
# As test_farm_merge's Combined: each pass is bit-identical wherever it runs; the sums' order,
# the divisions and the merge's cast to float leave a few 2^-24 of the pixel (measured at most
# 2.4e-7 here, over every layer). The pixel's scale is its largest channel in that layer, so
# a normal's small component is held to the normal's length.
MERGE_BOUND = 1e-6
SIZE = ["--width", "32", "--height", "24", "--photons", "4096", "--estimator", "pppm"]


def layers_of(g, path):
    """{layer: (H, W, channels) float64} of a multi-layer file, "ViewLayer." left out, the
    channels in Blender's order (RGBA, XYZ)."""
    channels = g.read_exr_channels(str(path))
    layers = {}
    for name in sorted(channels, key=lambda name: "RGBAXYZ".index(name[-1])):
        layer = name.rsplit(".", 1)[0].split(".", 1)[1]
        layers.setdefault(layer, []).append(channels[name].astype(np.float64))
    return {name: np.stack(planes, axis=-1) for name, planes in layers.items()}


def worst_difference(a, b):
    """The largest |a - b| of any channel over its pixel's scale in that layer (Combined's
    alpha on its own: its 1 would hide the colours' differences)."""
    if a.shape[-1] == 4:
        return max(worst_difference(a[..., :3], b[..., :3]),
                   worst_difference(a[..., 3:], b[..., 3:]))
    scale = np.maximum(np.abs(a), np.abs(b)).max(axis=-1, keepdims=True)
    d = np.abs(a - b)
    return float(np.divide(d, scale, out=np.where(d > 0, np.inf, 0.0), where=scale > 0).max())


def assert_layers_equal(merged, whole):
    assert set(merged) == set(whole)
    worst = {name: worst_difference(merged[name], whole[name]) for name in whole}
    assert max(worst.values()) <= MERGE_BOUND, worst


def merge(out, *inputs):
    return subprocess.run([MERGE, *map(str, inputs), "-o", str(out)], capture_output=True,
                          text=True, timeout=120)


def test_glass_ball_halves_merge_into_one_process_rendering_every_pass(glslppm, tmp_path):
    """The glass ball's caustic scene, every pass, rendered as two farm halves (passes 0-3,
    3-6; Renderer.write_passes_exr writes what glslppm-render --passes-out writes) and merged,
    against one process with two workers rendering passes 0-6: every layer equal within
    MERGE_BOUND of the pixel. A half alone is far off (the bound is not loose)."""
    g = glslppm
    scene = glass_ball_beam(g, rings=16).scene
    settings = dict(width=32, height=32, photons_per_pass=4096, estimator="pppm",
                    passes=["all"], seed=5)
    halves = []
    for first in (0, 3):
        r = g.Renderer(scene, g.Settings(**settings))
        r.run_passes(list(range(first, first + 3)))
        halves.append(tmp_path / f"half_{first}.exr")
        r.write_passes_exr(str(halves[-1]))
        r.close()
    result = merge(tmp_path / "merged.exr", *halves)
    assert result.returncode == 0, result.stderr
    assert g.read_exr(str(tmp_path / "merged.exr"))[1]["glslppm.pass_ranges"] == "0-6"

    whole = g.Renderer(scene, g.Settings(devices=[0, 0], **settings))
    whole.run_passes(list(range(6)))
    # The workers take passes by their own speed (a loaded core may deal 2 and 4).
    dealt = [d["passes"] for d in whole.stats()["devices"]]
    assert len(dealt) == 2 and sum(dealt) == 6, dealt
    names = [p["name"] for p in g.render_passes()]
    images = whole.render_passes(names)
    expected = {"Combined": whole.film().astype(np.float64)}
    for p in g.render_passes():
        channels = len(p["channel_names"])
        expected[p["blender"]] = images[p["name"]][..., :channels].astype(np.float64)
    whole.close()
    merged = layers_of(g, tmp_path / "merged.exr")
    # The beam reaches the floor through the ball only: the caustic is most of the light.
    assert expected["Caustics"].sum() > 0.5 * expected["Combined"][..., :3].sum() > 0
    assert_layers_equal(merged, expected)
    half = layers_of(g, halves[0])
    assert worst_difference(half["Caustics"], expected["Caustics"]) > 1e3 * MERGE_BOUND


def test_cli_halves_merge_every_layer(glslppm, tmp_path):
    """glslppm-render --passes-out all (the built-in box, its glass sphere's caustic) as two
    farm halves, merged by glslppm-merge under the same layer names, against one render of
    passes 0-6: every layer within MERGE_BOUND of the pixel."""
    def render(name, *extra):
        path = tmp_path / name
        result = subprocess.run([RENDER, *SIZE, "--passes-out", "all", "--out", str(path),
                                 *extra], capture_output=True, text=True, timeout=300, cwd="/")
        assert result.returncode == 0, result.stderr
        return path
    first = render("first.exr", "--passes", "3")
    second = render("second.exr", "--passes", "3", "--first-pass", "3")
    whole = render("whole.exr", "--passes", "6")
    result = merge(tmp_path / "merged.exr", second, first)
    assert result.returncode == 0, result.stderr
    assert "6 passes (0-6) from 2 files" in result.stdout
    merged = layers_of(glslppm, tmp_path / "merged.exr")
    assert_layers_equal(merged, layers_of(glslppm, whole))
    assert merged["Caustics"].max() > 0.1


@pytest.mark.parametrize("passes,message", [
    ("combined", "ViewLayer.Caustics, ViewLayer.Denoising Albedo, ViewLayer.Denoising Normal, "
                 "ViewLayer.Depth, ViewLayer.Direct, ViewLayer.Emission, ViewLayer.Environment, "
                 "ViewLayer.Indirect, ViewLayer.Normal only in {first}"),
    ("depth,caustics,normal", "ViewLayer.Denoising Albedo, ViewLayer.Denoising Normal, "
                              "ViewLayer.Direct, ViewLayer.Emission, ViewLayer.Environment, "
                              "ViewLayer.Indirect only in {first}"),
])
def test_frames_whose_passes_differ_are_refused(tmp_path, passes, message):
    """A frame with fewer passes cannot be merged into one with every pass: no layer of the
    whole would be the mean of all its passes. Refused, naming both files and the passes."""
    paths = []
    for name, layers, first in (("all.exr", "all", "0"), ("other.exr", passes, "3")):
        paths.append(tmp_path / name)
        result = subprocess.run([RENDER, *SIZE, "--passes", "3", "--first-pass", first,
                                 "--passes-out", layers, "--out", str(paths[-1])],
                                capture_output=True, text=True, timeout=300, cwd="/")
        assert result.returncode == 0, result.stderr
    out = tmp_path / "merged.exr"
    result = merge(out, *paths)
    assert result.returncode == 1
    assert (f"{paths[1]}: render passes differ from {paths[0]}'s: "
            + message.format(first=paths[0])) in result.stderr, result.stderr
    assert not out.exists()
    # A single-layer file's R, G, B, A are Combined, under other channel names.
    single = tmp_path / "single.exr"
    result = subprocess.run([RENDER, *SIZE, "--passes", "3", "--first-pass", "3", "--out",
                             str(single)], capture_output=True, text=True, timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    result = merge(out, paths[0], single)
    assert result.returncode == 1
    assert f"{single}: render passes differ from {paths[0]}'s: " in result.stderr
    assert f"Combined only in {single}" in result.stderr, result.stderr
