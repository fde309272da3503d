#include "loaders/obj_loader.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <tuple>
#include <utility>

#include "image/image_file.h"
#include "loaders/triangulate_polygon.h"
#include "loaders/vertex_normals.h"

namespace glslppm {
namespace {

// Numbers in messages as written in files (0.3, not 0.300000).
std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

// Phong exponents at least this high are mirror-like: Blender's OBJ exporter writes
// Ns = 1000 (1 - roughness)^2, so this is roughness below about 0.1.
constexpr float kMirrorShininess = 800.0f;

struct Source {
    std::string name;                       // the .obj, for messages
    std::string base_dir;                   // "" when loading from memory
    const std::string* mtl_text = nullptr;  // memory mode: the text of every mtllib
    MtlConvention convention = MtlConvention::Standard;
};

// Reads mtllib files next to the .obj (or the given text); a missing one is a warning.
class MtlReader : public tinyobj::MaterialReader {
  public:
    MtlReader(const Source& source, std::vector<std::string>& warnings)
        : source_(source), warnings_(warnings) {}

    bool operator()(const std::string& id, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* names, std::string* warn,
                    std::string* err) override {
        if (source_.mtl_text) {
            std::istringstream in(*source_.mtl_text);
            tinyobj::LoadMtl(names, materials, &in, warn, err);
            return true;
        }
        const std::string path = source_.base_dir + "/" + id;
        std::ifstream in(path);
        if (!in) {
            warnings_.push_back(source_.name + ": mtllib '" + id + "': cannot open " + path + " (" +
                                std::strerror(errno) +
                                "): its materials are rendered grey diffuse");
            return false;
        }
        tinyobj::LoadMtl(names, materials, &in, warn, err);
        return true;
    }

  private:
    const Source& source_;
    std::vector<std::string>& warnings_;
};

float max3(const float* c) { return std::max({c[0], c[1], c[2]}); }
glm::vec3 vec3_of(const float* c) { return {c[0], c[1], c[2]}; }

struct MaterialConverter {
    const Source& source;
    Scene& scene;
    std::vector<std::string>& warnings;
    std::map<std::string, int> texture_index;  // by path

