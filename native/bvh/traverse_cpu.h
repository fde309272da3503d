// Stackless MTBVH / TBVH traversal on the CPU (Hachisuka 2015, Figure 3), written to mirror
// shaders/common/mtbvh.glsl line by line, and the brute-force reference it is tested
// against. All four return the same answer bit for bit: see intersect.h. One walk serves the
// one-level tree here and both levels of a two-level tree (two_level_bvh.h declares those).
#pragma once

#include <cstdint>

#include "bvh/intersect.h"
#include "bvh/packed_bvh.h"
#include "scene/mesh.h"

namespace glslppm {

// Work done by one traversal, for benchmarks (MTBVH against TBVH).
struct TraversalCounts {
    std::uint64_t nodes_visited = 0;     // slab tests
    std::uint64_t triangles_tested = 0;  // triangle tests
};

// Closest hit in (ray.tmin, ray.tmax): smallest t, ties to the smaller original triangle id.
// Hit::triangle is the ORIGINAL triangle id, -1 for a miss.
Hit closest_hit(const PackedBvh& bvh, const Ray& ray, TraversalCounts* counts = nullptr);
// True when any triangle is hit in (ray.tmin, ray.tmax); stops at the first one found.
bool any_hit(const PackedBvh& bvh, const Ray& ray, TraversalCounts* counts = nullptr);

// Every kept triangle of the mesh, in id order: the reference.
Hit closest_hit_brute_force(const ValidMesh& mesh, const Ray& ray);
bool any_hit_brute_force(const ValidMesh& mesh, const Ray& ray);

}  // namespace glslppm
