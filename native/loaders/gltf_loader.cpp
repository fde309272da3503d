#include "loaders/gltf_loader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <iterator>
#include <memory>

#include "loaders/gltf_accessors.h"
#include "loaders/gltf_materials.h"
#include "loaders/gltf_punctual.h"
#include "scene/tangent_space.h"
#include "loaders/vertex_normals.h"

namespace glslppm {
namespace {

// Loads of huge instanced scenes are refused before they exhaust memory, and node chains
// deeper than any real scene's before they exhaust the stack.
constexpr std::size_t kMaxTriangles = std::size_t(1) << 28;
constexpr int kMaxNodeDepth = 1000;

struct Loader {
    const tinygltf::Model& model;
    std::string file;
    float aspect;
    LoadedScene& out;
    OwnedMesh& mesh;
    std::vector<int> parent;  // per node: the node that listed it first (-2: not reached)
    // glTF node instancing: a mesh that several nodes use is read once, in its own space,
    // into an instance mesh, and each node that uses it becomes an instance (nested nodes
    // flattened to one level: the instance's matrix is the node's world matrix).
    std::vector<int> mesh_users{};        // per glTF mesh: nodes that use it
    std::vector<int> instance_mesh_of{};  // per glTF mesh: index into instance_meshes, or -1
    std::vector<std::shared_ptr<OwnedMesh>> instance_meshes{};
    bool any_normals = false;
    bool any_uvs = false;
    bool any_tangents = false;
    bool any_colors = false;

    // Whether any primitive of the file has TANGENT (the others then get tangents made from
    // their uvs; a file without any leaves them to the renderer).
    int has_tangents = -1;  // unknown until asked
    bool file_has_tangents() {
        if (has_tangents < 0) {
            has_tangents = 0;
            for (const tinygltf::Mesh& m : model.meshes)
                for (const tinygltf::Primitive& p : m.primitives)
                    has_tangents |= p.attributes.count("TANGENT") ? 1 : 0;
        }
        return has_tangents == 1;
    }
    int default_material = -1;

    [[noreturn]] void fail(const std::string& element, const std::string& what) const {
        throw SceneFileError(file + ": " + element + ": " + what);
    }
    void warn(const std::string& element, const std::string& what) {
        out.warnings.push_back(file + ": " + element + ": " + what);
    }

    glm::mat4 local_transform(const tinygltf::Node& node, const std::string& element) const;
    void visit(int node, int from, const glm::mat4& parent_to_world, int depth);
    void count_mesh_users(int node, int depth);
    void add_mesh(int mesh, const glm::mat4& to_world, const std::string& element);
    void add_instance(int mesh, const glm::mat4& to_world, const std::string& element);
    // Appends a primitive's triangles to `target`: the scene's mesh (world space) or an
    // instance mesh (to_world the identity).
    void add_primitive(const tinygltf::Primitive& p, const glm::mat4& to_world,
                       const std::string& element, OwnedMesh& target);
    void add_camera(int camera, const glm::mat4& to_world, const std::string& element);
    void add_light(const tinygltf::Node& node, const glm::mat4& to_world,
                   const std::string& element);
    std::uint32_t material_of(int material, const std::string& element);
    // glTF's base colour is baseColorFactor x baseColorTexture x COLOR_0: the material of a
    // primitive with COLOR_0, and every leaf of it if it became a Mix, multiplies it in.
    void multiply_vertex_colors(std::uint32_t material, int depth = 0);
    std::vector<float> read_colors(int accessor, std::size_t vertex_count,
                                   const std::string& what);
};

std::string node_name(int index, const tinygltf::Node& node) {
    const std::string e = "nodes[" + std::to_string(index) + "]";
    return node.name.empty() ? e : e + " '" + node.name + "'";
}

bool all_finite(const std::vector<double>& v) {
    for (double x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

glm::mat4 Loader::local_transform(const tinygltf::Node& node, const std::string& element) const {
    if (!all_finite(node.matrix) || !all_finite(node.translation) || !all_finite(node.rotation) ||
        !all_finite(node.scale))
        fail(element, "its transform has NaN or infinite values");
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) fail(element, "matrix must have 16 values");
        glm::mat4 m;  // glTF matrices are column-major, as glm's
        for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = float(node.matrix[std::size_t(i)]);
        return m;
    }
    glm::mat4 m(1.0f);
    if (!node.translation.empty()) {
        if (node.translation.size() != 3) fail(element, "translation must have 3 values");
        m = glm::translate(
            m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
    }
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4) fail(element, "rotation must have 4 values");
        // glTF quaternions are (x, y, z, w); glm's constructor takes w first.
        glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                    float(node.rotation[2]));
        if (glm::length(q) == 0.0f) fail(element, "rotation is a zero quaternion");
        m *= glm::mat4_cast(glm::normalize(q));
    }
    if (!node.scale.empty()) {
        if (node.scale.size() != 3) fail(element, "scale must have 3 values");
        m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
    }
    return m;
}

