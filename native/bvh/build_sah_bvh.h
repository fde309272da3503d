// Binned SAH BVH construction (Wald 2007, "On fast construction of SAH-based bounding
// volume hierarchies"): primitives are binned by centroid along each axis and the split
// between bins with the lowest surface area heuristic cost is taken. The paper we implement
// (Hachisuka 2015) uses an exact sweep; binning gives trees of nearly the same quality in
// a fraction of the time.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "bvh/aabb.h"
#include "scene/cancel.h"
#include "scene/mesh.h"

namespace glslppm {

struct BvhBuildOptions {
    int leaf_size = 4;     // max triangles per leaf (>= 1)
    int bins = 16;         // SAH bins per axis (2..256); a node of n < bins triangles uses
                           // max(n, 4)
    bool parallel = true;  // build the two subtrees of the top levels on separate threads
    // Polled between nodes and every few thousand triangles: when set, the build throws
    // Cancelled (the caller keeps the flag alive until the build returns).
    const CancelFlag* cancel = nullptr;
};

// One node. Nodes are stored in depth-first preorder, left child first: node 0 is the root
// and an inner node's left child is the next node.
struct BvhNode {
    Aabb box;                // exact bounds of the node's triangles (unpadded)
    std::int32_t left = -1;  // children; -1 for a leaf
    std::int32_t right = -1;
    std::uint32_t first = 0;  // leaf: range [first, first + count) of Bvh::triangles
    std::uint32_t count = 0;  // 0 for an inner node
    bool is_leaf() const { return count > 0; }
};

struct Bvh {
    std::vector<BvhNode> nodes;
    std::vector<std::uint32_t> triangles;  // original triangle ids, in leaf order
    int max_depth = 0;                     // root alone = depth 0
    std::size_t leaf_count = 0;
};

// Builds over the kept (non-degenerate) triangles of `mesh`. Deterministic: the same input
// gives the same tree whether or not it is built in parallel. An empty mesh gives no nodes.
// Throws std::invalid_argument for leaf_size < 1 or bins outside 2..256, Cancelled when
// options.cancel is set meanwhile.
Bvh build_sah_bvh(const ValidMesh& mesh, const BvhBuildOptions& options);
// The same over arbitrary boxes (the top level of a two-level BVH: one box per instance);
// Bvh::triangles then holds box indices.
Bvh build_sah_bvh(std::span<const Aabb> boxes, const BvhBuildOptions& options);

}  // namespace glslppm
