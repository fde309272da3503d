"""glTF 2.0 and OBJ/MTL scene files, image files, and glslppm-render --scene/--environment.

Every file is written by the test into tmp_path: glTF as JSON with base64 buffers (or a .bin
beside it, or packed as .glb), OBJ/MTL as text, PNG with zlib and struct, .hdr as flat RGBE.
"""
import base64
import json
import math
import os
import re
import struct
import subprocess
import zlib

import numpy as np
import pytest

from conftest import BUILD

RENDER = os.path.join(BUILD, "glslppm-render")

# ---------------------------------------------------------------------------------------------
# Writers


def png_bytes(rgba, bit_depth=8):
    """A PNG (colour type 6, RGBA) of an (H, W, 4) array whose row 0 is the top row."""
    rgba = np.asarray(rgba)
    h, w, _ = rgba.shape
    dtype = ">u2" if bit_depth == 16 else np.uint8
    raw = b"".join(b"\x00" + rgba[y].astype(dtype).tobytes() for y in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", w, h, bit_depth, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw))
            + chunk(b"IEND", b""))


def hdr_bytes(rgbe):
    """A flat (not run-length encoded) Radiance .hdr of an (H, W, 4) uint8 RGBE array."""
    h, w, _ = rgbe.shape
    head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w)
    return head + np.asarray(rgbe, dtype=np.uint8).tobytes()


class Gltf:
    """Builds a glTF document with one binary buffer."""

    def __init__(self):
        self.blob = bytearray()
        self.doc = {"asset": {"version": "2.0"}, "buffers": [], "bufferViews": [],
                    "accessors": [], "meshes": [], "nodes": [], "scenes": [{"nodes": []}],
                    "scene": 0}

    def accessor(self, array, kind, component=5126):
        array = np.ascontiguousarray(array)
        while len(self.blob) % 4:
            self.blob += b"\x00"
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": array.nbytes}
        self.blob += array.tobytes()
        self.doc["bufferViews"].append(view)
        count = array.shape[0] if kind != "SCALAR" else array.size
        self.doc["accessors"].append({"bufferView": len(self.doc["bufferViews"]) - 1,
                                      "componentType": component, "count": int(count),
                                      "type": kind})
        return len(self.doc["accessors"]) - 1

    def mesh(self, positions, indices=None, material=None, uvs=None, normals=None, mode=None):
        attributes = {"POSITION": self.accessor(np.asarray(positions, np.float32), "VEC3")}
        if uvs is not None:
            attributes["TEXCOORD_0"] = self.accessor(np.asarray(uvs, np.float32), "VEC2")
        if normals is not None:
            attributes["NORMAL"] = self.accessor(np.asarray(normals, np.float32), "VEC3")
        primitive = {"attributes": attributes}
        if indices is not None:
            primitive["indices"] = self.accessor(np.asarray(indices, np.uint16).ravel(),
                                                 "SCALAR", 5123)
        if material is not None:
            primitive["material"] = material
        if mode is not None:
            primitive["mode"] = mode
        self.doc["meshes"].append({"primitives": [primitive]})
        return len(self.doc["meshes"]) - 1

    def node(self, root=True, **fields):
        self.doc["nodes"].append(fields)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def extension(self, name):
        self.doc.setdefault("extensionsUsed", [])
        if name not in self.doc["extensionsUsed"]:
            self.doc["extensionsUsed"].append(name)

    def json_text(self, external_bin=None):
        doc = json.loads(json.dumps(self.doc))
        uri = external_bin or ("data:application/octet-stream;base64,"
                               + base64.b64encode(bytes(self.blob)).decode())
        doc["buffers"] = [{"byteLength": len(self.blob), "uri": uri}]
        return json.dumps(doc)

    def write(self, path):
        path.write_text(self.json_text())
        return str(path)

    def glb(self):
        doc = json.loads(json.dumps(self.doc))
        blob = bytes(self.blob) + b"\x00" * (-len(self.blob) % 4)
        doc["buffers"] = [{"byteLength": len(blob)}]
        text = json.dumps(doc).encode()
        text += b" " * (-len(text) % 4)
        body = (struct.pack("<II", len(text), 0x4E4F534A) + text
                + struct.pack("<II", len(blob), 0x004E4942) + blob)
        return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


QUAD = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
QUAD_UV = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
QUAD_TRIS = np.array([[0, 1, 2], [0, 2, 3]])


def load(glslppm, path, aspect=1.0):
    scene, warnings = glslppm.load_scene(str(path), aspect)
    return scene, glslppm.scene_contents(scene), warnings


# ---------------------------------------------------------------------------------------------
# glTF


def test_gltf_node_transforms_apply_to_positions_and_normals(glslppm, tmp_path):
    g = Gltf()
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    mesh = g.mesh(QUAD, QUAD_TRIS, normals=normals)
    other = g.mesh(QUAD, QUAD_TRIS, normals=normals)  # one node each: world triangles
    child = g.node(root=False, mesh=mesh, scale=[2, 2, 2])
    # The parent turns 90 degrees about +Y (quaternion x, y, z, w) and moves by (1, 2, 3).
    s = math.sqrt(0.5)
    g.node(children=[child], translation=[1, 2, 3], rotation=[0, s, 0, s])
    g.node(mesh=other, matrix=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1])
    scene, c, warnings = load(glslppm, g.write(tmp_path / "t.gltf"))
    assert scene.triangle_count == 4 and scene.instance_count == 0
    assert len(c["materials"]) == 1 and c["materials"][0]["kind"] == "diffuse"  # the default
    p = c["positions"]
    # Child: scaled by 2, then Ry(90): (x, y, z) -> (z, y, -x), then translated.
    expected = np.array([[2 * q[2], 2 * q[1], -2 * q[0]] for q in QUAD]) + [1, 2, 3]
    np.testing.assert_allclose(p[:4], expected, atol=1e-6)
    np.testing.assert_allclose(p[4:], QUAD + [10, 0, 0], atol=1e-6)
    # The +Z normal turns to +X under Ry(90) and stays unit length despite the scale.
    np.testing.assert_allclose(c["normals"][:4], np.tile([1, 0, 0], (4, 1)), atol=1e-6)
    assert any("no camera" in w for w in warnings)


def box_mesh(g):
    """A unit cube, 12 triangles, outward winding, one mesh of the document."""
    c = np.array([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)], np.float32)
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4),
             (1, 5, 7, 3)]
    tris = [[a, b, c_] for a, b, c_, d in faces] + [[a, c_, d] for a, b, c_, d in faces]
    return g.mesh(c, np.array(tris))


