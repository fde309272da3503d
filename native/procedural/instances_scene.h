// An instancing benchmark scene: the room of million_scene.h (a closed white box lit by a
// ceiling area light) with `count` instances of one bumpy sphere of about `triangles`
// triangles standing on its floor, on a jittered grid, each turned about the vertical, scaled
// (non-uniformly) and every other one mirrored. count 1 is the mesh placed once: the
// baseline the instanced scenes are measured against.
#pragma once

#include <cstddef>
#include <cstdint>

#include "scene/scene.h"

namespace glslppm {

Scene make_instances_scene(std::size_t count, std::size_t triangles, std::uint32_t seed = 1);

}  // namespace glslppm
