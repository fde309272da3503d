"""Golden images: three scenes rendered with fixed seeds and settings, kept as test data so
that a change meant to leave images alone (a refactor of the renderer or the GPU layout)
is checked bit for bit (tests/python/test_golden_images.py).

    PYTHONPATH=build python3 tests/python/golden.py   # writes tests/data/golden/*.exr

Regenerate them only when an image is meant to change, and say so in the commit. Only the
stochastic hash is deterministic (the exact hash sums each cell's photons in the order the
GPU's atomics give), so the golden renders use it. They are llvmpipe's images: a GPU
driver's arithmetic differs in the last bits.
"""
import base64
import json
import os
import struct
import sys
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "data")
GOLDEN = os.path.join(DATA, "golden")
TEXTURED_GLTF = os.path.join(DATA, "textured_room.gltf")

SIZE = 48
PASSES = 12


def settings(g):
    # Photons alone: the images were made before light sampling existed, and this mode must
    # stay bit-identical to them (light sampling compiles only where it is asked for).
    # Regenerated for issue 30's warm-up of SPPM's photon paths (pass_stages.cpp), which
    # changes every SPPM film. The
    # same for light tracing: with it off the mirror and glass scenes render as before it
    # existed (the textured room has neither, and compiles none with it on).
    return g.Settings(width=SIZE, height=SIZE, photons_per_pass=8192, seed=11,
                      hash="stochastic", rng="pcg", direct_light="photons", light_tracing=False)


def scenes(g):
    """name -> Scene, for each golden image."""
    textured, _ = g.load_scene(TEXTURED_GLTF, 1.0)
    return {"cornell": g.cornell_box(sphere_rings=16),
            "caustic": g.caustic_scene(sphere_rings=24),
            "textured_gltf": textured}


def render(g, scene):
    r = g.Renderer(scene, settings(g))
    r.run(PASSES)
    film = r.film()
    r.close()
    return film


def _png(rgba):
    h, w, _ = rgba.shape
    raw = b"".join(b"\x00" + rgba[y].astype(np.uint8).tobytes() for y in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw))
            + chunk(b"IEND", b""))


def write_textured_gltf(path):
    """A floor and a back wall with a checker texture, an emissive ceiling panel and a
    camera: the textured glTF of the golden set (base colour texture, uvs, emission)."""
    blob = bytearray()
    views, accessors = [], []

    def accessor(array, kind, component=5126):
        array = np.ascontiguousarray(array)
        while len(blob) % 4:
            blob.extend(b"\x00")
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": array.nbytes})
        blob.extend(array.tobytes())
        count = array.shape[0] if kind != "SCALAR" else array.size
        accessors.append({"bufferView": len(views) - 1, "componentType": component,
                          "count": int(count), "type": kind})
        return len(accessors) - 1

    def quad(corners, material):
        p = np.array(corners, np.float32)
        uv = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], np.float32)
        n = np.cross(p[1] - p[0], p[2] - p[0])
        n = np.tile(n / np.linalg.norm(n), (4, 1)).astype(np.float32)
        idx = np.array([0, 1, 2, 0, 2, 3], np.uint16)
        return {"attributes": {"POSITION": accessor(p, "VEC3"), "NORMAL": accessor(n, "VEC3"),
                               "TEXCOORD_0": accessor(uv, "VEC2")},
                "indices": accessor(idx, "SCALAR", 5123), "material": material}

    checker = np.zeros((8, 8, 4), np.uint8)
    ii, jj = np.meshgrid(np.arange(8), np.arange(8), indexing="ij")
    checker[..., 0] = np.where((ii + jj) % 2, 230, 40)
    checker[..., 1] = np.where((ii + jj) % 2, 200, 90)
    checker[..., 2] = np.where((ii + jj) % 2, 120, 200)
    checker[..., 3] = 255
    primitives = [
        quad([(-2, 0, 2), (2, 0, 2), (2, 0, -2), (-2, 0, -2)], 0),     # floor, facing +y
        quad([(-2, 0, -2), (2, 0, -2), (2, 3, -2), (-2, 3, -2)], 0),   # back wall, facing +z
        quad([(-0.5, 2.9, -0.5), (0.5, 2.9, -0.5), (0.5, 2.9, 0.5), (-0.5, 2.9, 0.5)], 1),
    ]
    doc = {
        "asset": {"version": "2.0", "generator": "glslppm tests/python/golden.py"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(_png(checker)).decode()}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "textures": [{"source": 0, "sampler": 0}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}},
            {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0},
             "emissiveFactor": [1, 1, 1], "doubleSided": False,
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 20}}},
        ],
        "meshes": [{"primitives": primitives}],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.9, "aspectRatio": 1.0, "znear": 0.01}}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 1.4, 3.5]}],
        "scenes": [{"nodes": [0, 1]}],
        "scene": 0,
        "bufferViews": views,
        "accessors": accessors,
    }
    doc["buffers"] = [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                       + base64.b64encode(bytes(blob)).decode()}]
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)


def main():
    sys.path.insert(0, os.environ.get("GLSLPPM_BUILD", os.path.join(HERE, "..", "..", "build")))
    import _glslppm as g
    os.makedirs(GOLDEN, exist_ok=True)
    if not os.path.exists(TEXTURED_GLTF):
        write_textured_gltf(TEXTURED_GLTF)
    for name, scene in scenes(g).items():
        film = render(g, scene)
        assert np.isfinite(film).all() and film[..., :3].mean() > 0, name
        g.write_exr(os.path.join(GOLDEN, f"{name}.exr"), film)
        print(f"{name}: mean {film[..., :3].mean():.5f}")


if __name__ == "__main__":
    main()