def instancing_document(shared):
    """A floor, a sun, a camera and a cube placed by five nodes: nested (a parent that
    turns and a child that scales), mirrored, and translated. shared: one mesh used by all
    five nodes (glTF node instancing); else a copy of the mesh per node."""
    g = Gltf()
    g.doc["materials"] = [{"pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.3, 0.2, 1], "metallicFactor": 0.0}}]
    g.extension("KHR_lights_punctual")
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "directional", "intensity": 2000.0}]}}  # lux: about 3 W/m^2
    floor = g.mesh(np.array([[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5]], np.float32),
                   np.array([[0, 2, 1], [0, 3, 2]]))
    g.node(mesh=floor)
    s = math.sqrt(0.5)
    g.node(rotation=[-s, 0, 0, s], extensions={"KHR_lights_punctual": {"light": 0}})
    g.doc["cameras"] = [{"type": "perspective",
                         "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.0}}]
    g.node(camera=0, translation=[0, 4, 9], rotation=[-0.2164, 0, 0, 0.9763])
    cube = box_mesh(g)
    g.doc["meshes"][cube]["primitives"][0]["material"] = 0

    def mesh():
        if shared:
            return cube
        copy = json.loads(json.dumps(g.doc["meshes"][cube]))
        g.doc["meshes"].append(copy)
        return len(g.doc["meshes"]) - 1

    child = g.node(root=False, mesh=mesh(), scale=[0.5, 1.5, 0.5])
    g.node(children=[child], translation=[-2, 0, 0], rotation=[0, 0.3827, 0, 0.9239])
    g.node(mesh=mesh(), translation=[1.5, 0, 1], scale=[-1, 1, 1])  # mirrored
    g.node(mesh=mesh(), translation=[0, 0, -1.5], rotation=[0.2, 0.1, 0, 0.9747])
    g.node(mesh=mesh(), translation=[2.5, 0, -2], scale=[0.7, 0.7, 0.7])
    g.node(mesh=mesh(), translation=[-0.5, 0, 2], scale=[1.2, 0.4, 0.8])
    return g


def test_gltf_node_instancing_becomes_instances(glslppm, tmp_path):
    """One mesh used by five nodes (one nested under a parent) loads as one instance mesh
    and five instances, nested transforms flattened to one level; it renders as the same
    document with a mesh per node does (world triangles), from the same seed."""
    shared, _, _ = load(glslppm, instancing_document(True).write(tmp_path / "shared.gltf"))
    copies, _, _ = load(glslppm, instancing_document(False).write(tmp_path / "copies.gltf"))
    assert shared.instance_count == 5 and shared.triangle_count == 2
    assert copies.instance_count == 0 and copies.triangle_count == 2 + 5 * 12
    images = {}
    for name, scene, mode in (("two-level", shared, "two-level"),
                              ("flattened", shared, "flattened"), ("copies", copies, "auto")):
        r = glslppm.Renderer(scene, glslppm.Settings(width=48, height=48, seed=3,
                                                     photons_per_pass=8192, instancing=mode))
        r.run(4)
        assert r.stats()["instancing"] == {"copies": "none"}.get(name, name)
        images[name] = r.film()[..., :3]
    mean = float(images["copies"].mean())
    assert mean > 0.01
    # Same path, same bounds: rounding only (measured 1e-8 of the mean).
    diff = float(np.abs(images["two-level"] - images["flattened"]).mean()) / mean
    print(f"glTF instancing: two-level vs flattened {diff:.3g} of the mean; means "
          + ", ".join(f"{k} {float(v.mean()):.5f}" for k, v in images.items()))
    assert diff < 1e-6, diff
    # The copies' scene has no instances, so its bounds (the MTBVH's padded root box) and
    # with them the photon hash grid differ: the same estimate, other noise.
    for name in ("two-level", "flattened"):
        assert abs(float(images[name].mean()) / mean - 1.0) < 0.03, name


def test_gltf_mirroring_transform_reverses_the_winding(glslppm, tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS), scale=[-1, 1, 1])
    _, c, _ = load(glslppm, g.write(tmp_path / "m.gltf"))
    p, t = c["positions"], c["triangles"]
    n = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])
    # The quad faces +Z; mirrored in x it must still face +Z (glTF 2.0, section 3.7.4).
    assert np.all(n[:, 2] > 0)


def test_gltf_materials_map_onto_the_material_model(glslppm, tmp_path):
    g = Gltf()
    for ext in ("KHR_materials_transmission", "KHR_materials_ior",
                "KHR_materials_emissive_strength"):
        g.extension(ext)
    g.doc["materials"] = [
        {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.8, 0.3, 1],
                                                  "metallicFactor": 1, "roughnessFactor": 0}},
        {"name": "clay", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.4, 0.3, 1],
                                                  "metallicFactor": 0}},
        {"name": "water", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                        "KHR_materials_ior": {"ior": 1.33}}},
        {"name": "lamp", "pbrMetallicRoughness": {"metallicFactor": 0},
         "emissiveFactor": [1, 0.5, 0.25],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}},
        {"name": "halfmetal", "pbrMetallicRoughness": {"metallicFactor": 0.3}},
    ]
    for m in range(5):
        g.node(mesh=g.mesh(QUAD + [0, 0, m], QUAD_TRIS, material=m))
    _, c, warnings = load(glslppm, g.write(tmp_path / "mat.gltf"))
    mats = c["materials"]
    # glTF's default roughness is 1: the non-metals are rough plastic.
    assert [m["kind"] for m in mats[:5]] == ["conductor", "plastic", "dielectric", "plastic",
                                             "mix"]
    assert mats[0]["schlick"] and mats[0]["roughness"] == 0
    np.testing.assert_allclose(mats[0]["color"], [1, 0.8, 0.3], rtol=1e-6)
    np.testing.assert_allclose(mats[1]["color"], [0.5, 0.4, 0.3], rtol=1e-6)
    assert mats[1]["roughness"] == 1 and mats[1]["ior"] == pytest.approx(1.5, abs=1e-5)
    assert mats[2]["ior"] == pytest.approx(1.33) and not mats[2]["tint_reflection"]
    np.testing.assert_allclose(mats[3]["emission"], [4, 2, 1], rtol=1e-6)
    # metallicFactor 0.3: Mix(plastic, conductor) picking the conductor 30% of the time.
    half = mats[4]
    assert half["mix_factor"] == pytest.approx(0.3)
    assert [mats[half["mix_a"]]["kind"], mats[half["mix_b"]]["kind"]] == ["plastic",
                                                                          "conductor"]
    assert list(c["material_ids"]) == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4]
    assert not _material_warnings(warnings), warnings


def test_gltf_volume_attenuation_becomes_absorption(glslppm, tmp_path):
    """KHR_materials_volume: sigma_a = -ln(attenuationColor) / attenuationDistance on the
    material's root; an infinite (absent) distance absorbs nothing; thicknessFactor, a
    rasterizer's stand-in for the path length that rays measure, is not read."""
    g = Gltf()
    for ext in ("KHR_materials_transmission", "KHR_materials_volume"):
        g.extension(ext)
    g.doc["extensionsRequired"] = ["KHR_materials_volume"]
    glass = {"pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0}}
    g.doc["materials"] = [
        dict(glass, extensions={
            "KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": 0.3, "attenuationDistance": 2.0,
                                     "attenuationColor": [0.5, 0.25, 1.0]}}),
        dict(glass, extensions={
            "KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_volume": {"thicknessFactor": 1, "attenuationColor": [0.5, 0.5, 0.5]}}),
    ]
    for m in range(2):
        g.node(mesh=g.mesh(QUAD + [0, 0, m], QUAD_TRIS, material=m))
    _, c, warnings = load(glslppm, g.write(tmp_path / "volume.gltf"))
    mats = c["materials"]
    roots = [mats[c["material_ids"][0]], mats[c["material_ids"][2]]]
    np.testing.assert_allclose(roots[0]["absorption"],
                               [math.log(2) / 2, math.log(4) / 2, 0.0], rtol=1e-6, atol=1e-7)
    assert roots[1]["absorption"] == (0.0, 0.0, 0.0)
    assert all(m["absorption"] == (0.0, 0.0, 0.0) for m in mats if m is not roots[0])
    assert not _material_warnings(warnings), warnings


@pytest.mark.parametrize("volume, message", [
    ({"attenuationDistance": 0.0}, "attenuationDistance 0 must be > 0"),
    ({"attenuationDistance": 1.0, "attenuationColor": [0.5, 2.0, 0.5]},
     "attenuationColor must be 3 numbers in [0, 1]"),
])
def test_gltf_bad_volume_names_the_field(glslppm, tmp_path, volume, message):
    g = Gltf()
    g.extension("KHR_materials_volume")
    g.doc["materials"] = [{"extensions": {"KHR_materials_volume": volume}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0))
    with pytest.raises(ValueError) as e:
        glslppm.load_scene(g.write(tmp_path / "volume.gltf"))
    assert "materials[0]" in str(e.value) and message in str(e.value), str(e.value)


def _material_warnings(warnings):
    """The warnings about materials (a file without a camera also warns about that)."""
    return [w for w in warnings if "no camera" not in w]


def _data_png(channels):
    """A 2 x 1 PNG data URI from two RGBA texels."""
    pixels = np.array([channels], np.uint8)
    return "data:image/png;base64," + base64.b64encode(png_bytes(pixels)).decode()


