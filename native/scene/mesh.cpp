#include "scene/mesh.h"

#include <cmath>

namespace glslppm {
namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

[[noreturn]] void fail(const std::string& array, std::size_t index, const std::string& what) {
    throw SceneError(array + "[" + std::to_string(index) + "]: " + what);
}

}  // namespace

bool is_degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const glm::dvec3 e1 = glm::dvec3(b) - glm::dvec3(a);
    const glm::dvec3 e2 = glm::dvec3(c) - glm::dvec3(a);
    const double area2 = glm::length(glm::cross(e1, e2));
    // The sine of the angle between the edges: relative, so that a triangle 1e-7 of the
    // scene size still counts while a collinear one does not, at any scene scale.
    const double scale = glm::length(e1) * glm::length(e2);
    return !(area2 > 1e-9 * scale) || scale == 0.0;
}

ValidMesh validate_mesh(const MeshView& mesh, std::uint32_t material_count,
                        const CancelFlag* cancel) {
    const std::size_t vertex_count = mesh.positions.size();
    if (!mesh.normals.empty() && mesh.normals.size() != vertex_count)
        throw SceneError("normals: has " + std::to_string(mesh.normals.size()) +
                         " rows but positions has " + std::to_string(vertex_count));
    if (!mesh.uvs.empty() && mesh.uvs.size() != vertex_count)
        throw SceneError("uvs: has " + std::to_string(mesh.uvs.size()) +
                         " rows but positions has " + std::to_string(vertex_count));
    if (!mesh.tangents.empty() && mesh.tangents.size() != vertex_count)
        throw SceneError("tangents: has " + std::to_string(mesh.tangents.size()) +
                         " rows but positions has " + std::to_string(vertex_count));
    if (!mesh.colors.empty() && mesh.colors.size() != vertex_count)
        throw SceneError("colors: has " + std::to_string(mesh.colors.size()) +
                         " rows but positions has " + std::to_string(vertex_count));
    if (!mesh.material_ids.empty() && mesh.material_ids.size() != mesh.triangles.size())
        throw SceneError("material_ids: has " + std::to_string(mesh.material_ids.size()) +
                         " entries but indices has " + std::to_string(mesh.triangles.size()) +
                         " triangles");

    for (std::size_t i = 0; i < vertex_count; ++i)
        if (!finite(mesh.positions[i])) fail("positions", i, "coordinate is NaN or Inf");
    for (std::size_t i = 0; i < mesh.normals.size(); ++i)
        if (!finite(mesh.normals[i])) fail("normals", i, "component is NaN or Inf");
    for (std::size_t i = 0; i < mesh.uvs.size(); ++i)
        if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y))
            fail("uvs", i, "component is NaN or Inf");

    for (std::size_t i = 0; i < mesh.tangents.size(); ++i) {
        const glm::vec4 t = mesh.tangents[i];
        if (!finite(glm::vec3(t)) || !std::isfinite(t.w))
            fail("tangents", i, "component is NaN or Inf");
        if (!(glm::length(glm::vec3(t)) > 0.0f)) fail("tangents", i, "tangent has zero length");
    }

    // A colour scales reflected light: a negative one would make negative photons.
    for (std::size_t i = 0; i < mesh.colors.size(); ++i) {
        const glm::vec3 c = mesh.colors[i];
        if (!finite(c)) fail("colors", i, "component is NaN or Inf");
        if (c.x < 0.0f || c.y < 0.0f || c.z < 0.0f) fail("colors", i, "component is negative");
    }

    ValidMesh valid{mesh, {}, {}};
    valid.stats.input_triangles = mesh.triangles.size();
    valid.kept.reserve(mesh.triangles.size());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        if ((t & 0xFFFFu) == 0) throw_if_cancelled(cancel);
        const glm::uvec3 tri = mesh.triangles[t];
        for (int k = 0; k < 3; ++k)
            if (tri[k] >= vertex_count)
                fail("indices", t,
                     "vertex index " + std::to_string(tri[k]) + " is out of range (" +
                         std::to_string(vertex_count) + " vertices)");
        if (!mesh.material_ids.empty() && mesh.material_ids[t] >= material_count)
            fail("material_ids", t,
                 "material " + std::to_string(mesh.material_ids[t]) + " does not exist (" +
                     std::to_string(material_count) + " materials)");
        if (is_degenerate(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z]))
            ++valid.stats.degenerate_dropped;
        else
            valid.kept.push_back(static_cast<std::uint32_t>(t));
    }
    return valid;
}

}  // namespace glslppm
