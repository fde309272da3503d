// Tangent frames for normal maps (scene/tangent_space.h): the 32-bit packing the GPU reads
// and the tangents made from uvs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "scene/tangent_space.h"

namespace glslppm {
namespace {

TEST(TangentSpace, PackingKeepsDirectionWithin2e4AndTheSign) {
    std::mt19937 rng(7);
    std::normal_distribution<float> normal;
    float worst = 0.0f;
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 t = glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
        const float sign = (i & 1) ? -1.0f : 1.0f;
        const glm::vec4 back = unpack_tangent(pack_tangent(glm::vec4(t, sign)));
        worst = std::max(worst, glm::length(glm::vec3(back) - t));  // the angle, in radians
        ASSERT_EQ(back.w, sign);
    }
    // 15 bits per octahedral coordinate: about 1e-4 rad at worst.
    EXPECT_LT(worst, 2e-4f) << "worst angle " << worst;
    for (const glm::vec3 axis : {glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, -1)})
        EXPECT_LT(glm::length(glm::vec3(unpack_tangent(pack_tangent(glm::vec4(axis, 1)))) - axis),
                  1e-4f);
}

TEST(TangentSpace, GeneratedTangentsFollowDpDuAndTheSignDpDv) {
    // A quad in the xz plane, normal +y: u along -z, v along +x (n x t = +y x -z = -x: the
    // bitangent runs against dp/dv, sign -1); a second copy with v along -x has sign +1.
    const std::vector<glm::vec3> p = {{0, 0, 0}, {0, 0, -1}, {1, 0, -1}, {1, 0, 0}};
    const std::vector<glm::uvec3> t = {{0, 2, 1}, {0, 3, 2}};
    const std::vector<glm::vec3> n(4, glm::vec3(0, 1, 0));
    const std::vector<glm::vec2> uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (const glm::vec4& g : generate_tangents(p, t, n, uv)) {
        EXPECT_NEAR(glm::length(glm::vec3(g) - glm::vec3(0, 0, -1)), 0.0f, 1e-6f);
        EXPECT_EQ(g.w, -1.0f);
    }
    std::vector<glm::vec2> flipped = uv;
    for (glm::vec2& w : flipped) w.y = 1.0f - w.y;
    for (const glm::vec4& g : generate_tangents(p, t, n, flipped)) EXPECT_EQ(g.w, 1.0f);
    // A tilted vertex normal: the tangent is made orthogonal to it.
    std::vector<glm::vec3> tilted = n;
    tilted[0] = glm::normalize(glm::vec3(0, 1, -1));
    const glm::vec4 g0 = generate_tangents(p, t, tilted, uv)[0];
    EXPECT_NEAR(glm::dot(glm::vec3(g0), tilted[0]), 0.0f, 1e-6f);
    // uvs that span nothing: still a unit tangent orthogonal to the normal.
    const std::vector<glm::vec2> flat(4, glm::vec2(0.5f));
    const glm::vec4 g1 = generate_tangents(p, t, n, flat)[1];
    EXPECT_NEAR(glm::length(glm::vec3(g1)), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(glm::vec3(g1), n[1]), 0.0f, 1e-6f);
}

}  // namespace
}  // namespace glslppm