// Depth-first over the node tree. glTF requires a tree (section 3.5.3: one parent per node);
// a node reached twice would mean a cycle or exponential re-instancing, so it is an error.
void Loader::visit(int index, int from, const glm::mat4& parent_to_world, int depth) {
    const std::string via = from < 0 ? "scene" : "nodes[" + std::to_string(from) + "].children";
    if (index < 0 || std::size_t(index) >= model.nodes.size())
        fail(via, "node " + std::to_string(index) + " is out of range (the file has " +
                      std::to_string(model.nodes.size()) + " nodes)");
    const tinygltf::Node& node = model.nodes[std::size_t(index)];
    const std::string element = node_name(index, node);
    if (parent[std::size_t(index)] != -2)
        fail(element,
             "is reached twice (listed by " + via + " too): the node hierarchy must be a tree");
    parent[std::size_t(index)] = from;
    if (depth > kMaxNodeDepth)
        fail(element, "is nested deeper than " + std::to_string(kMaxNodeDepth) + " levels");
    const glm::mat4 to_world = parent_to_world * local_transform(node, element);
    if (node.mesh >= 0) {
        if (std::size_t(node.mesh) < mesh_users.size() && mesh_users[std::size_t(node.mesh)] > 1)
            add_instance(node.mesh, to_world, element);
        else
            add_mesh(node.mesh, to_world, element);
    }
    if (node.camera >= 0) add_camera(node.camera, to_world, element);
    if (node.extensions.count("KHR_lights_punctual")) add_light(node, to_world, element);
    if (node.skin >= 0) warn(element, "skinning is not supported: the bind pose is rendered");
    for (int child : node.children) visit(child, index, to_world, depth + 1);
}

// Counts the nodes that use each mesh, over the same nodes visit() reaches (errors in the
// tree itself are left to visit(), which names them).
void Loader::count_mesh_users(int index, int depth) {
    if (index < 0 || std::size_t(index) >= model.nodes.size() || depth > kMaxNodeDepth) return;
    const tinygltf::Node& node = model.nodes[std::size_t(index)];
    if (node.mesh >= 0 && std::size_t(node.mesh) < mesh_users.size())
        ++mesh_users[std::size_t(node.mesh)];
    for (int child : node.children) count_mesh_users(child, depth + 1);
}

void Loader::add_mesh(int index, const glm::mat4& to_world, const std::string& element) {
    if (std::size_t(index) >= model.meshes.size())
        fail(element, "mesh " + std::to_string(index) + " is out of range (the file has " +
                          std::to_string(model.meshes.size()) + " meshes)");
    const tinygltf::Mesh& m = model.meshes[std::size_t(index)];
    for (std::size_t p = 0; p < m.primitives.size(); ++p)
        add_primitive(
            m.primitives[p], to_world,
            "meshes[" + std::to_string(index) + "].primitives[" + std::to_string(p) + "]", mesh);
}

void Loader::add_instance(int index, const glm::mat4& to_world, const std::string& element) {
    const glm::mat3 linear(to_world);
    if (!(std::abs(glm::determinant(glm::dmat3(linear))) > 0.0)) {
        add_mesh(index, to_world, element);  // a flattening transform: no instance of it
        return;
    }
    int& k = instance_mesh_of[std::size_t(index)];
    if (k < 0) {
        k = int(instance_meshes.size());
        auto target = std::make_shared<OwnedMesh>();
        const tinygltf::Mesh& m = model.meshes[std::size_t(index)];
        for (std::size_t p = 0; p < m.primitives.size(); ++p)
            add_primitive(
                m.primitives[p], glm::mat4(1.0f),
                "meshes[" + std::to_string(index) + "].primitives[" + std::to_string(p) + "]",
                *target);
        instance_meshes.push_back(target);
    }
    Instance inst;
    inst.to_world = to_world;
    inst.mesh = std::uint32_t(k);
    out.scene.instances.push_back(inst);
}

