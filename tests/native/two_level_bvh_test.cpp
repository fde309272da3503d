// The two-level MTBVH (two_level_bvh.h) on the CPU: its closest and any hit equal the
// instance-space brute force bit for bit (id, t, u, v), and agree with the flattened copy's
// MTBVH within the bound that moving the ray instead of the triangles allows.
#include "bvh/two_level_bvh.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "bvh/packed_bvh.h"
#include "bvh/traverse_cpu.h"
#include "instance_test_scenes.h"

namespace glslppm {
namespace {

using bvh_test::InstancedScene;

struct Config {
    const char* name;
    int instances;
    std::size_t soup_triangles;
    int second;  // a second mesh: 0 none, 1 the Cornell box scaled to 2 units, 2 a 2-unit cube
    glm::vec3 offset;
    std::size_t rays;
};

OwnedMesh small_cornell() {
    OwnedMesh m = bvh_test::make_cornell_box();
    m.scale(1.0f / 277.5f);
    return m;
}

InstancedScene make(const Config& c, std::uint32_t seed) {
    std::vector<OwnedMesh> meshes{bvh_test::make_random_soup(c.soup_triangles, seed)};
    if (c.second == 1) meshes.push_back(small_cornell());
    if (c.second == 2) {
        OwnedMesh cube;
        bvh_test::add_block(cube, glm::vec3(-1.0f), glm::vec3(1.0f));
        meshes.push_back(std::move(cube));
    }
    return bvh_test::make_instanced_scene(std::move(meshes), c.instances, seed + 1, c.offset);
}

std::string describe(const Ray& r) {
    char text[256];
    std::snprintf(text, sizeof text, "o (%a, %a, %a) d (%a, %a, %a) [%a, %a]", r.origin.x,
                  r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z, r.tmin, r.tmax);
    return text;
}

std::string describe(const InstanceHit& h) {
    char text[160];
    std::snprintf(text, sizeof text, "instance %d triangle %d t %a u %a v %a", h.instance,
                  h.triangle, h.t, h.u, h.v);
    return text;
}

const glm::vec3 kFar(1e5f, -1e5f, 1e5f);

// 1, 10 and 1,000 instances, near the origin and translated by 1e5 on every axis. The brute
// force costs instances x triangles per ray, so the 1,000-instance scenes use 12-triangle
// meshes (a 12-triangle soup and a cube).
const Config kConfigs[] = {
    {"1 instance", 1, 2000, 0, glm::vec3(0.0f), 100000},
    {"1 instance at 1e5", 1, 2000, 0, kFar, 100000},
    {"10 instances", 10, 200, 1, glm::vec3(0.0f), 100000},
    {"10 instances at 1e5", 10, 200, 1, kFar, 100000},
    {"1000 instances", 1000, 12, 2, glm::vec3(0.0f), 100000},
    {"1000 instances at 1e5", 1000, 12, 2, kFar, 100000},
};

// One test per scene (the brute force costs instances x triangles per ray: minutes for the
// 1,000-instance scenes on a busy machine, so each gets its own ctest time limit).
class TwoLevelBruteForce : public ::testing::TestWithParam<int> {};

TEST_P(TwoLevelBruteForce, EqualsInstanceBruteForceBitForBit) {
    const int index = GetParam();
    const std::uint32_t seed = 110 + 10 * static_cast<std::uint32_t>(index);
    {
        const Config& c = kConfigs[index];
        const InstancedScene s = make(c, seed);
        const TwoLevelBvh bvh = build_two_level_bvh(s.meshes, s.instances, BvhBuildOptions{});
        const std::vector<Ray> rays = bvh_test::make_instance_rays(s, c.rays, seed + 5);
        int mismatches = 0, hits = 0, occluded = 0, mirrored_hits = 0;
        for (const Ray& r : rays) {
            const InstanceHit want = closest_hit_brute_force(bvh, s.meshes, s.instances, r);
            const InstanceHit got = closest_hit(bvh, r);
            const bool any_want = any_hit_brute_force(bvh, s.meshes, s.instances, r);
            const bool any_got = any_hit(bvh, r);
            hits += want.instance >= 0;
            occluded += any_want;
            if (want.instance >= 0 &&
                glm::determinant(glm::mat3(
                    s.instances[static_cast<std::size_t>(want.instance)].to_world)) < 0.0f)
                ++mirrored_hits;
            const bool same =
                got.instance == want.instance && got.triangle == want.triangle &&
                std::bit_cast<std::uint32_t>(got.t) == std::bit_cast<std::uint32_t>(want.t) &&
                std::bit_cast<std::uint32_t>(got.u) == std::bit_cast<std::uint32_t>(want.u) &&
                std::bit_cast<std::uint32_t>(got.v) == std::bit_cast<std::uint32_t>(want.v) &&
                any_got == any_want && any_want == (want.instance >= 0);
            if (!same && mismatches++ < 5)
                ADD_FAILURE() << c.name << ": " << describe(r) << "\n  brute force "
                              << describe(want) << " any " << any_want << "\n  two-level   "
                              << describe(got) << " any " << any_got;
        }
        EXPECT_EQ(mismatches, 0) << c.name << ", of " << rays.size() << " rays";
        // The rays must exercise the scene: most hit, mirrored instances among them.
        EXPECT_GT(hits, static_cast<int>(rays.size() / 3)) << c.name;
        if (c.instances > 1) {
            EXPECT_GT(mirrored_hits, hits / 5) << c.name;
        }
        std::printf(
            "[ two-level] %-22s %zu rays, %d hits (%d on mirrored instances), "
            "%d occluded: all equal\n",
            c.name, rays.size(), hits, mirrored_hits, occluded);
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, TwoLevelBruteForce, ::testing::Range(0, 6));

// The flattened copy intersects triangles whose vertices were moved to world space and
// rounded there (by up to half an ulp of each world coordinate: 0.004 at 1e5, where these
// triangles are 0.1 to 1 across); the two-level traversal moves the ray into instance space
// and rounds that instead. Neither is exact, so bit equality cannot hold between them (it
// does hold between each and its own brute force). What holds, with delta = 2^-20 x the
// largest |coordinate| of the ray origin and the hit point (16 ulps of it):
//   - the same triangle is hit at world points within delta kappa / |cos| of each other;
//   - where the triangles differ, one of the two hits lies within that bound of an edge of
//     its triangle (the ray passes an edge closer than rounding) or of the ray's origin (a
//     surface through the origin, to rounding), or the two hit points lie within it of each
//     other (another surface at the same depth to rounding).
// kappa = |e1| |e2| / |e1 x e2| >= 1 of the triangle scales the bound: Moller-Trumbore's
// error in t grows with it for slivers. Grazing hits (|cos| < 1e-3) are left out: their
// position along the ray is ill-conditioned.
double max_abs(const glm::dvec3& v) {
    return std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z)));
}

