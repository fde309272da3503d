"""Shared helpers for the module's tests: small scenes built from numpy arrays."""
import os
import sys

import numpy as np
import pytest

BUILD = os.environ.get("GLSLPPM_BUILD",
                       os.path.join(os.path.dirname(__file__), "..", "..", "build"))
sys.path.insert(0, os.path.abspath(BUILD))

import _glslppm as native  # noqa: E402


@pytest.fixture
def glslppm():
    return native


def quad(a, b, c, d):
    """Two triangles, counter-clockwise seen from the side the normal points to."""
    p = np.array([a, b, c, d], dtype=np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    return p, t


def merge(*parts):
    """Concatenates (positions, indices, material) parts into one mesh."""
    positions, indices, materials = [], [], []
    base = 0
    for p, t, m in parts:
        positions.append(p)
        indices.append(t + base)
        materials.append(np.full(len(t), m, dtype=np.uint32))
        base += len(p)
    return (np.concatenate(positions).astype(np.float32),
            np.concatenate(indices).astype(np.uint32),
            np.concatenate(materials).astype(np.uint32))


def sphere(center, radius, rings, segments, inward=False):
    """Latitude-longitude sphere (zero-area pole triangles left out)."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.cos(th), np.sin(th) * np.sin(ph)],
                 axis=-1).reshape(-1, 3)
    p = (np.asarray(center) + radius * n).astype(np.float32)
    row = segments + 1
    tris = []
    for i in range(rings):
        for j in range(segments):
            a = i * row + j
            b = a + row
            t0, t1 = [a, a + 1, b], [a + 1, b + 1, b]
            if inward:
                t0, t1 = [t0[0], t0[2], t0[1]], [t1[0], t1[2], t1[1]]
            if i != 0:
                tris.append(t0)
            if i != rings - 1:
                tris.append(t1)
    normals = (-n if inward else n).astype(np.float32)
    return p, np.array(tris, dtype=np.uint32), normals


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """Camera-to-world matrix (row-major, as Blender's matrix_world) looking down -Z."""
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    back = eye - target
    back /= np.linalg.norm(back)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    true_up = np.cross(back, right)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, true_up, back, eye
    return m.astype(np.float32)


# Test durations. `make test` lists each suite's 20 slowest tests (scripts/test_summary.py
# reads the DURATION lines printed below); a test over SLOW_SECONDS on this project's
# 2-core machine carries @pytest.mark.slow("why it needs that long"), and the list names
# any that does not.
SLOW_SECONDS = 30.0
SLOWEST_SHOWN = 20
_durations = {}


def pytest_configure(config):
    config.addinivalue_line("markers", "slow(reason): a test that takes over 30 s here, and why")


def pytest_runtest_logreport(report):
    _durations[report.nodeid] = _durations.get(report.nodeid, 0.0) + report.duration


def pytest_collection_modifyitems(items):
    for item in items:
        mark = item.get_closest_marker("slow")
        if mark is not None:
            _slow_reasons[item.nodeid] = mark.args[0] if mark.args else ""


_slow_reasons = {}


def pytest_terminal_summary(terminalreporter):
    slowest = sorted(_durations.items(), key=lambda item: -item[1])[:SLOWEST_SHOWN]
    terminalreporter.write_line(f"{SLOWEST_SHOWN} slowest tests (over {SLOW_SECONDS:.0f} s "
                                "they carry a slow mark that says why):")
    for name, seconds in slowest:
        terminalreporter.write_line(duration_line(name, seconds, _slow_reasons.get(name)))


def duration_line(name, seconds, reason):
    """DURATION SECONDS NAME [(slow: REASON) | (over 30 s, NOT MARKED SLOW)]"""
    line = f"DURATION {seconds:.1f} {name}"
    if reason is not None:
        return f"{line} (slow: {reason})"
    return f"{line} (over {SLOW_SECONDS:.0f} s, NOT MARKED SLOW)" if seconds > SLOW_SECONDS else line
