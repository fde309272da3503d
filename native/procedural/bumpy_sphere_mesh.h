// A deterministic bumpy sphere mesh of any triangle count, for the BVH benchmark and tests
// (the scenes of glslppm-render and the bench are the other generators of this folder).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "scene/scene.h"  // OwnedMesh

namespace glslppm {

// Exactly `triangle_count` triangles tessellating a bumpy unit sphere (latitude-longitude
// grid between +-85 degrees, radius 1 + 0.05 sin(7 theta) sin(5 phi)), with per-vertex
// normals and uvs. Same input, same mesh.
OwnedMesh make_sphere_mesh(std::size_t triangle_count);

}  // namespace glslppm
