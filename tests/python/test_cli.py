"""glslppm-render: the built-in scene, its JSON statistics and its EXR output."""
import json
import os
import subprocess

import numpy as np

from conftest import BUILD

RENDER = os.path.join(BUILD, "glslppm-render")


def test_render_writes_exr_with_statistics_in_its_header(glslppm, tmp_path):
    out = tmp_path / "cornell.exr"
    result = subprocess.run(
        [RENDER, "--width", "32", "--height", "24", "--passes", "6", "--photons", "4096",
         "--hash", "exact", "--rng", "pcg", "--out", str(out), "--json"],
        capture_output=True, text=True, timeout=300, cwd="/")
    assert result.returncode == 0, result.stderr
    stats = json.loads(result.stdout)
    assert stats["passes"] == 6
    # Path regeneration: each pass starts a path where one ended (a photon thread at most one
    # a pass); the warm-up's paths are not counted, so 6 passes start 6 x 4096 over the mean
    # path length (the box's is far below 6).
    assert 4096 <= stats["photons_emitted"] <= 6 * 4096
    assert stats["photons_per_second"] > 0 and stats["rays_per_second"] > 0
    assert "hash=exact" in stats["variant"] and "rng=pcg" in stats["variant"]
    assert stats["renderer"]

    image, header = glslppm.read_exr(str(out))
    assert image.shape == (24, 32, 4)
    assert np.isfinite(image).all()
    assert np.all(image[..., 3] == 1.0)
    # The ceiling light is seen directly at the top centre of the image: its radiance, 17.
    assert image[:, :, :3].max() >= 16.9
    assert int(header["passes"]) == 6
    assert int(header["photons_emitted"]) == stats["photons_emitted"]
    assert header["hash"] == "exact" and header["rng"] == "pcg"
    assert float(header["seconds"]) > 0


def test_render_rejects_bad_options():
    result = subprocess.run([RENDER, "--hash", "fast"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 1
    assert "hash: 'fast' is not a hash mode" in result.stderr
    result = subprocess.run([RENDER, "--width"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 1 and "--width needs a value" in result.stderr


def test_exr_round_trip(glslppm, tmp_path):
    rgba = np.random.default_rng(0).random((5, 7, 4), dtype=np.float32) * 1e4
    glslppm.write_exr(str(tmp_path / "a.exr"), rgba, {"note": "x"})
    back, header = glslppm.read_exr(str(tmp_path / "a.exr"))
    assert np.array_equal(back, rgba)
    assert header == {"note": "x"}


BENCH = os.path.join(BUILD, "glslppm-bench")


def test_bad_numbers_are_errors_naming_the_option():
    """The CLI and every benchmark read numbers strictly: a bad one is a failing exit status
    (2 for the benchmarks) and a line naming the option, never a silent 0; --help prints the
    usage and exits 0."""
    cases = [
        ([RENDER, "--width", "12x"], "--width: '12x' is not a number"),
        ([BENCH, "passes", "--passes", "1x"], "--passes: '1x' is not a number"),
        ([BENCH, "passes", "--width", "abc"], "--width: 'abc' is not a number"),
        ([BENCH, "bvh", "--triangles", "1e3x"], "--triangles: '1e3x' is not a number"),
        ([BENCH, "rays", "--batches", "two"], "--batches: 'two' is not a number"),
        ([BENCH, "longrun", "--passes", "0.5"], "--passes: '0.5' is not a whole number"),
        ([BENCH, "converge", "--size", "12q"], "--size: '12q' is not a number"),
        ([BENCH, "specialize", "--rounds"], "--rounds needs a value"),
    ]
    for command, message in cases:
        result = subprocess.run(command, capture_output=True, text=True, timeout=60)
        assert result.returncode == (2 if command[0] == BENCH else 1), (command, result)
        assert message in result.stderr, (command, result.stderr)
    for command in ([RENDER, "--help"], [BENCH, "--help"]):
        result = subprocess.run(command, capture_output=True, text=True, timeout=60)
        assert result.returncode == 0 and result.stdout.startswith("usage:"), command


def test_max_bounces_and_its_older_name_max_depth_set_the_same_setting(glslppm, tmp_path):
    """--max-bounces is Blender's name; --max-depth stays accepted for scripts written
    before the rename. Both give the same image, bit for bit, and record max_bounces."""
    images = []
    for option in ("--max-bounces", "--max-depth"):
        out = tmp_path / f"{option[2:]}.exr"
        result = subprocess.run(
            [RENDER, "--width", "16", "--height", "12", "--passes", "2", "--photons", "1024",
             option, "2", "--out", str(out)], capture_output=True, text=True, timeout=300,
            cwd="/")
        assert result.returncode == 0, result.stderr
        image, header = glslppm.read_exr(str(out))
        assert header["max_bounces"] == "2"
        images.append(image)
    assert np.array_equal(images[0], images[1])
    # One bounce fewer changes the image: the option is not ignored.
    out = tmp_path / "one.exr"
    subprocess.run([RENDER, "--width", "16", "--height", "12", "--passes", "2", "--photons",
                    "1024", "--max-bounces", "1", "--out", str(out)], check=True, timeout=300,
                   capture_output=True, cwd="/")
    assert not np.array_equal(glslppm.read_exr(str(out))[0], images[0])
    help_text = subprocess.run([RENDER, "--help"], capture_output=True, text=True,
                               timeout=60).stdout
    assert "--max-bounces N" in help_text and "--max-depth is accepted" in help_text


def test_per_kind_bounce_limits_reach_the_render(glslppm, tmp_path):
    """--diffuse-bounces, --glossy-bounces and --transmission-bounces (Cycles' Light Paths,
    docs/bounces.md) are recorded in the file and change the image: the Cornell box at
    diffuse 0 loses its interreflections, so it is darker than at the default."""
    means = {}
    for name, extra in (("default", []), ("limited", ["--diffuse-bounces", "0",
                                                      "--glossy-bounces", "1",
                                                      "--transmission-bounces", "3"])):
        out = tmp_path / f"{name}.exr"
        result = subprocess.run(
            [RENDER, "--width", "16", "--height", "12", "--passes", "2", "--photons", "1024",
             *extra, "--out", str(out)], capture_output=True, text=True, timeout=300, cwd="/")
        assert result.returncode == 0, result.stderr
        image, header = glslppm.read_exr(str(out))
        means[name] = float(image[..., :3].mean())
        if name == "limited":
            assert (header["max_diffuse_bounces"], header["max_glossy_bounces"],
                    header["max_transmission_bounces"]) == ("0", "1", "3")
    assert means["limited"] < 0.95 * means["default"], means  # measured 0.90 of it
