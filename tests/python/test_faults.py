"""Faults: renders too large for the GPU, a renderer closed or dropped
while another thread runs it, many renderers in one process, and renders asked for at once
from several threads. test_errors.py checks the too-many-photons message; here every fault
must also give back what it took (resident memory, threads, file descriptors) and leave the
next render exactly as it would have been."""
import gc
import os
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

from conftest import BUILD, look_at, quad


def lamp_scene(g):
    """A lamp over a square, seen from above: every pixel sees lit floor."""
    p, t = quad((-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1))
    camera = g.Camera(look_at((0, 3, 0), (0, 0, 0), up=(0, 0, -1)), fov_x=0.5)
    return g.Scene(p, t, materials=[g.Material()], camera=camera,
                   lights=[g.Light("point", position=(0, 1, 0))])


def small_settings(g, seed=1):
    return g.Settings(width=8, height=8, photons_per_pass=1024, seed=seed)


def resident_mib():
    """Resident set size of this process (/proc/self/statm, second field, in pages)."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def threads_and_fds():
    return len(os.listdir("/proc/self/task")), len(os.listdir("/proc/self/fd"))


def film_after(g, scene, settings, passes):
    r = g.Renderer(scene, settings)
    r.run(passes)
    film = r.film()
    r.close()
    assert np.mean(film[..., :3] > 0) > 0.5, "the camera should see lit surfaces"
    return film


# --- too large for the GPU ----------------------------------------------------------------

@pytest.mark.parametrize("what", ["resolution", "photons"])
def test_too_large_a_render_frees_everything_and_the_next_is_unchanged(glslppm, what):
    """16384 x 16384 pixels (12 GiB of visible points) or 2^26 photons per pass (3 GiB):
    beyond any GPU's largest storage buffer. Each attempt raises GlslppmError naming the
    buffer and what to lower, keeps no thread, descriptor or memory (measured: resident
    memory +0.1 MiB over 10 attempts), and the next render is the one made before."""
    g = glslppm
    scene = lamp_scene(g)
    before = film_after(g, scene, small_settings(g), 4)
    large = (g.Settings(width=16384, height=16384, photons_per_pass=256)
             if what == "resolution" else g.Settings(width=8, height=8, photons_per_pass=1 << 26))
    hint = "lower the resolution" if what == "resolution" else "photons per pass"
    with pytest.raises(glslppm.GlslppmError, match=hint):
        g.Renderer(scene, large)  # the first attempt may load driver code for good
    memory, counts, objects = resident_mib(), threads_and_fds(), g.gl_object_counts()
    for _ in range(10):
        with pytest.raises(glslppm.GlslppmError, match="more than this GPU's largest"):
            g.Renderer(scene, large)
    assert threads_and_fds() == counts
    assert g.gl_object_counts() == objects
    assert resident_mib() - memory < 8.0
    np.testing.assert_array_equal(film_after(g, scene, small_settings(g), 4), before)


# --- many renderers -----------------------------------------------------------------------

def test_hundred_renderers_leave_memory_threads_and_descriptors_flat(glslppm):
    """Create, run, close a renderer 100 times (then 20 more dropped without close()): the
    resident memory grows by less than 4 MiB (measured: +0.1 MiB for 100, about 1 KiB per
    renderer), and no EGL thread, descriptor, EGL context or GL object (buffer, texture,
    program, query, counted where glslppm creates and deletes them) is left behind; while one
    renderer lives, its objects are counted."""
    g = glslppm
    scene = lamp_scene(g)
    for _ in range(10):  # driver caches, lazily loaded code
        film_after(g, scene, small_settings(g), 1)
    gc.collect()
    objects = g.gl_object_counts()
    alive = g.Renderer(scene, small_settings(g))
    during = g.gl_object_counts()
    assert during["contexts"] == objects["contexts"] + 1
    assert during["buffers"] > objects["buffers"] and during["programs"] > objects["programs"]
    alive.close()
    assert g.gl_object_counts() == objects
    memory, counts = resident_mib(), threads_and_fds()
    for _ in range(100):
        film_after(g, scene, small_settings(g), 1)
    for _ in range(20):
        r = g.Renderer(scene, small_settings(g))
        r.run(1)
        del r
    gc.collect()
    assert threads_and_fds() == counts
    assert g.gl_object_counts() == objects, (g.gl_object_counts(), objects)
    assert resident_mib() - memory < 4.0, resident_mib() - memory


# --- closing while another thread renders -------------------------------------------------

CLOSE_DURING_RUN = textwrap.dedent("""
    import os, sys, threading, time
    sys.path.insert(0, {build!r})
    import numpy as np, _glslppm as g
    p = np.array([[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]], np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    down = np.array([[1, 0, 0, 0], [0, 0, 1, 3], [0, -1, 0, 0], [0, 0, 0, 1]], np.float32)
    scene = g.Scene(p, t, materials=[g.Material()], camera=g.Camera(down, fov_x=0.5),
                    lights=[g.Light("point", position=(0, 1, 0))])
    settings = g.Settings(width=8, height=8, photons_per_pass=256, seed=1)
    def counts():
        return len(os.listdir("/proc/self/task")), len(os.listdir("/proc/self/fd"))
    r = g.Renderer(scene, settings); r.run(1); r.close()
    baseline = counts()
    outcomes = []
    for delay in [0.0, 0.0005, 0.002, 0.01, 0.05] * 4:
        r = g.Renderer(scene, settings)
        holder = [r]
        def work():
            mine = holder.pop()  # the worker's only reference, dropped when run() ends
            try:
                mine.run({passes})
                outcomes.append("ran")
            except RuntimeError as e:
                assert "closed" in str(e), e
                outcomes.append("closed")
            del mine
        worker = threading.Thread(target=work)
        worker.start()
        time.sleep(delay)
        if {drop}:
            del r
        else:
            r.close()
            assert r.closed
            try:
                r.stats()
                raise AssertionError("stats() after close() did not raise")
            except RuntimeError as e:
                assert "closed" in str(e)
        worker.join()
    import gc; gc.collect()
    # Mesa's shader-cache writer may still be finishing a write for a moment (seen under
    # load with a cold cache): wait for it, up to 5 s; a leaked thread never goes.
    for _ in range(50):
        if counts() == baseline:
            break
        time.sleep(0.1)
    assert counts() == baseline, (counts(), baseline)
    r = g.Renderer(scene, settings); r.run(2)
    assert r.film()[..., :3].mean() > 0 and r.stats()["passes"] == 2
    print("OUTCOMES", sorted(set(outcomes)), len(outcomes))
""")


@pytest.mark.parametrize("drop", [False, True], ids=["close", "drop"])
def test_closing_or_dropping_a_renderer_mid_run_never_crashes(drop):
    """Another thread calls close() on (or drops the last reference to) a renderer while
    run(300) is going, 20 times at delays from 0 to 50 ms, in a child process so that a
    crash fails the test instead of ending pytest: the child exits cleanly, run() either
    finishes or says the renderer was closed, and no thread or descriptor is left. (Today
    close() waits for the running passes: run() is one GL job, there is no cancel.)"""
    code = CLOSE_DURING_RUN.format(build=os.path.abspath(BUILD), passes=300, drop=drop)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, (out.returncode, out.stdout[-2000:], out.stderr[-2000:])
    assert "OUTCOMES" in out.stdout


# --- two renders at once ------------------------------------------------------------------

def test_two_threads_on_one_renderer_run_one_after_the_other(glslppm):
    """Two threads call run(200) on one renderer at once while a third reads film() over and
    over: the GL thread runs each call's passes as one job, so the result is exactly run(400)
    (same pass count, photon count and, bit for bit, the same film), and every film read in
    between is, bit for bit, the film after 0, 200 or 400 passes: never interleaved."""
    g = glslppm
    scene = lamp_scene(g)
    sequential = g.Renderer(scene, small_settings(g, seed=3))
    snapshots = [sequential.film()]
    for _ in range(2):
        sequential.run(200)
        snapshots.append(sequential.film())
    expected_stats = sequential.stats()
    sequential.close()
    assert not np.array_equal(snapshots[1], snapshots[2])

    shared = g.Renderer(scene, small_settings(g, seed=3))
    start = threading.Barrier(3)
    reads, running = [], [True]

    def work(delay):
        start.wait()
        time.sleep(delay)  # the second call comes while the first is running
        shared.run(200)

    def read():
        start.wait()
        time.sleep(0.002)
        while running[0]:
            reads.append(shared.film())

    workers = [threading.Thread(target=work, args=(delay,)) for delay in (0.0, 0.05)]
    reader = threading.Thread(target=read)
    for w in workers + [reader]:
        w.start()
    for w in workers:
        w.join()
    running[0] = False
    reader.join()
    stats = shared.stats()
    assert stats["passes"] == 400
    assert stats["photons_emitted"] == expected_stats["photons_emitted"]
    np.testing.assert_array_equal(shared.film(), snapshots[2])
    assert reads
    for film in reads:
        assert any(np.array_equal(film, s) for s in snapshots)
    shared.close()


def test_two_renderers_on_two_threads_each_give_their_own_image(glslppm):
    """Two renderers (two scenes, two seeds) running on two threads at once: each film is,
    bit for bit, the film it gives when run alone: their GL contexts share nothing."""
    g = glslppm
    scenes = [lamp_scene(g), g.cornell_box(sphere_rings=8)]
    settings = [small_settings(g, seed=5),
                g.Settings(width=16, height=16, photons_per_pass=1024, seed=6)]
    alone = [film_after(g, s, st, 12) for s, st in zip(scenes, settings)]

    renderers = [g.Renderer(s, st) for s, st in zip(scenes, settings)]
    start = threading.Barrier(2)

    def work(r):
        start.wait()
        for _ in range(4):
            r.run(3)

    workers = [threading.Thread(target=work, args=(r,)) for r in renderers]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    for r, expected in zip(renderers, alone):
        assert r.stats()["passes"] == 12
        np.testing.assert_array_equal(r.film(), expected)
        r.close()
