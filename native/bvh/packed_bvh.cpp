#include "bvh/packed_bvh.h"

#include <bit>
#include <chrono>
#include <future>
#include <stdexcept>
#include <utility>

#include "scene/tangent_space.h"

namespace glslppm {
namespace {

float int_bits(std::int32_t i) { return std::bit_cast<float>(i); }

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

PackedBvh pack_bvh(const ValidMesh& mesh, const Bvh& bvh, ThreadedBvh threaded, bool parallel,
                   const CancelFlag* cancel) {
    if (threaded.node_count != bvh.nodes.size())
        throw std::invalid_argument("pack_bvh: the links were threaded from another BVH");
    PackedBvh packed;
    packed.order_count = threaded.order_count;
    packed.node_count = threaded.node_count;
    packed.triangle_count = static_cast<std::uint32_t>(bvh.triangles.size());
    packed.links = std::move(threaded.links);

    // Leaves get padded boxes; inner boxes are the unions of their children's, computed in
    // reverse preorder (children come after their parent), so containment stays exact.
    std::vector<Aabb> boxes;
    resize_polling(boxes, bvh.nodes.size(), cancel);
    for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
        if ((i & 0xFFFFu) == 0) throw_if_cancelled(cancel);
        const BvhNode& node = bvh.nodes[i];
        if (node.is_leaf()) {
            boxes[i] = pad_box(node.box);
        } else {
            boxes[i] = boxes[node.left];
            boxes[i].grow(boxes[node.right]);
        }
    }
    resize_polling(packed.nodes, 2 * bvh.nodes.size(), cancel);
    for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
        if ((i & 0xFFFFu) == 0) throw_if_cancelled(cancel);
        const BvhNode& node = bvh.nodes[i];
        packed.nodes[2 * i] =
            glm::vec4(boxes[i].lo, int_bits(static_cast<std::int32_t>(node.first)));
        packed.nodes[2 * i + 1] =
            glm::vec4(boxes[i].hi, int_bits(static_cast<std::int32_t>(node.count)));
    }

    const MeshView& view = mesh.view;
    const std::size_t n = packed.triangle_count;
    resize_polling(packed.triangles, 3 * n, cancel);
    // Tangents ride in the normals' w (scene/tangent_space.h); a mesh with tangents but no
    // normals packs its faces' normals.
    const bool tangents = !view.tangents.empty();
    if (!view.normals.empty() || tangents) resize_polling(packed.normals, 3 * n, cancel);
    if (!view.uvs.empty()) resize_polling(packed.uvs, 2 * n, cancel);
    if (!view.colors.empty()) resize_polling(packed.colors, 3 * n, cancel);
    auto fill = [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            if ((i & 0xFFFFu) == 0) throw_if_cancelled(cancel);
            const std::uint32_t id = bvh.triangles[i];
            const glm::uvec3 tri = view.triangles[id];
            const std::uint32_t material = view.material_ids.empty() ? 0 : view.material_ids[id];
            packed.triangles[3 * i] =
                glm::vec4(view.positions[tri.x], int_bits(static_cast<std::int32_t>(material)));
            packed.triangles[3 * i + 1] =
                glm::vec4(view.positions[tri.y], int_bits(static_cast<std::int32_t>(id)));
            packed.triangles[3 * i + 2] = glm::vec4(view.positions[tri.z], 0.0f);
            if (!view.normals.empty() || tangents) {
                const glm::vec3 face =
                    view.normals.empty()
                        ? glm::normalize(glm::cross(view.positions[tri.y] - view.positions[tri.x],
                                                    view.positions[tri.z] - view.positions[tri.x]))
                        : glm::vec3(0.0f);
                for (int k = 0; k < 3; ++k) {
                    const float w =
                        tangents ? std::bit_cast<float>(pack_tangent(view.tangents[tri[k]])) : 0.0f;
                    packed.normals[3 * i + k] =
                        glm::vec4(view.normals.empty() ? face : view.normals[tri[k]], w);
                }
            }
            if (!view.uvs.empty()) {
                packed.uvs[2 * i] = glm::vec4(view.uvs[tri.x], view.uvs[tri.y]);
                packed.uvs[2 * i + 1] = glm::vec4(view.uvs[tri.z], 0.0f, 0.0f);
            }
            if (!view.colors.empty())
                for (int k = 0; k < 3; ++k)
                    packed.colors[3 * i + k] = glm::vec4(view.colors[tri[k]], 0.0f);
        }
    };
    if (parallel && n >= 65536) {
        auto upper = std::async(std::launch::async, fill, n / 2, n);
        fill(0, n / 2);
        upper.get();
    } else {
        fill(0, n);
    }

    BvhStats& s = packed.stats;
    s.triangles = n;
    s.degenerate_dropped = mesh.stats.degenerate_dropped;
    s.nodes = bvh.nodes.size();
    s.leaves = bvh.leaf_count;
    s.max_depth = bvh.max_depth;
    s.bytes_total =
        packed.nodes.size() * sizeof(glm::vec4) + packed.links.size() * sizeof(glm::ivec2) +
        packed.triangles.size() * sizeof(glm::vec4) + packed.normals.size() * sizeof(glm::vec4) +
        (packed.uvs.size() + packed.colors.size()) * sizeof(glm::vec4);
    s.bytes_per_triangle = n == 0 ? 0.0 : static_cast<double>(s.bytes_total) / n;
    return packed;
}

PackedBvh build_packed_bvh(const ValidMesh& mesh, const BvhBuildOptions& options, int order_count) {
    auto start = std::chrono::steady_clock::now();
    const Bvh bvh = build_sah_bvh(mesh, options);
    const double build_seconds = seconds_since(start);
    throw_if_cancelled(options.cancel);
    start = std::chrono::steady_clock::now();
    ThreadedBvh threaded = thread_bvh(bvh, order_count, options.parallel, options.cancel);
    const double thread_seconds = seconds_since(start);
    start = std::chrono::steady_clock::now();
    PackedBvh packed = pack_bvh(mesh, bvh, std::move(threaded), options.parallel, options.cancel);
    packed.stats.pack_seconds = seconds_since(start);
    packed.stats.build_seconds = build_seconds;
    packed.stats.thread_seconds = thread_seconds;
    return packed;
}

std::vector<std::int32_t> node_parents(const PackedBvh& bvh) {
    auto count_of = [&](std::uint32_t j) {
        return std::bit_cast<std::int32_t>(bvh.nodes[2 * j + 1].w);
    };
    std::vector<std::int32_t> parent(bvh.node_count, -1);
    std::vector<std::uint32_t> open;
    for (std::uint32_t j = 0; j < bvh.node_count; ++j) {
        if (j > 0) {
            if (count_of(j - 1) == 0) {
                parent[j] = std::int32_t(j - 1);
            } else {
                parent[j] = std::int32_t(open.back());
                open.pop_back();
            }
        }
        if (count_of(j) == 0) open.push_back(j);
    }
    return parent;
}

}  // namespace glslppm