double edge_distance(const glm::dvec3& p, const glm::dvec3 v[3]) {
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
        const glm::dvec3 a = v[k], e = v[(k + 1) % 3] - v[k];
        const double s = glm::clamp(glm::dot(p - a, e) / glm::dot(e, e), 0.0, 1.0);
        best = std::min(best, glm::length(p - (a + s * e)));
    }
    return best;
}

TEST(TwoLevelBvh, AgreesWithFlattenedCopyWithinRounding) {
    std::uint32_t seed = 300;
    for (const Config& c : kConfigs) {
        const InstancedScene s = make(c, seed += 10);
        const TwoLevelBvh bvh = build_two_level_bvh(s.meshes, s.instances, BvhBuildOptions{});
        const ValidMesh flat_mesh = validate_mesh(s.flattened.view(), 1);
        const PackedBvh flat = build_packed_bvh(flat_mesh, BvhBuildOptions{}, 6);
        const std::vector<Ray> rays = bvh_test::make_instance_rays(s, c.rays, seed + 5);
        int same_id = 0, near_edge = 0, near_origin = 0, same_depth = 0, grazing = 0, bad = 0;
        int hits = 0;
        double worst = 0.0;  // same triangle: |p2 - pf| |cos| / delta
        for (const Ray& r : rays) {
            const InstanceHit two = closest_hit(bvh, r);
            const Hit f = closest_hit(flat, r);
            const int two_id =
                two.instance < 0
                    ? -1
                    : static_cast<int>(s.id_base[static_cast<std::size_t>(two.instance)]) +
                          two.triangle;
            hits += f.triangle >= 0;
            if (two_id < 0 && f.triangle < 0) {
                ++same_id;
                continue;
            }
            const glm::dvec3 o(r.origin), d(r.dir);
            struct Seen {
                glm::dvec3 p;
                double cos, edge, kappa;
            };
            auto seen = [&](int id, float t) {
                const glm::uvec3 tri = s.flattened.triangles[static_cast<std::size_t>(id)];
                const glm::vec3* q = s.flattened.positions.data();
                const glm::dvec3 v[3] = {glm::dvec3(q[tri.x]), glm::dvec3(q[tri.y]),
                                         glm::dvec3(q[tri.z])};
                const glm::dvec3 e1 = v[1] - v[0], e2 = v[2] - v[0], n = glm::cross(e1, e2);
                const glm::dvec3 p = o + double(t) * d;
                return Seen{p, std::abs(glm::dot(glm::normalize(n), glm::normalize(d))),
                            edge_distance(p, v),
                            glm::length(e1) * glm::length(e2) / glm::length(n)};
            };
            const bool has2 = two_id >= 0, hasf = f.triangle >= 0;
            const Seen s2 = has2 ? seen(two_id, two.t) : Seen{};
            const Seen sf = hasf ? seen(f.triangle, f.t) : Seen{};
            const glm::dvec3 far = hasf ? sf.p : s2.p;
            const double delta = std::ldexp(std::max(max_abs(o), max_abs(far)), -20);
            const double cos = std::min(has2 ? s2.cos : 1.0, hasf ? sf.cos : 1.0);
            if (cos < 1e-3) {
                ++grazing;
                continue;
            }
            const double kappa = std::max(has2 ? s2.kappa : 1.0, hasf ? sf.kappa : 1.0);
            const double reach = delta * kappa / cos;
            if (two_id == f.triangle) {
                ++same_id;
                const double err = glm::length(s2.p - sf.p);
                worst = std::max(worst, err / reach);
                if (err > reach && bad++ < 5)
                    ADD_FAILURE() << c.name << ": " << describe(r) << " flat t " << f.t
                                  << " two-level t " << two.t << ": " << err << " apart, delta "
                                  << delta << " cos " << cos;
                continue;
            }
            if ((has2 && s2.edge <= reach) || (hasf && sf.edge <= reach)) {
                ++near_edge;
            } else if ((has2 && glm::length(s2.p - o) <= reach) ||
                       (hasf && glm::length(sf.p - o) <= reach)) {
                ++near_origin;
            } else if (has2 && hasf && glm::length(s2.p - sf.p) <= reach) {
                ++same_depth;
            } else if (bad++ < 5) {
                ADD_FAILURE() << c.name << ": " << describe(r) << "\n  flat id " << f.triangle
                              << " t " << f.t << " edge " << sf.edge << "\n  two-level "
                              << describe(two) << " (flat id " << two_id << ") edge " << s2.edge
                              << "\n  delta " << delta << " cos " << cos;
            }
        }
        EXPECT_EQ(bad, 0) << c.name;
        EXPECT_GT(hits, static_cast<int>(rays.size() / 3)) << c.name;
        std::printf(
            "[ flattened] %-22s %zu rays, %d hits: %d same triangle (worst distance "
            "%.3g of the bound), %d differ within the bound of an edge, %d of the "
            "origin, %d at the same depth; %d grazing\n",
            c.name, rays.size(), hits, same_id, worst, near_edge, near_origin, same_depth, grazing);
    }
}

