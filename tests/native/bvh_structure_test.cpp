// Structure of the SAH BVH, its six threadings and the packed GPU layout.
#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "bvh/packed_bvh.h"
#include "bvh/thread_mtbvh.h"
#include "bvh_test_scenes.h"

namespace glslppm {
namespace {

std::int32_t bits(float f) { return std::bit_cast<std::int32_t>(f); }

struct Built {
    OwnedMesh mesh;
    ValidMesh valid;
    Bvh bvh;
};

Built build(OwnedMesh mesh, int leaf_size, bool parallel = true) {
    Built b{std::move(mesh), {}, {}};
    b.valid = validate_mesh(b.mesh.view(), 1);
    BvhBuildOptions options;
    options.leaf_size = leaf_size;
    options.parallel = parallel;
    b.bvh = build_sah_bvh(b.valid, options);
    return b;
}

std::vector<std::pair<std::string, OwnedMesh>> structure_scenes() {
    std::vector<std::pair<std::string, OwnedMesh>> s;
    s.emplace_back("soup_1", bvh_test::make_random_soup(1, 1));
    s.emplace_back("soup_3", bvh_test::make_random_soup(3, 3));
    s.emplace_back("soup_20000", bvh_test::make_random_soup(20000, 2));
    s.emplace_back("sphere_30000", make_sphere_mesh(30000));
    s.emplace_back("cornell", bvh_test::make_cornell_box());
    s.emplace_back("coplanar_duplicates", bvh_test::make_coplanar_duplicates(3));
    s.emplace_back("thin", bvh_test::make_thin_triangles(3000, 4));
    return s;
}

// Number of nodes in the subtree of each node (preorder: children after their parent).
std::vector<std::int32_t> subtree_sizes(const Bvh& bvh) {
    std::vector<std::int32_t> size(bvh.nodes.size(), 1);
    for (std::size_t i = bvh.nodes.size(); i-- > 0;)
        if (!bvh.nodes[i].is_leaf()) size[i] += size[bvh.nodes[i].left] + size[bvh.nodes[i].right];
    return size;
}

TEST(BvhStructure, TreeIsWellFormed) {
    for (const int leaf_size : {1, 4, 8}) {
        for (auto& [name, mesh] : structure_scenes()) {
            SCOPED_TRACE(name + " leaf size " + std::to_string(leaf_size));
            const Built b = build(std::move(mesh), leaf_size);
            const Bvh& bvh = b.bvh;
            ASSERT_FALSE(bvh.nodes.empty());
            // Every kept triangle in exactly one leaf; leaves cover the list in order.
            std::vector<int> seen(b.mesh.triangles.size(), 0);
            std::vector<int> covered(bvh.triangles.size(), 0);
            std::size_t leaves = 0;
            int max_depth = 0;
            std::vector<int> depth(bvh.nodes.size(), 0);
            for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
                const BvhNode& node = bvh.nodes[i];
                max_depth = std::max(max_depth, depth[i]);
                if (node.is_leaf()) {
                    ++leaves;
                    EXPECT_LE(node.count, static_cast<std::uint32_t>(leaf_size));
                    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                        ++covered[k];
                        const std::uint32_t id = bvh.triangles[k];
                        ++seen[id];
                        const glm::uvec3 t = b.mesh.triangles[id];
                        for (int v = 0; v < 3; ++v)
                            EXPECT_TRUE(node.box.contains(b.mesh.positions[t[v]]));
                    }
                    EXPECT_EQ(node.left, -1);
                    EXPECT_EQ(node.right, -1);
                } else {
                    // Preorder, left first; boxes contain the children's.
                    EXPECT_EQ(node.left, static_cast<std::int32_t>(i + 1));
                    ASSERT_GT(node.right, node.left);
                    ASSERT_LT(node.right, static_cast<std::int32_t>(bvh.nodes.size()));
                    EXPECT_TRUE(node.box.contains(bvh.nodes[node.left].box));
                    EXPECT_TRUE(node.box.contains(bvh.nodes[node.right].box));
                    depth[node.left] = depth[node.right] = depth[i] + 1;
                }
            }
            for (const int c : covered) EXPECT_EQ(c, 1);
            for (const std::uint32_t id : b.valid.kept) EXPECT_EQ(seen[id], 1);
            EXPECT_EQ(bvh.triangles.size(), b.valid.kept.size());
            EXPECT_EQ(leaves, bvh.leaf_count);
            EXPECT_EQ(max_depth, bvh.max_depth);
            EXPECT_EQ(bvh.nodes.size(), 2 * leaves - 1);
        }
    }
}

