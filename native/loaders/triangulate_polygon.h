// Splitting an OBJ face (a planar polygon, possibly concave) into triangles that keep its
// winding.
#pragma once

#include <glm/glm.hpp>
#include <span>
#include <vector>

namespace glslppm {

// Triangles as indices into `corners` (n >= 3 corners, in the face's order). Ear clipping
// in the plane of the polygon's Newell normal; a polygon left without an ear (one that
// crosses itself) is finished as a fan, and a polygon without area is a fan too.
std::vector<glm::uvec3> triangulate_polygon(std::span<const glm::vec3> corners);

}  // namespace glslppm