std::uint32_t Loader::material_of(int material, const std::string& element) {
    if (material >= 0) {
        if (std::size_t(material) >= model.materials.size())
            fail(element, "material " + std::to_string(material) +
                              " is out of range (the file has " +
                              std::to_string(model.materials.size()) + " materials)");
        return std::uint32_t(material);
    }
    // No material: Blender's grey diffuse rather than the specification's default (a
    // metallic white), which is what users of both expect to see.
    if (default_material < 0) {
        default_material = int(out.scene.materials.size());
        out.scene.materials.push_back(Material{});
    }
    return std::uint32_t(default_material);
}

void Loader::multiply_vertex_colors(std::uint32_t material, int depth) {
    Material& m = out.scene.materials[material];
    m.vertex_color = true;
    if (m.kind != MaterialKind::Mix || depth > 16) return;
    for (const std::int32_t leaf : {m.mix_a, m.mix_b})
        if (leaf >= 0 && std::size_t(leaf) < out.scene.materials.size())
            multiply_vertex_colors(std::uint32_t(leaf), depth + 1);
}

// COLOR_0 as linear rgb: VEC3 or VEC4 (alpha is not read: the renderer has no vertex
// alpha), float or normalized unsigned byte or short (glTF 2.0 section 3.7.2.1).
std::vector<float> Loader::read_colors(int accessor, std::size_t vertex_count,
                                       const std::string& what) {
    const std::size_t count = gltf::accessor_count(model, accessor, what, file);
    const tinygltf::Accessor& a = model.accessors[std::size_t(accessor)];
    if (a.type != TINYGLTF_TYPE_VEC3 && a.type != TINYGLTF_TYPE_VEC4)
        fail(what, "must be VEC3 or VEC4, the accessor has type " + std::to_string(a.type));
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !a.normalized)
        fail(what, "integer colours must be normalized (glTF 2.0 section 3.7.2.1)");
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT &&
        a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)
        fail(what, "must be float, unsigned byte or unsigned short, the accessor has component "
                   "type " + std::to_string(a.componentType));
    if (count != vertex_count)
        fail(what, "has " + std::to_string(count) + " elements, POSITION has " +
                       std::to_string(vertex_count));
    const int components = a.type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
    const std::vector<float> read = gltf::read_floats(model, accessor, components, what, file);
    std::vector<float> rgb(3 * vertex_count);
    for (std::size_t v = 0; v < vertex_count; ++v)
        for (int c = 0; c < 3; ++c) {
            const float x = read[std::size_t(components) * v + std::size_t(c)];
            if (x < 0.0f)
                fail(what, "element " + std::to_string(v) + " has a negative component");
            rgb[3 * v + std::size_t(c)] = x;
        }
    return rgb;
}

// Triangles from a list, strip or fan (glTF 2.0 section 3.7.2.1); other modes give none.
std::vector<glm::uvec3> assemble(const std::vector<std::uint32_t>& v, int mode) {
    std::vector<glm::uvec3> t;
    if (mode == TINYGLTF_MODE_TRIANGLES)
        for (std::size_t i = 0; i + 2 < v.size(); i += 3) t.emplace_back(v[i], v[i + 1], v[i + 2]);
    else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP)
        for (std::size_t i = 0; i + 2 < v.size(); ++i)
            t.push_back(i % 2 ? glm::uvec3(v[i + 1], v[i], v[i + 2])
                              : glm::uvec3(v[i], v[i + 1], v[i + 2]));
    else if (mode == TINYGLTF_MODE_TRIANGLE_FAN)
        for (std::size_t i = 1; i + 1 < v.size(); ++i) t.emplace_back(v[i], v[i + 1], v[0]);
    return t;
}

