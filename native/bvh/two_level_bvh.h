// A two-level MTBVH for instanced geometry: one bottom MTBVH per distinct mesh, in the
// mesh's own space and shared by every instance of it, and a top MTBVH over the instances'
// world boxes. Traversal stays stackless: a top-level leaf (one instance) moves the ray
// into the instance's space and walks the mesh's tree along its own six orders; when that
// walk ends, traversal resumes at the top leaf's link, the one saved node index.
//
// GPU layout (shaders/common/mtbvh_instances.glsl reads it; packed_bvh.h has the record
// formats of nodes, links, triangles, normals and uvs):
//   nodes, links  the top tree first (nodes [0, top_node_count), links [0, 6 x that)), its
//                 leaves holding (lo.w = instance index, hi.w = 1); then each mesh's tree,
//                 its node indices, link targets and leaf triangle ranges made absolute.
//   triangles, normals, uvs, colors  every mesh's packed triangles, one after another;
//                 material and original triangle ids stay the mesh's own.
//   instances     kInstanceRecordVec4 vec4 per instance:
//                   [0..2] rows of A^-1, w = the translation T (world -> instance:
//                          A^-1 (x - T); subtracting T first keeps the precision of
//                          instances far from the origin for rays that start near them)
//                   [3..5] rows of A, w = T again (instance -> world: A x + T)
//                   [6]    bits of (mesh root node, mesh node count, mesh link base,
//                          material offset)
//                   [7]    (bits of mesh index, sign of det A, 0, 0)
//
// Hit rule (intersect.h) unchanged, applied in instance space: the ray's direction is
// mapped by A^-1 without normalizing, so t is the same ray parameter in both spaces and one
// best t orders hits across instances. Ties go to the smaller (instance, original triangle)
// pair, which is the order of the flattened copy's triangle ids (instance by instance).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <span>
#include <vector>

#include "bvh/intersect.h"
#include "bvh/packed_bvh.h"
#include "bvh/traverse_cpu.h"
#include "scene/mesh.h"

namespace glslppm {

constexpr int kInstanceRecordVec4 = 8;

struct TwoLevelStats {
    std::size_t meshes = 0, instances = 0;
    std::size_t mesh_triangles = 0;       // packed triangles of all meshes once
    std::size_t instanced_triangles = 0;  // what a flattened copy would hold
    std::size_t top_nodes = 0, bottom_nodes = 0;
    double bottom_seconds = 0.0, top_seconds = 0.0;
    std::size_t bytes_total = 0;  // nodes + links + triangles + normals + uvs + colors + instances
};

struct TwoLevelBvh {
    std::uint32_t top_node_count = 0;
    std::vector<glm::vec4> nodes;
    std::vector<glm::ivec2> links;
    std::vector<glm::vec4> triangles, normals, uvs, colors;
    std::vector<glm::vec4> instances;
    // The top tree's children (left, right) per node, (-1, -1) at leaves: what a refit of
    // the top level for moved instances walks (render/motion_pass.cpp).
    std::vector<glm::ivec2> top_children;
    TwoLevelStats stats;
};

// Rewrites an instance record's transform (its vec4s 0-5 and the sign of det A) for a new
// to_world (finite, affine, invertible; the mesh and bases stay).
void write_instance_transform(glm::vec4* record, const glm::mat4& to_world);

// The world box the top level culls an instance by: the corners of the mesh's (padded) root
// box mapped by to_world in double precision, rounded outwards to float and padded by
// kInstanceBoxPadRelative of its magnitude. The pad absorbs the rounding of the ray's move
// into instance space (a few ulps of the world coordinates), so that culling by this box
// never drops an instance whose own tree the moved ray would hit.
constexpr float kInstanceBoxPadRelative = 1.0f / 65536.0f;
Aabb instance_world_box(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& to_world);

// Throws std::invalid_argument for an instance naming a mesh out of range or a transform
// that is not finite, affine and invertible; Cancelled when options.cancel is set. Meshes
// without instances are built all the same (cheap) so that mesh indices stay stable; empty
// meshes are allowed and never hit. normals / uvs / colors are uploaded when any mesh has
// them (zeros for the others' normals and uvs, white for their colours).
TwoLevelBvh build_two_level_bvh(std::span<const ValidMesh> meshes,
                                std::span<const Instance> instances,
                                const BvhBuildOptions& options);
// The same from meshes already built as MTBVHs (packed_bvh.h, six orders).
TwoLevelBvh build_two_level_bvh(std::span<const PackedBvh> bottoms,
                                std::span<const Instance> instances,
                                const BvhBuildOptions& options);

// Traversal (defined in traverse_cpu.cpp: one walk serves both levels and one-level trees).
//
// The instance-space ray: A^-1 (origin - T) and A^-1 dir, tmin and tmax unchanged; record is
// the instance's first vec4.
Ray ray_to_instance(const glm::vec4* record, const Ray& world);
Ray ray_to_instance(const TwoLevelBvh& bvh, std::int32_t instance, const Ray& world);

InstanceHit closest_hit(const TwoLevelBvh& bvh, const Ray& ray, TraversalCounts* counts = nullptr);
bool any_hit(const TwoLevelBvh& bvh, const Ray& ray, TraversalCounts* counts = nullptr);

// Every kept triangle of every instance, instance by instance in id order, each with the
// ray moved by ray_to_instance: the reference for the two-level traversal.
InstanceHit closest_hit_brute_force(const TwoLevelBvh& bvh, std::span<const ValidMesh> meshes,
                                    std::span<const Instance> instances, const Ray& ray);
bool any_hit_brute_force(const TwoLevelBvh& bvh, std::span<const ValidMesh> meshes,
                         std::span<const Instance> instances, const Ray& ray);

}  // namespace glslppm
