#include "loaders/vertex_normals.h"

#include <cmath>

namespace glslppm {

void fill_missing_normals(OwnedMesh& mesh) {
    if (mesh.normals.size() != mesh.positions.size()) return;
    bool missing = false;
    for (const glm::vec3& n : mesh.normals) missing |= (n == glm::vec3(0.0f));
    if (!missing) return;
    // The cross product of two edges is twice the triangle's area along its normal.
    std::vector<glm::vec3> sum(mesh.positions.size(), glm::vec3(0.0f));
    const auto& p = mesh.positions;
    for (const glm::uvec3& t : mesh.triangles) {
        const glm::vec3 c = glm::cross(p[t.y] - p[t.x], p[t.z] - p[t.x]);
        sum[t.x] += c;
        sum[t.y] += c;
        sum[t.z] += c;
    }
    for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
        if (mesh.normals[i] != glm::vec3(0.0f)) continue;
        const float length = glm::length(sum[i]);
        mesh.normals[i] =
            length > 0.0f && std::isfinite(length) ? sum[i] / length : glm::vec3(0.0f, 0.0f, 1.0f);
    }
}

}  // namespace glslppm
