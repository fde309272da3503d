// Threading a BVH for stackless traversal (Simonsen and Thrane 2005; Hachisuka 2015,
// "Multiple-Threaded BVH"). A threaded BVH replaces child pointers by two links per node:
//   hit  = the next node of a depth-first preorder (for a leaf, the same as miss),
//   miss = the node that follows the node's whole subtree in that preorder (-1 = done).
// The MTBVH stores six such link sets, one per ray direction class +x,-x,+y,-y,+z,-z
// (order = 2*axis + negative), each from a preorder that visits the child nearer along
// that direction first; select_order() in intersect.h picks the set for a ray. The TBVH
// baseline stores one set, children in build order (left first). The root is node 0 in
// every order.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "bvh/build_sah_bvh.h"
#include "scene/cancel.h"

namespace glslppm {

constexpr int kMtbvhOrderCount = 6;
constexpr int kTbvhOrderCount = 1;

struct ThreadedBvh {
    int order_count = 0;
    std::uint32_t node_count = 0;
    std::vector<glm::ivec2> links;  // links[order * node_count + node] = (hit, miss)
};

// True when, for link order `order` (0..5), the right child is visited before the left:
// for +axis the child whose box centroid is smaller along the axis goes first, for -axis
// the larger one; ties keep the build order.
bool right_child_first(const BvhNode& left, const BvhNode& right, int order);

// order_count 6: MTBVH; 1: TBVH. Throws std::invalid_argument for any other count, Cancelled
// when `cancel` is set meanwhile.
ThreadedBvh thread_bvh(const Bvh& bvh, int order_count, bool parallel = true,
                       const CancelFlag* cancel = nullptr);
inline ThreadedBvh thread_mtbvh(const Bvh& bvh) { return thread_bvh(bvh, kMtbvhOrderCount); }
inline ThreadedBvh thread_tbvh(const Bvh& bvh) { return thread_bvh(bvh, kTbvhOrderCount); }

}  // namespace glslppm
