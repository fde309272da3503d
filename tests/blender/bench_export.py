"""Times the export of a 1,000,000-triangle mesh (smooth shaded, so split normals
are read too). Target: under 2 s.

    blender -b --factory-startup --python tests/blender/bench_export.py -- \
        [--source addon | --module NAME] [--triangles N] [--instances K]
"""

import argparse
import os
import sys
import tempfile
import time

import bpy
import numpy as np


def build_grid(quads_x, quads_y, smooth=True):
    """A flat grid of quads_x * quads_y quads built with foreach_set (fast)."""
    xs, ys = np.meshgrid(np.linspace(-1, 1, quads_x + 1), np.linspace(-1, 1, quads_y + 1))
    vertices = np.stack([xs.ravel(), ys.ravel(), 0.05 * np.sin(8 * xs.ravel())], 1)
    row = quads_x + 1
    i, j = np.meshgrid(np.arange(quads_x), np.arange(quads_y))
    base = (j * row + i).ravel()
    quads = np.stack([base, base + 1, base + row + 1, base + row], 1)
    mesh = bpy.data.meshes.new("Grid")
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", vertices.astype(np.float32).ravel())
    mesh.loops.add(quads.size)
    mesh.loops.foreach_set("vertex_index", quads.astype(np.int32).ravel())
    mesh.polygons.add(len(quads))
    mesh.polygons.foreach_set("loop_start", np.arange(0, quads.size, 4, dtype=np.int32))
    if bpy.app.version < (4, 0, 0):
        mesh.polygons.foreach_set("loop_total", np.full(len(quads), 4, dtype=np.int32))
    mesh.polygons.foreach_set("use_smooth", np.full(len(quads), smooth))
    mesh.update()
    mesh.validate()
    obj = bpy.data.objects.new("Grid", mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", default=None)
    parser.add_argument("--module", default=None)
    parser.add_argument("--triangles", type=int, default=1_000_000)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args(argv)
    if args.module:
        import addon_utils
        package = addon_utils.enable(args.module, default_set=True)
    else:
        source = args.source or os.path.join(os.path.dirname(__file__), "..", "..", "addon")
        link_dir = tempfile.mkdtemp()
        os.symlink(os.path.abspath(source), os.path.join(link_dir, "glslppm"))
        sys.path.insert(0, link_dir)
        import glslppm as package
        package.register()

    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    quads = args.triangles // 2
    quads_x = int(np.sqrt(quads))
    build_grid(quads_x, quads // quads_x)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0, 0, 5)
    bpy.context.scene.collection.objects.link(camera)
    bpy.context.scene.camera = camera

    depsgraph = bpy.context.evaluated_depsgraph_get()
    times = []
    for _ in range(args.runs):
        began = time.perf_counter()
        data = package.export.export_scene(depsgraph, camera, 640, 480)
        times.append(time.perf_counter() - began)
    version = ".".join(map(str, bpy.app.version))
    print(f"BENCH export Blender {version}: {data.triangle_count} triangles "
          f"(normals {'yes' if data.normals is not None else 'no'}): "
          f"best {min(times):.3f} s, mean {np.mean(times):.3f} s over {args.runs} runs; "
          f"runs {[round(t, 2) for t in times]}; "
          f"{'PASS' if min(times) < 2.0 else 'FAIL'} (target < 2 s)", flush=True)


main()
