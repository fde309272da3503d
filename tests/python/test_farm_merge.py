"""glslppm-merge: PPPM renders of one frame made in pieces (contiguous farm chunks from
glslppm-render --first-pass, interleaved halves from the module) merge into the image of one
render of all the passes; files that do not belong together are refused by file and field."""
import os
import subprocess

import numpy as np
import pytest

from conftest import BUILD

RENDER = os.path.join(BUILD, "glslppm-render")
MERGE = os.path.join(BUILD, "glslppm-merge")
# As tests/python/test_pppm.py: each pass is bit-identical wherever it runs; the sums' order,
# the divisions and the merge's cast to float differ by a few 2^-24.
MERGE_BOUND = 1e-6
SIZE = ["--width", "32", "--height", "24", "--photons", "4096", "--estimator", "pppm"]


def render(path, *extra):
    result = subprocess.run([RENDER, *SIZE, "--out", str(path), *extra],
                            capture_output=True, text=True, timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    return str(path)


def merge(out, *inputs):
    return subprocess.run([MERGE, *inputs, "-o", str(out)], capture_output=True, text=True,
                          timeout=120)


def relative_difference(a, b):
    scale = np.maximum(np.abs(a), np.abs(b))
    d = np.divide(np.abs(a - b), scale, out=np.zeros_like(scale), where=scale > 0)
    return float(d.max())


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    d = tmp_path_factory.mktemp("farm")
    return {
        "whole": render(d / "whole.exr", "--passes", "6"),
        "first": render(d / "first.exr", "--passes", "3"),
        "second": render(d / "second.exr", "--passes", "3", "--first-pass", "3"),
        "overlap": render(d / "overlap.exr", "--passes", "2", "--first-pass", "2"),
        "seed": render(d / "seed.exr", "--passes", "3", "--first-pass", "3", "--seed", "7"),
        "photons": render(d / "photons.exr", "--passes", "3", "--first-pass", "3",
                          "--photons", "2048"),
        "scene": render(d / "scene.exr", "--passes", "3", "--first-pass", "3",
                        "--environment-color", "0.1,0.1,0.1"),
        # Cycles' per-kind limits shape the image too (docs/bounces.md).
        "diffuse": render(d / "diffuse.exr", "--passes", "3", "--first-pass", "3",
                          "--diffuse-bounces", "2"),
    }


def test_farm_chunks_merge_into_the_whole_render(glslppm, renders, tmp_path):
    g = glslppm
    result = merge(tmp_path / "merged.exr", renders["second"], renders["first"])
    assert result.returncode == 0, result.stderr
    merged, header = g.read_exr(str(tmp_path / "merged.exr"))
    whole, whole_header = g.read_exr(renders["whole"])
    assert header["glslppm.pass_ranges"] == "0-6" == whole_header["glslppm.pass_ranges"]
    assert header["glslppm.passes"] == "6"
    assert header["glslppm.scene_hash"] == whole_header["glslppm.scene_hash"]
    assert relative_difference(merged, whole) <= MERGE_BOUND
    first, _ = g.read_exr(renders["first"])
    assert relative_difference(first, whole) > 1e3 * MERGE_BOUND  # the bound is not loose


def test_interleaved_halves_from_the_module_merge(glslppm, tmp_path):
    g = glslppm
    scene = g.cornell_box(sphere_rings=12)
    settings = g.Settings(width=32, height=24, photons_per_pass=4096, estimator="pppm")
    paths, films = [], {}
    for name, indices in (("even", [0, 2, 4]), ("odd", [1, 3, 5]), ("all", range(6))):
        r = g.Renderer(scene, settings)
        r.run_passes(list(indices))
        films[name] = r.film()
        attributes = r.farm_attributes()
        r.close()
        path = str(tmp_path / f"{name}.exr")
        g.write_exr(path, films[name], attributes)
        paths.append(path)
    assert g.read_exr(paths[0])[1]["glslppm.pass_ranges"] == "0-1,2-3,4-5"
    result = merge(tmp_path / "merged.exr", paths[0], paths[1])
    assert result.returncode == 0, result.stderr
    merged, header = g.read_exr(str(tmp_path / "merged.exr"))
    assert header["glslppm.pass_ranges"] == "0-6"
    assert relative_difference(merged, films["all"]) <= MERGE_BOUND


@pytest.mark.parametrize("other,message", [
    ("overlap", "overlap.exr: glslppm.pass_ranges overlaps {first}'s at pass 2"),
    ("seed", "seed.exr: glslppm.seed 7 differs from {first}'s 0"),
    ("photons", "photons.exr: glslppm.settings has photons_per_pass=2048 where it has "
                "photons_per_pass=4096 in {first}"),
    ("scene", "scene.exr: glslppm.scene_hash "),
    ("diffuse", "diffuse.exr: glslppm.settings has max_diffuse_bounces=2 where it has (none) "
                "in {first}"),
])
def test_files_that_do_not_belong_together_are_refused(renders, tmp_path, other, message):
    out = tmp_path / "merged.exr"
    result = merge(out, renders["first"], renders[other])
    assert result.returncode == 1
    assert message.format(first=renders["first"]) in result.stderr, result.stderr
    assert not out.exists()


def test_sppm_and_foreign_files_are_refused(glslppm, renders, tmp_path):
    sppm = tmp_path / "sppm.exr"
    result = subprocess.run([RENDER, *SIZE[:-2], "--passes", "2", "--out", str(sppm)],
                            capture_output=True, text=True, timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    result = merge(tmp_path / "m.exr", renders["first"], str(sppm))
    assert result.returncode == 1
    assert "sppm.exr: glslppm.estimator is sppm: only pppm or vcm renders merge" in result.stderr
    foreign = tmp_path / "foreign.exr"
    glslppm.write_exr(str(foreign), np.zeros((24, 32, 4), np.float32), {"note": "x"})
    result = merge(tmp_path / "m.exr", renders["first"], str(foreign))
    assert result.returncode == 1
    assert "foreign.exr: glslppm.estimator is missing" in result.stderr
    result = merge(tmp_path / "m.exr")
    assert result.returncode == 2 and "usage: glslppm-merge" in result.stderr
