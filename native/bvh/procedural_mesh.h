// Deterministic procedural meshes for the BVH benchmark and tests.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "scene/mesh.h"

namespace glslppm {

// A mesh that owns its arrays; view() lends them as a MeshView (valid while this lives).
struct OwnedMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    std::vector<glm::vec3> normals;           // per vertex, or empty
    std::vector<glm::vec2> uvs;               // per vertex, or empty
    std::vector<std::uint32_t> material_ids;  // per triangle, or empty
    MeshView view() const { return MeshView{positions, triangles, normals, uvs, material_ids}; }
    // Multiplies every position by `factor` (normals and uvs unchanged).
    void scale(float factor);
};

// Exactly `triangle_count` triangles tessellating a bumpy unit sphere (latitude-longitude
// grid between +-85 degrees, radius 1 + 0.05 sin(7 theta) sin(5 phi)), with per-vertex
// normals and uvs. Same input, same mesh.
OwnedMesh make_sphere_mesh(std::size_t triangle_count);

}  // namespace glslppm
