// MTBVH and TBVH traversal against brute force: the closest hit (original triangle id, t,
// u, v) and any-hit must agree exactly, for every ray, every scene, leaf sizes 1, 4 and 8.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <thread>

#include "bvh/packed_bvh.h"
#include "bvh/traverse_cpu.h"
#include "bvh_test_scenes.h"

namespace glslppm {
namespace {

using bvh_test::make_coplanar_duplicates;
using bvh_test::make_cornell_box;
using bvh_test::make_random_soup;
using bvh_test::make_test_rays;
using bvh_test::make_thin_triangles;

// Splits [0, n) over the cores.
void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body) {
    const std::size_t workers = std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::thread> threads;
    for (std::size_t w = 1; w < workers; ++w)
        threads.emplace_back(body, n * w / workers, n * (w + 1) / workers);
    body(0, n / workers);
    for (std::thread& t : threads) t.join();
}

struct SceneCase {
    std::string name;
    std::function<OwnedMesh()> make;
    std::size_t rays = 100000;
    // Rays also checked against brute force: all of them except on the biggest soup, where
    // 100k rays x 100k triangles would take minutes; there the first 5k are checked
    // against brute force and all 100k across leaf sizes and MTBVH/TBVH.
    std::size_t brute_force_rays = 100000;
};

// gtest prints the case by name rather than as raw bytes.
void PrintTo(const SceneCase& c, std::ostream* os) { *os << c.name; }

std::function<OwnedMesh()> scaled(std::function<OwnedMesh()> make, float factor) {
    return [make, factor] {
        OwnedMesh m = make();
        m.scale(factor);
        return m;
    };
}

std::vector<SceneCase> scene_cases() {
    std::vector<SceneCase> cases;
    for (std::size_t n : {1, 2, 10, 100, 1000, 10000})
        cases.push_back({"soup_" + std::to_string(n),
                         [n] { return make_random_soup(n, static_cast<std::uint32_t>(n)); }});
    cases.push_back({"soup_100000", [] { return make_random_soup(100000, 100000); }, 100000, 5000});
    const std::vector<std::pair<std::string, std::function<OwnedMesh()>>> base = {
        {"sphere", [] { return make_sphere_mesh(3000); }},
        {"cornell_box", [] { return make_cornell_box(); }},
        {"thin_triangles", [] { return make_thin_triangles(1000, 5); }},
        {"coplanar_duplicates", [] { return make_coplanar_duplicates(9); }},
        {"soup_1000_", [] { return make_random_soup(1000, 77); }},
    };
    for (const auto& [name, make] : base) {
        if (name.back() != '_') cases.push_back({name, make});
        cases.push_back(
            {name + (name.back() == '_' ? "" : "_") + "scaled_1em3", scaled(make, 1e-3f)});
        cases.push_back(
            {name + (name.back() == '_' ? "" : "_") + "scaled_1e5", scaled(make, 1e5f)});
    }
    return cases;
}

bool same_hit(const Hit& a, const Hit& b) {
    return a.triangle == b.triangle &&
           std::bit_cast<std::uint32_t>(a.t) == std::bit_cast<std::uint32_t>(b.t) && a.u == b.u &&
           a.v == b.v;
}

std::string describe(const Ray& r, const Hit& expected, const Hit& got) {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "ray o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) t=[%.9g %.9g]: expected tri %d "
                  "t=%.9g, got tri %d t=%.9g",
                  r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z, r.tmin, r.tmax,
                  expected.triangle, expected.t, got.triangle, got.t);
    return buf;
}

class TraversalTest : public ::testing::TestWithParam<SceneCase> {};