def test_gltf_metallic_roughness_texture_reads_blue_and_green_as_numbers(glslppm, tmp_path):
    """metallicRoughnessTexture scales metallic by its blue channel and roughness by its
    green, read as numbers (no sRGB decoding); transmissionTexture's red scales
    transmission; KHR_materials_specular scales F0."""
    g = Gltf()
    for ext in ("KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_specular"):
        g.extension(ext)
    g.doc["images"] = [{"uri": _data_png([[0, 128, 255, 255], [0, 64, 0, 255]])}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [
        {"name": "mapped", "pbrMetallicRoughness": {
            "metallicFactor": 1, "roughnessFactor": 0.8,
            "metallicRoughnessTexture": {"index": 0}}},
        {"name": "glass", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.2},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5,
                                                       "transmissionTexture": {"index": 0}},
                        "KHR_materials_ior": {"ior": 1.5},
                        "KHR_materials_specular": {"specularFactor": 0.5}}},
    ]
    for m in range(2):
        g.node(mesh=g.mesh(QUAD + [0, 0, m], QUAD_TRIS, material=m, uvs=QUAD_UV))
    _, c, warnings = load(glslppm, g.write(tmp_path / "mr.gltf"))
    assert not _material_warnings(warnings), warnings
    mats, textures = c["materials"], c["textures"]
    mapped = mats[0]
    assert mapped["kind"] == "mix" and mapped["mix_factor"] == 1
    assert mapped["mix_channel"] == "blue"
    data = textures[mapped["mix_texture"]]
    assert data["encoding"] == "linear"
    np.testing.assert_allclose(data["pixels"][0, :, 1], [128 / 255, 64 / 255], rtol=1e-6)
    for part in (mats[mapped["mix_a"]], mats[mapped["mix_b"]]):
        assert part["roughness"] == pytest.approx(0.8)
        assert part["roughness_texture"] == mapped["mix_texture"]
        assert part["roughness_channel"] == "green"
    glass = mats[1]
    assert glass["mix_factor"] == 0.5 and glass["mix_channel"] == "red"
    plastic, dielectric = mats[glass["mix_a"]], mats[glass["mix_b"]]
    assert dielectric["kind"] == "dielectric" and dielectric["roughness"] == pytest.approx(0.2)
    # F0 = 0.04 x 0.5 = 0.02: index (1 + sqrt(0.02)) / (1 - sqrt(0.02)).
    assert plastic["kind"] == "plastic"
    assert plastic["ior"] == pytest.approx((1 + math.sqrt(0.02)) / (1 - math.sqrt(0.02)),
                                           rel=1e-5)


@pytest.mark.parametrize("color, f0, warned", [
    ([0, 0, 0], 0.0, False),           # Blender's exporter's Specular 0
    ([0.5, 0.5, 0.5], 0.02, False),    # grey: exactly
    ([0.2, 0.5, 0.8], 0.02, True),     # tinted: its mean, with a warning
    ([30, 30, 30], 0.999, False),      # min(F0 colour, 1), kept below 1 as every F0
])
def test_gltf_specular_color_factor_scales_f0(glslppm, tmp_path, color, f0, warned):
    """KHR_materials_specular's specularColorFactor multiplies F0 = ((ior - 1) / (ior + 1))^2
    (0.04 at 1.5) before the clamp to 1, as the specification's min(F0 color, 1); it was read
    as white, which made Blender's exported Specular 0 a layer of F0 0.034 (issue 30)."""
    g = Gltf()
    g.extension("KHR_materials_specular")
    g.doc["materials"] = [{"pbrMetallicRoughness": {"metallicFactor": 0},
                           "extensions": {"KHR_materials_specular": {
                               "specularColorFactor": color}}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0))
    _, c, warnings = load(glslppm, g.write(tmp_path / "specular.gltf"))
    assert bool(_material_warnings(warnings)) == warned, warnings
    plastic = next(m for m in c["materials"] if m["kind"] == "plastic")
    # Near F0 = 1 the index is 1 / (1 - sqrt(F0)): float rounding of 1 - sqrt is ~1e-4 of it.
    assert plastic["ior"] == pytest.approx((1 + math.sqrt(f0)) / (1 - math.sqrt(f0)),
                                           rel=1e-3 if f0 > 0.5 else 1e-5)


def test_gltf_alpha_modes(glslppm, tmp_path):
    """BLEND: Mix(transparent, material) by the alpha factor times the base colour's
    alpha; MASK: the coverage compared with the cutoff, baked into a 0/1 texture (or a
    constant where untextured); OPAQUE: no mix."""
    g = Gltf()
    g.doc["images"] = [{"uri": _data_png([[255, 255, 255, 200], [255, 255, 255, 40]])}]
    g.doc["textures"] = [{"source": 0}]
    pbr = {"metallicFactor": 0, "baseColorTexture": {"index": 0},
           "baseColorFactor": [1, 1, 1, 0.5]}
    g.doc["materials"] = [
        {"name": "blend", "alphaMode": "BLEND", "pbrMetallicRoughness": pbr},
        {"name": "mask", "alphaMode": "MASK", "alphaCutoff": 0.3, "pbrMetallicRoughness": pbr},
        {"name": "opaque", "alphaMode": "OPAQUE", "pbrMetallicRoughness": pbr},
        {"name": "hidden", "alphaMode": "MASK", "alphaCutoff": 0.6,
         "pbrMetallicRoughness": {"metallicFactor": 0, "baseColorFactor": [1, 1, 1, 0.5]}},
    ]
    for m in range(4):
        g.node(mesh=g.mesh(QUAD + [0, 0, m], QUAD_TRIS, material=m, uvs=QUAD_UV))
    _, c, warnings = load(glslppm, g.write(tmp_path / "alpha.gltf"))
    assert not _material_warnings(warnings), warnings
    mats, textures = c["materials"], c["textures"]
    blend = mats[0]
    assert blend["kind"] == "mix" and blend["mix_factor"] == 0.5
    assert blend["mix_channel"] == "alpha" and blend["mix_texture"] == 0
    assert mats[blend["mix_a"]]["kind"] == "transparent"
    mask = mats[1]
    assert mask["mix_factor"] == 1 and mask["mix_channel"] == "alpha"
    # 0.5 x 200/255 = 0.39 >= 0.3 is kept, 0.5 x 40/255 = 0.08 cut.
    np.testing.assert_array_equal(textures[mask["mix_texture"]]["pixels"][0, :, 3], [1, 0])
    assert mats[2]["kind"] == "plastic"
    assert mats[3]["kind"] == "transparent"


