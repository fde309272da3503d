#include "bvh/thread_mtbvh.h"

#include <future>
#include <stdexcept>
#include <string>

namespace glslppm {
namespace {

// Per inner node: its children and, per order, whether the right child goes first (bit
// `order`), so that the six walks read 12 bytes per node instead of 40-byte nodes.
struct Branch {
    std::int32_t left = -1, right = -1;  // -1: a leaf
    std::uint32_t right_first = 0;
};

// One link set: an iterative preorder walk carrying each node's miss link (the node after
// its subtree), so no recursion and no parent pointers are needed.
void thread_order(const std::vector<Branch>& branches, int order, glm::ivec2* links,
                  const CancelFlag* cancel) {
    struct Item {
        std::int32_t node, miss;
    };
    std::vector<Item> stack{{0, -1}};
    for (std::uint32_t step = 0; !stack.empty(); ++step) {
        if ((step & 0xFFFFu) == 0) throw_if_cancelled(cancel);
        const Item item = stack.back();
        stack.pop_back();
        const Branch& branch = branches[item.node];
        if (branch.left < 0) {
            links[item.node] = glm::ivec2(item.miss, item.miss);
            continue;
        }
        std::int32_t first = branch.left, second = branch.right;
        if (branch.right_first >> order & 1) std::swap(first, second);
        links[item.node] = glm::ivec2(first, item.miss);
        stack.push_back({second, item.miss});
        stack.push_back({first, second});  // popped next: the preorder visits it right away
    }
}

}  // namespace

bool right_child_first(const BvhNode& left, const BvhNode& right, int order) {
    const int axis = order / 2;
    const float l = left.box.centroid()[axis];
    const float r = right.box.centroid()[axis];
    return (order & 1) == 0 ? r < l : r > l;
}

ThreadedBvh thread_bvh(const Bvh& bvh, int order_count, bool parallel,
                       const CancelFlag* cancel) {
    if (order_count != kMtbvhOrderCount && order_count != kTbvhOrderCount)
        throw std::invalid_argument("a threaded BVH has 6 (MTBVH) or 1 (TBVH) link orders, not " +
                                    std::to_string(order_count));
    ThreadedBvh threaded;
    threaded.order_count = order_count;
    threaded.node_count = static_cast<std::uint32_t>(bvh.nodes.size());
    resize_polling(threaded.links, static_cast<std::size_t>(order_count) * threaded.node_count,
                   cancel);
    if (threaded.node_count == 0) return threaded;
    std::vector<Branch> branches;
    resize_polling(branches, bvh.nodes.size(), cancel);
    for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
        if ((i & 0xFFFFu) == 0) throw_if_cancelled(cancel);
        const BvhNode& node = bvh.nodes[i];
        if (node.is_leaf()) continue;
        Branch& b = branches[i];
        b.left = node.left;
        b.right = node.right;
        if (order_count == kMtbvhOrderCount)
            for (int order = 0; order < kMtbvhOrderCount; ++order)
                if (right_child_first(bvh.nodes[node.left], bvh.nodes[node.right], order))
                    b.right_first |= 1u << order;
    }
    auto run = [&](int begin, int end) {
        for (int order = begin; order < end; ++order)
            thread_order(
                branches, order,
                threaded.links.data() + static_cast<std::size_t>(order) * threaded.node_count,
                cancel);
    };
    if (parallel && order_count > 1 && threaded.node_count > 4096) {
        auto upper = std::async(std::launch::async, run, order_count / 2, order_count);
        run(0, order_count / 2);
        upper.get();
    } else {
        run(0, order_count);
    }
    return threaded;
}

}  // namespace glslppm
