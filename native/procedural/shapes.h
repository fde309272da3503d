// Triangle shapes for procedural scenes: quads, boxes and tessellated spheres.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace glslppm {

struct Shape {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;  // per vertex, outward (or inward when flipped)
    std::vector<glm::uvec3> triangles;
};

// Quad a, b, c, d counter-clockwise seen from the side its normal points to.
Shape make_quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d);

// Latitude-longitude sphere; `inward` flips the winding and normals (the inside of a
// closed room).
Shape make_sphere(glm::vec3 center, float radius, int rings, int segments, bool inward = false);

// Appends a shape (positions, normals, triangles) to a mesh, all with one material.
void append_shape(OwnedMesh& mesh, const Shape& shape, std::uint32_t material);

}  // namespace glslppm
