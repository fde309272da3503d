"""Cancelling a Renderer's construction (BVH build, GL set-up) from another thread: a
2,000,000-triangle scene takes about 3 s to set up on llvmpipe; a cancel at any moment
of it must end the construction within 0.5 s (the flag is polled every few milliseconds
of work; the bound leaves room for a loaded machine)."""
import threading
import time

import numpy as np
import pytest

from conftest import native

LATENCY_BOUND = 0.5


def bumpy_grid(quads_per_side):
    """A grid of 2 * n^2 triangles with random heights, so the SAH build does real work."""
    n = quads_per_side
    axis = np.linspace(-1.0, 1.0, n + 1, dtype=np.float32)
    xs, ys = np.meshgrid(axis, axis)
    zs = 0.05 * np.random.default_rng(1).random(xs.shape, dtype=np.float32)
    positions = np.stack([xs, ys, zs], -1).reshape(-1, 3)
    corner = np.arange(n * n).reshape(n, n)
    a = ((corner // n) * (n + 1) + corner % n).ravel()
    b, c, d = a + 1, a + n + 2, a + n + 1
    indices = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return np.ascontiguousarray(positions), np.ascontiguousarray(indices, dtype=np.uint32)


@pytest.fixture(scope="module")
def big_scene():
    positions, indices = bumpy_grid(1000)
    camera = np.eye(4, dtype=np.float32)
    camera[2, 3] = 3.0
    return native.Scene(positions, indices,
                        materials=[native.Material("diffuse", color=(0.8, 0.8, 0.8))],
                        lights=[native.Light("point", power=100.0, position=(0, 0, 2))],
                        camera=native.Camera(to_world=camera, fov_x=0.8))


def settings():
    return native.Settings(width=32, height=32, photons_per_pass=1024)


def construct(scene, flag):
    """Builds a Renderer on a worker thread; returns (thread, outcome dict)."""
    outcome = {}

    def work():
        try:
            renderer = native.Renderer(scene, settings(), cancel=flag)
            outcome["renderer"] = renderer
        except native.Cancelled as error:
            outcome["cancelled"] = error
        except Exception as error:  # noqa: BLE001 - reported by the test
            outcome["error"] = error
        outcome["ended"] = time.perf_counter()

    thread = threading.Thread(target=work)
    thread.start()
    return thread, outcome


@pytest.fixture(scope="module")
def construction_seconds(big_scene):
    """How long an uncancelled construction takes here and now (the cancels below are
    placed at fractions of it, since other work on the machine moves it)."""
    flag = native.CancelFlag()
    start = time.perf_counter()
    thread, outcome = construct(big_scene, flag)
    thread.join()
    renderer = outcome.get("renderer")
    assert renderer is not None, outcome
    seconds = outcome["ended"] - start
    stats = renderer.stats()
    print(f"construction of {stats['triangles']} triangles: {seconds:.2f} s "
          f"(BVH {stats['bvh_seconds']:.2f} s)")
    assert stats["triangles"] == 2_000_000
    renderer.run(2)
    assert renderer.film()[..., :3].mean() > 0.0  # the flag, never set, changes nothing
    renderer.close()
    return seconds


@pytest.mark.parametrize("fraction", [0.02, 0.2, 0.4, 0.6, 0.8])
def test_cancel_during_construction_ends_it_quickly(big_scene, construction_seconds,
                                                    fraction):
    """Cancelled at a fraction of the construction's time (bounds, SAH build, threading,
    packing, GL set-up and uploads as the fraction grows): it ends within LATENCY_BOUND of
    the cancel, with Cancelled. Where the machine was faster this time and the renderer
    was already built, the cancel is tried again earlier."""
    delay = fraction * construction_seconds
    for _ in range(4):
        flag = native.CancelFlag()
        thread, outcome = construct(big_scene, flag)
        time.sleep(delay)
        cancelled_at = time.perf_counter()
        flag.set()
        thread.join(timeout=30)
        assert not thread.is_alive()
        latency = outcome["ended"] - cancelled_at
        if "renderer" in outcome:
            outcome["renderer"].close()
            assert latency < LATENCY_BOUND, latency
            delay *= 0.7
            continue
        assert "cancelled" in outcome, outcome
        assert isinstance(outcome["cancelled"], native.GlslppmError)
        print(f"cancel after {delay:.2f} s: construction ended {latency * 1000:.0f} ms "
              f"later (bound {LATENCY_BOUND * 1000:.0f} ms)")
        assert latency < LATENCY_BOUND, latency
        return
    pytest.fail(f"the construction always finished before a cancel {delay:.2f} s in")


def test_flag_set_before_construction_cancels_at_once(big_scene):
    flag = native.CancelFlag()
    flag.set()
    assert flag.is_set
    start = time.perf_counter()
    with pytest.raises(native.Cancelled):
        native.Renderer(big_scene, settings(), cancel=flag)
    assert time.perf_counter() - start < LATENCY_BOUND
