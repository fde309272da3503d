"""The equal-cost harness's scenes, built from scratch with bpy (docs/equal_cost.md).

Each builder fills an empty scene (camera, lights, objects, a black world) and returns
nothing. Objects that cast caustics carry obj["equal_cost_role"] = "caster", the surfaces
that receive them "receiver", and the lights light["equal_cost_caustics_light"] = True, so
that the Cycles MNEE method can flag them (Cycles' shadow caustics need all three).

SCENES maps a name to its builder; the regions each is scored in and whether MNEE
applies are the driver's (scripts/equal_cost.py), which runs without bpy.
"""

import math
import os
import sys

import bpy
import mathutils

WHITE = (0.8, 0.8, 0.8)


def _y_up(x, y, z):
    """glslppm's procedural scenes are Y-up; Blender is Z-up (a +90 degree turn about x)."""
    return (x, -z, y)


def _material(name, node_type, **inputs):
    """A material whose Surface is one shader node (demo/cornell_box.py's shader_material)."""
    return _demo().shader_material(name, node_type, **inputs)


def _demo():
    """demo/cornell_box.py, imported from the repository's demo/ (not a package)."""
    demo = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "demo")
    if demo not in sys.path:
        sys.path.insert(0, os.path.abspath(demo))
    import cornell_box
    return cornell_box


def diffuse(name, color):
    return _material(name, "ShaderNodeBsdfDiffuse", Color=tuple(color) + (1.0,))


def glass(name, ior):
    return _material(name, "ShaderNodeBsdfGlass", IOR=ior, Roughness=0.0,
                     Color=(1.0, 1.0, 1.0, 1.0))


def mirror(name, color=(0.9, 0.9, 0.9)):
    return _material(name, "ShaderNodeBsdfGlossy", Roughness=0.0, Color=tuple(color) + (1.0,))


def mesh_object(name, vertices, faces, material, role="receiver", smooth=False):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(map(float, v)) for v in vertices], [],
                     [tuple(f) for f in faces])
    mesh.materials.append(material)
    if smooth:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj["equal_cost_role"] = role
    bpy.context.scene.collection.objects.link(obj)
    return obj


def quad(name, corners, material):
    return mesh_object(name, corners, [(0, 1, 2, 3)], material)


def uv_sphere(name, center, radius, rings, material, role="caster"):
    """rings x 2 rings segments, smooth normals (as glslppm's make_sphere)."""
    segments = 2 * rings
    vertices = [(center[0], center[1], center[2] + radius)]
    for i in range(1, rings):
        theta = math.pi * i / rings
        for j in range(segments):
            phi = 2 * math.pi * j / segments
            vertices.append((center[0] + radius * math.sin(theta) * math.cos(phi),
                             center[1] + radius * math.sin(theta) * math.sin(phi),
                             center[2] + radius * math.cos(theta)))
    bottom = len(vertices)
    vertices.append((center[0], center[1], center[2] - radius))
    faces = []

    def ring(i, j):
        return 1 + (i - 1) * segments + j % segments
    for j in range(segments):
        faces.append((0, ring(1, j), ring(1, j + 1)))
        faces.append((bottom, ring(rings - 1, j + 1), ring(rings - 1, j)))
    for i in range(1, rings - 1):
        for j in range(segments):
            faces.append((ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)))
    return mesh_object(name, vertices, faces, material, role=role, smooth=True)


def add_light(kind, name, location, power, direction=None, caustics=True, **settings):
    light = bpy.data.lights.new(name, kind)
    light.energy = power
    for key, value in settings.items():
        setattr(light, key, value)
    light["equal_cost_caustics_light"] = caustics
    obj = bpy.data.objects.new(name, light)
    obj.location = location
    if direction is not None:  # lights shine along their local -Z
        obj.rotation_euler = mathutils.Vector(direction).to_track_quat('-Z', 'Y').to_euler()
    bpy.context.scene.collection.objects.link(obj)
    return obj


