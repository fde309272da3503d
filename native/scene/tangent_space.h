// Tangent frames for normal maps: a vertex's tangent is (dp/du, sign), the bitangent
// sign * cross(n, t) runs along dp/dv, as MikkTSpace (Blender's mesh.calc_tangents(), glTF's
// TANGENT) defines them. The GPU carries each vertex's tangent in the w word of its packed
// normal (shaders/common/surface.glsl decodes it), so a normal-mapped scene binds no buffer
// more than one with smooth normals.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace glslppm {

// A unit tangent and its bitangent sign in 32 bits: the octahedral encoding of the direction
// (Meyer et al. 2010), 15 bits per coordinate (about 1e-4 rad), and the sign in bit 31.
std::uint32_t pack_tangent(const glm::vec4& tangent);
glm::vec4 unpack_tangent(std::uint32_t bits);  // the CPU mirror of unpack_tangent in GLSL

// Per-vertex tangents from the uvs for a mesh that has none (a glTF file without TANGENT):
// each triangle's dp/du and dp/dv (Lengyel's method), summed over the triangles sharing a
// vertex weighted by their area, made orthogonal to the vertex normal (the face normal where
// there are no normals). Where uvs are split this equals MikkTSpace; across smooth shared
// vertices it averages as MikkTSpace does, without MikkTSpace's angle weights. A triangle
// whose uvs span no area gets any tangent orthogonal to its normal.
std::vector<glm::vec4> generate_tangents(std::span<const glm::vec3> positions,
                                         std::span<const glm::uvec3> triangles,
                                         std::span<const glm::vec3> normals,
                                         std::span<const glm::vec2> uvs);

}  // namespace glslppm
