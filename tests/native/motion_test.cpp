// Motion blur's CPU side (render/motion.h): the interpolation reproduces its steps, and the
// scene's box grown over the motion holds every vertex at every time of the shutter, a
// turning mesh included (the hash grid and ray offsets assume it does).
#include "render/motion.h"
#include "render/emitters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace glslppm {
namespace {

glm::mat4 placement(float angle, float scale, glm::vec3 move) {
    glm::mat4 m(1.0f);
    m[0] = glm::vec4(scale * std::cos(angle), scale * std::sin(angle), 0, 0);
    m[1] = glm::vec4(-scale * std::sin(angle), scale * std::cos(angle), 0, 0);
    m[2] = glm::vec4(0, 0, scale, 0);
    m[3] = glm::vec4(move, 1);
    return m;
}

TEST(Motion, InterpolationReproducesItsSteps) {
    // Three mirrored steps (validation wants one handedness), turned, scaled and sheared.
    const glm::mat4 mirror(glm::mat3(-1, 0, 0, 0, 1, 0, 0, 0, 1));
    const glm::mat4 shear(glm::mat3(1, 0, 0, 0.3f, 1, 0, 0, 0, 1));
    TransformSteps s;
    s.times = {-1.0f, 0.0f, 0.5f};
    s.to_world = {mirror, placement(2.0f, 0.5f, {1, 2, 3}) * shear * mirror,
                  placement(-1.0f, 2.0f, {-4, 0, 1}) * mirror};
    const TransformMotion motion(s);
    for (std::size_t k = 0; k < s.times.size(); ++k) {
        const glm::mat4 m = motion.at(s.times[k]);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                EXPECT_NEAR(m[c][r], s.to_world[k][c][r], 2e-6f) << "step " << k;
    }
}

TEST(Motion, GrownBoundsHoldTheMeshAtEveryTime) {
    // A mesh off its own origin, turning a half turn per interval and growing.
    const std::vector<glm::vec3> positions{{2, 0, 0}, {3, 1, 0}, {2.5f, -1, 0.5f}};
    const std::vector<glm::uvec3> triangles{{0, 1, 2}};
    Scene scene;
    MeshView mesh;
    mesh.positions = positions;
    mesh.triangles = triangles;
    scene.instance_meshes.push_back(mesh);
    scene.instances.push_back(Instance{placement(0.0f, 1.0f, {0, 0, 0}), 0, 0});
    scene.motion.shutter_length = 2.0f;
    scene.motion.shutter_open = -1.0f;
    InstanceMotion im{0, {}};
    im.steps.times = {-1.0f, 0.0f, 1.0f};
    im.steps.to_world = {placement(0.0f, 1.0f, {0, 0, 0}), placement(3.1f, 1.5f, {1, 0, 0}),
                         placement(6.2f, 2.0f, {0, 1, 0})};
    scene.motion.instances.push_back(im);
    const auto plan = plan_motion(scene);
    ASSERT_TRUE(plan);
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    grow_bounds_over_motion(scene, *plan, lo, hi);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> time(-1.0, 1.0);
    for (int i = 0; i < 20000; ++i) {
        const glm::mat4 m = plan->instance_motion[0].at(time(rng));
        for (const glm::vec3& p : positions) {
            const glm::vec3 w(m * glm::vec4(p, 1.0f));
            for (int k = 0; k < 3; ++k) {
                ASSERT_GE(w[k], lo[k]);
                ASSERT_LE(w[k], hi[k]);
            }
        }
    }
    // Not a box of everything: the motion's reach (scale 2, radius ~3.2) bounds it.
    EXPECT_LT(hi.x - lo.x, 16.0f);
}

TEST(Motion, StepsThatDoNotMovePlanNothing) {
    Scene scene;
    scene.instances.push_back(Instance{});
    scene.motion.shutter_length = 0.5f;
    scene.motion.instances.push_back(
        InstanceMotion{0, {{0.0f, 1.0f}, {glm::mat4(1.0f), glm::mat4(1.0f)}}});
    EXPECT_FALSE(plan_motion(scene));
    scene.motion.instances[0].steps.to_world[1][3].x = 1e-6f;
    EXPECT_TRUE(plan_motion(scene));
}

// A moving spot light: at the matrix's origin, shining along its -Z (Blender's lamps), the
// rotation slerped; place_light moves its record and keeps the rest of it.
TEST(Motion, MovingLightStandsAtItsInterpolatedTransform) {
    const auto turned = [](float angle, glm::vec3 move) {  // about x
        glm::mat4 m(1.0f);
        m[1] = glm::vec4(0, std::cos(angle), std::sin(angle), 0);
        m[2] = glm::vec4(0, -std::sin(angle), std::cos(angle), 0);
        m[3] = glm::vec4(move, 1);
        return m;
    };
    TransformSteps s;
    s.times = {0.0f, 1.0f};
    s.to_world = {turned(0.0f, {0, 0, 0}), turned(1.5707963f, {2, 0, 4})};
    Light spot;
    spot.kind = LightKind::Spot;
    spot.power = 7.0f;
    const MovingLight moving{0, spot, TransformMotion(s)};
    const Light at = moving.at(0.5);
    EXPECT_NEAR(glm::length(at.position - glm::vec3(1, 0, 2)), 0.0f, 1e-6f);
    // A quarter turn about x halfway: -Z turned by pi/4 is (0, sin, -cos) pi/4.
    const float h = std::sqrt(0.5f);
    EXPECT_NEAR(glm::length(at.direction - glm::vec3(0, h, -h)), 0.0f, 1e-6f);
    EXPECT_EQ(at.power, 7.0f);
    glm::vec4 record[4] = {glm::vec4(9, 9, 9, 1.5f), glm::vec4(0, 0, -1, 0.8f),
                           glm::vec4(0.1f, 0.2f, 0.3f, 0.4f), glm::vec4(5, 5, 5, 0.5f)};
    place_light(at, record);
    EXPECT_EQ(record[0], glm::vec4(at.position, 1.5f));
    EXPECT_EQ(record[1], glm::vec4(glm::normalize(at.direction), 0.8f));
    EXPECT_EQ(record[2], glm::vec4(0.1f, 0.2f, 0.3f, 0.4f));
    EXPECT_EQ(record[3], glm::vec4(5, 5, 5, 0.5f));
}

}  // namespace
}  // namespace glslppm
