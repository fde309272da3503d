"""Reading the film back: into a new array or the caller's (film(out=...)), top row first or
bottom row first (bottom_up, as Blender stores images), through the staging buffers
(gl/buffer_reader.h: reads of 1 MiB and more, in 16 MiB chunks) or directly (smaller ones),
with one worker or two. Every way gives the same floats, exactly."""
import numpy as np
import pytest


def rendered(g, width, height, devices=None):
    settings = g.Settings(width=width, height=height, photons_per_pass=4096, seed=3)
    if devices:
        settings = g.Settings(width=width, height=height, photons_per_pass=4096, seed=3,
                              estimator="pppm", devices=devices)
    r = g.Renderer(g.cornell_box(sphere_rings=8), settings)
    r.run(2)
    return r


# 40 x 30: 19 KB, read directly; 1100 x 1000: 17.6 MB, two staging chunks whose rows are
# split at a chunk's end unless the reader keeps rows whole.
@pytest.mark.parametrize("width, height", [(40, 30), (1100, 1000)])
def test_every_way_of_reading_gives_the_same_film(glslppm, width, height):
    r = rendered(glslppm, width, height)
    film = r.film()
    assert film.shape == (height, width, 4) and film.dtype == np.float32
    assert np.isfinite(film).all() and film[..., :3].max() > 0
    # The image is not symmetric top to bottom: a flipped read would differ.
    assert not np.array_equal(film, film[::-1])
    out = np.full_like(film, np.nan)
    assert r.film(out=out) is out
    np.testing.assert_array_equal(out, film)
    flipped = np.full_like(film, np.nan)
    r.film(out=flipped, bottom_up=True)
    np.testing.assert_array_equal(flipped, film[::-1])
    np.testing.assert_array_equal(r.film(bottom_up=True), film[::-1])
    # The same buffer again after more passes: every pixel rewritten.
    r.run(1)
    again = r.film()
    r.film(out=out)
    np.testing.assert_array_equal(out, again)
    r.close()


def test_two_workers_read_into_the_callers_array(glslppm):
    probe = rendered(glslppm, 32, 24)
    device = probe.stats()["devices"][0]["device"]
    probe.close()
    r = rendered(glslppm, 32, 24, devices=[device, device])
    film = r.film()
    out = np.empty_like(film)
    r.film(out=out, bottom_up=True)
    np.testing.assert_array_equal(out, film[::-1])
    r.close()


@pytest.mark.parametrize("bad", [
    np.zeros((24, 32, 4), np.float64),                 # dtype
    np.zeros((32, 24, 4), np.float32),                 # shape
    np.zeros((24, 32, 8), np.float32)[..., ::2],       # not contiguous
])
def test_a_wrong_array_is_refused_by_name(glslppm, bad):
    r = rendered(glslppm, 32, 24)
    with pytest.raises(ValueError, match=r"film\(out\).*shape \(24, 32, 4\)"):
        r.film(out=bad)
    readonly = np.zeros((24, 32, 4), np.float32)
    readonly.flags.writeable = False
    with pytest.raises(ValueError, match="writable"):
        r.film(out=readonly)
    r.close()