    void warn(const std::string& element, const std::string& what) {
        warnings.push_back(source.name + ": " + element + ": " + what);
    }
    int texture(const std::string& file, const tinyobj::texture_option_t& options,
                const std::string& element);
    Material convert(const tinyobj::material_t& m);
    void choose_kind(const tinyobj::material_t& m, Material& out, const std::string& element);
    void choose_glslppm2015(const tinyobj::material_t& m, Material& out,
                            const std::string& element);
};

int MaterialConverter::texture(const std::string& file, const tinyobj::texture_option_t& options,
                               const std::string& element) {
    if (file.empty()) return -1;
    if (source.base_dir.empty()) {
        warn(element,
             "map_Kd '" + file + "' is not read when loading from memory: Kd alone is used");
        return -1;
    }
    std::string relative = file;  // files written on Windows use backslashes
    std::replace(relative.begin(), relative.end(), '\\', '/');
    const std::string path = source.base_dir + "/" + relative;
    if (auto it = texture_index.find(path); it != texture_index.end()) return it->second;
    try {
        Texture t = load_texture(path);
        t.wrap = options.clamp ? TextureWrap::Clip : TextureWrap::Repeat;
        scene.textures.push_back(std::move(t));
        return texture_index[path] = int(scene.textures.size()) - 1;
    } catch (const ImageFileError& e) {
        warn(element,
             "map_Kd '" + file + "' cannot be loaded (" + e.what() + "): Kd alone is used");
        return texture_index[path] = -1;
    }
}

// Ns -> roughness as Blender writes and reads it: its OBJ exporter writes
// Ns = 1000 (1 - roughness)^2, so roughness = 1 - sqrt(Ns / 1000), Ns clamped to [0, 1000].
float roughness_of_shininess(float ns) {
    return 1.0f - std::sqrt(std::clamp(std::isfinite(ns) ? ns : 0.0f, 0.0f, 1000.0f) / 1000.0f);
}

// Mirrors and glass whose Ns is tinyobjloader's default (1: not written) are smooth, as
// before Ns was read; a written Ns above 1 roughens them.
float specular_roughness(const tinyobj::material_t& m) {
    return m.shininess > 1.0f ? roughness_of_shininess(m.shininess) : 0.0f;
}

// illum (the MTL specification's illumination models): 1 is Kd alone; 0 (also what a file
// without illum reads as) and 2 add the specular Ks with Ns, as Blender's importer reads
// them: a white specular layer of F0 = 0.08 mean(Ks) (Principled's Specular = mean(Ks))
// over Kd, Ns giving its roughness; 3 and 5 are mirrors of colour Ks, 4, 6 and 7 glass
// (as is d < 1); 8 and above are rendered diffuse. Ns >= 800 with Ks at least Kd is
// mirror-like whatever the illum.
void MaterialConverter::choose_kind(const tinyobj::material_t& m, Material& out,
                                    const std::string& element) {
    const bool glass_illum = m.illum == 4 || m.illum == 6 || m.illum == 7;
    if (glass_illum || m.dissolve < 1.0f) {
        out.kind = MaterialKind::Dielectric;
        out.ior = m.ior > 1.0f ? m.ior : 1.5f;
        if (!(m.ior > 1.0f))
            warn(element, "transparent without Ni > 1: rendered as glass of index 1.5");
        // Tf tints the glass where given; tinyobjloader leaves it zero otherwise.
        out.color = max3(m.transmittance) > 0.0f ? vec3_of(m.transmittance) : glm::vec3(1.0f);
        out.roughness = specular_roughness(m);
        return;
    }
    const bool mirror_illum = m.illum == 3 || m.illum == 5;
    const bool mirror_like = m.shininess >= kMirrorShininess && max3(m.specular) > 0.0f &&
                             max3(m.specular) >= max3(m.diffuse);
    if (mirror_illum || mirror_like || m.metallic >= 0.5f) {
        out.kind = MaterialKind::Conductor;
        if (max3(m.specular) > 0.0f) out.color = vec3_of(m.specular);
        if (m.metallic >= 0.5f && !mirror_illum && !mirror_like) out.color = vec3_of(m.diffuse);
        out.roughness = specular_roughness(m);
        return;
    }
    out.kind = MaterialKind::Diffuse;
    if (m.illum > 7) warn(element, "illum " + std::to_string(m.illum) + " is rendered diffuse");
    const float specular = (m.specular[0] + m.specular[1] + m.specular[2]) / 3.0f;
    if (m.illum == 1 || m.illum > 7 || !(specular > 0.0f)) return;
    out.kind = MaterialKind::Plastic;
    const float f0 = std::min(0.08f * specular, 0.999f);
    out.ior = (1.0f + std::sqrt(f0)) / (1.0f - std::sqrt(f0));
    out.roughness = roughness_of_shininess(m.shininess);
    if (max3(m.specular) - std::min({m.specular[0], m.specular[1], m.specular[2]}) > 1e-3f)
        warn(element, "the colour of Ks is not rendered: a white specular of its mean");
}

// The original glslppm's lobe tilts the shading normal by a Phong lobe of exponent
// n = ((1 - g) / 2)^-e with g = max(Ns / 100, 0.5). Microfacet normals spread as cos^n have
// Beckmann's (and about GGX's) alpha = sqrt(2 / (n + 2)) (Walter et al. 2007); Blender's
// roughness is sqrt(alpha). Ns above 100 has no such exponent there (a negative base).
float glslppm2015_roughness(float ns) {
    const float g = std::max(ns / 100.0f, 0.5f);
    const double n = std::pow(0.5 * (1.0 - double(g)), -std::exp(1.0));
    return float(std::pow(2.0 / (n + 2.0), 0.25));
}

// MtlConvention::Glslppm2015: the rules of the original glslppm's scene loader, as its only
// public copy (a fork of the 2015 release) has them, in its order:
//  - Ka not black: a light of radiance Kd, emitting from the side its normals face. That
//    program's rays never hit a light, so here no eye ray sees it and photons and shadow
//    rays pass through it.
//  - a name beginning "glass": smooth glass of index 1 + |Ks|^2 / 3; sqrt(Kd) tints each
//    refraction (Kd through a solid piece), not the reflection.
//  - Ns exactly 100: Ks exactly white is a perfect mirror of colour Kd (no Fresnel); any
//    other non-black Ks a smooth coat of index 1.7 over a Lambert base of 0.9 Kd.
//  - Ns other than 100: the same glass, mirror or coat, rough (glslppm2015_roughness).
//  - everything else: Lambert of albedo 0.9 Kd.
// Ke is not read (the copy's Ke is a fork's addition). Approximations, each warned: a name
// beginning "sss" (the copy's subsurface lobe) is Lambert; Ns above 100 is smooth.
void MaterialConverter::choose_glslppm2015(const tinyobj::material_t& m, Material& out,
                                           const std::string& element) {
    const glm::vec3 ka = vec3_of(m.ambient), kd = vec3_of(m.diffuse), ks = vec3_of(m.specular);
    const float ks2 = glm::dot(ks, ks);
    if (glm::dot(ka, ka) > 0.0f) {
        out.kind = MaterialKind::Diffuse;
        out.color = glm::vec3(0.0f);
        out.emission = kd;
        out.emission_two_sided = false;
        out.visible_to_camera = false;
        out.visible_in_reflections = false;
        out.casts_shadow = false;
        return;
    }
    const bool smooth = m.shininess == 100.0f;
    if (!smooth && m.shininess > 100.0f && (ks2 > 0.0f || m.name.rfind("glass", 0) == 0))
        warn(element, "Ns " + number_text(m.shininess) +
                          " above 100 has no glossy lobe in the glslppm2015 convention: "
                          "rendered smooth");
    const float roughness =
        smooth || m.shininess > 100.0f ? 0.0f : glslppm2015_roughness(m.shininess);
    if (m.name.rfind("glass", 0) == 0) {
        out.kind = MaterialKind::Dielectric;
        out.ior = 1.0f + ks2 / 3.0f;
        out.color = glm::sqrt(glm::max(kd, glm::vec3(0.0f)));
        out.roughness = roughness;
        if (!(ks2 > 0.0f))
            warn(element,
                 "glass with a black Ks has index 1 in the glslppm2015 convention: "
                 "it bends no light");
        return;
    }
    if (ks2 == 3.0f) {
        out.kind = MaterialKind::Conductor;
        out.color = kd;
        out.roughness = roughness;
        return;
    }
    out.color = 0.9f * kd;
    if (m.name.rfind("sss", 0) == 0)
        warn(element, "the glslppm2015 convention's subsurface material is rendered Lambert");
    if (ks2 > 0.0f) {
        out.kind = MaterialKind::Plastic;
        out.ior = 1.7f;
        out.roughness = roughness;
    }
}

Material MaterialConverter::convert(const tinyobj::material_t& m) {
    const std::string element = "material '" + m.name + "'";
    Material out;
    out.color = vec3_of(m.diffuse);
    out.emission = vec3_of(m.emission);
    if (source.convention == MtlConvention::Glslppm2015) {
        if (glm::dot(out.emission, out.emission) > 0.0f)
            warn(element, "Ke is not read in the glslppm2015 convention (Ka marks a light)");
        out.emission = glm::vec3(0.0f);
        choose_glslppm2015(m, out, element);
    } else {
        choose_kind(m, out, element);
    }
    const auto bad = [](glm::vec3 c) {
        return !std::isfinite(c.x + c.y + c.z) || c.x < 0.0f || c.y < 0.0f || c.z < 0.0f;
    };
    if (bad(out.color)) {
        warn(element, "colour is negative or not finite: grey used");
        out.color = glm::vec3(0.8f);
    }
    if (bad(out.emission)) {
        warn(element, "Ke is negative or not finite: no emission");
        out.emission = glm::vec3(0.0f);
    }
    if (!std::isfinite(out.ior)) out.ior = 1.5f;
    // A glslppm2015 emitter's map_Kd scales what it emits (its colour is black).
    const bool textured_emitter = glm::dot(out.emission, out.emission) > 0.0f &&
                                source.convention == MtlConvention::Glslppm2015;
    (textured_emitter ? out.emission_texture : out.color_texture) =
        texture(m.diffuse_texname, m.diffuse_texopt, element);
    if (!m.bump_texname.empty() || !m.normal_texname.empty())
        warn(element, "bump and normal maps are not supported: ignored");
    if (!m.specular_texname.empty() || !m.alpha_texname.empty() || !m.emissive_texname.empty())
        warn(element, "map_Ks, map_d and map_Ke are not supported: ignored");
    return out;
}

struct CornerKey {
    int v, vt, vn;
    auto operator<=>(const CornerKey&) const = default;
};

struct MeshBuilder {
    const Source& source;
    const tinyobj::attrib_t& attrib;
    OwnedMesh& mesh;
    std::map<CornerKey, std::uint32_t> vertex_of;
    bool any_normals = false;

