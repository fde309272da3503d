#include "procedural/shapes.h"

#include <cmath>

namespace glslppm {

Shape make_quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    return Shape{{a, b, c, d}, {n, n, n, n}, {{0, 1, 2}, {0, 2, 3}}};
}

Shape make_sphere(glm::vec3 center, float radius, int rings, int segments, bool inward) {
    Shape s;
    const float pi = 3.14159265358979f;
    for (int i = 0; i <= rings; ++i) {
        const float theta = pi * static_cast<float>(i) / static_cast<float>(rings);
        for (int j = 0; j <= segments; ++j) {
            const float phi = 2.0f * pi * static_cast<float>(j) / static_cast<float>(segments);
            const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                              std::sin(theta) * std::sin(phi));
            s.positions.push_back(center + radius * n);
            s.normals.push_back(inward ? -n : n);
        }
    }
    const auto row = static_cast<unsigned>(segments + 1);
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            const unsigned a = static_cast<unsigned>(i) * row + static_cast<unsigned>(j);
            const unsigned b = a + row;
            // Outward winding: counter-clockwise seen from outside.
            glm::uvec3 t0(a, a + 1, b), t1(a + 1, b + 1, b);
            if (inward) {
                std::swap(t0.y, t0.z);
                std::swap(t1.y, t1.z);
            }
            if (i != 0) s.triangles.push_back(t0);           // the pole rows have one
            if (i != rings - 1) s.triangles.push_back(t1);   // zero-area triangle each
        }
    }
    return s;
}

void append_shape(OwnedMesh& mesh, const Shape& shape, std::uint32_t material) {
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), shape.positions.begin(), shape.positions.end());
    mesh.normals.insert(mesh.normals.end(), shape.normals.begin(), shape.normals.end());
    for (const glm::uvec3& t : shape.triangles) {
        mesh.triangles.push_back(t + glm::uvec3(base));
        mesh.material_ids.push_back(material);
    }
}

}  // namespace glslppm