def test_gltf_clearcoat_is_a_fresnel_mix_with_a_warning(glslppm, tmp_path):
    g = Gltf()
    g.extension("KHR_materials_clearcoat")
    g.doc["materials"] = [{"name": "car", "pbrMetallicRoughness": {"metallicFactor": 0},
                           "extensions": {"KHR_materials_clearcoat": {
                               "clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.1}}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0))
    _, c, warnings = load(glslppm, g.write(tmp_path / "coat.gltf"))
    mats = c["materials"]
    root = mats[0]
    assert root["mix_mode"] == "layer_fresnel" and root["mix_ior"] == pytest.approx(1.5)
    inner = mats[root["mix_b"]]
    assert inner["mix_a"] == root["mix_a"] and inner["mix_factor"] == pytest.approx(0.7)
    coat = mats[inner["mix_b"]]
    assert coat["kind"] == "conductor" and coat["roughness"] == pytest.approx(0.1)
    warnings = _material_warnings(warnings)
    assert len(warnings) == 1 and "'car'" in warnings[0] and "clearcoat" in warnings[0]


def test_gltf_punctual_lights_use_blenders_units(glslppm, tmp_path):
    g = Gltf()
    g.extension("KHR_lights_punctual")
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": 100.0, "color": [1, 0.5, 0.25]},
        {"type": "spot", "intensity": 683.0, "spot": {"innerConeAngle": 0.25,
                                                      "outerConeAngle": 0.5}},
        {"type": "directional", "intensity": 1366.0},
    ]}}
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    s = math.sqrt(0.5)
    g.node(translation=[0, 3, 0], extensions={"KHR_lights_punctual": {"light": 0}})
    g.node(translation=[1, 2, 3], extensions={"KHR_lights_punctual": {"light": 1}})
    # Turned -90 degrees about +X: the light's -Z becomes -Y (straight down).
    g.node(rotation=[-s, 0, 0, s], extensions={"KHR_lights_punctual": {"light": 2}})
    _, c, _ = load(glslppm, g.write(tmp_path / "lights.gltf"))
    point, spot, sun = c["lights"]
    # Candela to Blender watts at 683 lm/W, radiated over 4 pi sr: W = cd * 4 pi / 683.
    assert point["kind"] == "point"
    assert point["power"] == pytest.approx(100.0 * 4 * math.pi / 683.0, rel=1e-6)
    np.testing.assert_allclose(point["position"], [0, 3, 0])
    np.testing.assert_allclose(point["color"], [1, 0.5, 0.25])
    assert spot["kind"] == "spot"
    assert spot["power"] == pytest.approx(4 * math.pi, rel=1e-6)
    assert spot["spot_size"] == pytest.approx(1.0)   # twice the outer cone angle
    assert spot["spot_blend"] == pytest.approx(0.5)  # 1 - inner / outer
    np.testing.assert_allclose(spot["direction"], [0, 0, -1], atol=1e-6)
    np.testing.assert_allclose(spot["position"], [1, 2, 3])
    assert sun["kind"] == "sun"
    assert sun["power"] == pytest.approx(2.0, rel=1e-6)  # lux / 683 = W/m^2
    np.testing.assert_allclose(sun["direction"], [0, -1, 0], atol=1e-6)


def _lights_with_extras(tmp_path, extras):
    """A quad and a point, a spot and a sun, each given its entry of `extras`."""
    g = Gltf()
    g.extension("KHR_lights_punctual")
    kinds = [{"type": "point", "intensity": 1.0},
             {"type": "spot", "intensity": 1.0, "spot": {"outerConeAngle": 0.5}},
             {"type": "directional", "intensity": 1.0}]
    for light, extra in zip(kinds, extras):
        if extra is not None:
            light["extras"] = extra
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": kinds}}
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    for k in range(3):
        g.node(translation=[0, 3, 0], extensions={"KHR_lights_punctual": {"light": k}})
    return g.write(tmp_path / "sized.gltf")


def test_gltf_lights_take_blenders_size_from_their_extras(glslppm, tmp_path):
    """glTF lights are points; scripts/showcase_gltf.py keeps Blender's Radius and Soft
    Falloff (and a sun's Angle) in the light's extras, and glslppm-render reads them back."""
    path = _lights_with_extras(tmp_path, [{"radius": 0.02},
                                          {"radius": 0.5, "soft_falloff": False},
                                          {"angle": 0.00873}])
    point, spot, sun = load(glslppm, path)[1]["lights"]
    assert point["radius"] == pytest.approx(0.02) and point["facing_disc"] is True
    assert spot["radius"] == pytest.approx(0.5) and spot["facing_disc"] is False
    assert sun["angle"] == pytest.approx(0.00873) and sun["radius"] == 0.0
    plain = load(glslppm, _lights_with_extras(tmp_path, [None, {}, None]))[1]["lights"]
    assert [(l["radius"], l["angle"], l["facing_disc"]) for l in plain] == [(0.0, 0.0, False)] * 3


@pytest.mark.parametrize("extras, message", [
    ([{"radius": -1.0}, None, None], "lights[0]: extras.radius must be a finite number >= 0"),
    ([{"radius": "big"}, None, None], "extras.radius must be a finite number >= 0"),
    ([None, {"soft_falloff": 1}, None], "extras.soft_falloff must be true or false"),
    ([None, None, {"angle": 4.0}], "extras.angle must be below pi"),
])
def test_gltf_light_extras_out_of_range_name_the_key(glslppm, tmp_path, extras, message):
    with pytest.raises(Exception, match=re.escape(message)):
        glslppm.load_scene(str(_lights_with_extras(tmp_path, extras)), 1.0)


@pytest.mark.parametrize("aspect", [1.0, 2.0])
def test_gltf_cameras_convert_to_the_render_aspect(glslppm, tmp_path, aspect):
    g = Gltf()
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
                        {"type": "orthographic",
                         "orthographic": {"xmag": 2, "ymag": 1.5, "znear": 0, "zfar": 9}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    g.node(camera=0, translation=[0, 0, 5])
    scene, c, warnings = load(glslppm, g.write(tmp_path / "cam.gltf"), aspect)
    cam = c["camera"]
    assert cam["projection"] == "perspective"
    assert cam["fov_x"] == pytest.approx(2 * math.atan(math.tan(0.25) * aspect), rel=1e-6)
    np.testing.assert_allclose(cam["to_world"][:3, 3], [0, 0, 5])
    assert not any("no camera" in w for w in warnings)

    g.doc["nodes"][1]["camera"] = 1
    _, c, _ = load(glslppm, g.write(tmp_path / "ortho.gltf"), aspect)
    assert c["camera"]["projection"] == "orthographic"
    assert c["camera"]["ortho_scale"] == pytest.approx(2 * max(2.0, 1.5 * aspect))


def test_gltf_embedded_texture_with_flipped_uvs_and_clamp_sampler(glslppm, tmp_path):
    g = Gltf()
    # 2 x 2 image, top row red and green, bottom row blue and white.
    pixels = np.array([[[255, 0, 0, 255], [0, 255, 0, 255]],
                       [[0, 0, 255, 255], [255, 255, 255, 255]]], np.uint8)
    g.doc["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png_bytes(pixels))
                        .decode()}]
    g.doc["samplers"] = [{"wrapS": 33071, "wrapT": 33071, "magFilter": 9728}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}]
    g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                    "metallicFactor": 0}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0, uvs=QUAD_UV))
    _, c, warnings = load(glslppm, g.write(tmp_path / "tex.gltf"))
    assert len(c["textures"]) == 1
    t = c["textures"][0]
    assert (t["width"], t["height"], t["wrap"], t["encoding"]) == (2, 2, "extend", "srgb8")  # CLAMP_TO_EDGE
    assert t["interpolation"] == "closest"  # magFilter NEAREST, as Blender's importer
    # Rows are stored bottom-first: row 0 is the image's bottom row (blue, white).
    np.testing.assert_array_equal(t["pixels"], pixels[::-1])
    assert c["materials"][0]["color_texture"] == 0
    # glTF's v runs down the image; ours runs up.
    np.testing.assert_allclose(c["uvs"], np.c_[QUAD_UV[:, 0], 1 - QUAD_UV[:, 1]])


def test_glb_and_external_buffer_load_the_same_scene(glslppm, tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS), translation=[0, 0, -2])
    (tmp_path / "s.glb").write_bytes(g.glb())
    (tmp_path / "data.bin").write_bytes(bytes(g.blob))
    (tmp_path / "ext.gltf").write_text(g.json_text(external_bin="data.bin"))
    _, a, _ = load(glslppm, tmp_path / "s.glb")
    _, b, _ = load(glslppm, tmp_path / "ext.gltf")
    np.testing.assert_allclose(a["positions"], QUAD + [0, 0, -2])
    np.testing.assert_allclose(b["positions"], QUAD + [0, 0, -2])
    np.testing.assert_array_equal(a["triangles"], QUAD_TRIS)


def test_gltf_external_image_uri_is_percent_decoded(glslppm, tmp_path):
    g = Gltf()
    g.doc["images"] = [{"uri": "my%20wood.png"}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                    "metallicFactor": 0}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0, uvs=QUAD_UV))
    (tmp_path / "my wood.png").write_bytes(png_bytes(np.full((2, 3, 4), 9, np.uint8)))
    _, c, warnings = load(glslppm, g.write(tmp_path / "ext.gltf"))
    assert c["materials"][0]["color_texture"] == 0, warnings
    assert (c["textures"][0]["width"], c["textures"][0]["height"]) == (3, 2)
    assert c["textures"][0]["wrap"] == "repeat"  # no sampler: glTF's default
    assert c["textures"][0]["interpolation"] == "linear"


