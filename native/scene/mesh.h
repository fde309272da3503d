// Triangle meshes as they arrive (from numpy, from loaders, from procedural scenes) and
// their validation. A MeshView never owns its arrays: the caller keeps them alive (the
// Python module keeps the numpy arrays referenced), so no copy is made where dtype and
// layout already fit.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/cancel.h"

namespace glslppm {

// A bad input array: names the array and the first bad element, so that a user can find it.
class SceneError : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

struct MeshView {
    std::span<const glm::vec3> positions;     // (V,3) float32
    std::span<const glm::uvec3> triangles;    // (T,3) uint32 vertex indices
    std::span<const glm::vec3> normals;       // (V,3) or empty: geometric normals are used
    std::span<const glm::vec2> uvs;           // (V,2) or empty: no texture coordinates
    std::span<const std::uint32_t> material_ids;  // (T,) or empty: material 0 everywhere
    // (V,4) or empty: tangent dp/du in xyz, bitangent sign in w (scene/tangent_space.h);
    // read only by normal-mapped materials, generated from the uvs where absent.
    std::span<const glm::vec4> tangents;
    // (V,3) or empty: linear RGB per vertex (Blender's Color Attribute, glTF's COLOR_0),
    // multiplied into the colour of materials that ask for it (Material::vertex_color).
    std::span<const glm::vec3> colors;
};

struct MeshStats {
    std::size_t input_triangles = 0;
    std::size_t degenerate_dropped = 0;  // zero-area triangles, dropped (not an error)
};

// A mesh that passed validation: every index in range, every coordinate finite, and the
// list of triangles that have area (`kept`, ascending ids into view.triangles).
struct ValidMesh {
    MeshView view;
    std::vector<std::uint32_t> kept;
    MeshStats stats;
};

// One placement of a mesh (instancing; bvh/two_level_bvh.h): world = to_world * (x, 1),
// to_world affine (bottom row 0 0 0 1) and invertible; its material ids are the mesh's plus
// material_offset.
struct Instance {
    glm::mat4 to_world{1.0f};
    std::uint32_t mesh = 0;
    std::uint32_t material_offset = 0;
};

// Throws SceneError naming the array and the first bad index: index out of range, NaN or
// Inf coordinates or normals or uvs, negative or non-finite colours, material id >= material_count, arrays whose lengths
// disagree. Zero-area triangles are dropped and counted. Polls `cancel` (Cancelled) every
// 65,536 triangles.
ValidMesh validate_mesh(const MeshView& mesh, std::uint32_t material_count,
                        const CancelFlag* cancel = nullptr);

// True when the triangle spans no area relative to its own edges (collinear or coincident
// vertices); such a triangle can never be hit robustly and is dropped.
bool is_degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

}  // namespace glslppm
