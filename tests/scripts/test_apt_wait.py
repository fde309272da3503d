"""scripts/apt-wait.sh: the install scripts wait, saying so, while another process holds
apt's or dpkg's lock, then go on; past their limit they fail naming the lock. Locks are
held here on a file of the test's own (GLSLPPM_APT_LOCKS), by flock(1) and, as apt
itself locks, by fcntl, so no real apt run on the machine is held up."""
import fcntl
import os
import subprocess
import sys
import time

import pytest

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
HOLD_SECONDS = 3.0


def wait_for_apt(lock, limit=None):
    """Runs wait_for_apt on lock; returns (exit status, stderr, seconds)."""
    env = dict(os.environ, GLSLPPM_APT_LOCKS=lock)
    if limit is not None:
        env["GLSLPPM_APT_WAIT"] = str(limit)
    start = time.perf_counter()
    run = subprocess.run(["bash", "-c", f"source {REPO}/scripts/apt-wait.sh && wait_for_apt"],
                         env=env, capture_output=True, text=True, timeout=60)
    return run.returncode, run.stderr, time.perf_counter() - start


def hold(lock, kind, seconds):
    """A process holding lock for seconds, by flock(1) or by fcntl as apt does; returns
    once the lock is held."""
    if kind == "flock":
        holder = subprocess.Popen(["flock", lock, "sleep", str(seconds)])
    else:
        code = (f"import fcntl, sys, time\nf = open({lock!r}, 'w')\n"
                "fcntl.lockf(f, fcntl.LOCK_EX)\nprint('held', flush=True)\n"
                f"time.sleep({seconds})\n")
        holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                                  text=True)
        assert holder.stdout.readline().strip() == "held"
    deadline = time.time() + 5
    while time.time() < deadline:  # flock(1) takes the lock a moment after it starts
        with open(lock, "w") as f:
            try:
                fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB) if kind == "flock" else \
                    fcntl.lockf(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                return holder
            fcntl.flock(f, fcntl.LOCK_UN) if kind == "flock" else \
                fcntl.lockf(f, fcntl.LOCK_UN)
        time.sleep(0.05)
    raise AssertionError("the lock was never taken")


def test_free_lock_goes_on_at_once(tmp_path):
    lock = str(tmp_path / "lock-frontend")
    open(lock, "w").close()
    status, stderr, seconds = wait_for_apt(lock)
    assert status == 0 and stderr == "" and seconds < 1.0, (status, stderr, seconds)


@pytest.mark.parametrize("kind", ["flock", "fcntl"])
def test_held_lock_is_waited_for_with_a_message(tmp_path, kind):
    """Held for 3 s: the script says whose lock it waits for, waits until it is free
    (3 s, within 1.5 s for the 1 s poll and start-up), and succeeds."""
    lock = str(tmp_path / "lock-frontend")
    open(lock, "w").close()
    holder = hold(lock, kind, HOLD_SECONDS)
    try:
        status, stderr, seconds = wait_for_apt(lock)
    finally:
        holder.wait()
    print(f"{kind}: waited {seconds:.1f} s for a {HOLD_SECONDS} s lock")
    assert status == 0, stderr
    assert stderr.startswith(f"waiting for {lock}: another process is using apt/dpkg "
                             "(up to 900 s)\n"), stderr
    assert "apt/dpkg is free after" in stderr
    assert HOLD_SECONDS - 1.0 < seconds < HOLD_SECONDS + 1.5, seconds


def test_lock_held_past_the_limit_fails_naming_it(tmp_path):
    lock = str(tmp_path / "lock-frontend")
    open(lock, "w").close()
    holder = hold(lock, "fcntl", 10)
    try:
        status, stderr, seconds = wait_for_apt(lock, limit=1)
    finally:
        holder.kill()
        holder.wait()
    assert status == 1
    assert f"{lock} is still locked after 1 s" in stderr, stderr
    assert seconds < 4.0