def test_gltf_environment_map_up_is_the_files_up(glslppm, tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    _, c, _ = load(glslppm, g.write(tmp_path / "env.gltf"))
    # Blender's equirectangular frame is Z-up; glTF is Y-up: the map's +Z must land on +Y.
    np.testing.assert_allclose(c["environment_to_world"] @ [0, 0, 1], [0, 1, 0], atol=1e-7)
    np.testing.assert_allclose(np.linalg.det(c["environment_to_world"]), 1.0, atol=1e-6)


# ---------------------------------------------------------------------------------------------
# OBJ / MTL

OBJ = """# a textured quad (one 4-sided face), a concave pentagon, a mirror, glass and a lamp
mtllib scene.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 2 0 1
v 2 2 1
v 1 0.5 1
v 0 2 1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl painted
f 1/1 2/2 3/3 4/4
usemtl mirror
f 5 6 7 8 9
usemtl glass
f 1 2 3
usemtl lamp
f 1 3 4
usemtl plastic
f 2 3 4
"""

MTL = """newmtl painted
Kd 0.5 0.5 0.5
map_Kd maps\\wood.png
newmtl mirror
illum 3
Kd 0 0 0
Ks 0.9 0.8 0.7
newmtl glass
Ni 1.45
d 0.2
newmtl lamp
Kd 0 0 0
Ke 10 9 8
newmtl plastic
Kd 0.2 0.2 0.2
Ks 0.9 0.9 0.9
Ns 50
"""


def write_obj(tmp_path, obj=OBJ, mtl=MTL, texture=True):
    (tmp_path / "scene.obj").write_text(obj)
    if mtl is not None:
        (tmp_path / "scene.mtl").write_text(mtl)
    if texture:  # in a folder, named with a backslash as files written on Windows do
        (tmp_path / "maps").mkdir(exist_ok=True)
        wood = png_bytes(np.full((4, 8, 4), 200, np.uint8))
        (tmp_path / "maps" / "wood.png").write_bytes(wood)
    return tmp_path / "scene.obj"


def test_obj_mtl_materials_textures_and_triangulation(glslppm, tmp_path):
    scene, c, warnings = load(glslppm, write_obj(tmp_path))
    # Quad: 2 triangles; concave pentagon: 3 (ear clipping); three triangles: 3.
    assert scene.triangle_count == 8
    mats = c["materials"]
    assert [m["kind"] for m in mats] == ["diffuse", "conductor", "dielectric", "diffuse",
                                         "plastic"]
    assert mats[0]["color_texture"] == 0
    assert c["textures"][0]["width"] == 8 and c["textures"][0]["height"] == 4
    np.testing.assert_allclose(mats[1]["color"], [0.9, 0.8, 0.7], rtol=1e-6)
    assert mats[2]["ior"] == pytest.approx(1.45)
    np.testing.assert_allclose(mats[3]["emission"], [10, 9, 8])
    # Ks 0.9 Ns 50: F0 = 0.08 x 0.9, roughness 1 - sqrt(50 / 1000), as Blender reads them.
    f0 = 0.072
    assert mats[4]["ior"] == pytest.approx((1 + math.sqrt(f0)) / (1 - math.sqrt(f0)), rel=1e-5)
    assert mats[4]["roughness"] == pytest.approx(1 - math.sqrt(0.05), rel=1e-5)
    assert mats[1]["roughness"] == 0 and mats[2]["roughness"] == 0   # no Ns: smooth
    # The pentagon's triangles cover exactly its area (concave at vertex 8): 2.5.
    p, t, ids = c["positions"], c["triangles"], c["material_ids"]
    tri = t[ids == 1]
    area = 0.5 * np.linalg.norm(np.cross(p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]),
                                axis=1)
    assert area.sum() == pytest.approx(2.5, rel=1e-6)
    # Every triangle keeps the face's winding (+Z facing).
    n = np.cross(p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]])
    assert np.all(n[:, 2] > 0)


ILLUM_OBJ = """mtllib scene.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
usemtl matte
f 1 2 3
usemtl satin
f 1 3 4
usemtl brushed
f 1 2 4
usemtl frosted
f 2 3 4
usemtl tinted
f 1 2 3
"""

ILLUM_MTL = """newmtl matte
illum 1
Kd 0.5 0.5 0.5
Ks 0.5 0.5 0.5
newmtl satin
illum 2
Kd 0.6 0.2 0.1
Ks 0.25 0.25 0.25
Ns 360
newmtl brushed
illum 3
Ks 0.9 0.9 0.9
Ns 250
newmtl frosted
illum 7
Ni 1.5
Ns 640
newmtl tinted
illum 2
Kd 0.5 0.5 0.5
Ks 0.5 0.2 0.2
"""


def test_mtl_illum_modes_and_ns_as_roughness(glslppm, tmp_path):
    """illum 1: Kd alone; illum 2: Kd under a specular layer of F0 = 0.08 mean(Ks) (Blender's
    Principled Specular = mean(Ks)); 3: a mirror of Ks; 7: glass; Ns -> roughness =
    1 - sqrt(Ns / 1000), the inverse of Blender's exporter's Ns = 1000 (1 - roughness)^2."""
    _, c, warnings = load(glslppm, write_obj(tmp_path, ILLUM_OBJ, ILLUM_MTL, texture=False))
    mats = {name: m for name, m in zip(["matte", "satin", "brushed", "frosted", "tinted"],
                                       c["materials"])}
    assert mats["matte"]["kind"] == "diffuse"
    satin = mats["satin"]
    assert satin["kind"] == "plastic"
    np.testing.assert_allclose(satin["color"], [0.6, 0.2, 0.1], rtol=1e-6)
    assert satin["roughness"] == pytest.approx(0.4, rel=1e-5)   # 1 - sqrt(0.36)
    f0 = 0.02
    assert satin["ior"] == pytest.approx((1 + math.sqrt(f0)) / (1 - math.sqrt(f0)), rel=1e-5)
    brushed = mats["brushed"]
    assert brushed["kind"] == "conductor" and brushed["roughness"] == pytest.approx(0.5)
    frosted = mats["frosted"]
    assert frosted["kind"] == "dielectric" and frosted["roughness"] == pytest.approx(0.2)
    assert mats["tinted"]["kind"] == "plastic"
    assert [w for w in warnings if "material '" in w] == [
        w for w in warnings if "material 'tinted'" in w and "colour of Ks" in w], warnings
    assert any("material 'tinted'" in w for w in warnings), warnings


def test_obj_missing_mtl_and_texture_are_warnings_with_fallbacks(glslppm, tmp_path):
    scene, c, warnings = load(glslppm, write_obj(tmp_path, texture=False))
    assert scene.triangle_count == 8
    assert any("wood.png" in w and "material 'painted'" in w for w in warnings), warnings
    assert c["materials"][0]["color_texture"] == -1

    other = tmp_path / "other"
    other.mkdir()
    scene, c, warnings = load(glslppm, write_obj(other, mtl=None, texture=False))
    assert scene.triangle_count == 8
    assert any("scene.mtl" in w and "scene.obj" in w for w in warnings), warnings
    assert all(m["kind"] == "diffuse" for m in c["materials"])


# ---------------------------------------------------------------------------------------------
# Broken files: the message names the file and the element.


def broken_gltf(tmp_path, edit):
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    edit(g)
    return g.write(tmp_path / "broken.gltf")


def set_position(g, value):
    g.blob[0:4] = struct.pack("<f", value)


@pytest.mark.parametrize("edit, element", [
    (lambda g: g.doc["meshes"][0]["primitives"][0]["attributes"].update(POSITION=7),
     "meshes[0].primitives[0].attributes.POSITION: accessor 7 is out of range"),
    (lambda g: g.blob.__setitem__(slice(48, 50), struct.pack("<H", 9)),
     "meshes[0].primitives[0].indices: element 0 = 9 is past the vertex count 4"),
    (lambda g: set_position(g, float("nan")),
     "meshes[0].primitives[0].attributes.POSITION (accessors[0]): element 0 component 0 is NaN"),
    (lambda g: g.doc["accessors"][0].update(count=40), "accessors[0]"),
    (lambda g: g.doc["scenes"][0]["nodes"].append(0), "nodes[0]"),
    (lambda g: g.doc["nodes"][0].update(mesh=3), "nodes[0]: mesh 3 is out of range"),
])
def test_broken_gltf_errors_name_file_and_element(glslppm, tmp_path, edit, element):
    path = broken_gltf(tmp_path, edit)
    with pytest.raises(ValueError) as e:
        glslppm.load_scene(path)
    assert "broken.gltf" in str(e.value) and element in str(e.value), str(e.value)


