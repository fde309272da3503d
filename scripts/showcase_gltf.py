"""The showcase scene (demo/showcase.py) as the add-on exports it, written as glTF 2.0 for
glslppm-render on a machine without Blender (the README's GPU picture):

    blender -b --factory-startup --python scripts/showcase_gltf.py -- \
        --out out/showcase.gltf [--width 1920 --height 1080]
    glslppm-render --scene out/showcase.gltf --width 1920 --height 1080 \
        --environment-color R,G,B (printed) --out showcase.exr

The triangles, normals and camera are the add-on's own (instances flattened). Materials
map to glTF's metallic-roughness model as glslppm-render reads it back
(native/loaders/gltf_materials.cpp): Lambert is specular 0, a conductor metallic 1, glass
transmission 1 with KHR_materials_ior and KHR_materials_volume for its absorption. The
spot lamp keeps its power (KHR_lights_punctual's candela at 683 lm/W) and cone; its radius,
which glTF has no field for, goes in the light's extras ("radius", "soft_falloff"), which
glslppm-render reads (native/loaders/gltf_punctual.h) and other readers ignore. Writes no
textures: the showcase has none.
"""

import base64
import json
import math
import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "demo"))
import showcase  # noqa: E402

WATTS_TO_LUMENS = 683.0


def flattened(data):
    """(positions, normals, indices, material ids) of the whole scene, instances applied."""
    positions, normals, indices, ids = [data.positions], [data.normals], [data.indices], \
        [data.material_ids]
    offset = len(data.positions)
    if data.normals is None:
        raise SystemExit("showcase_gltf: the export has no normals")
    for k in range(data.instance_count):
        mesh = data.instance_meshes[int(data.instance_mesh[k])]
        matrix = np.asarray(data.instances[k], np.float64)
        p = mesh["positions"] @ matrix[:3, :3].T + matrix[:3, 3]
        n = mesh["normals"] @ np.linalg.inv(matrix[:3, :3])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        positions.append(p.astype(np.float32))
        normals.append(n.astype(np.float32))
        indices.append(mesh["indices"] + offset)
        ids.append(mesh["material_ids"])
        offset += len(p)
    return (np.concatenate(positions).astype(np.float32),
            np.concatenate(normals).astype(np.float32),
            np.concatenate(indices).astype(np.uint32), np.concatenate(ids).astype(np.uint32))