TEST(TwoLevelBvh, BadInstancesAreErrorsAndEmptyMeshesAreNeverHit) {
    OwnedMesh soup = bvh_test::make_random_soup(50, 3), empty;
    std::vector<ValidMesh> meshes{validate_mesh(soup.view(), 1), validate_mesh(empty.view(), 1)};
    std::vector<Instance> bad{{glm::mat4(1.0f), 2, 0}};
    EXPECT_THROW(build_two_level_bvh(meshes, bad, {}), std::invalid_argument);
    bad[0] = Instance{glm::mat4(0.0f), 0, 0};
    bad[0].to_world[3][3] = 1.0f;
    EXPECT_THROW(build_two_level_bvh(meshes, bad, {}), std::invalid_argument);
    bad[0] = Instance{glm::mat4(1.0f), 0, 0};
    bad[0].to_world[0][3] = 0.5f;  // not affine
    EXPECT_THROW(build_two_level_bvh(meshes, bad, {}), std::invalid_argument);
    bad[0] = Instance{glm::mat4(1.0f), 0, 0};
    bad[0].to_world[3][0] = NAN;
    EXPECT_THROW(build_two_level_bvh(meshes, bad, {}), std::invalid_argument);

    // Only the empty mesh placed: nothing to hit. Both placed: the soup is hit as alone.
    const std::vector<Instance> only_empty{{glm::mat4(1.0f), 1, 0}};
    const TwoLevelBvh none = build_two_level_bvh(meshes, only_empty, {});
    const std::vector<Instance> both{{glm::mat4(1.0f), 1, 0}, {glm::mat4(1.0f), 0, 0}};
    const TwoLevelBvh two = build_two_level_bvh(meshes, both, {});
    const PackedBvh alone = build_packed_bvh(meshes[0], {}, 6);
    int hits = 0;
    for (const Ray& r : bvh_test::make_test_rays(soup, 2000, 9)) {
        EXPECT_EQ(closest_hit(none, r).instance, -1);
        EXPECT_FALSE(any_hit(none, r));
        const InstanceHit h = closest_hit(two, r);
        const Hit want = closest_hit(alone, r);
        EXPECT_EQ(h.triangle, want.triangle);
        EXPECT_EQ(h.instance, want.triangle < 0 ? -1 : 1);
        EXPECT_EQ(std::bit_cast<std::uint32_t>(h.t), std::bit_cast<std::uint32_t>(want.t));
        hits += want.triangle >= 0;
    }
    EXPECT_GT(hits, 500);
}

}  // namespace
}  // namespace glslppm