def test_unsupported_primitive_mode_is_skipped_with_a_warning(glslppm, tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    g.node(mesh=g.mesh(QUAD, [0, 1, 1, 2], mode=1))  # lines
    scene, _, warnings = load(glslppm, g.write(tmp_path / "lines.gltf"))
    assert scene.triangle_count == 2
    assert any("lines.gltf: meshes[1].primitives[0]: mode 1 (lines) is not supported" in w
               for w in warnings), warnings


def test_missing_gltf_texture_is_a_warning(glslppm, tmp_path):
    g = Gltf()
    g.doc["images"] = [{"uri": "nowhere.png"}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"name": "painted", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0}, "metallicFactor": 0}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0, uvs=QUAD_UV))
    _, c, warnings = load(glslppm, g.write(tmp_path / "t.gltf"))
    assert c["materials"][0]["color_texture"] == -1
    assert any("t.gltf" in w and "materials[0] 'painted'" in w and "nowhere.png" in w
               for w in warnings), warnings


def test_glb_image_view_past_its_buffer_is_a_warning(glslppm, tmp_path):
    """Regression (fuzz/gltf_fuzz.cpp): tinygltf 2.7.0 hands an image's bufferView to the
    decoder without checking it against the buffer; the loader checks it first."""
    g = Gltf()
    g.doc["images"] = [{"bufferView": 2, "mimeType": "image/png"}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                    "metallicFactor": 0}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0))  # bufferViews 0 and 1
    g.doc["bufferViews"].append({"buffer": 0, "byteOffset": 40, "byteLength": 4000})
    (tmp_path / "v.glb").write_bytes(g.glb())
    _, c, warnings = load(glslppm, tmp_path / "v.glb")
    assert c["materials"][0]["color_texture"] == -1
    assert any("v.glb: materials[0]" in w and "bufferViews[2] (offset 40, length 4000) runs "
               "past the end of buffers[0]" in w for w in warnings), warnings


def test_unreadable_files_name_the_file(glslppm, tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    (tmp_path / "cut.glb").write_bytes(g.glb()[:60])
    (tmp_path / "syntax.gltf").write_text(g.json_text()[:-5])
    cases = [(tmp_path / "absent.gltf", "absent.gltf: cannot open"),
             (tmp_path / "absent.obj", "absent.obj: cannot open"),
             (tmp_path / "cut.glb", "cut.glb: GLB header: length"),
             (tmp_path / "syntax.gltf", "syntax.gltf: [json.exception.parse_error"),
             (tmp_path / "scene.fbx", "scene.fbx: unknown scene file type")]
    for path, message in cases:
        with pytest.raises(ValueError) as e:
            glslppm.load_scene(str(path))
        assert message in str(e.value), str(e.value)


def test_broken_obj_errors_name_file_and_element(glslppm, tmp_path):
    bad_index = "v 0 0 0\nv 1 0 0\nv 0 1 0\no thing\nf 1 2 3\nf 1 2 9\n"
    with pytest.raises(ValueError) as e:
        glslppm.load_scene(str(write_obj(tmp_path, obj=bad_index, mtl=None, texture=False)))
    assert "scene.obj: object 'thing' face 2: vertex index 9 is out of range" in str(e.value)
    # tinyobjloader reads "nan" as 0; a value beyond float's range reaches us as infinity.
    huge = "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"
    with pytest.raises(ValueError) as e:
        glslppm.load_scene(str(write_obj(tmp_path, obj=huge, mtl=None, texture=False)))
    assert "scene.obj: vertex 2 (counting v lines): coordinate x is infinite" in str(e.value)


# ---------------------------------------------------------------------------------------------
# Image files


def test_png_rows_are_stored_bottom_first_and_16_bit_is_decoded_exactly(glslppm, tmp_path):
    top_first = np.arange(3 * 2 * 4, dtype=np.uint8).reshape(3, 2, 4)
    (tmp_path / "a.png").write_bytes(png_bytes(top_first))
    t = glslppm.load_texture(str(tmp_path / "a.png"))
    assert t["encoding"] == "srgb8"
    np.testing.assert_array_equal(t["pixels"], top_first[::-1])

    # 16-bit: decoded to linear with the sRGB curve (IEC 61966-2-1), exact at 0, 0.5, 1.
    v = np.array([0, 32768, 65535, 65535], np.uint16).reshape(1, 1, 4)
    (tmp_path / "b.png").write_bytes(png_bytes(v, bit_depth=16))
    t = glslppm.load_texture(str(tmp_path / "b.png"))
    assert t["encoding"] == "linear"
    half = 32768 / 65535
    np.testing.assert_allclose(t["pixels"][0, 0], [0.0, ((half + 0.055) / 1.055) ** 2.4, 1, 1],
                               rtol=1e-6)


def test_hdr_is_linear_float(glslppm, tmp_path):
    # RGBE: value = mantissa * 2^(e - 136); e = 129 gives 1, 0.5, 0.25.
    rgbe = np.tile(np.array([128, 64, 32, 129], np.uint8), (2, 3, 1))
    rgbe[0, 0] = [128, 128, 128, 130]  # top-left: 2, 2, 2
    (tmp_path / "sky.hdr").write_bytes(hdr_bytes(rgbe))
    t = glslppm.load_texture(str(tmp_path / "sky.hdr"))
    assert (t["width"], t["height"], t["encoding"]) == (3, 2, "linear")
    np.testing.assert_array_equal(t["pixels"][0, 0], [1, 0.5, 0.25, 1])
    np.testing.assert_array_equal(t["pixels"][1, 0], [2, 2, 2, 1])  # top row stored last


def test_bad_images_name_the_file(glslppm, tmp_path):
    (tmp_path / "junk.png").write_bytes(b"not an image at all")
    with pytest.raises(RuntimeError, match="junk.png"):
        glslppm.load_texture(str(tmp_path / "junk.png"))
    with pytest.raises(RuntimeError, match="absent.png: cannot open"):
        glslppm.load_texture(str(tmp_path / "absent.png"))


# ---------------------------------------------------------------------------------------------
# Rendering loaded scenes


def lit_floor(g):
    """A 2 x 2 floor at y = 0 facing +Y, with an emissive quad above it facing down."""
    g.extension("KHR_materials_emissive_strength")
    g.doc["materials"] = [
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1],
                                                   "metallicFactor": 0}},
        {"name": "lamp", "pbrMetallicRoughness": {"metallicFactor": 0},
         "emissiveFactor": [1, 1, 1],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}}]
    floor = np.array([[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]], np.float32)
    lamp = np.array([[-0.3, 1, -0.3], [0.3, 1, -0.3], [0.3, 1, 0.3], [-0.3, 1, 0.3]], np.float32)
    g.node(mesh=g.mesh(floor, QUAD_TRIS, material=0))
    g.node(mesh=g.mesh(lamp, QUAD_TRIS, material=1))
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.01}}]
    s = math.sqrt(0.5)
    g.node(camera=0, translation=[0, 3, 0], rotation=[-s, 0, 0, s])  # looking down -Y


def test_loaded_gltf_scene_renders(glslppm, tmp_path):
    g = Gltf()
    lit_floor(g)
    scene, warnings = glslppm.load_scene(g.write(tmp_path / "room.gltf"))
    r = glslppm.Renderer(scene, glslppm.Settings(width=32, height=32, photons_per_pass=4096))
    r.run(2)
    film = r.film()
    r.close()
    assert np.isfinite(film).all()
    # The floor around the lamp's footprint is lit: its irradiance is far from zero.
    corner = film[8:12, 8:12, :3].mean()
    assert corner > 0.01, corner


def run_cli(*args):
    return subprocess.run([RENDER, "--width", "16", "--height", "16", "--passes", "2",
                           "--photons", "2048", "--json", *map(str, args)],
                          capture_output=True, text=True, timeout=300, cwd="/")


