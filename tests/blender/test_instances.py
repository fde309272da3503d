"""Instanced geometry exported by mesh: a geometry-nodes scatter becomes one mesh in
object space and an instance table (one matrix per instance), rendered through the
two-level MTBVH; its export time is measured."""

import importlib
import math
import time

import bpy
import numpy as np

import helpers
from helpers import add_camera, add_light, add_quad, assert_close, export, load_native


def scatter(count_x, count_y, size, radius, subdivisions, material=None):
    """An object whose geometry nodes place an ico sphere (of `material`, if given) on every
    point of a grid of count_x x count_y points, size across, in the XY plane at z =
    radius."""
    tree = bpy.data.node_groups.new("Scatter", 'GeometryNodeTree')
    if helpers.BLENDER_4:
        tree.interface.new_socket(name="Geometry", in_out='INPUT',
                                  socket_type='NodeSocketGeometry')
        tree.interface.new_socket(name="Geometry", in_out='OUTPUT',
                                  socket_type='NodeSocketGeometry')
    else:
        tree.inputs.new('NodeSocketGeometry', "Geometry")
        tree.outputs.new('NodeSocketGeometry', "Geometry")
    nodes, links = tree.nodes, tree.links
    nodes.new('NodeGroupInput')
    output = nodes.new('NodeGroupOutput')
    grid = nodes.new('GeometryNodeMeshGrid')
    grid.inputs["Size X"].default_value = size
    grid.inputs["Size Y"].default_value = size
    grid.inputs["Vertices X"].default_value = count_x
    grid.inputs["Vertices Y"].default_value = count_y
    ball = nodes.new('GeometryNodeMeshIcoSphere')
    ball.inputs["Radius"].default_value = radius
    ball.inputs["Subdivisions"].default_value = subdivisions
    place = nodes.new('GeometryNodeInstanceOnPoints')
    links.new(grid.outputs["Mesh"], place.inputs["Points"])
    ball_mesh = ball.outputs["Mesh"]
    if material is not None:
        assign = nodes.new('GeometryNodeSetMaterial')
        assign.inputs["Material"].default_value = material
        links.new(ball_mesh, assign.inputs["Geometry"])
        ball_mesh = assign.outputs["Geometry"]
    links.new(ball_mesh, place.inputs["Instance"])
    links.new(place.outputs["Instances"], output.inputs[0])
    mesh = bpy.data.meshes.new("ScatterBase")
    obj = bpy.data.objects.new("Scatter", mesh)
    obj.location = (0.0, 0.0, radius)
    bpy.context.scene.collection.objects.link(obj)
    obj.modifiers.new("Scatter", 'NODES').node_group = tree
    return obj


def _scene(count_x, count_y, subdivisions):
    add_camera((0, -14, 9), (math.radians(58), 0, 0))
    add_quad("Floor", [(-8, -8, 0), (8, -8, 0), (8, 8, 0), (-8, 8, 0)])
    add_light('SUN', 3.0, rotation=(0.3, 0.2, 0))
    return scatter(count_x, count_y, 10.0, 0.04 * 100 / max(count_x, count_y) + 0.02,
                   subdivisions)


def test_geometry_nodes_scatter_exports_by_mesh():
    _scene(100, 100, 3)  # Blender: subdivisions 1 is the icosahedron, 3 has 320 faces
    bpy.context.evaluated_depsgraph_get().update()  # evaluate the nodes before timing
    times = []
    for _ in range(3):
        start = time.perf_counter()
        data = export()
        times.append(time.perf_counter() - start)
    print(f"10,000-instance scatter: export {min(times):.3f} s (best of 3: "
          f"{', '.join(f'{t:.3f}' for t in times)}), {data.stats['seconds']:.3f} s inside "
          "export_scene")
    # Not flattened: one mesh (an ico sphere of 320 triangles) and 10,000 rows.
    assert data.instance_count == 10000, data.stats
    assert len(data.instance_meshes) == 1, data.stats
    mesh = data.instance_meshes[0]
    assert mesh["indices"].shape == (320, 3)
    assert data.triangle_count == 2  # the floor alone in world space
    assert data.instances.dtype == np.float32 and data.instances.shape == (10000, 4, 4)
    # The grid's points, 10 units across, at z = the sphere radius.
    translations = data.instances[:, :3, 3]
    assert_close(translations.min(axis=0)[:2], (-5, -5), 1e-5, "grid corner")
    assert_close(translations.max(axis=0)[:2], (5, 5), 1e-5, "grid corner")
    assert_close(np.ptp(translations[:, 2]), 0.0, 1e-6, "one height")
    assert min(times) < 2.0, times

    native = load_native()
    native_scene = importlib.import_module(helpers.ADDON.__name__ +
                                           ".engine.native_scene").native_scene
    renderer = native.Renderer(native_scene(native, data),
                               native.Settings(width=32, height=32, photons_per_pass=4096))
    renderer.run(1)
    stats = renderer.stats()
    assert stats["instancing"] == "two-level", stats["instancing_reason"]
    assert stats["instances"] == 10000 and stats["instanced_triangles"] == 3200000
    assert stats["triangles"] == 2 + 320
    assert float(np.mean(renderer.film()[..., :3])) > 0.0