TEST(BvhStructure, ParallelBuildEqualsSerialBuild) {
    const Built a = build(make_sphere_mesh(60000), 4, true);
    const Built b = build(make_sphere_mesh(60000), 4, false);
    ASSERT_EQ(a.bvh.nodes.size(), b.bvh.nodes.size());
    EXPECT_EQ(a.bvh.triangles, b.bvh.triangles);
    for (std::size_t i = 0; i < a.bvh.nodes.size(); ++i) {
        const BvhNode &x = a.bvh.nodes[i], &y = b.bvh.nodes[i];
        ASSERT_TRUE(x.box.lo == y.box.lo && x.box.hi == y.box.hi && x.left == y.left &&
                    x.right == y.right && x.first == y.first && x.count == y.count)
            << "node " << i;
    }
}

TEST(BvhStructure, DuplicatedTrianglesSplitDownToLeafSizeOne) {
    OwnedMesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.triangles.assign(37, glm::uvec3(0, 1, 2));
    const Built b = build(std::move(mesh), 1);
    EXPECT_EQ(b.bvh.leaf_count, 37u);
    EXPECT_LE(b.bvh.max_depth, 7);  // halved each time: ceil(log2(37)) = 6
}

// Links of every order: a walk from node 0 terminates and visits each node at most once;
// always taking the hit link visits every node, in a preorder in which the child nearer
// along the order's direction comes first; miss links skip exactly the subtree.
TEST(MtbvhThreading, LinksFollowTheNearerChildFirstPreorder) {
    for (auto& [name, mesh] : structure_scenes()) {
        SCOPED_TRACE(name);
        const Built b = build(std::move(mesh), 4);
        const Bvh& bvh = b.bvh;
        const auto n = static_cast<std::int32_t>(bvh.nodes.size());
        const std::vector<std::int32_t> size = subtree_sizes(bvh);
        for (const int order_count : {6, 1}) {
            const ThreadedBvh threaded = thread_bvh(bvh, order_count);
            ASSERT_EQ(threaded.links.size(), static_cast<std::size_t>(order_count) * n);
            for (int order = 0; order < order_count; ++order) {
                SCOPED_TRACE("order " + std::to_string(order) + " of " +
                             std::to_string(order_count));
                const glm::ivec2* links = threaded.links.data() + order * n;
                std::vector<std::int32_t> sequence, position(n, -1);
                for (std::int32_t node = 0; node != -1; node = links[node].x) {
                    ASSERT_GE(node, 0);
                    ASSERT_LT(node, n);
                    ASSERT_EQ(position[node], -1) << "node visited twice";
                    position[node] = static_cast<std::int32_t>(sequence.size());
                    sequence.push_back(node);
                }
                ASSERT_EQ(sequence.size(), static_cast<std::size_t>(n));
                EXPECT_EQ(sequence[0], 0);
                const int axis = order / 2;
                for (std::int32_t i = 0; i < n; ++i) {
                    const BvhNode& node = bvh.nodes[i];
                    const std::int32_t after = position[i] + size[i];
                    EXPECT_EQ(links[i].y, after < n ? sequence[after] : -1) << "miss of " << i;
                    if (node.is_leaf()) {
                        EXPECT_EQ(links[i].x, links[i].y);
                        continue;
                    }
                    std::int32_t first = node.left, second = node.right;
                    if (position[second] < position[first]) std::swap(first, second);
                    EXPECT_EQ(position[first], position[i] + 1);
                    EXPECT_EQ(position[second], position[i] + 1 + size[first]);
                    const float c_first = bvh.nodes[first].box.centroid()[axis];
                    const float c_second = bvh.nodes[second].box.centroid()[axis];
                    if (order_count == 1) {
                        EXPECT_EQ(first, node.left);  // TBVH: build order
                    } else {
                        if (order % 2 == 0) {
                            EXPECT_LE(c_first, c_second);
                        } else {
                            EXPECT_GE(c_first, c_second);
                        }
                        if (c_first == c_second) {
                            EXPECT_EQ(first, node.left);  // ties keep the build order
                        }
                    }
                }
                // Random hit/miss choices: always terminates, no node twice.
                std::mt19937 rng(order);
                for (int walk = 0; walk < 200; ++walk) {
                    std::vector<char> visited(n, 0);
                    int steps = 0;
                    for (std::int32_t node = 0; node != -1;
                         node = (rng() % 3 ? links[node].x : links[node].y)) {
                        ASSERT_FALSE(visited[node]);
                        visited[node] = 1;
                        ASSERT_LE(++steps, n);
                    }
                }
            }
        }
    }
}

