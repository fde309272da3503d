#include "bvh/build_sah_bvh.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <stdexcept>
#include <thread>

namespace glslppm {
namespace {

// SAH constants: cost of visiting a node relative to testing one triangle. Equal costs suit
// a stackless GPU traversal, where a node costs one slab test plus one dependent fetch.
constexpr float kTraversalCost = 1.0f;
constexpr float kIntersectionCost = 1.0f;
// Subtrees smaller than this are not worth a thread of their own.
constexpr std::uint32_t kParallelMinTriangles = 8192;

// A triangle during the build: its bounds and original id, 32 bytes.
struct PrimRef {
    glm::vec3 lo;
    std::uint32_t id;
    glm::vec3 hi;
    float unused;
};

// Twice the centroid: binning only needs positions relative to the centroid bounds, which
// are kept in the same doubled space, so the halving is skipped.
inline glm::vec3 centroid2(const PrimRef& r) { return r.lo + r.hi; }

struct Range {
    Aabb box;        // bounds of the triangles
    Aabb centroids;  // bounds of centroid2() of the triangles
    std::uint32_t begin = 0, end = 0;
    int depth = 0;
    std::uint32_t size() const { return end - begin; }
};

struct Bin {
    Aabb box;
    std::uint32_t count = 0;
};

// Maps centroids to bins along one axis; the same function is used for binning and for
// partitioning, so both always agree.
struct BinMapping {
    float origin = 0.0f, scale = 0.0f;
    int bins = 0;
    int operator()(const glm::vec3& c2, int axis) const {
        // Clamped in float before the conversion: centroid sums of coordinates near
        // FLT_MAX overflow to inf or NaN, and converting those to int is undefined
        // (found by fuzz/scene_fuzz.cpp, tests/fuzz/scene/crash-bvh-bin-nan).
        const float x = (c2[axis] - origin) * scale;
        if (!(x >= 0.0f)) return 0;
        return x < static_cast<float>(bins) ? static_cast<int>(x) : bins - 1;
    }
};

struct Split {
    int axis = -1;
    int bin = 0;  // left side = bins [0, bin)
    float cost = 0.0f;
    BinMapping mapping;
    Range left, right;
};

class Builder {
  public:
    Builder(std::vector<PrimRef>& refs, const BvhBuildOptions& options)
        : refs_(refs), options_(options) {
        if (options.parallel) {
            // Spawn down to depth d so that 2^d tasks cover the cores twice over.
            const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
            while ((1u << spawn_depth_) < 2 * cores && spawn_depth_ < 8) ++spawn_depth_;
            if (cores == 1) spawn_depth_ = 0;
        }
    }

    // Appends the subtree of `range` to `out` in preorder (left first); returns its depth.
    int build(const Range& range, std::vector<BvhNode>& out) {
        throw_if_cancelled(options_.cancel);
        if (range.depth >= spawn_depth_ || range.size() < kParallelMinTriangles)
            return build_serial(range, out);
        Split split;
        const std::size_t index = out.size();
        out.push_back(BvhNode{range.box});
        if (!choose_split(range, split)) {
            make_leaf(range, out[index]);
            return range.depth;
        }
        // Right subtree on another thread into its own array, left subtree here; then the
        // right array is appended with its indices shifted, which keeps the preorder.
        std::vector<BvhNode> right_nodes;
        auto right_task = std::async(std::launch::async, [&] {
            Builder worker(*this);  // its own scratch bins
            return worker.build(split.right, right_nodes);
        });
        int depth = build(split.left, out);
        depth = std::max(depth, right_task.get());
        const auto offset = static_cast<std::int32_t>(out.size());
        out[index].left = static_cast<std::int32_t>(index + 1);
        out[index].right = offset;
        for (std::size_t k = 0; k < right_nodes.size(); ++k) {
            if ((k & 0xFFFFu) == 0) throw_if_cancelled(options_.cancel);
            BvhNode node = right_nodes[k];
            if (!node.is_leaf()) {
                node.left += offset;
                node.right += offset;
            }
            out.push_back(node);
        }
        return depth;
    }

  private:
    // Iterative (explicit stack), so that unbalanced trees cannot overflow the call stack.
    int build_serial(const Range& root, std::vector<BvhNode>& out) {
        struct Item {
            Range range;
            std::int64_t parent;  // node whose `right` is this item, or -1
        };
        std::vector<Item> stack{{root, -1}};
        int max_depth = 0;
        Split split;
        while (!stack.empty()) {
            throw_if_cancelled(options_.cancel);
            const Item item = stack.back();
            stack.pop_back();
            const auto index = static_cast<std::int32_t>(out.size());
            if (item.parent >= 0) out[item.parent].right = index;
            out.push_back(BvhNode{item.range.box});
            max_depth = std::max(max_depth, item.range.depth);
            if (!choose_split(item.range, split)) {
                make_leaf(item.range, out.back());
                continue;
            }
            out.back().left = index + 1;  // popped next: preorder, left first
            stack.push_back({split.right, index});
            stack.push_back({split.left, -1});
        }
        return max_depth;
    }

