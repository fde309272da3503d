"""The showcase scene: the light this engine is for, on a tabletop, built from scratch with
bpy and ordinary Blender nodes a user can open and edit:

- a glass tumbler of amber tea (Glass BSDF shell; the tea is Principled BSDF transmission
  with a Volume Absorption inside, so its caustic is tinted);
- a gold ring whose cardioid falls on the table inside it;
- a blue glass ball (Glass BSDF with Volume Absorption: a blue caustic);
- a rough copper ball (Principled BSDF, metallic, roughness 0.3) and a frosted glass cube
  (Glass BSDF, roughness 0.25);
- one small spot lamp (radius 2 cm) low behind the objects, so the caustics are sharp and
  fall towards the camera, and a dim grey world that lifts the shadows.

Render it (what `make demo` does):

    blender -b --factory-startup --python demo/showcase.py -- \
        --out out/demo --size 512 --time-limit 120 [--save out/demo.blend]

writes out/demo.png (display-referred, through Blender's colour management) and
out/demo.exr (linear) with the GLSLPPM engine; --engine CYCLES renders the same scene with
Cycles (caustics on, no clamping, a 1-px box filter), for comparisons.
"""

import argparse
import math
import os
import sys
import time

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cornell_box import enable_addon, quad, shader_material, sphere  # noqa: E402  (demo/ is no package)

# Where each object stands on the table (x to the right, y away from the camera, z up).
TUMBLER = (-0.55, 0.35)
RING = (0.55, -0.35)
BLUE_BALL = (0.75, 0.75)
COPPER_BALL = (-1.25, -0.35)
FROSTED_CUBE = (-0.05, -0.75)
LIGHT = (-1.2, 3.4, 2.4)
LAMP_TARGET = (-0.1, -0.1, 0.0)
# Every object stands a tenth of a millimetre above the table, not in its plane: where two
# surfaces coincide, which one a ray hits follows its last bits, so two exports an ulp apart
# rendered different paths (docs/nondeterminism.md).
LIFT = 1e-4


def _material_with_volume(name, node_type, volume_color, density, **inputs):
    """shader_material plus a Volume Absorption (Blender's node) on the Volume output."""
    material = shader_material(name, node_type, **inputs)
    tree = material.node_tree
    absorption = tree.nodes.new("ShaderNodeVolumeAbsorption")
    absorption.inputs["Color"].default_value = tuple(volume_color) + (1.0,)
    absorption.inputs["Density"].default_value = density
    output = next(node for node in tree.nodes if node.type == 'OUTPUT_MATERIAL')
    tree.links.new(absorption.outputs[0], output.inputs["Volume"])
    return material


def _principled(name, **inputs):
    """A Principled BSDF material; inputs by their Blender 4.x names, mapped for 3.x."""
    if bpy.app.version < (4, 0, 0) and "Transmission Weight" in inputs:
        inputs["Transmission"] = inputs.pop("Transmission Weight")
    return shader_material(name, "ShaderNodeBsdfPrincipled", **inputs)


def lathe(name, profile, material, location=(0.0, 0.0, 0.0), segments=96):
    """A solid of revolution about z: profile [(r, z), ...] runs around the solid's cross
    section, each straight piece its own band of faces (smooth along the turn, sharp at the
    profile's corners), a point of r = 0 closing its band as a fan. Counter-clockwise
    profiles (seen with r to the right, z up) give outward normals."""
    vertices, faces = [], []
    for (r0, z0), (r1, z1) in zip(profile, profile[1:]):
        base = len(vertices)
        for r, z in ((r0, z0), (r1, z1)):
            for k in range(segments):
                angle = 2.0 * math.pi * k / segments
                vertices.append((r * math.cos(angle), r * math.sin(angle), z))
        for k in range(segments):
            a, b = base + k, base + (k + 1) % segments
            c, d = b + segments, a + segments
            faces.append((a, b, c, d) if r0 > 0.0 or r1 > 0.0 else ())
    faces = [f for f in faces if f]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.validate()
    mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    _merge_and_orient(mesh)
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _merge_and_orient(mesh):
    """Degenerate fan corners merged and every face turned outward (bmesh)."""
    import bmesh
    bm = bmesh.new()
    bm.from_mesh(mesh)
    centre_verts = [v for v in bm.verts if v.co.xy.length < 1e-7]
    bmesh.ops.remove_doubles(bm, verts=centre_verts, dist=1e-6)
    bmesh.ops.dissolve_degenerate(bm, edges=bm.edges, dist=1e-7)
    bmesh.ops.recalc_face_normals(bm, faces=bm.faces)
    bm.to_mesh(mesh)
    bm.free()


