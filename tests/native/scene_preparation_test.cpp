// The scene's preparation on the CPU, without a GL context: the feature set, the Frame, the
// sizes and the automatic radius the renderer uploads (render/scene_preparation.h).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <string>

#include "gl/object_counts.h"
#include "render/scene_preparation.h"
#include "procedural/cornell_box.h"

namespace glslppm {
namespace {

RenderSettings small_settings() {
    RenderSettings s;
    s.width = 64;
    s.height = 48;
    s.photons_per_pass = 3000;
    return s;
}

bool has_define(const PreparedScene& p, const std::string& name) {
    for (const auto& [define, value] : p.defines)
        if (define == name) return true;
    return false;
}

TEST(ScenePreparation, CornellBoxFeaturesSizesAndFrameWithoutGl) {
    const auto before = gl::gl_object_counts();
    const PreparedScene p = prepare_scene(make_cornell_box(), small_settings(), 64);
    // Only what the scene uses: smooth spheres, an emissive quad, and light tracing of the
    // mirror's and the glass' caustics.
    for (const char* d : {"HAS_NORMALS", "HAS_TRIANGLE_EMITTERS", "HAS_LIGHT_TRACING"})
        EXPECT_TRUE(has_define(p, d)) << d;
    for (const char* d : {"HAS_TEXTURES", "HAS_SPOT_LIGHTS", "HAS_ENVIRONMENT_MAP"})
        EXPECT_FALSE(has_define(p, d)) << d;
    EXPECT_NE(p.variant.find("direct=sampled"), std::string::npos) << p.variant;
    EXPECT_EQ(p.pixels, 64u * 48u);
    EXPECT_EQ(p.frame.image_width, 64u);
    EXPECT_EQ(p.frame.image_height, 48u);
    EXPECT_EQ(p.photon_threads, 3000u);
    EXPECT_EQ(p.hash_cells, 8192u);  // the power of two at or above 2 x photons (1024 at least)
    EXPECT_EQ(p.frame.hash_cell_count, p.hash_cells);
    EXPECT_EQ(p.frame.emitter_count, p.emitters.count);
    // The film's half extent: tan(fov_x / 2) across, times the aspect up.
    const float tan_x = std::tan(0.5f * make_cornell_box().camera.fov_x);
    EXPECT_FLOAT_EQ(p.frame.film_half_extent.x, tan_x);
    EXPECT_FLOAT_EQ(p.frame.film_half_extent.y, tan_x * 48.0f / 64.0f);
    // The automatic radius: positive, at most 5% of the scene's diagonal.
    const float diagonal = glm::length(p.bounds.hi - p.bounds.lo);
    EXPECT_GT(p.initial_radius, 0.0f);
    EXPECT_LE(p.initial_radius, 0.05f * diagonal);
    EXPECT_FLOAT_EQ(p.frame.radius_floor, 1e-5f * diagonal);
    // No GL object was made.
    EXPECT_EQ(gl::gl_object_counts().contexts, before.contexts);
}

// Multiple importance sampling of emissive triangles: compiled where a glossy lobe can
// send a BSDF sample to one, with each packed triangle's emitter record after the records
// (render/emitters.h), and nowhere else.
TEST(ScenePreparation, EmitterMisMapsEachEmissiveTriangleToItsRecord) {
    CornellBoxOptions glossy;
    glossy.glossy = true;
    // Lambertian visible points take the BSDF sample too (issue 30), so MIS is compiled
    // wherever light sampling meets emissive triangles, whatever the glossy threshold.
    EXPECT_TRUE(has_define(prepare_scene(make_cornell_box(glossy), small_settings(), 64),
                           "HAS_EMITTER_MIS"));
    RenderSettings settings = small_settings();
    settings.glossy_threshold = 0.2f;
    const PreparedScene p = prepare_scene(make_cornell_box(glossy), settings, 64);
    EXPECT_TRUE(has_define(p, "HAS_EMITTER_MIS"));
    EXPECT_NE(p.variant.find("emitter-mis"), std::string::npos) << p.variant;
    const std::vector<std::int32_t>& map = p.emitters.triangle_records;
    ASSERT_EQ(map.size(), p.bvh.triangle_count);
    ASSERT_EQ(p.emitters.records.size(), 4 * p.emitters.count + (map.size() + 3) / 4);
    std::size_t emissive = 0;
    for (std::uint32_t t = 0; t < p.bvh.triangle_count; ++t) {
        const std::int32_t in_buffer = std::bit_cast<std::int32_t>(
            p.emitters.records[4 * p.emitters.count + t / 4][static_cast<int>(t % 4)]);
        EXPECT_EQ(in_buffer, map[t]) << t;
        if (map[t] < 0) continue;
        ++emissive;
        // The record holds this triangle's corners, as the light sample draws them.
        const glm::vec4* record = &p.emitters.records[4 * static_cast<std::size_t>(map[t])];
        EXPECT_EQ(glm::vec3(record[0]), glm::vec3(p.bvh.triangles[3 * t])) << t;
        EXPECT_EQ(glm::vec3(record[2]), glm::vec3(p.bvh.triangles[3 * t + 2])) << t;
    }
    EXPECT_EQ(emissive, 2u);  // the light's quad
    // The diffuse box too (its Lambertian points); without light sampling, or with light
    // samples alone, the programs and the records are as before.
    CornellBoxOptions diffuse;
    diffuse.mirror_sphere = diffuse.glass_sphere = false;
    const PreparedScene plain = prepare_scene(make_cornell_box(diffuse), small_settings(), 64);
    EXPECT_TRUE(has_define(plain, "HAS_EMITTER_MIS"));
    EXPECT_EQ(plain.emitters.records.size(),
              4 * plain.emitters.count + (plain.bvh.triangle_count + 3) / 4);
    for (DirectLight direct : {DirectLight::Photons, DirectLight::SampledNoMis}) {
        RenderSettings s = small_settings();
        s.direct_light = direct;
        const PreparedScene off = prepare_scene(make_cornell_box(glossy), s, 64);
        EXPECT_FALSE(has_define(off, "HAS_EMITTER_MIS")) << to_string(direct);
        EXPECT_EQ(off.emitters.records.size(), 4 * off.emitters.count) << to_string(direct);
    }
}

TEST(ScenePreparation, RadiusScaleAndRegion) {
    RenderSettings s = small_settings();
    const PreparedScene base = prepare_scene(make_cornell_box(), s, 64);
    s.radius_scale = 0.5f;
    EXPECT_FLOAT_EQ(prepare_scene(make_cornell_box(), s, 64).initial_radius,
                    0.5f * base.initial_radius);
    // The right half of a 128 x 48 frame: half the extent across, centred at +1/2.
    Scene scene = make_cornell_box();
    scene.camera.full_width = 128;
    scene.camera.full_height = 48;
    scene.camera.region_x = 64;
    const PreparedScene window = prepare_scene(scene, small_settings(), 64);
    const float tan_x = std::tan(0.5f * scene.camera.fov_x);
    EXPECT_FLOAT_EQ(window.frame.film_half_extent.x, 0.5f * tan_x);
    EXPECT_FLOAT_EQ(window.frame.film_shift.x, 0.5f * tan_x);
}

TEST(ScenePreparation, BadValuesAreErrorsBeforeAnyWork) {
    Scene scene = make_cornell_box();
    scene.lights.push_back(Light{});
    scene.lights.back().power = -1.0f;
    EXPECT_THROW(prepare_scene(scene, small_settings(), 64), SceneError);
}

}  // namespace
}  // namespace glslppm