    void make_leaf(const Range& range, BvhNode& node) const {
        node.first = range.begin;
        node.count = range.size();
        node.left = node.right = -1;
    }

    Range bounds_of(std::uint32_t begin, std::uint32_t end, int depth) const {
        Range r;
        r.begin = begin;
        r.end = end;
        r.depth = depth;
        for (std::uint32_t i = begin; i < end; ++i) {
            r.box.grow(Aabb{refs_[i].lo, refs_[i].hi});
            r.centroids.grow(centroid2(refs_[i]));
        }
        return r;
    }

    // Picks the best binned SAH split and partitions refs_ accordingly. Returns false when
    // the range should become a leaf.
    bool choose_split(const Range& range, Split& split) {
        const std::uint32_t n = range.size();
        const bool must_split = n > static_cast<std::uint32_t>(options_.leaf_size);
        if (n <= 1) return false;
        // Small nodes, which are most nodes, need no more bins than triangles: the bin
        // sweep would otherwise cost more than the binning itself.
        const int nb = std::min(options_.bins, std::max(4, static_cast<int>(n)));

        bins_.assign(3 * static_cast<std::size_t>(nb), Bin{});
        BinMapping mapping[3];
        const glm::vec3 c_extent = range.centroids.extent();
        for (int a = 0; a < 3; ++a) {
            mapping[a].origin = range.centroids.lo[a];
            mapping[a].bins = nb;
            // Slightly less than nb/extent so the largest centroid lands in the last bin.
            const float scale = nb * (1.0f - 1e-6f) / c_extent[a];
            mapping[a].scale = c_extent[a] > 0.0f && std::isfinite(scale) ? scale : 0.0f;
        }
        for (std::uint32_t i = range.begin; i < range.end; ++i) {
            const PrimRef& r = refs_[i];
            const glm::vec3 c2 = centroid2(r);
            for (int a = 0; a < 3; ++a) {
                Bin& bin = bins_[a * nb + mapping[a](c2, a)];
                bin.box.lo = glm::min(bin.box.lo, r.lo);
                bin.box.hi = glm::max(bin.box.hi, r.hi);
                ++bin.count;
            }
        }

        // SAH: cost = C_trav + C_isect * (A_L N_L + A_R N_R) / A (MacDonald and Booth 1990).
        const float area = std::max(range.box.half_area(), std::numeric_limits<float>::min());
        float best_cost = std::numeric_limits<float>::infinity();
        int best_axis = -1, best_bin = 0;
        right_area_.resize(nb);
        for (int a = 0; a < 3; ++a) {
            if (mapping[a].scale == 0.0f) continue;
            const Bin* bins = &bins_[a * nb];
            Aabb acc;
            std::uint32_t count = 0;
            for (int b = nb - 1; b >= 1; --b) {
                acc.grow(bins[b].box);
                count += bins[b].count;
                right_area_[b] = acc.half_area() * static_cast<float>(count);
            }
            acc = Aabb{};
            count = 0;
            for (int b = 1; b < nb; ++b) {
                acc.grow(bins[b - 1].box);
                count += bins[b - 1].count;
                if (count == 0 || count == n) continue;
                const float cost = kTraversalCost + kIntersectionCost *
                                                        (acc.half_area() * count + right_area_[b]) /
                                                        area;
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = a;
                    best_bin = b;
                }
            }
        }

        if (!must_split && (best_axis < 0 || kIntersectionCost * n <= best_cost)) return false;

