"""Long native calls (the renderer's construction, a batch of passes) run on a worker
thread while Blender's thread keeps asking whether the user cancelled: the module
releases the GIL, so the poll runs every few milliseconds and a cancel reaches the
module at once instead of after the call (seconds for a large scene's BVH)."""

import threading
import time

POLL_SECONDS = 0.02


def call_cancellable(work, should_stop, on_stop, poll=POLL_SECONDS, grace=None):
    """Runs work() on a worker thread; while it runs, polls should_stop() every poll
    seconds and, the first time it is True, calls on_stop() (which must make work()
    return soon). Returns (work's result, whether stopped); work's exception is raised
    here. With grace (seconds), a stopped work() still running that long after
    on_stop() is left to finish on its own: (None, True) at once. That suits a GPU
    pass, which cannot be interrupted and whose result is no longer wanted."""
    outcome = {}

    def run():
        try:
            outcome["result"] = work()
        except BaseException as error:  # noqa: BLE001 - re-raised on the caller's thread
            outcome["error"] = error

    worker = threading.Thread(target=run, name="glslppm-native", daemon=True)
    worker.start()
    stopped = False
    while worker.is_alive():
        worker.join(poll)
        if not stopped and worker.is_alive() and should_stop():
            stopped = True
            on_stop()
            if grace is not None:
                worker.join(grace)
                if worker.is_alive():
                    return None, True
    if "error" in outcome:
        raise outcome["error"]
    return outcome.get("result"), stopped


class StageClock:
    """Which stage a render is in (export, build, render) and since when: the tests'
    cancel measurements read it."""

    def __init__(self):
        self.stage = None
        self.since = time.perf_counter()

    def enter(self, stage):
        self.stage = stage
        self.since = time.perf_counter()