def material(entry, materials):
    """One add-on material as a glTF material (a Mix: its larger part)."""
    while entry.kind == "mix":
        entry = materials[entry.mix_b if entry.mix_factor >= 0.5 else entry.mix_a]
    out = {"name": entry.kind, "doubleSided": True, "extensions": {},
           "pbrMetallicRoughness": {"baseColorFactor": list(entry.color) + [1.0],
                                    "metallicFactor": 0.0,
                                    "roughnessFactor": float(entry.roughness)}}
    pbr = out["pbrMetallicRoughness"]
    if entry.kind == "diffuse":
        pbr["roughnessFactor"] = 1.0
        out["extensions"]["KHR_materials_specular"] = {"specularFactor": 0.0}
    elif entry.kind == "conductor":
        pbr["metallicFactor"] = 1.0
    elif entry.kind == "dielectric":
        out["extensions"]["KHR_materials_transmission"] = {"transmissionFactor": 1.0}
        out["extensions"]["KHR_materials_ior"] = {"ior": float(entry.ior)}
        if max(entry.absorption) > 0.0:
            # sigma_a = -ln(colour) / distance at distance 1.
            out["extensions"]["KHR_materials_volume"] = {
                "attenuationDistance": 1.0,
                "attenuationColor": [math.exp(-a) for a in entry.absorption]}
    if max(entry.emission) > 0.0:
        strength = max(entry.emission)
        out["emissiveFactor"] = [c / strength for c in entry.emission]
        out["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
    if not out["extensions"]:
        del out["extensions"]
    return out


def light_matrix(light):
    """A glTF node matrix (column-major) at the lamp, its -Z along the lamp's direction."""
    back = -np.asarray(light.direction, np.float64)
    back /= np.linalg.norm(back)
    side = np.cross([0.0, 0.0, 1.0] if abs(back[2]) < 0.9 else [1.0, 0.0, 0.0], back)
    side /= np.linalg.norm(side)
    up = np.cross(back, side)
    matrix = np.identity(4)
    matrix[:3, 0], matrix[:3, 1], matrix[:3, 2] = side, up, back
    matrix[:3, 3] = light.position
    return matrix.T.reshape(-1).tolist()


def write_gltf(data, path):
    positions, normals, indices, ids = flattened(data)
    buffers, views, accessors, primitives = bytearray(), [], [], []

    def add(array, target, kind, component):
        while len(buffers) % 4:
            buffers.append(0)
        views.append({"buffer": 0, "byteOffset": len(buffers), "byteLength": array.nbytes,
                      "target": target})
        buffers.extend(array.tobytes())
        accessor = {"bufferView": len(views) - 1, "componentType": component,
                    "count": int(array.shape[0]), "type": kind}
        if kind == "VEC3" and component == 5126:
            accessor["min"] = array.min(axis=0).tolist()
            accessor["max"] = array.max(axis=0).tolist()
        accessors.append(accessor)
        return len(accessors) - 1

    position = add(positions, 34962, "VEC3", 5126)
    normal = add(normals, 34962, "VEC3", 5126)
    for m in range(len(data.materials)):
        triangles = indices[ids == m]
        if len(triangles):
            primitives.append({"attributes": {"POSITION": position, "NORMAL": normal},
                               "indices": add(triangles.reshape(-1), 34963, "SCALAR", 5125),
                               "material": m})
    lights = []
    for light in data.lights:
        if light.kind not in ("point", "spot"):
            raise SystemExit(f"showcase_gltf: a {light.kind} lamp is not written")
        entry = {"type": light.kind, "color": list(light.color),
                 "intensity": light.power * WATTS_TO_LUMENS / (4.0 * math.pi),
                 "extras": {"radius": light.radius, "soft_falloff": bool(light.facing_disc)}}
        if light.kind == "spot":
            outer = 0.5 * light.spot_size
            entry["spot"] = {"outerConeAngle": outer,
                             "innerConeAngle": outer * (1.0 - light.spot_blend)}
        lights.append(entry)
    camera = data.camera
    aspect = data.width / data.height
    yfov = 2.0 * math.atan(math.tan(0.5 * camera.fov_x) / aspect)
    to_world = np.asarray(camera.to_world, np.float64)
    nodes = [{"mesh": 0},
             {"camera": 0, "matrix": to_world.T.reshape(-1).tolist()}]
    for k, light in enumerate(data.lights):
        nodes.append({"matrix": light_matrix(light),
                      "extensions": {"KHR_lights_punctual": {"light": k}}})
    document = {
        "asset": {"version": "2.0", "generator": "glslppm scripts/showcase_gltf.py"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_ior",
                           "KHR_materials_specular", "KHR_materials_transmission",
                           "KHR_materials_volume", "KHR_materials_emissive_strength"],
        "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
        "meshes": [{"primitives": primitives}],
        "materials": [material(m, data.materials) for m in data.materials],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": yfov, "aspectRatio": aspect, "znear": 0.01}}],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": len(buffers),
                     "uri": "data:application/octet-stream;base64," +
                            base64.b64encode(bytes(buffers)).decode()}],
    }
    with open(path, "w") as f:
        json.dump(document, f)
    return len(indices)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    import argparse
    parser = argparse.ArgumentParser(prog="showcase_gltf.py")
    parser.add_argument("--out", default="out/showcase.gltf")
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    args = parser.parse_args(argv)
    showcase.enable_addon()
    showcase._clear()
    scene = showcase.build_showcase()
    scene.render.resolution_x, scene.render.resolution_y = args.width, args.height
    scene.render.resolution_percentage = 100
    addon = next(module for name, module in sys.modules.items()
                 if name.split(".")[-1] == "glslppm" and hasattr(module, "export"))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    data = addon.export.export_scene(depsgraph, scene.camera, args.width, args.height)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    triangles = write_gltf(data, args.out)
    environment = ",".join(f"{c:g}" for c in data.environment)
    print(f"showcase_gltf: {triangles} triangles, {len(data.materials)} materials, "
          f"{len(data.lights)} lights into {args.out}; render with "
          f"glslppm-render --scene {args.out} --width {args.width} --height {args.height} "
          f"--environment-color {environment}")


if __name__ == "__main__":
    main()