void Loader::add_primitive(const tinygltf::Primitive& p, const glm::mat4& to_world,
                           const std::string& element, OwnedMesh& target) {
    const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        static const char* names[] = {"points", "lines", "line loop", "line strip"};
        warn(element, "mode " + std::to_string(mode) +
                          (mode >= 0 && mode < 4 ? std::string(" (") + names[mode] + ")" : "") +
                          " is not supported (triangles only): skipped");
        return;
    }
    if (!p.targets.empty())
        warn(element, "morph targets are not supported: the base shape is used");
    const auto attribute = [&](const char* name) {
        const auto it = p.attributes.find(name);
        return it == p.attributes.end() ? -1 : it->second;
    };
    const int position_accessor = attribute("POSITION");
    if (position_accessor < 0) fail(element, "has no POSITION attribute");
    const std::vector<float> positions =
        gltf::read_floats(model, position_accessor, 3, element + ".attributes.POSITION", file);
    const std::size_t vertex_count = positions.size() / 3;
    std::vector<std::uint32_t> corners;
    if (p.indices >= 0) {
        corners = gltf::read_indices(model, p.indices, element + ".indices", file);
        for (std::size_t i = 0; i < corners.size(); ++i)
            if (corners[i] >= vertex_count)
                fail(element + ".indices",
                     "element " + std::to_string(i) + " = " + std::to_string(corners[i]) +
                         " is past the vertex count " + std::to_string(vertex_count));
    } else {
        if (vertex_count > 0xffffffffu) fail(element, "too many vertices");
        corners.resize(vertex_count);
        for (std::size_t i = 0; i < vertex_count; ++i) corners[i] = std::uint32_t(i);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES && corners.size() % 3 != 0)
        warn(element,
             std::to_string(corners.size()) +
                 " indices are not a multiple of 3: the last incomplete triangle is dropped");
    std::vector<glm::uvec3> triangles = assemble(corners, mode);
    if (target.triangles.size() + triangles.size() > kMaxTriangles)
        fail(element, "the scene exceeds " + std::to_string(kMaxTriangles) + " triangles");

    std::vector<float> normals, uvs, tangents;
    if (const int a = attribute("NORMAL"); a >= 0) {
        normals = gltf::read_floats(model, a, 3, element + ".attributes.NORMAL", file);
        if (normals.size() != positions.size())
            fail(element + ".attributes.NORMAL", "has " + std::to_string(normals.size() / 3) +
                                                     " elements, POSITION has " +
                                                     std::to_string(vertex_count));
    }
    if (const int a = attribute("TEXCOORD_0"); a >= 0) {
        uvs = gltf::read_floats(model, a, 2, element + ".attributes.TEXCOORD_0", file);
        if (uvs.size() / 2 != vertex_count)
            fail(element + ".attributes.TEXCOORD_0", "has " + std::to_string(uvs.size() / 2) +
                                                         " elements, POSITION has " +
                                                         std::to_string(vertex_count));
    }
    if (const int a = attribute("TANGENT"); a >= 0) {
        tangents = gltf::read_floats(model, a, 4, element + ".attributes.TANGENT", file);
        if (tangents.size() / 4 != vertex_count)
            fail(element + ".attributes.TANGENT", "has " + std::to_string(tangents.size() / 4) +
                                                      " elements, POSITION has " +
                                                      std::to_string(vertex_count));
    }
    std::vector<float> colors;
    if (const int a = attribute("COLOR_0"); a >= 0)
        colors = read_colors(a, vertex_count, element + ".attributes.COLOR_0");
    const std::uint32_t material = material_of(p.material, element);
    if (!colors.empty()) multiply_vertex_colors(material);

    // Positions by the node's matrix, normals by its inverse transpose; a mirroring
    // transform (negative determinant) reverses the winding (glTF 2.0 section 3.7.4).
    const glm::mat3 linear(to_world);
    const glm::mat3 normal_matrix = glm::transpose(glm::inverse(linear));
    const bool mirrored = glm::determinant(linear) < 0.0f;
    const std::size_t base = target.positions.size();
    if (base + vertex_count > 0xffffffffu) fail(element, "the scene exceeds 2^32 vertices");
    for (std::size_t v = 0; v < vertex_count; ++v) {
        const glm::vec3 world(to_world * glm::vec4(positions[3 * v], positions[3 * v + 1],
                                                   positions[3 * v + 2], 1.0f));
        if (!std::isfinite(world.x) || !std::isfinite(world.y) || !std::isfinite(world.z))
            fail(element + ".attributes.POSITION",
                 "element " + std::to_string(v) + " is not finite once transformed");
        target.positions.push_back(world);
        glm::vec3 n(0.0f);
        if (!normals.empty()) {
            n = normal_matrix * glm::vec3(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
            const float length = glm::length(n);
            n = length > 0.0f && std::isfinite(length) ? n / length : glm::vec3(0.0f);
        }
        target.normals.push_back(n);
        // White where the primitive has no COLOR_0 (the specification's default), so that
        // its mesh keeps one array; dropped below if no primitive has one.
        target.colors.push_back(colors.empty() ? glm::vec3(1.0f)
                                               : glm::vec3(colors[3 * v], colors[3 * v + 1],
                                                           colors[3 * v + 2]));
        target.uvs.push_back(uvs.empty()
                                 ? glm::vec2(0.0f)
                                 : glm::vec2(uvs[2 * v], 1.0f - uvs[2 * v + 1]));  // v flipped
        // TANGENT turns with the surface; its w keeps its meaning with v flipped (Blender's
        // exporter writes Blender's own bitangent sign beside flipped uvs), and flips with
        // a mirroring transform. Without TANGENT, tangents come from the uvs below.
        if (!tangents.empty()) {
            const glm::vec3 t = linear * glm::vec3(tangents[4 * v], tangents[4 * v + 1],
                                                   tangents[4 * v + 2]);
            const float length = glm::length(t);
            const float sign = (tangents[4 * v + 3] < 0.0f ? -1.0f : 1.0f) * (mirrored ? -1.0f : 1.0f);
            target.tangents.push_back(length > 0.0f && std::isfinite(length)
                                          ? glm::vec4(t / length, sign)
                                          : glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
        }
    }
    any_tangents |= !tangents.empty();
    any_normals |= !normals.empty();
    any_uvs |= !uvs.empty();
    any_colors |= !colors.empty();
    for (glm::uvec3 t : triangles) {
        if (mirrored) std::swap(t.y, t.z);
        target.triangles.push_back(t + glm::uvec3(std::uint32_t(base)));
        target.material_ids.push_back(material);
    }
    if (tangents.empty() && file_has_tangents()) {
        // This primitive's own tangents from its uvs (scene/tangent_space.h), so that a
        // mesh mixing primitives with and without TANGENT keeps one array.
        std::vector<glm::uvec3> local(target.triangles.end() - std::ptrdiff_t(triangles.size()),
                                      target.triangles.end());
        for (glm::uvec3& t : local) t -= glm::uvec3(std::uint32_t(base));
        const std::span<const glm::vec3> own_normals =
            normals.empty() ? std::span<const glm::vec3>()
                            : std::span<const glm::vec3>(target.normals).subspan(base, vertex_count);
        const std::vector<glm::vec4> made = generate_tangents(
            std::span<const glm::vec3>(target.positions).subspan(base, vertex_count), local,
            own_normals, std::span<const glm::vec2>(target.uvs).subspan(base, vertex_count));
        target.tangents.insert(target.tangents.end(), made.begin(), made.end());
    }
}

void Loader::add_camera(int index, const glm::mat4& to_world, const std::string& element) {
    if (std::size_t(index) >= model.cameras.size())
        fail(element, "camera " + std::to_string(index) + " is out of range (the file has " +
                          std::to_string(model.cameras.size()) + " cameras)");
    if (out.has_camera) {  // the first camera of the node tree (depth first) is the one
        warn(element, "cameras[" + std::to_string(index) + "] is not the first camera: ignored");
        return;
    }
    out.scene.camera = gltf::convert_camera(model.cameras[std::size_t(index)], to_world, aspect,
                                            file, "cameras[" + std::to_string(index) + "]");
    out.has_camera = true;
}

void Loader::add_light(const tinygltf::Node& node, const glm::mat4& to_world,
                       const std::string& element) {
    const tinygltf::Value& ext = node.extensions.at("KHR_lights_punctual");
    if (!ext.Has("light") || !ext.Get("light").IsNumber())
        fail(element, "extensions.KHR_lights_punctual has no light index");
    const int index = ext.Get("light").GetNumberAsInt();
    if (index < 0 || std::size_t(index) >= model.lights.size())
        fail(element, "KHR_lights_punctual light " + std::to_string(index) +
                          " is out of range (the file has " + std::to_string(model.lights.size()) +
                          " lights)");
    const std::string what = "KHR_lights_punctual.lights[" + std::to_string(index) + "]";
    if (auto light = gltf::convert_light(model.lights[std::size_t(index)], to_world, file, what,
                                         out.warnings))
        out.scene.lights.push_back(*light);
}

// The roots to walk: the default scene's, else the first scene's, else every parentless node.
std::vector<int> roots(const tinygltf::Model& model, const std::string& file) {
    if (!model.scenes.empty()) {
        const int s = model.defaultScene >= 0 ? model.defaultScene : 0;
        if (std::size_t(s) >= model.scenes.size())
            throw SceneFileError(file + ": scene " + std::to_string(s) + " is out of range");
        return model.scenes[std::size_t(s)].nodes;
    }
    std::vector<bool> is_child(model.nodes.size(), false);
    for (const tinygltf::Node& n : model.nodes)
        for (int c : n.children)
            if (c >= 0 && std::size_t(c) < is_child.size()) is_child[std::size_t(c)] = true;
    std::vector<int> r;
    for (std::size_t i = 0; i < model.nodes.size(); ++i)
        if (!is_child[i]) r.push_back(int(i));
    return r;
}

// glTF is Y-up; Blender's equirectangular mapping is Z-up. Blender's importer maps glTF
// (x, y, z) to Blender (x, -z, y), so Blender's axes land on glTF's x, -z, +y: the map's
// +Z (up) becomes +Y.
glm::mat3 environment_frame() {
    return glm::mat3(glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, -1.0f),
                     glm::vec3(0.0f, 1.0f, 0.0f));
}