def test_cli_renders_a_scene_file_and_reports_warnings(glslppm, tmp_path):
    g = Gltf()
    lit_floor(g)
    g.doc["materials"][0]["extensions"] = {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5}}
    path = g.write(tmp_path / "room.gltf")
    out = tmp_path / "room.exr"
    result = run_cli("--scene", path, "--out", out)
    assert result.returncode == 0, result.stderr
    stats = json.loads(result.stdout)
    assert any("materials[0] 'floor'" in w for w in stats["warnings"]), stats["warnings"]
    assert "warning: " in result.stderr and "'floor'" in result.stderr
    image, _ = glslppm.read_exr(str(out))
    assert image.shape == (16, 16, 4) and np.isfinite(image).all() and image[..., :3].max() > 0


def test_cli_environment_map_and_colour(glslppm, tmp_path):
    rgbe = np.tile(np.array([128, 128, 128, 129], np.uint8), (4, 8, 1))
    (tmp_path / "sky.hdr").write_bytes(hdr_bytes(rgbe))
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    path = g.write(tmp_path / "quad.gltf")
    result = run_cli("--scene", path, "--environment", tmp_path / "sky.hdr",
                     "--environment-color", "0.5,0.5,0.5", "--out", tmp_path / "e.exr")
    assert result.returncode == 0, result.stderr
    image, _ = glslppm.read_exr(str(tmp_path / "e.exr"))
    # Rays that miss the quad see the map (1) times the colour (0.5).
    background = image[0, 0, :3]
    np.testing.assert_allclose(background, 0.5, rtol=1e-5)

    bad = run_cli("--environment-color", "1,x,2")
    assert bad.returncode == 1 and "--environment-color: '1,x,2'" in bad.stderr


def test_cli_gltf_texture_appears_upright(glslppm, tmp_path):
    """End to end: a glTF exporter's UVs (v = 0 at the image's top) on a quad facing the
    camera show the image the right way up."""
    g = Gltf()
    red, blue = [255, 0, 0, 255], [0, 0, 255, 255]
    image = np.array([[red] * 4] * 2 + [[blue] * 4] * 2, np.uint8)  # top half red
    g.doc["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png_bytes(image))
                        .decode()}]
    g.doc["samplers"] = [{"wrapS": 33071, "wrapT": 33071}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}]
    g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                    "metallicFactor": 0}}]
    quad = QUAD * [2, 2, 1] - [1, 1, 0]  # z = 0
    gltf_uv = np.c_[QUAD_UV[:, 0], 1 - QUAD_UV[:, 1]]  # what exporters write
    g.node(mesh=g.mesh(quad, QUAD_TRIS, material=0, uvs=gltf_uv))
    # The quad exactly fills the view: half height 1 at distance 3.
    g.doc["cameras"] = [{"type": "perspective",
                         "perspective": {"yfov": 2 * math.atan(1 / 3), "znear": 0.1}}]
    g.node(camera=0, translation=[0, 0, 3])
    out = tmp_path / "upright.exr"
    result = run_cli("--scene", g.write(tmp_path / "upright.gltf"), "--environment-color",
                     "1,1,1", "--passes", "4", "--photons", "16384", "--out", out)
    assert result.returncode == 0, result.stderr
    film, _ = glslppm.read_exr(str(out))  # row 0 at the top
    top, bottom = film[:4, :, :3].mean(axis=(0, 1)), film[-4:, :, :3].mean(axis=(0, 1))
    assert top[0] > 3 * top[2] and bottom[2] > 3 * bottom[0], (top, bottom)
    # No green anywhere but the non-metal's 4% specular reflection of the white world: the
    # quad fills the frame (the white background would show).
    assert film[..., 1].mean() < 0.03


def test_cli_scene_without_lights_says_so(glslppm, tmp_path):
    g = Gltf()
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS))
    result = run_cli("--scene", g.write(tmp_path / "dark.gltf"))
    assert result.returncode == 1
    assert "no lights" in result.stderr, result.stderr


def test_gltf_normal_texture_with_and_without_tangent(glslppm, tmp_path):
    """normalTexture: its texels read as numbers, its scale as the strength; TANGENT turns
    with the node (and its w flips under a mirror); a primitive without TANGENT in a file
    with some gets tangents from its uvs (dp/du, sign from dp/dv with v flipped up)."""
    g = Gltf()
    g.doc["images"] = [{"uri": _data_png([[191, 128, 255, 255], [191, 128, 255, 255]])}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"name": "bumpy", "normalTexture": {"index": 0, "scale": 0.5}}]
    tangent = np.tile([1.0, 0.0, 0.0, -1.0], (4, 1)).astype(np.float32)

    def with_tangent():  # one mesh per node: world triangles, not instances
        mesh = g.mesh(QUAD, QUAD_TRIS, material=0, uvs=QUAD_UV)
        g.doc["meshes"][mesh]["primitives"][0]["attributes"]["TANGENT"] = g.accessor(
            tangent, "VEC4")
        return mesh

    g.node(mesh=with_tangent(),
           rotation=[0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)])
    g.node(mesh=with_tangent(), scale=[-1.0, 1.0, 1.0], translation=[5.0, 0.0, 0.0])
    g.node(mesh=g.mesh(QUAD + [0, 0, 1], QUAD_TRIS, material=0, uvs=QUAD_UV))
    _, c, warnings = load(glslppm, g.write(tmp_path / "normal.gltf"))
    assert not _material_warnings(warnings), warnings
    m = c["materials"][0]
    assert m["normal_strength"] == 0.5
    data = c["textures"][m["normal_texture"]]
    assert data["encoding"] == "linear"
    np.testing.assert_allclose(data["pixels"][0, 0, :3], [191 / 255, 128 / 255, 1.0], rtol=1e-6)
    t = c["tangents"]
    assert t.shape == (12, 4)
    # Rotated 90 degrees about z: the x tangent turns to +y, its sign kept.
    np.testing.assert_allclose(t[0:4], np.tile([0, 1, 0, -1], (4, 1)), atol=1e-6)
    # Mirrored in x: the tangent turns to -x and the sign flips.
    np.testing.assert_allclose(t[4:8], np.tile([-1, 0, 0, 1], (4, 1)), atol=1e-6)
    # From the uvs: u runs along +x; glTF's v runs along +y, ours (flipped) along -y, so the
    # bitangent n x t = +y is against dp/dv: sign -1.
    np.testing.assert_allclose(t[8:12], np.tile([1, 0, 0, -1], (4, 1)), atol=1e-6)


def test_gltf_normal_texture_tilts_the_shading(glslppm, tmp_path):
    """A normalTexture of one texel tilting the normal 30 degrees along +x, on a quad lit by
    a sun 25 degrees the other way: the quad reads rho / pi E cos(55 degrees), as Blender
    renders the file (the flat quad would read cos(25 degrees))."""
    tilt = math.radians(30.0)
    texel = [round(255 * (math.sin(tilt) + 1) / 2), 128, round(255 * (math.cos(tilt) + 1) / 2),
             255]
    g = Gltf()
    g.doc["images"] = [{"uri": _data_png([texel, texel])}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"name": "tilted", "normalTexture": {"index": 0},
                           "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1],
                                                    "metallicFactor": 0, "roughnessFactor": 1}}]
    big = (QUAD - [0.5, 0.5, 0]) * 4
    g.node(mesh=g.mesh(big, QUAD_TRIS, material=0, uvs=QUAD_UV,
                       normals=np.tile([0.0, 0.0, 1.0], (4, 1))))
    scene, c, _ = load(glslppm, g.write(tmp_path / "tilt.gltf"))
    mapped = (np.array(texel[:3]) / 255.0) * 2 - 1
    mapped /= np.linalg.norm(mapped)
    n = glslppm
    sun = math.radians(-25.0)
    sun_from = np.array([math.sin(sun), 0.0, math.cos(sun)])
    to_world = np.eye(4, dtype=np.float32)
    to_world[2, 3] = 3.0
    textures = [n.Texture(t["pixels"].astype(np.float32) if t["encoding"] == "linear"
                          else t["pixels"], name="t") for t in c["textures"]]
    diffuse = n.Material("diffuse", color=(0.8, 0.8, 0.8),
                         normal_texture=c["materials"][0]["normal_texture"])
    rebuilt = n.Scene(c["positions"], c["triangles"], normals=c["normals"], uvs=c["uvs"],
                      materials=[diffuse], textures=textures,
                      lights=[n.Light("sun", power=3.0, direction=tuple(-sun_from))],
                      camera=n.Camera(to_world, projection="orthographic", ortho_scale=2.0))
    r = n.Renderer(rebuilt, n.Settings(width=24, height=24, photons_per_pass=4096, seed=1))
    r.run(2)
    got = float(r.film()[4:-4, 4:-4, 0].mean())
    want = 0.8 / math.pi * 3.0 * float(np.dot(mapped, sun_from))
    assert got == pytest.approx(want, rel=0.003), (got, want)