def add_camera(location, target, fov_x=None, lens=None):
    camera = bpy.data.cameras.new("Camera")
    camera.sensor_fit = 'HORIZONTAL'
    if fov_x is not None:
        camera.angle = fov_x
    if lens is not None:
        camera.lens = lens
    camera.clip_start, camera.clip_end = 1e-3, 1e3
    obj = bpy.data.objects.new("Camera", camera)
    obj.location = location
    direction = mathutils.Vector(target) - mathutils.Vector(location)
    obj.rotation_euler = direction.to_track_quat('-Z', 'Y').to_euler()
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    return obj


def area_power(radiance, area):
    """Blender power of an area light of this radiance: Cycles 4.x emits L = P / (pi A),
    3.x L = P / (4 A) (addon/export/light.py says where this comes from)."""
    return radiance * area * (math.pi if bpy.app.version >= (4, 0, 0) else 4.0)


def build_caustic():
    """glslppm's built-in caustic scene (native/procedural/caustic_scene.cpp) in Blender:
    a glass ball (ior 1.5, r 0.5, 64 rings) on a white floor before a bluish wall, lit by
    a 0.25 x 0.25 one-sided quad of radiance 600 (here an area light, which Cycles' MNEE
    can sample), camera at (0.6, 2.2, 3.4) looking at (0.25, 0.3, 0), 0.8 rad wide."""
    floor, wall = diffuse("Floor", WHITE), diffuse("Wall", (0.6, 0.6, 0.7))
    quad("Floor", [_y_up(-3, 0, -2), _y_up(-3, 0, 3), _y_up(3, 0, 3), _y_up(3, 0, -2)], floor)
    quad("Wall", [_y_up(-3, 0, -2), _y_up(3, 0, -2), _y_up(3, 3, -2), _y_up(-3, 3, -2)], wall)
    uv_sphere("Ball", _y_up(0, 0.5, 0), 0.5, 64, glass("Glass", 1.5))
    add_light('AREA', "Light", _y_up(-2.5, 2.5, 0), area_power(600.0, 0.0625),
              direction=_y_up(2.5, -2.0, 0.0), shape='SQUARE', size=0.25)
    add_camera(_y_up(0.6, 2.2, 3.4), _y_up(0.25, 0.3, 0.0), fov_x=0.8)


def build_point_ball():
    """The same ball and room under a point light of radius 0.01: the caustic's source is
    almost a point, which a path tracer's BSDF samples through the glass cannot hit."""
    floor, wall = diffuse("Floor", WHITE), diffuse("Wall", (0.6, 0.6, 0.7))
    quad("Floor", [_y_up(-3, 0, -2), _y_up(-3, 0, 3), _y_up(3, 0, 3), _y_up(3, 0, -2)], floor)
    quad("Wall", [_y_up(-3, 0, -2), _y_up(3, 0, -2), _y_up(3, 3, -2), _y_up(-3, 3, -2)], wall)
    uv_sphere("Ball", _y_up(0, 0.5, 0), 0.5, 64, glass("Glass", 1.5))
    add_light('POINT', "Light", _y_up(-2.5, 2.5, 0), 300.0, shadow_soft_size=0.01)
    add_camera(_y_up(0.6, 2.2, 3.4), _y_up(0.25, 0.3, 0.0), fov_x=0.8)


def build_ring():
    """A mirror ring (open tube, r 1, 0.3 high, 128 segments, smooth) on a white floor,
    lit from the side and above by a small area light: the inside of the ring focuses the
    light into a cardioid on the floor (reflective: Cycles' MNEE does not handle it)."""
    quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], diffuse("Floor", WHITE))
    segments, radius, height = 128, 1.0, 0.3
    vertices, faces = [], []
    for j in range(segments):
        phi = 2 * math.pi * j / segments
        x, y = radius * math.cos(phi), radius * math.sin(phi)
        vertices += [(x, y, 0.0), (x, y, height)]
        k, n = 2 * j, 2 * ((j + 1) % segments)
        faces.append((k, n, n + 1, k + 1))
    mesh_object("Ring", vertices, faces, mirror("Metal"), role="caster", smooth=True)
    add_light('AREA', "Light", (-3.0, 0.0, 1.2), area_power(2000.0, 0.01),
              direction=(3.0, 0.0, -1.0), shape='SQUARE', size=0.1)
    add_camera((0.0, -2.2, 3.2), (0.0, 0.1, 0.0), fov_x=0.9)