    [[noreturn]] void fail(const std::string& element, const std::string& what) const {
        throw SceneFileError(source.name + ": " + element + ": " + what);
    }
    std::uint32_t vertex(const tinyobj::index_t& i, const std::string& element);
    void add_face(std::span<const tinyobj::index_t> corners, std::uint32_t material,
                  const std::string& element);
};

std::uint32_t MeshBuilder::vertex(const tinyobj::index_t& i, const std::string& element) {
    const std::size_t nv = attrib.vertices.size() / 3, nt = attrib.texcoords.size() / 2,
                      nn = attrib.normals.size() / 3;
    const auto check = [&](int index, std::size_t count, const char* kind, bool optional) {
        if ((optional && index == -1) || (index >= 0 && std::size_t(index) < count)) return;
        fail(element, std::string(kind) + " index " + std::to_string(index + 1) +
                          " is out of range (the file has " + std::to_string(count) + ")");
    };
    check(i.vertex_index, nv, "vertex", false);
    check(i.texcoord_index, nt, "texture coordinate", true);
    check(i.normal_index, nn, "normal", true);
    const CornerKey key{i.vertex_index, i.texcoord_index, i.normal_index};
    if (auto it = vertex_of.find(key); it != vertex_of.end()) return it->second;
    const float* p = &attrib.vertices[3 * std::size_t(i.vertex_index)];
    mesh.positions.emplace_back(p[0], p[1], p[2]);
    glm::vec3 n(0.0f);
    if (i.normal_index >= 0) {
        const float* q = &attrib.normals[3 * std::size_t(i.normal_index)];
        n = glm::vec3(q[0], q[1], q[2]);
        const float length = glm::length(n);
        n = length > 0.0f && std::isfinite(length) ? n / length : glm::vec3(0.0f);
        any_normals = true;
    }
    mesh.normals.push_back(n);
    glm::vec2 uv(0.0f);  // OBJ's v already runs bottom-up, as Texture rows do
    if (i.texcoord_index >= 0)
        uv = {attrib.texcoords[2 * std::size_t(i.texcoord_index)],
              attrib.texcoords[2 * std::size_t(i.texcoord_index) + 1]};
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
        fail(element,
             "texture coordinate " + std::to_string(i.texcoord_index + 1) + " is not finite");
    mesh.uvs.push_back(uv);
    return vertex_of[key] = std::uint32_t(mesh.positions.size() - 1);
}

void MeshBuilder::add_face(std::span<const tinyobj::index_t> corners, std::uint32_t material,
                           const std::string& element) {
    std::vector<std::uint32_t> ids;
    std::vector<glm::vec3> points;
    for (const tinyobj::index_t& c : corners) {
        ids.push_back(vertex(c, element));
        points.push_back(mesh.positions[ids.back()]);
    }
    for (const glm::uvec3& t : triangulate_polygon(points)) {
        mesh.triangles.emplace_back(ids[t.x], ids[t.y], ids[t.z]);
        mesh.material_ids.push_back(material);
    }
}

// The original glslppm's emitters (emissive meshes) emit around their vertex normals;
// one-sided emission here leaves the front of the winding. Emitters whose winding faces
// against their normals are turned round (nothing sees them, so only their emission's side
// changes).
void face_emitters_along_normals(OwnedMesh& mesh, const std::vector<Material>& materials) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Material& m = materials[mesh.material_ids[t]];
        if (m.emission_two_sided || !(glm::dot(m.emission, m.emission) > 0.0f)) continue;
        glm::uvec3& tri = mesh.triangles[t];
        const glm::vec3 winding = glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                             mesh.positions[tri.z] - mesh.positions[tri.x]);
        const glm::vec3 normals = mesh.normals[tri.x] + mesh.normals[tri.y] + mesh.normals[tri.z];
        if (glm::dot(winding, normals) < 0.0f) std::swap(tri.y, tri.z);
    }
}

