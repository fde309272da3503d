"""Same seed, same settings, same image, bit for bit: the built-in Cornell box, the caustic
scene and a textured glTF against the images kept in tests/data/golden/ (written by
tests/python/golden.py, which says when to regenerate them). Guards changes meant to leave
images alone: the GPU layout, the scene preparation, renamed settings."""
import os

import numpy as np
import pytest

import golden


@pytest.mark.parametrize("name", ["cornell", "caustic", "textured_gltf"])
def test_image_is_bit_identical_to_the_golden_one(glslppm, name):
    g = glslppm
    film = golden.render(g, golden.scenes(g)[name])
    kept, _ = g.read_exr(os.path.join(golden.GOLDEN, f"{name}.exr"))
    assert film.shape == kept.shape
    differ = film != kept
    assert not differ.any(), (
        f"{differ.any(axis=-1).sum()} of {film.shape[0] * film.shape[1]} pixels differ; "
        f"largest difference {np.abs(film - kept).max():.3g}, mean {film[..., :3].mean():.6f} "
        f"against {kept[..., :3].mean():.6f}")