def test_instances_of_different_geometry_stay_apart():
    """Geometry nodes picking an ico sphere or a cube per point: both instanced geometries
    are named 'Mesh' on one object, and must still export as two meshes."""
    add_camera((0, -14, 9), (math.radians(58), 0, 0))
    obj = scatter(3, 3, 4.0, 0.5, 1)
    tree = obj.modifiers[0].node_group
    nodes, links = tree.nodes, tree.links
    place = next(n for n in nodes if n.bl_idname == 'GeometryNodeInstanceOnPoints')
    ball = next(n for n in nodes if n.bl_idname == 'GeometryNodeMeshIcoSphere')
    cube = nodes.new('GeometryNodeMeshCube')
    both = nodes.new('GeometryNodeGeometryToInstance')
    links.new(ball.outputs["Mesh"], both.inputs[0])
    links.new(cube.outputs["Mesh"], both.inputs[0])
    links.new(both.outputs[0], place.inputs["Instance"])
    place.inputs["Pick Instance"].default_value = True
    links.new(nodes.new('GeometryNodeInputIndex').outputs[0], place.inputs["Instance Index"])
    data = export()
    assert data.instance_count == 9, data.stats
    counts = sorted(len(m["indices"]) for m in data.instance_meshes)
    assert counts == [12, 20], counts  # a cube's 12 triangles, an icosahedron's 20
    per_instance = sorted(len(data.instance_meshes[k]["indices"]) for k in data.instance_mesh)
    # Index modulo 2 over 9 points: 5 of the first geometry, 4 of the second (the
    # multi-input socket's order decides which is first).
    assert per_instance in ([12] * 4 + [20] * 5, [12] * 5 + [20] * 4), per_instance


def test_small_scatter_matches_cycles():
    """A 4 x 4 scatter of ico spheres on a floor under a sun and a grey world, traced
    through the two-level MTBVH (Instancing: Two-Level; the automatic rule would flatten
    so few triangles), against Cycles with a 1-pixel box filter: the worst of 3 x 3
    regions within 3% of the brightest and the image means within 1% (measured before
    these bounds under 3.4: 0.98% and 0.04%). Floor and spheres are a diffuse 0.8 grey, as
    every Cycles renders it: left without a material they were Blender's default surface,
    which 5.0 made a Principled BSDF (test_export's test of objects without a material)."""
    helpers.reset_scene(size=(48, 48))
    add_camera((0, -9, 7), (math.radians(52), 0, 0))
    grey = helpers.diffuse_material("Grey", (0.8, 0.8, 0.8))
    add_quad("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], material=grey)
    add_light('SUN', 3.0, rotation=(0.4, 0.3, 0))
    helpers.set_world((0.2, 0.2, 0.2))
    scatter(4, 4, 6.0, 0.7, 3, material=grey)
    scene = bpy.context.scene
    scene.glslppm.instancing = 'TWO_LEVEL'
    scene.glslppm.passes = 64
    scene.glslppm.photons_per_pass = 16384
    ours, error, engine = helpers.render_recorded("scatter_glslppm")
    assert error is None, error
    stats = engine.last_stats
    assert stats["instancing"] == "two-level" and stats["instances"] == 16, stats
    reference = helpers.render_cycles_box_filter("scatter", samples=64)
    a, b, region_error, mean_error = helpers.region_comparison(ours, reference, grid=3)
    print(f"  scatter: worst region {region_error:.4f} of the brightest, image means "
          f"{mean_error:.4f} apart (GLSLPPM {a.mean():.4f}, Cycles {b.mean():.4f})")
    assert region_error < 0.03 and mean_error < 0.01