// tinyobjloader's messages hold several lines; one warning each.
void append_lines(const std::string& text, const std::string& file, std::vector<std::string>& out) {
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        // Ours already names the missing .mtl; tinyobjloader's generic line adds nothing.
        if (line.rfind("Failed to load material file", 0) == 0) continue;
        if (!line.empty() && line != ".") out.push_back(file + ": " + line);
    }
}

void check_vertices(const tinyobj::attrib_t& attrib, const std::string& file) {
    for (std::size_t i = 0; i < attrib.vertices.size(); ++i)
        if (!std::isfinite(attrib.vertices[i]))
            throw SceneFileError(file + ": vertex " + std::to_string(i / 3 + 1) +
                                 " (counting v lines): coordinate " + "xyz"[i % 3] + " is " +
                                 (std::isnan(attrib.vertices[i]) ? "NaN" : "infinite"));
    for (std::size_t i = 0; i < attrib.normals.size(); ++i)
        if (!std::isfinite(attrib.normals[i]))
            throw SceneFileError(file + ": normal " + std::to_string(i / 3 + 1) +
                                 " (vn) is not finite");
}

LoadedScene load_obj(std::istream& obj, const Source& source, float aspect) {
    if (!(aspect > 0.0f) || !std::isfinite(aspect))
        throw SceneFileError(source.name + ": the aspect ratio must be positive");
    LoadedScene out;
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    MtlReader reader(source, out.warnings);
    // Triangulated here, after the indices are checked (tinyobjloader's own triangulation
    // reads vertices before checking them).
    const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &obj, &reader,
                                     /*triangulate=*/false, /*default_vcols_fallback=*/false);
    if (!ok)
        throw SceneFileError(
            source.name + ": " +
            (err.empty() ? "cannot parse" : err.substr(0, err.find_last_not_of("\n ") + 1)));
    append_lines(warn, source.name, out.warnings);
    append_lines(err, source.name, out.warnings);
    check_vertices(attrib, source.name);

    MaterialConverter converter{source, out.scene, out.warnings, {}};
    for (const tinyobj::material_t& m : materials)
        out.scene.materials.push_back(converter.convert(m));
    int default_material = -1;

    auto mesh = std::make_shared<OwnedMesh>();
    MeshBuilder builder{source, attrib, *mesh, {}};
    for (const tinyobj::shape_t& shape : shapes) {
        const tinyobj::mesh_t& m = shape.mesh;
        std::size_t total = 0;
        for (unsigned char n : m.num_face_vertices) total += n;
        const std::string element = "object '" + shape.name + "'";
        if (total != m.indices.size() || m.material_ids.size() != m.num_face_vertices.size())
            throw SceneFileError(source.name + ": " + element +
                                 ": a face has more than 255 vertices (not supported)");
        std::size_t first = 0;
        for (std::size_t f = 0; f < m.num_face_vertices.size(); ++f) {
            const std::size_t n = m.num_face_vertices[f];
            int material = m.material_ids[f];
            if (material < 0 || std::size_t(material) >= out.scene.materials.size()) {
                if (default_material < 0) {
                    default_material = int(out.scene.materials.size());
                    out.scene.materials.push_back(Material{});
                }
                material = default_material;
            }
            if (n >= 3)
                builder.add_face(std::span(m.indices).subspan(first, n), std::uint32_t(material),
                                 element + " face " + std::to_string(f + 1));
            first += n;
        }
    }
    // A file without faces still gets a material, so that what the renderer reports is the
    // missing geometry.
    if (out.scene.materials.empty()) out.scene.materials.push_back(Material{});
    if (!builder.any_normals)
        mesh->normals.clear();
    else
        fill_missing_normals(*mesh);
    if (attrib.texcoords.empty()) mesh->uvs.clear();
    if (source.convention == MtlConvention::Glslppm2015 && builder.any_normals)
        face_emitters_along_normals(*mesh, out.scene.materials);

    Scene scene = make_scene(mesh);
    scene.materials = std::move(out.scene.materials);
    scene.textures = std::move(out.scene.textures);
    // OBJ files are Y-up by convention (Blender exports them so): as for glTF, the
    // environment map's +Z (up) becomes +Y.
    scene.environment_to_world =
        glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0));
    out.scene = std::move(scene);
    return out;
}

}  // namespace

LoadedScene load_obj_from_memory(const std::string& obj_text, const std::string& mtl_text,
                                 const std::string& name, float aspect, MtlConvention convention) {
    std::istringstream in(obj_text);
    const Source source{name, "", &mtl_text, convention};
    return load_obj(in, source, aspect);
}

LoadedScene load_obj_file(const std::string& path, float aspect, MtlConvention convention) {
    std::ifstream in(path);
    if (!in) throw SceneFileError(path + ": cannot open the file (" + std::strerror(errno) + ")");
    const auto slash = path.find_last_of('/');
    const Source source{path, slash == std::string::npos ? "." : path.substr(0, slash), nullptr,
                        convention};
    return load_obj(in, source, aspect);
}

}  // namespace glslppm