// With no directory to read from, nothing touches the disk.
bool no_file_exists(const std::string&, void*) { return false; }
std::string same_path(const std::string& path, void*) { return path; }
bool no_read(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
    if (err) *err += "external file '" + path + "' is not read when loading from memory\n";
    return false;
}
bool no_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is disabled\n";
    return false;
}
bool no_size(std::size_t*, std::string* err, const std::string& path, void*) {
    if (err) *err += "external file '" + path + "' is not read when loading from memory\n";
    return false;
}

// tinygltf 2.9 (Debian 13) added a file-size callback and refuses a set with any left null;
// 2.7 (Debian 12) has none. (A template, so that the branch is discarded where it is absent.)
template <typename Callbacks>
void set_size_callback(Callbacks& fs) {
    if constexpr (requires { fs.GetFileSizeInBytes; }) fs.GetFileSizeInBytes = &no_size;
}

tinygltf::FsCallbacks memory_only_callbacks() {
    tinygltf::FsCallbacks fs{};
    fs.FileExists = &no_file_exists;
    fs.ExpandFilePath = &same_path;
    fs.ReadWholeFile = &no_read;
    fs.WriteWholeFile = &no_write;
    set_size_callback(fs);
    return fs;
}

// tinygltf's messages end in newlines and may hold several lines; one line each for ours.
void append_lines(const std::string& text, const std::string& file, std::vector<std::string>& out) {
    std::size_t start = 0;
    while (start < text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        if (end > start) out.push_back(file + ": " + text.substr(start, end - start));
        start = end + 1;
    }
}