        std::uint32_t mid;
        if (best_axis < 0) {
            // All centroids coincide (duplicated triangles): split the list in half.
            mid = range.begin + n / 2;
            split.left = bounds_of(range.begin, mid, range.depth + 1);
            split.right = bounds_of(mid, range.end, range.depth + 1);
        } else {
            const BinMapping& m = mapping[best_axis];
            const int axis = best_axis, bin = best_bin;
            auto goes_left = [&](const PrimRef& r) { return m(centroid2(r), axis) < bin; };
            // Hoare partition that also gathers each side's centroid bounds on the way.
            Aabb left_centroids, right_centroids;
            PrimRef* l = refs_.data() + range.begin;
            PrimRef* r = refs_.data() + range.end;
            for (;;) {
                while (l < r && goes_left(*l)) left_centroids.grow(centroid2(*l++));
                while (l < r && !goes_left(*(r - 1))) right_centroids.grow(centroid2(*--r));
                if (l >= r) break;
                std::swap(*l, *--r);
                left_centroids.grow(centroid2(*l++));
                right_centroids.grow(centroid2(*r));
            }
            mid = static_cast<std::uint32_t>(l - refs_.data());
            // The children's boxes are unions of their bins' boxes: no extra pass.
            const Bin* bins = &bins_[axis * nb];
            split.left = Range{{}, left_centroids, range.begin, mid, range.depth + 1};
            split.right = Range{{}, right_centroids, mid, range.end, range.depth + 1};
            for (int b = 0; b < nb; ++b) (b < bin ? split.left : split.right).box.grow(bins[b].box);
        }
        split.axis = best_axis;
        split.bin = best_bin;
        split.cost = best_cost;
        return true;
    }

    std::vector<PrimRef>& refs_;
    const BvhBuildOptions& options_;
    int spawn_depth_ = 0;
    // Scratch, per thread: each spawned task gets a copy of the builder.
    std::vector<Bin> bins_;
    std::vector<float> right_area_;

  public:
    Builder(const Builder& other)
        : refs_(other.refs_), options_(other.options_), spawn_depth_(other.spawn_depth_) {}
};

}  // namespace

namespace {

void check_options(const BvhBuildOptions& options) {
    if (options.leaf_size < 1)
        throw std::invalid_argument("BVH leaf size must be at least 1, got " +
                                    std::to_string(options.leaf_size));
    if (options.bins < 2 || options.bins > 256)
        throw std::invalid_argument("BVH bins must be in 2..256, got " +
                                    std::to_string(options.bins));
}

// Fills refs[i] from box_of(i) for i < n (in two halves on two threads when parallel), then
// builds: the part both overloads share.
template <class BoxOf>
Bvh build_over(std::uint32_t n, BoxOf box_of, const BvhBuildOptions& options) {
    Bvh bvh;
    if (n == 0) return bvh;
    std::vector<PrimRef> refs;
    resize_polling(refs, n, options.cancel);
    auto fill = [&](std::uint32_t begin, std::uint32_t end) {
        Range r;
        r.begin = begin;
        r.end = end;
        for (std::uint32_t i = begin; i < end; ++i) {
            if ((i & 0xFFFFu) == 0) throw_if_cancelled(options.cancel);
            std::uint32_t id = 0;
            const Aabb b = box_of(i, id);
            refs[i] = PrimRef{b.lo, id, b.hi, 0.0f};
            r.box.grow(b);
            r.centroids.grow(centroid2(refs[i]));
        }
        return r;
    };
    Range root;
    if (options.parallel && n >= kParallelMinTriangles) {
        auto upper = std::async(std::launch::async, fill, n / 2, n);
        root = fill(0, n / 2);
        const Range r = upper.get();
        root.box.grow(r.box);
        root.centroids.grow(r.centroids);
    } else {
        root = fill(0, n);
    }
    root.begin = 0;
    root.end = n;
    root.depth = 0;

    Builder builder(refs, options);
    bvh.nodes.reserve(2 * static_cast<std::size_t>(n));
    bvh.max_depth = builder.build(root, bvh.nodes);
    resize_polling(bvh.triangles, n, options.cancel);
    for (std::uint32_t i = 0; i < n; ++i) bvh.triangles[i] = refs[i].id;
    throw_if_cancelled(options.cancel);
    for (const BvhNode& node : bvh.nodes) bvh.leaf_count += node.is_leaf() ? 1 : 0;
    return bvh;
}

}  // namespace

Bvh build_sah_bvh(const ValidMesh& mesh, const BvhBuildOptions& options) {
    check_options(options);
    const auto n = static_cast<std::uint32_t>(mesh.kept.size());
    return build_over(
        n,
        [&](std::uint32_t i, std::uint32_t& id) {
            id = mesh.kept[i];
            const glm::uvec3 tri = mesh.view.triangles[id];
            return Aabb::of_triangle(mesh.view.positions[tri.x], mesh.view.positions[tri.y],
                                     mesh.view.positions[tri.z]);
        },
        options);
}

Bvh build_sah_bvh(std::span<const Aabb> boxes, const BvhBuildOptions& options) {
    check_options(options);
    return build_over(
        static_cast<std::uint32_t>(boxes.size()),
        [&](std::uint32_t i, std::uint32_t& id) {
            id = i;
            return boxes[i];
        },
        options);
}

}  // namespace glslppm