def _wave(x, y):
    return 0.04 * (math.sin(3.1 * x + 0.4) + math.sin(3.7 * y + 1.3) +
                   0.7 * math.sin(2.3 * (x + y)))


def build_pool():
    """A pool: a wavy water surface (glass ior 1.33, 2 x 2, 64 x 64 quads, smooth) at
    height 0.6 over a white floor inside diffuse walls, under a sun of 0.5 degrees. The
    camera sees the floor through the water: its caustics are specular-diffuse-specular
    paths, which only photons (or merging) find."""
    floor, wall = diffuse("Floor", WHITE), diffuse("Wall", (0.5, 0.6, 0.7))
    quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], floor)
    for name, corners in (("WallN", [(-1, 1, 0), (1, 1, 0), (1, 1, 0.8), (-1, 1, 0.8)]),
                          ("WallS", [(1, -1, 0), (-1, -1, 0), (-1, -1, 0.8), (1, -1, 0.8)]),
                          ("WallE", [(1, 1, 0), (1, -1, 0), (1, -1, 0.8), (1, 1, 0.8)]),
                          ("WallW", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 0.8), (-1, -1, 0.8)])):
        quad(name, corners, wall)
    n = 64
    vertices = [(-1 + 2 * i / n, -1 + 2 * j / n, 0.6 + _wave(-1 + 2 * i / n, -1 + 2 * j / n))
                for j in range(n + 1) for i in range(n + 1)]
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
              (j + 1) * (n + 1) + i) for j in range(n) for i in range(n)]
    mesh_object("Water", vertices, faces, glass("Water", 1.33), role="caster", smooth=True)
    add_light('SUN', "Sun", (0, 0, 5), 3.0, direction=(0.3, 0.2, -1.0),
              angle=math.radians(0.5))
    add_camera((0.0, -2.0, 2.6), (0.0, 0.0, 0.2), fov_x=0.75)


def build_cornell():
    """The demo Cornell box (demo/cornell_box.py: glass and mirror spheres, ceiling
    area light), mostly diffuse."""
    _demo().build_cornell_box()
    for obj in bpy.context.scene.objects:
        if obj.type == 'MESH':
            obj["equal_cost_role"] = "caster" if obj.name == "GlassSphere" else "receiver"
        elif obj.type == 'LIGHT':
            obj.data["equal_cost_caustics_light"] = True


def build_showcase():
    """The showcase `make demo` renders (demo/showcase.py: a tumbler of amber tea, a gold
    ring, a blue glass ball, a copper ball and a frosted cube under one 2 cm spot lamp, a dim
    grey world). Casters for MNEE are the smooth glass (the tumbler, its tea, the blue ball);
    the table receives; the gold ring is a mirror, which MNEE does not solve."""
    _demo()  # demo/ on sys.path
    import showcase
    showcase.build_showcase()
    casters = {"Tumbler", "Tea", "BlueBall"}
    for obj in bpy.context.scene.objects:
        if obj.type == 'MESH':
            obj["equal_cost_role"] = "caster" if obj.name in casters else "receiver"
        elif obj.type == 'LIGHT':
            obj.data["equal_cost_caustics_light"] = True


SCENES = {"caustic": build_caustic, "ring": build_ring, "pool": build_pool,
          "point_ball": build_point_ball, "cornell": build_cornell,
          "showcase": build_showcase}