std::string one_line(const std::string& text) {
    std::string s = text;
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    for (char& c : s)
        if (c == '\n') c = ';';
    return s;
}

// The 12-byte GLB header and the JSON chunk's header (glTF 2.0 section 4.4), checked
// against the size so that a truncated file says so.
void check_glb_header(std::span<const std::uint8_t> b, const std::string& name) {
    const auto u32 = [&](std::size_t at) {
        std::uint32_t v;
        std::memcpy(&v, b.data() + at, 4);
        return v;  // GLB is little-endian, as every platform we build for
    };
    if (b.size() < 20)
        throw SceneFileError(name + ": GLB header: the file is only " + std::to_string(b.size()) +
                             " bytes (truncated)");
    if (u32(4) != 2)
        throw SceneFileError(name + ": GLB header: version " + std::to_string(u32(4)) +
                             " is not 2");
    if (u32(8) > b.size())
        throw SceneFileError(name + ": GLB header: length " + std::to_string(u32(8)) +
                             " bytes, but the file has " + std::to_string(b.size()) +
                             " (truncated)");
    if (std::uint64_t(u32(12)) + 20 > b.size())
        throw SceneFileError(name + ": GLB JSON chunk: length " + std::to_string(u32(12)) +
                             " runs past the end of the file (truncated)");
}

}  // namespace