TEST(PackedBvh, LayoutMatchesTheTree) {
    const Built b = build(make_sphere_mesh(5000), 4);
    const PackedBvh packed = pack_bvh(b.valid, b.bvh, thread_bvh(b.bvh, 6));
    ASSERT_EQ(packed.node_count, b.bvh.nodes.size());
    ASSERT_EQ(packed.triangle_count, b.bvh.triangles.size());
    ASSERT_EQ(packed.nodes.size(), 2 * b.bvh.nodes.size());
    ASSERT_EQ(packed.triangles.size(), 3 * b.bvh.triangles.size());
    ASSERT_EQ(packed.normals.size(), 3 * b.bvh.triangles.size());
    ASSERT_EQ(packed.uvs.size(), 2 * b.bvh.triangles.size());
    for (std::size_t i = 0; i < b.bvh.nodes.size(); ++i) {
        const BvhNode& node = b.bvh.nodes[i];
        const Aabb box{glm::vec3(packed.nodes[2 * i]), glm::vec3(packed.nodes[2 * i + 1])};
        EXPECT_EQ(bits(packed.nodes[2 * i + 1].w), static_cast<std::int32_t>(node.count));
        if (node.is_leaf()) {
            EXPECT_EQ(bits(packed.nodes[2 * i].w), static_cast<std::int32_t>(node.first));
            // Padded strictly outwards.
            EXPECT_TRUE(glm::all(glm::lessThan(box.lo, node.box.lo)));
            EXPECT_TRUE(glm::all(glm::greaterThan(box.hi, node.box.hi)));
        } else {
            for (const std::int32_t c : {node.left, node.right}) {
                const Aabb child{glm::vec3(packed.nodes[2 * c]),
                                 glm::vec3(packed.nodes[2 * c + 1])};
                EXPECT_TRUE(box.contains(child));
            }
        }
    }
    for (std::size_t i = 0; i < b.bvh.triangles.size(); ++i) {
        const std::uint32_t id = b.bvh.triangles[i];
        const glm::uvec3 t = b.mesh.triangles[id];
        EXPECT_EQ(bits(packed.triangles[3 * i].w), 0);  // material
        EXPECT_EQ(bits(packed.triangles[3 * i + 1].w), static_cast<std::int32_t>(id));
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(glm::vec3(packed.triangles[3 * i + k]), b.mesh.positions[t[k]]);
            EXPECT_EQ(glm::vec3(packed.normals[3 * i + k]), b.mesh.normals[t[k]]);
        }
        EXPECT_EQ(packed.uvs[2 * i], glm::vec4(b.mesh.uvs[t.x], b.mesh.uvs[t.y]));
        EXPECT_EQ(packed.uvs[2 * i + 1], glm::vec4(b.mesh.uvs[t.z], 0, 0));
    }
    const std::size_t expected_bytes =
        packed.node_count * (32 + 6 * 8) + packed.triangle_count * (48 + 48 + 32);
    EXPECT_EQ(packed.stats.bytes_total, expected_bytes);
    EXPECT_DOUBLE_EQ(packed.stats.bytes_per_triangle,
                     static_cast<double>(expected_bytes) / packed.triangle_count);
}

TEST(PackedBvh, MaterialIdsAndMissingAttributes) {
    OwnedMesh mesh = bvh_test::make_cornell_box();
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
        mesh.material_ids.push_back(static_cast<std::uint32_t>(i % 3));
    const ValidMesh valid = validate_mesh(mesh.view(), 3);
    const PackedBvh packed = build_packed_bvh(valid, {}, 1);
    EXPECT_TRUE(packed.normals.empty());
    EXPECT_TRUE(packed.uvs.empty());
    EXPECT_EQ(packed.order_count, 1);
    EXPECT_EQ(packed.links.size(), packed.node_count);
    for (std::uint32_t i = 0; i < packed.triangle_count; ++i) {
        const std::int32_t id = bits(packed.triangles[3 * i + 1].w);
        EXPECT_EQ(bits(packed.triangles[3 * i].w), id % 3);
    }
    EXPECT_EQ(packed.stats.bytes_total, packed.node_count * (32 + 8) + packed.triangle_count * 48);
}

TEST(PackedBvh, RejectsBadOptions) {
    const OwnedMesh mesh = bvh_test::make_cornell_box();
    const ValidMesh valid = validate_mesh(mesh.view(), 1);
    EXPECT_THROW(build_packed_bvh(valid, {.leaf_size = 0}, 6), std::invalid_argument);
    EXPECT_THROW(build_packed_bvh(valid, {.leaf_size = 4, .bins = 1}, 6), std::invalid_argument);
    EXPECT_THROW(build_packed_bvh(valid, {}, 2), std::invalid_argument);
}

}  // namespace
}  // namespace glslppm