def test_gltf_emissive_texture_multiplies_the_factor(glslppm, tmp_path):
    """emissiveTexture: an sRGB image on the root material, its factor (times
    KHR_materials_emissive_strength) the emission it multiplies."""
    g = Gltf()
    g.extension("KHR_materials_emissive_strength")
    g.doc["images"] = [{"uri": _data_png([[255, 128, 0, 255], [0, 0, 255, 255]])}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"name": "screen", "emissiveFactor": [1.0, 0.5, 1.0],
                           "emissiveTexture": {"index": 0},
                           "extensions": {"KHR_materials_emissive_strength":
                                          {"emissiveStrength": 3.0}}}]
    g.node(mesh=g.mesh(QUAD, QUAD_TRIS, material=0, uvs=QUAD_UV))
    _, c, warnings = load(glslppm, g.write(tmp_path / "emissive.gltf"))
    assert not _material_warnings(warnings), warnings
    root = c["materials"][0]
    assert root["emission_texture"] >= 0
    assert c["textures"][root["emission_texture"]]["encoding"] == "srgb8"
    np.testing.assert_allclose(root["emission"], [3.0, 1.5, 3.0])


def _with_colors(g, mesh, colors, kind, component=5126, normalized=False):
    """Gives a mesh's primitive a COLOR_0 accessor."""
    accessor = g.accessor(colors, kind, component)
    if normalized:
        g.doc["accessors"][accessor]["normalized"] = True
    g.doc["meshes"][mesh]["primitives"][0]["attributes"]["COLOR_0"] = accessor
    return mesh


def test_gltf_color_0_float_and_normalized_integers(glslppm, tmp_path):
    """COLOR_0 as float VEC3, normalized unsigned byte VEC4 (alpha not read) and normalized
    unsigned short VEC3 reads as linear rgb (c / 255, c / 65535); a primitive without one is
    white, and every material of a primitive with one (a Mix's leaves too) multiplies it in."""
    g = Gltf()
    g.doc["materials"] = [{"name": "painted", "pbrMetallicRoughness": {"metallicFactor": 0}},
                          {"name": "plain", "pbrMetallicRoughness": {"metallicFactor": 0}},
                          {"name": "halfmetal", "pbrMetallicRoughness": {"metallicFactor": 0.3}}]
    floats = np.array([[0.25, 0.5, 1.0], [0, 0, 0], [2.0, 1.0, 0.5], [1, 1, 1]], np.float32)
    bytes_ = np.array([[51, 102, 255, 7], [0, 0, 0, 0], [255, 255, 255, 255], [1, 2, 3, 4]],
                      np.uint8)
    shorts = np.array([[32768, 0, 65535]] * 4, np.uint16)
    g.node(mesh=_with_colors(g, g.mesh(QUAD, QUAD_TRIS, material=0), floats, "VEC3"))
    g.node(mesh=_with_colors(g, g.mesh(QUAD + [0, 0, 1], QUAD_TRIS, material=0), bytes_,
                             "VEC4", 5121, True))
    g.node(mesh=_with_colors(g, g.mesh(QUAD + [0, 0, 2], QUAD_TRIS, material=2), shorts,
                             "VEC3", 5123, True))
    g.node(mesh=g.mesh(QUAD + [0, 0, 3], QUAD_TRIS, material=1))
    _, c, warnings = load(glslppm, g.write(tmp_path / "colors.gltf"))
    assert not _material_warnings(warnings), warnings
    colors = c["colors"]
    assert colors.shape == (16, 3) and colors.dtype == np.float32
    np.testing.assert_array_equal(colors[0:4], floats)
    np.testing.assert_allclose(colors[4:8], bytes_[:, :3] / 255.0, rtol=1e-6)
    np.testing.assert_allclose(colors[8:12], shorts / 65535.0, rtol=1e-6)
    np.testing.assert_array_equal(colors[12:16], np.ones((4, 3)))
    mats = c["materials"]
    assert mats[0]["vertex_color"] and not mats[1]["vertex_color"]
    half = mats[2]
    assert half["kind"] == "mix" and mats[half["mix_a"]]["vertex_color"] \
        and mats[half["mix_b"]]["vertex_color"]

    # A file without COLOR_0 has no colours at all.
    plain = Gltf()
    plain.node(mesh=plain.mesh(QUAD, QUAD_TRIS))
    _, c, _ = load(glslppm, plain.write(tmp_path / "plain.gltf"))
    assert c["colors"].shape == (0, 3) and not c["materials"][0]["vertex_color"]


@pytest.mark.parametrize("kind,component,normalized,message", [
    ("VEC3", 5121, False, "integer colours must be normalized"),
    ("VEC2", 5126, False, "must be VEC3 or VEC4"),
    ("VEC3", 5120, True, "must be float, unsigned byte or unsigned short"),
])
def test_gltf_bad_color_0_is_named(glslppm, tmp_path, kind, component, normalized, message):
    g = Gltf()
    width = {"VEC2": 2, "VEC3": 3}[kind]
    dtype = {5121: np.uint8, 5120: np.int8, 5126: np.float32}[component]
    g.node(mesh=_with_colors(g, g.mesh(QUAD, QUAD_TRIS), np.ones((4, width), dtype), kind,
                             component, normalized))
    with pytest.raises(ValueError, match=r"meshes\[0\]\.primitives\[0\]\.attributes\.COLOR_0.*"
                       + message):
        load(glslppm, g.write(tmp_path / "bad.gltf"))


def test_gltf_color_0_renders_as_the_base_color_it_multiplies(glslppm, tmp_path):
    """baseColorFactor b with COLOR_0 c renders as the same file with factor b x c and no
    COLOR_0 (glTF: base colour = factor x texture x COLOR_0): a rough plastic under a sun,
    seen through the file's camera; the same seed draws the same numbers, so the two films
    agree to float rounding (measured: 1.2e-7 relative; the bound 1e-3 fails a 0.1% change)."""
    base, colour = np.array([0.8, 0.6, 0.5]), np.array([0.25, 0.5, 1.0])

    def write(factor, with_colors, name):
        g = Gltf()
        g.extension("KHR_lights_punctual")
        g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "intensity": 683.0 * 3}]}}
        g.doc["materials"] = [{"pbrMetallicRoughness": {
            "baseColorFactor": [*factor, 1.0], "metallicFactor": 0, "roughnessFactor": 0.5}}]
        g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1}}]
        mesh = g.mesh((QUAD - [0.5, 0.5, 0]) * 4, QUAD_TRIS, material=0,
                      normals=np.tile([0.0, 0.0, 1.0], (4, 1)))
        if with_colors:
            _with_colors(g, mesh, np.tile(colour.astype(np.float32), (4, 1)), "VEC3")
        g.node(mesh=mesh)
        g.node(camera=0, translation=[0, 0, 3])
        g.node(rotation=[0.2, 0, 0, 0.98], extensions={"KHR_lights_punctual": {"light": 0}})
        scene, _ = glslppm.load_scene(g.write(tmp_path / name))
        r = glslppm.Renderer(scene, glslppm.Settings(width=24, height=24,
                                                     photons_per_pass=4096, seed=4))
        r.run(4)
        return r.film()[..., :3], r.stats()["variant"].split(",")

    painted, variant = write(base, True, "painted.gltf")
    baked, baked_variant = write(base * colour, False, "baked.gltf")
    assert "vertex-colors" in variant and "vertex-colors" not in baked_variant
    assert painted.mean() > 0.05
    np.testing.assert_allclose(painted, baked, rtol=1e-3, atol=1e-5)