LoadedScene load_gltf_from_memory(std::span<const std::uint8_t> bytes, const std::string& name,
                                  float aspect, bool binary, const std::string& base_dir) {
    if (!(aspect > 0.0f) || !std::isfinite(aspect))
        throw SceneFileError(name + ": the aspect ratio must be positive");
    if (bytes.size() > 0xffffffffu) throw SceneFileError(name + ": larger than 4 GiB");
    tinygltf::TinyGLTF parser;
    gltf::DecodedImages images;
    images.file = name;
    parser.SetImageLoader(&gltf::decode_image, &images);
    if (base_dir.empty()) parser.SetFsCallbacks(memory_only_callbacks());
    tinygltf::Model model;
    std::string err, warn;
    if (binary) check_glb_header(bytes, name);
    const auto size = static_cast<unsigned int>(bytes.size());
    bool ok = false;
    try {
        ok = binary ? parser.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), size, base_dir)
                    : parser.LoadASCIIFromString(&model, &err, &warn,
                                                 reinterpret_cast<const char*>(bytes.data()), size,
                                                 base_dir);
    } catch (const std::exception& e) {  // tinygltf's JSON library may throw
        err = e.what();
    }
    if (!ok) throw SceneFileError(name + ": " + (err.empty() ? "cannot parse" : one_line(err)));

    LoadedScene out;
    append_lines(warn, name, out.warnings);
    for (const std::string& e : model.extensionsRequired)
        if (e != "KHR_materials_transmission" && e != "KHR_materials_ior" &&
            e != "KHR_materials_emissive_strength" && e != "KHR_materials_specular" &&
            e != "KHR_materials_clearcoat" && e != "KHR_materials_volume" &&
            e != "KHR_lights_punctual")
            throw SceneFileError(name + ": extensionsRequired: " + e + " is not supported");
    auto mesh = std::make_shared<OwnedMesh>();
    gltf::convert_materials(model, images, base_dir, out.scene, out.warnings);
    Loader loader{model, name, aspect, out, *mesh, std::vector<int>(model.nodes.size(), -2)};
    loader.mesh_users.assign(model.meshes.size(), 0);
    loader.instance_mesh_of.assign(model.meshes.size(), -1);
    const std::vector<int> root_nodes = roots(model, name);
    for (int root : root_nodes) loader.count_mesh_users(root, 0);
    for (int root : root_nodes) loader.visit(root, -1, glm::mat4(1.0f), 0);
    if (!loader.any_normals)
        mesh->normals.clear();
    else
        fill_missing_normals(*mesh);
    if (!loader.any_uvs) mesh->uvs.clear();
    // No TANGENT anywhere: the renderer makes them where a normal map needs them.
    if (!loader.any_tangents) mesh->tangents.clear();
    if (!loader.any_colors) mesh->colors.clear();
    // Instance meshes: vertices of primitives without normals keep zero normals (the
    // renderer's geometric normal); arrays no primitive had are dropped.
    for (const std::shared_ptr<OwnedMesh>& m : loader.instance_meshes) {
        if (std::all_of(m->normals.begin(), m->normals.end(),
                        [](const glm::vec3& n) { return n == glm::vec3(0.0f); }))
            m->normals.clear();
        if (!loader.any_uvs) m->uvs.clear();
        if (!loader.any_tangents) m->tangents.clear();
        if (!loader.any_colors) m->colors.clear();
    }
    std::vector<Instance> instances = std::move(out.scene.instances);
    Scene scene = make_scene(mesh);
    if (!instances.empty()) {
        struct Meshes {
            std::shared_ptr<OwnedMesh> world;
            std::vector<std::shared_ptr<OwnedMesh>> instanced;
        };
        auto owner = std::make_shared<Meshes>(Meshes{mesh, loader.instance_meshes});
        for (const std::shared_ptr<OwnedMesh>& m : owner->instanced)
            scene.instance_meshes.push_back(m->view());
        scene.instances = std::move(instances);
        scene.keepalive = owner;
    }
    scene.materials = std::move(out.scene.materials);
    scene.textures = std::move(out.scene.textures);
    scene.lights = std::move(out.scene.lights);
    scene.camera = out.scene.camera;
    scene.environment_to_world = environment_frame();
    out.scene = std::move(scene);
    return out;
}

LoadedScene load_gltf_file(const std::string& path, float aspect) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw SceneFileError(path + ": cannot open the file (" + std::strerror(errno) + ")");
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                          std::istreambuf_iterator<char>());
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
    const bool binary = bytes.size() >= 4 && std::equal(bytes.begin(), bytes.begin() + 4, "glTF");
    return load_gltf_from_memory(bytes, path, aspect, binary, dir);
}

}  // namespace glslppm
