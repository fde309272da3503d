"""Failures reach the caller as errors that say what is wrong and what to do."""
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from conftest import BUILD, quad

SHADERS = os.path.join(os.path.dirname(__file__), "..", "..", "shaders")


def small_scene(g):
    p, t = quad((-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1))
    return g.Scene(p, t, materials=[g.Material()], lights=[g.Light("point", position=(0, 1, 0))])


def test_egl_failure_says_what_to_install():
    """With no EGL vendor library to load, creating a renderer raises GlslppmError naming
    the missing driver and the Debian packages for software rendering."""
    code = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {os.path.abspath(BUILD)!r})
        import numpy as np, _glslppm as g
        p = np.array([[0,0,0],[1,0,0],[0,1,0]], np.float32)
        t = np.array([[0,1,2]], np.uint32)
        s = g.Scene(p, t, lights=[g.Light("point", position=(0,0,1))])
        try:
            g.Renderer(s, g.Settings(width=8, height=8, photons_per_pass=64))
        except g.GlslppmError as e:
            print("ERROR:", e)
    """)
    env = dict(os.environ, __EGL_VENDOR_LIBRARY_FILENAMES="/nonexistent/egl_vendor.json",
               __EGL_VENDOR_LIBRARY_DIRS="/nonexistent")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert "ERROR:" in out.stdout, out.stdout
    assert "libegl-mesa0" in out.stdout
    assert "GPU driver" in out.stdout


def test_shader_compile_error_names_program_file_and_line(glslppm, tmp_path, monkeypatch):
    """A syntax error in an included file is reported with the program, the included file
    and the line, and the renderer is not created."""
    root = tmp_path / "shaders"
    shutil.copytree(SHADERS, root)
    path = root / "common" / "sampling.glsl"
    lines = path.read_text().splitlines()
    bad_line = 12
    lines.insert(bad_line - 1, "float broken = ;")
    path.write_text("\n".join(lines) + "\n")
    monkeypatch.setenv("GLSLPPM_SHADER_DIR", str(root))
    with pytest.raises(glslppm.GlslppmError) as e:
        glslppm.Renderer(small_scene(glslppm),
                         glslppm.Settings(width=8, height=8, photons_per_pass=64))
    message = str(e.value)
    assert "eye_trace.comp" in message
    assert f"common/sampling.glsl:{bad_line}" in message


def test_scene_without_lights_is_an_error(glslppm):
    p, t = quad((-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1))
    scene = glslppm.Scene(p, t, materials=[glslppm.Material()])
    with pytest.raises(ValueError, match="no lights"):
        glslppm.Renderer(scene, glslppm.Settings(width=8, height=8, photons_per_pass=64))


def test_degenerate_triangles_are_dropped_and_counted(glslppm):
    p, t = quad((-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1))
    p = np.concatenate([p, np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2]], np.float32)])
    t = np.concatenate([t, np.array([[4, 5, 6], [4, 4, 4]], np.uint32)])
    scene = glslppm.Scene(p, t, materials=[glslppm.Material()],
                          lights=[glslppm.Light("point", position=(0, 1, 0))])
    r = glslppm.Renderer(scene, glslppm.Settings(width=8, height=8, photons_per_pass=64))
    stats = r.stats()
    assert stats["triangles"] == 2
    assert stats["degenerate_dropped"] == 2