TEST_P(TraversalTest, MtbvhAndTbvhEqualBruteForce) {
    const SceneCase& scene = GetParam();
    const OwnedMesh mesh = scene.make();
    const ValidMesh valid = validate_mesh(mesh.view(), 1);
    const std::vector<Ray> rays = make_test_rays(mesh, scene.rays, 1234);
    const std::size_t brute_n = std::min(scene.brute_force_rays, rays.size());

    // Brute force. Any-hit brute force must equal "closest hit found something"; it is run
    // on every 8th ray only (it scans all triangles on a miss), the traversal any-hit is
    // checked on every ray against the closest-hit brute force.
    std::vector<Hit> expected(brute_n);
    parallel_for(brute_n, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            expected[i] = closest_hit_brute_force(valid, rays[i]);
            if (i % 8 == 0) {
                EXPECT_EQ(any_hit_brute_force(valid, rays[i]), expected[i].triangle >= 0)
                    << "brute force, ray " << i;
            }
        }
    });
    std::size_t hits = 0, axis_parallel = 0;
    for (const Hit& h : expected) hits += h.triangle >= 0;
    for (const Ray& r : rays) axis_parallel += r.dir.x == 0 || r.dir.y == 0 || r.dir.z == 0;
    EXPECT_GT(hits, brute_n / 20) << "too few rays hit anything to test";
    EXPECT_GT(axis_parallel, rays.size() / 10);

    // The leaf size 4 MTBVH goes first: beyond brute_n rays it is the reference for the rest.
    std::vector<Hit> reference = expected;
    const std::pair<int, int> configs[] = {{4, 6}, {1, 6}, {8, 6}, {4, 1}, {1, 1}, {8, 1}};
    for (const auto& [leaf_size, order_count] : configs) {
        BvhBuildOptions options;
        options.leaf_size = leaf_size;
        const PackedBvh bvh = build_packed_bvh(valid, options, order_count);
        std::vector<Hit> got(rays.size());
        std::vector<char> got_any(rays.size());
        parallel_for(rays.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                got[i] = closest_hit(bvh, rays[i]);
                got_any[i] = any_hit(bvh, rays[i]);
            }
        });
        if (reference.size() < rays.size()) {
            ASSERT_EQ(leaf_size, 4);
            reference.insert(reference.end(), got.begin() + brute_n, got.end());
        }
        std::size_t mismatches = 0, any_mismatches = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if (!same_hit(reference[i], got[i]) && mismatches++ < 5)
                ADD_FAILURE() << scene.name << " leaf " << leaf_size << " orders " << order_count
                              << ": " << describe(rays[i], reference[i], got[i]);
            if ((reference[i].triangle >= 0) != (got_any[i] != 0) && any_mismatches++ < 5)
                ADD_FAILURE() << scene.name << " any_hit leaf " << leaf_size << " orders "
                              << order_count << " ray " << i;
        }
        EXPECT_EQ(mismatches, 0u) << scene.name << " leaf " << leaf_size << " orders "
                                  << order_count;
        EXPECT_EQ(any_mismatches, 0u);
    }
    std::printf(
        "[ scene    ] %-34s %7zu triangles, %6zu rays (%zu vs brute force), %zu hits, "
        "%zu axis-parallel\n",
        scene.name.c_str(), valid.kept.size(), rays.size(), brute_n, hits, axis_parallel);
}

INSTANTIATE_TEST_SUITE_P(Scenes, TraversalTest, ::testing::ValuesIn(scene_cases()),
                         [](const ::testing::TestParamInfo<SceneCase>& p) { return p.param.name; });

// Rays through shared vertices and edge midpoints of a mesh with exact coordinates hit
// several triangles at the same t: the smaller original id must win everywhere.
TEST(TraversalTies, SharedEdgesAndDuplicatesGoToSmallerId) {
    OwnedMesh mesh;
    // Two quads (4 triangles) in z = 0 sharing edges, and a duplicate of triangle 1 as 4.
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}};
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}, {0, 2, 3}};
    const ValidMesh valid = validate_mesh(mesh.view(), 1);
    const PackedBvh mt = build_packed_bvh(valid, {.leaf_size = 1}, 6);
    const PackedBvh t1 = build_packed_bvh(valid, {.leaf_size = 1}, 1);
    struct Case {
        glm::vec3 target;
        int expected;
    };
    // Diagonal 0-2 (triangles 0 and 1): 0. Edge 1-2 (0 and 3): 0. Vertex 2 (0, 1, 3, 4): 0.
    // Inside triangle 1 (and its duplicate 4): 1. Inside triangle 3: 3.
    const Case cases[] = {{{0.5f, 0.5f, 0}, 0},   {{1, 0.5f, 0}, 0},     {{1, 1, 0}, 0},
                          {{0.25f, 0.75f, 0}, 1}, {{1.75f, 0.5f, 0}, 2}, {{1.25f, 0.75f, 0}, 3}};
    for (const Case& c : cases) {
        for (const glm::vec3 dir : {glm::vec3(0, 0, -1), glm::vec3(0, 0, 1),
                                    glm::vec3(0.25f, -0.125f, -1), glm::vec3(-0.5f, 0.5f, 1)}) {
            const Ray ray{c.target - dir * 2.0f, dir, 0.0f, 1e30f};
            const Hit want = closest_hit_brute_force(valid, ray);
            EXPECT_EQ(want.triangle, c.expected);
            EXPECT_EQ(want.t, 2.0f);
            EXPECT_TRUE(same_hit(closest_hit(mt, ray), want));
            EXPECT_TRUE(same_hit(closest_hit(t1, ray), want));
        }
    }
}

TEST(TraversalEmpty, NoTrianglesMeansNoHit) {
    OwnedMesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    mesh.triangles = {{0, 1, 2}};  // collinear: dropped
    const ValidMesh valid = validate_mesh(mesh.view(), 1);
    const PackedBvh bvh = build_packed_bvh(valid, {}, 6);
    EXPECT_EQ(bvh.node_count, 0u);
    EXPECT_EQ(bvh.stats.degenerate_dropped, 1u);
    const Ray ray{{0.5f, -1, 0}, {0, 1, 0}, 0.0f, 10.0f};
    const Hit hit = closest_hit(bvh, ray);
    EXPECT_EQ(hit.triangle, -1);
    EXPECT_EQ(hit.t, 10.0f);
    EXPECT_FALSE(any_hit(bvh, ray));
}

}  // namespace
}  // namespace glslppm
