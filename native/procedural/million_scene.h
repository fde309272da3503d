// A scalable benchmark scene: a field of bumpy (displaced, tessellated) spheres standing on
// the floor of a closed white room lit by a ceiling area light, about `triangles` triangles
// in all (1k to 4M for the scaling runs; 100k and 1M are the `rays` benchmark's sizes). The
// room matches the Cornell box (x, z in [-1, 1], y in [0, 2]); the camera looks down at it.
// Fixed seed: the same count gives the same scene. Positions only (no shading normals),
// which keeps 4M triangles within a GPU's storage-buffer limits.
#pragma once

#include <cstddef>

#include "scene/scene.h"

namespace glslppm {

struct MillionSceneOptions {
    std::size_t triangles = 1000000;  // target; the result is within a few percent above 1k
    std::uint32_t seed = 1;
};

Scene make_million_scene(const MillionSceneOptions& options = {});

}  // namespace glslppm
