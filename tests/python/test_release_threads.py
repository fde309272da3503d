"""Renderers let go of on threads other than Python's own (issue 26: F12 in Blender's UI
crashed or froze Blender when the last reference to a renderer fell on Blender's render job
thread). A Renderer holds the Scene's numpy arrays; whichever thread frees it must neither
wait for the GIL (a deadlock when the GIL's holder waits for that thread) nor touch a
Python object without it. The arrays' reference counts are the exact check: each test
ends with every array back at the count it had before the Scene existed, and every thread
joined within its time bound."""
import sys
import threading
import time

import numpy as np

from conftest import native, quad

JOIN_SECONDS = 30.0


def arrays():
    positions, indices = quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0))
    return np.ascontiguousarray(positions), np.ascontiguousarray(indices)


def scene_of(positions, indices):
    camera = np.eye(4, dtype=np.float32)
    camera[2, 3] = 3.0
    return native.Scene(positions, indices,
                        materials=[native.Material("diffuse", color=(0.8, 0.8, 0.8))],
                        lights=[native.Light("point", power=50.0, position=(0, 0, 2))],
                        camera=native.Camera(to_world=camera, fov_x=0.8))


def settings():
    return native.Settings(width=16, height=16, photons_per_pass=256)


def counts(positions, indices):
    return [sys.getrefcount(positions), sys.getrefcount(indices)]


def wait_for_counts(positions, indices, expected, seconds=5.0):
    """The references freed off Python's thread are released by a pending call on Python's
    main thread, which runs between bytecodes: a short loop of them lets it run."""
    expected = [count + 1 for count in expected]  # this frame's own references
    deadline = time.perf_counter() + seconds
    while time.perf_counter() < deadline:
        if counts(positions, indices) == expected:
            return
        time.sleep(0.001)
    raise AssertionError(f"reference counts {counts(positions, indices)}, expected "
                         f"{expected}: arrays leaked or released twice")


def test_scene_arrays_released_on_a_thread_python_never_saw():
    """The last reference to a Scene's arrays dropped on a thread without a Python thread
    state while Python's main thread waits with the GIL released: the arrays go back to
    Python at its next bytecode, not before (touching them there would be a data race) and
    not never (a leak of every exported mesh)."""
    positions, indices = arrays()
    before = counts(positions, indices)
    scene = scene_of(positions, indices)
    native._debug_hold_scene(scene)
    del scene  # the module's copy now holds the arrays alone
    held = counts(positions, indices)
    assert held == [count + 1 for count in before], held
    native._debug_drop_held_scene_on_native_thread()
    wait_for_counts(positions, indices, before)
    assert native._debug_deferred_releases() == 0


def test_renderer_freed_on_a_thread_python_never_saw():
    positions, indices = arrays()
    before = counts(positions, indices)
    renderer = native.Renderer(scene_of(positions, indices), settings())
    assert renderer.run(passes=2) == 2
    renderer._debug_close_on_native_thread()
    assert renderer.closed
    wait_for_counts(positions, indices, before)


def test_close_while_a_worker_thread_runs_passes():
    """The Blender engine's pattern: run() on a worker thread, close() from the render
    thread mid-run (Esc), so the worker's own reference is the last one."""
    positions, indices = arrays()
    before = counts(positions, indices)
    for round_ in range(20):
        scene = scene_of(positions, indices)
        renderer = native.Renderer(scene, settings())
        del scene
        outcome = {}

        def work():
            try:
                outcome["ran"] = renderer.run(passes=100000)
            except RuntimeError as error:  # closed before run() took its reference
                outcome["error"] = str(error)

        worker = threading.Thread(target=work)
        worker.start()
        time.sleep(0.002 * (round_ % 5))
        if round_ % 2:
            renderer._debug_close_on_native_thread()
        else:
            renderer.close()
        worker.join(JOIN_SECONDS)
        assert not worker.is_alive(), f"round {round_}: run() did not return after close()"
        assert "ran" in outcome or "closed" in outcome.get("error", ""), outcome
        assert outcome.get("ran", 0) < 100000
        del renderer
    wait_for_counts(positions, indices, before)


def test_renderers_freed_on_many_threads_at_once():
    positions, indices = arrays()
    before = counts(positions, indices)
    renderers = [native.Renderer(scene_of(positions, indices), settings()) for _ in range(6)]
    for renderer in renderers:
        renderer.run(passes=1)
    threads = [threading.Thread(target=r._debug_close_on_native_thread) for r in renderers]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(JOIN_SECONDS)
        assert not thread.is_alive(), "a renderer's release did not finish"
    del renderers, threads
    wait_for_counts(positions, indices, before)