def _cube(name, location, size, material, rotation=0.0):
    bpy.ops.mesh.primitive_cube_add(size=size, location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.rotation_euler = (0.0, 0.0, rotation)
    obj.data.materials.append(material)
    return obj


def build_showcase(light_power=600.0, light_radius=0.02, lens=42.0):
    """The tabletop: table z = 0 spanning x, y in [-6, 6], under a spot's pool of light.
    light_radius: the lamp's (Blender's Radius); a larger one softens the caustics
    until a path tracer finds them too (the test against Cycles uses one). Returns the
    scene."""
    scene = bpy.context.scene
    # Diffuse BSDF, not Principled: Blender 3.x's Principled diffuse is Disney's, which
    # glslppm renders as Lambert (7% darker at this table's grazing far end, docs/materials.md).
    table = shader_material("Table", "ShaderNodeBsdfDiffuse", Color=(0.80, 0.76, 0.70, 1.0))
    quad("Table", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], table)

    # The tumbler: a glass shell 2.5 mm thick (on a 0.32 m radius) with a thicker base.
    radius, height, wall, base = 0.32, 0.78, 0.025, 0.06
    glass = shader_material("Glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.0)
    lathe("Tumbler", [(0.0, 0.0), (radius, 0.0), (radius, height), (radius - wall, height),
                      (radius - wall, base), (0.0, base)], glass, (*TUMBLER, LIFT))
    tea = _material_with_volume(
        "Tea", "ShaderNodeBsdfPrincipled", (0.95, 0.55, 0.18), 2.5,
        **{("Transmission Weight" if bpy.app.version >= (4, 0, 0) else "Transmission"): 1.0,
           "IOR": 1.33, "Roughness": 0.0, "Base Color": (1.0, 1.0, 1.0, 1.0)})
    inner, level = radius - wall - 0.002, 0.55
    lathe("Tea", [(0.0, base + 0.002), (inner, base + 0.002), (inner, level), (0.0, level)],
          tea, (*TUMBLER, LIFT))

    # The ring: a gold band 1.2 cm thick whose inside mirrors the light into a cardioid.
    gold = _principled("Gold", **{"Base Color": (1.0, 0.78, 0.34, 1.0), "Metallic": 1.0,
                                  "Roughness": 0.02})
    ring_radius, ring_height, band = 0.5, 0.22, 0.012
    lathe("Ring", [(ring_radius, 0.0), (ring_radius + band, 0.0),
                   (ring_radius + band, ring_height), (ring_radius, ring_height),
                   (ring_radius, 0.0)], gold, (*RING, LIFT))

    blue = _material_with_volume("BlueGlass", "ShaderNodeBsdfGlass", (0.25, 0.55, 0.95), 6.0,
                                 IOR=1.5, Roughness=0.0)
    sphere("BlueBall", (*BLUE_BALL, 0.24 + LIFT), 0.24, blue, segments=64)
    copper = _principled("Copper", **{"Base Color": (0.95, 0.64, 0.54, 1.0), "Metallic": 1.0,
                                      "Roughness": 0.3})
    sphere("CopperBall", (*COPPER_BALL, 0.3 + LIFT), 0.3, copper, segments=64)
    frosted = shader_material("FrostedGlass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.25)
    next(n for n in frosted.node_tree.nodes if n.type == 'BSDF_GLASS').distribution = 'GGX'
    _cube("FrostedCube", (*FROSTED_CUBE, 0.18 + LIFT), 0.36, frosted, rotation=0.5)

    # A spot, not a point lamp: the same 2 cm source, its photons all sent towards the
    # table (a point lamp sends half of them to the sky; the cone's 13x denser photons are
    # what makes the caustics converge within the demo's two minutes).
    light = bpy.data.lights.new("Lamp", 'SPOT')
    light.energy = light_power
    light.shadow_soft_size = light_radius
    light.spot_size = math.radians(64.0)
    light.spot_blend = 0.35
    light.color = (1.0, 0.95, 0.88)
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = LIGHT
    aim = Vector(LAMP_TARGET) - Vector(LIGHT)
    lamp.rotation_euler = aim.to_track_quat('-Z', 'Y').to_euler()
    scene.collection.objects.link(lamp)

    world = bpy.data.worlds.new("World")
    world.color = (0.02, 0.022, 0.025)
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    background = world.node_tree.nodes.get("Background")
    if background is not None:
        background.inputs["Color"].default_value = (0.02, 0.022, 0.025, 1.0)
        background.inputs["Strength"].default_value = 1.0
    scene.world = world

    camera = bpy.data.cameras.new("Camera")
    camera.lens = lens
    camera_object = bpy.data.objects.new("Camera", camera)
    camera_object.location = (0.0, -4.2, 2.9)
    camera_object.rotation_euler = (math.radians(57.0), 0.0, 0.0)
    scene.collection.objects.link(camera_object)
    scene.camera = camera_object
    return scene


def _clear():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.lights, bpy.data.cameras,
                       bpy.data.materials, bpy.data.worlds):
        for item in list(collection):
            collection.remove(item)


def use_cycles(scene, samples):
    """Cycles as the comparisons run it: caustics on, no clamping, no filter glossy, a 1-px
    box filter, on the CPU."""
    scene.render.engine = 'CYCLES'
    cycles = scene.cycles
    cycles.device = 'CPU'
    cycles.samples = samples
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    cycles.caustics_reflective = cycles.caustics_refractive = True
    cycles.sample_clamp_direct = cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.max_bounces = cycles.transmission_bounces = 12
    cycles.glossy_bounces = cycles.diffuse_bounces = 4
    cycles.pixel_filter_type = 'BOX'
    cycles.filter_width = 1.0


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="showcase.py")
    parser.add_argument("--out", default="out/demo")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--passes", type=int, default=100000,
                        help="at most this many passes (the time limit usually ends first)")
    parser.add_argument("--time-limit", type=float, default=120.0)
    parser.add_argument("--photons", type=int, default=65536)
    parser.add_argument("--radius-scale", type=float, default=0.5)
    parser.add_argument("--engine", choices=("GLSLPPM", "CYCLES"), default="GLSLPPM")
    parser.add_argument("--samples", type=int, default=64, help="Cycles only")
    parser.add_argument("--save", default=None, help="also save the scene as .blend")
    parser.add_argument("--light-tracing", choices=("on", "off"), default="on")
    args = parser.parse_args(argv)

    enable_addon()
    _clear()
    scene = build_showcase()
    scene.render.resolution_x = scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = 'Standard'
    scene.render.engine = 'GLSLPPM'
    settings = scene.glslppm
    settings.passes = args.passes
    settings.photons_per_pass = args.photons
    settings.time_limit = args.time_limit
    settings.radius_scale = args.radius_scale
    settings.hash_mode = 'EXACT'
    settings.light_tracing = args.light_tracing == "on"
    out = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    if args.save:
        # Saved with the GLSLPPM engine chosen, whatever renders here.
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save), copy=True)
    if args.engine == 'CYCLES':
        use_cycles(scene, args.samples)

    started = time.perf_counter()
    bpy.ops.render.render()
    seconds = time.perf_counter() - started
    result = bpy.data.images["Render Result"]
    image = scene.render.image_settings
    image.file_format = 'PNG'
    image.color_depth = '8'
    result.save_render(out + ".png", scene=scene)
    image.file_format = 'OPEN_EXR'
    image.color_depth = '32'
    result.save_render(out + ".exr", scene=scene)
    print(f"demo: {args.engine} rendered {args.size}x{args.size} in {seconds:.1f} s; "
          f"wrote {out}.png and {out}.exr")


if __name__ == "__main__":
    main()
