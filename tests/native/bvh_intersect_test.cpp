// The shared ray-box and ray-triangle tests against closed-form answers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bvh/intersect.h"
#include "bvh/packed_bvh.h"

namespace glslppm {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(SelectOrder, DominantAxisAndSign) {
    EXPECT_EQ(select_order({1, 0, 0}), 0);
    EXPECT_EQ(select_order({-1, 0.5f, 0}), 1);
    EXPECT_EQ(select_order({0.1f, 2, -1}), 2);
    EXPECT_EQ(select_order({0.1f, -2, -1}), 3);
    EXPECT_EQ(select_order({0, 0, 1}), 4);
    EXPECT_EQ(select_order({0.3f, -0.2f, -0.9f}), 5);
    // Ties go to the lowest axis.
    EXPECT_EQ(select_order({1, 1, 1}), 0);
    EXPECT_EQ(select_order({-1, 1, -1}), 1);
    EXPECT_EQ(select_order({0, -1, 1}), 3);
    EXPECT_EQ(select_order({0.5f, -1, -1}), 3);
    EXPECT_EQ(select_order({0, 0, 0}), 0);
}

TEST(HitBox, ClosedFormDistances) {
    const glm::vec3 lo(1, 1, 1), hi(2, 2, 2);
    const glm::vec3 o(0, 1.5f, 1.5f);
    const glm::vec3 inv = safe_inverse_dir({1, 0, 0});
    EXPECT_TRUE(hit_box(lo, hi, o, inv, 0.0f, kInf));
    EXPECT_TRUE(hit_box(lo, hi, o, inv, 0.0f, 1.0f));    // entry at exactly tmax: inclusive
    EXPECT_FALSE(hit_box(lo, hi, o, inv, 0.0f, 0.99f));  // ends before the box
    EXPECT_TRUE(hit_box(lo, hi, o, inv, 2.0f, kInf));    // exit at exactly tmin
    EXPECT_FALSE(hit_box(lo, hi, o, inv, 2.01f, kInf));  // starts after the box
    EXPECT_FALSE(hit_box(lo, hi, o, safe_inverse_dir({-1, 0, 0}), 0.0f, kInf));  // behind
}

TEST(HitBox, AxisParallelRaysNeverProduceNaN) {
    const glm::vec3 lo(-1, -1, -1), hi(1, 1, 1);
    // Zero direction components, origins on the slab planes (0 * inf would be NaN).
    for (const glm::vec3 dir : {glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, 1),
                                glm::vec3(1, 1, 0), glm::vec3(-0.0f, 0, -1)}) {
        const glm::vec3 inv = safe_inverse_dir(dir);
        EXPECT_TRUE(std::isfinite(inv.x) && std::isfinite(inv.y) && std::isfinite(inv.z));
        // Starting inside.
        EXPECT_TRUE(hit_box(lo, hi, {0, 0, 0}, inv, 0.0f, kInf));
        EXPECT_TRUE(hit_box(lo, hi, {0.5f, -0.5f, 0.25f}, inv, 0.0f, 1e-3f));
        // Beside the box, parallel to it: miss.
        EXPECT_FALSE(hit_box(lo, hi,
                             glm::vec3(3, 3, 3) * (glm::vec3(1) - glm::abs(dir)) - dir * 5.0f, inv,
                             0.0f, kInf));
    }
    // Origin on the lo slab plane of the zero component: the ray lies in the box face.
    EXPECT_TRUE(hit_box(lo, hi, {-5, -1, 0}, safe_inverse_dir({1, 0, 0}), 0.0f, kInf));
}

TEST(IntersectTriangle, ClosedFormHit) {
    const glm::vec3 v0(0, 0, 0), v1(4, 0, 0), v2(0, 4, 0);
    float t, u, v;
    ASSERT_TRUE(intersect_triangle({1, 2, 3}, {0, 0, -1}, 0.0f, kInf, v0, v1, v2, t, u, v));
    EXPECT_EQ(t, 3.0f);
    EXPECT_EQ(u, 0.25f);
    EXPECT_EQ(v, 0.5f);
    // From below too (no back-face culling).
    ASSERT_TRUE(intersect_triangle({1, 2, -2}, {0, 0, 2}, 0.0f, kInf, v0, v1, v2, t, u, v));
    EXPECT_EQ(t, 1.0f);
    // Interval is open: t == tmax and t == tmin are misses.
    EXPECT_FALSE(intersect_triangle({1, 2, 3}, {0, 0, -1}, 0.0f, 3.0f, v0, v1, v2, t, u, v));
    EXPECT_FALSE(intersect_triangle({1, 2, 3}, {0, 0, -1}, 3.0f, kInf, v0, v1, v2, t, u, v));
}

TEST(IntersectTriangle, EdgesAndVerticesAreInclusive) {
    const glm::vec3 v0(0, 0, 0), v1(4, 0, 0), v2(0, 4, 0);
    float t, u, v;
    for (const glm::vec3 p : {glm::vec3(0, 0, 0), glm::vec3(4, 0, 0), glm::vec3(0, 4, 0),
                              glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), glm::vec3(2, 2, 0)}) {
        EXPECT_TRUE(
            intersect_triangle(p + glm::vec3(0, 0, 1), {0, 0, -1}, 0.0f, kInf, v0, v1, v2, t, u, v))
            << p.x << " " << p.y;
        EXPECT_EQ(t, 1.0f);
    }
    EXPECT_FALSE(intersect_triangle({2.25f, 2, 1}, {0, 0, -1}, 0.0f, kInf, v0, v1, v2, t, u, v));
    EXPECT_FALSE(intersect_triangle({-0.25f, 1, 1}, {0, 0, -1}, 0.0f, kInf, v0, v1, v2, t, u, v));
}

TEST(IntersectTriangle, RayInThePlaneIsAMiss) {
    const glm::vec3 v0(0, 0, 0), v1(4, 0, 0), v2(0, 4, 0);
    float t, u, v;
    EXPECT_FALSE(intersect_triangle({-1, 1, 0}, {1, 0, 0}, 0.0f, kInf, v0, v1, v2, t, u, v));
}

TEST(PadBox, RelativeToMagnitudeAtEveryScale) {
    for (const float scale : {1e-3f, 1.0f, 1e5f}) {
        const Aabb box{glm::vec3(1, 2, -3) * scale, glm::vec3(1.5f, 2, -2.5f) * scale};
        const Aabb padded = pad_box(box);
        EXPECT_TRUE(glm::all(glm::lessThan(padded.lo, box.lo)));
        EXPECT_TRUE(glm::all(glm::greaterThan(padded.hi, box.hi)));
        // Padding is 2^-19 of the magnitude (3 * scale): at least 16 ulps, at most ~1e-5.
        const glm::vec3 grown = padded.extent() - box.extent();
        EXPECT_NEAR(grown.x, 2 * 3 * scale * kBoxPadRelative, 3 * scale * 1e-7);
    }
}

}  // namespace
}  // namespace glslppm
