// The GPU layout of a threaded BVH: flat arrays of vec4 / ivec2 records that upload as
// std430 shader storage buffers unchanged (shaders/common/mtbvh.glsl reads them).
//
//   nodes      2 vec4 per node, node 0 = root, in build preorder:
//                [2n]   = (lo.xyz, intBitsToFloat(first packed triangle))
//                [2n+1] = (hi.xyz, intBitsToFloat(triangle count; 0 = inner node))
//              Leaf boxes are padded outwards relative to their magnitude (pad_box in
//              aabb.h), inner boxes are the unions of their children's.
//   links      ivec2 per node per order: links[order * node_count + node] = (hit, miss),
//              -1 = end of traversal. order = 2*axis + (dir[axis] < 0) for the MTBVH
//              (6 orders, see thread_mtbvh.h), always 0 for the TBVH (1 order).
//   triangles  3 vec4 per packed triangle, in leaf order:
//                (v0.xyz, intBitsToFloat(material id)),
//                (v1.xyz, intBitsToFloat(original triangle id)),
//                (v2.xyz, 0)
//   normals    empty unless the mesh has normals or tangents; 3 vec4 per packed triangle:
//                (n0.xyz, t0), (n1.xyz, t1), (n2.xyz, t2), t the vertex's tangent packed
//                by pack_tangent (scene/tangent_space.h) as float bits, or 0 without tangents
//   uvs        empty unless the mesh has uvs; 2 vec4 per packed triangle:
//                (u0, v0, u1, v1), (u2, v2, 0, 0)
//   colors     empty unless the mesh has vertex colours; 3 vec4 per packed triangle:
//                (c0.rgb, 0), (c1.rgb, 0), (c2.rgb, 0), linear
//
// Storage per triangle is reported in stats (Hachisuka 2015 counts about 9 vec4 per
// triangle for a TBVH and 14 for the MTBVH with its six link sets).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "bvh/build_sah_bvh.h"
#include "bvh/thread_mtbvh.h"
#include "scene/mesh.h"

namespace glslppm {

struct BvhStats {
    std::size_t triangles = 0;           // packed (kept) triangles
    std::size_t degenerate_dropped = 0;  // zero-area triangles left out by validate_mesh
    std::size_t nodes = 0, leaves = 0;
    int max_depth = 0;
    double build_seconds = 0.0, thread_seconds = 0.0, pack_seconds = 0.0;
    std::size_t bytes_total = 0;      // nodes + links + triangles + normals + uvs + colors
    double bytes_per_triangle = 0.0;  // bytes_total / triangles (0 when empty)
    double total_seconds() const { return build_seconds + thread_seconds + pack_seconds; }
    double vec4_per_triangle() const { return bytes_per_triangle / 16.0; }
};

struct PackedBvh {
    int order_count = 0;  // 6 = MTBVH, 1 = TBVH
    std::uint32_t node_count = 0, triangle_count = 0;
    std::vector<glm::vec4> nodes;
    std::vector<glm::ivec2> links;
    std::vector<glm::vec4> triangles;
    std::vector<glm::vec4> normals;
    std::vector<glm::vec4> uvs;
    std::vector<glm::vec4> colors;
    BvhStats stats;
};

// Packs an already built and threaded BVH (for building the MTBVH and the TBVH of one tree).
PackedBvh pack_bvh(const ValidMesh& mesh, const Bvh& bvh, ThreadedBvh threaded,
                   bool parallel = true, const CancelFlag* cancel = nullptr);

// Builds (binned SAH), threads (order_count 6 or 1) and packs, with timings in stats; all
// three stages poll options.cancel (Cancelled).
PackedBvh build_packed_bvh(const ValidMesh& mesh, const BvhBuildOptions& options, int order_count);

// Each node's parent (-1 for the root), read from the preorder layout: a node's parent is
// the node before it if that one is inner, else the innermost inner node still waiting for
// its right child. (A refit sweeps the nodes backwards, growing each parent by its child.)
std::vector<std::int32_t> node_parents(const PackedBvh& bvh);

}  // namespace glslppm
