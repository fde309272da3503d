#include "procedural/bumpy_sphere_mesh.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace glslppm {

OwnedMesh make_sphere_mesh(std::size_t triangle_count) {
    OwnedMesh mesh;
    if (triangle_count == 0) return mesh;
    // A grid of `segments` x `rings` quads, two triangles each, trimmed to the count asked.
    const std::size_t segments =
        std::max<std::size_t>(3, static_cast<std::size_t>(std::sqrt(triangle_count)));
    const std::size_t rings =
        std::max<std::size_t>(1, (triangle_count + 2 * segments - 1) / (2 * segments));
    const double max_lat = 85.0 * std::numbers::pi / 180.0;
    mesh.positions.reserve((segments + 1) * (rings + 1));
    for (std::size_t r = 0; r <= rings; ++r) {
        const double lat = -max_lat + 2.0 * max_lat * static_cast<double>(r) / rings;
        for (std::size_t s = 0; s <= segments; ++s) {
            const double lon = 2.0 * std::numbers::pi * static_cast<double>(s) / segments;
            const glm::dvec3 dir(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon),
                                 std::sin(lat));
            const double radius = 1.0 + 0.05 * std::sin(7.0 * lat) * std::sin(5.0 * lon);
            mesh.positions.push_back(glm::vec3(dir * radius));
            mesh.normals.push_back(glm::vec3(dir));
            mesh.uvs.push_back(
                glm::vec2(static_cast<float>(s) / segments, static_cast<float>(r) / rings));
        }
    }
    mesh.triangles.reserve(triangle_count);
    const auto row = static_cast<std::uint32_t>(segments + 1);
    for (std::uint32_t r = 0; r < rings && mesh.triangles.size() < triangle_count; ++r) {
        for (std::uint32_t s = 0; s < segments && mesh.triangles.size() < triangle_count; ++s) {
            const std::uint32_t a = r * row + s, b = a + 1, c = a + row, d = c + 1;
            mesh.triangles.emplace_back(a, b, d);
            if (mesh.triangles.size() < triangle_count) mesh.triangles.emplace_back(a, d, c);
        }
    }
    return mesh;
}

}  // namespace glslppm
