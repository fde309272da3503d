// The pass state's bytes (render/memory_estimate.h) against the sizes written out by hand,
// and the for_each_tile loop's order and inputs, without a GPU. The estimate against what a
// Renderer allocates is tests/python/test_memory_estimate.py.
#include "render/memory_estimate.h"

#include <gtest/gtest.h>

#include "procedural/cornell_box.h"
#include "render/gpu_layout.h"
#include "render/tiled_render.h"

using namespace glslppm;

TEST(MemoryEstimate, SppmBuffersWrittenOut) {
    PassStateShape shape;
    shape.pixels = 100;
    shape.photon_threads = 1000;
    shape.hash_cells = hash_cell_count(1000);
    shape.photon_slot = 1000;
    shape.paper_rng = true;
    const PassStateBytes b = pass_state_bytes(shape);
    EXPECT_EQ(shape.hash_cells, 2048u);
    EXPECT_EQ(b.visible_points, 100u * 4 * 16);
    EXPECT_EQ(b.pixel_stats + b.direct_light + b.film, 100u * 5 * 16);
    EXPECT_EQ(b.photon_paths, 1000u * 48);
    EXPECT_EQ(b.photons, 1000u * 48);
    EXPECT_EQ(b.hash_cells, 2048u * 16);
    EXPECT_EQ(b.sorted_photons, 4u);  // the stochastic hash's placeholder
    EXPECT_EQ(b.rng_states, 1100u * 16);
    EXPECT_EQ(b.pass_films + b.light_splats, 0u);
    EXPECT_EQ(b.total(),
              100u * 9 * 16 + 1000u * 96 + 2048u * 16 + 4 + 1100u * 16 + kRadiusStatsThreads * 8);
    EXPECT_EQ(b.bytes_per_pixel, 9u * 16);
    EXPECT_EQ(b.block_bytes_per_pixel, 64u);
    EXPECT_DOUBLE_EQ(b.bytes_per_photon, (1000.0 * 96 + 2048 * 16 + 1000 * 16) / 1000.0);
}

TEST(MemoryEstimate, PassesSplatsAndTheExactHash) {
    PassStateShape shape;
    shape.pixels = 10;
    shape.photon_threads = 4096;
    shape.hash_cells = hash_cell_count(4096);
    shape.photon_slot = 4096;
    shape.pass_stride = 6;
    shape.light_tracing = true;
    shape.exact_hash = true;
    const PassStateBytes b = pass_state_bytes(shape);
    EXPECT_EQ(b.pass_films, 10u * 6 * 16);
    EXPECT_EQ(b.light_splats, 10u * kLightSplatBytes);
    EXPECT_EQ(b.sorted_photons, (4096u + 8192 / 1024) * 4);
    EXPECT_EQ(b.bytes_per_pixel, 9u * 16 + 6 * 16 + kLightSplatBytes);
    EXPECT_EQ(b.block_bytes_per_pixel, 96u);         // the pass films outgrow the visible points
    EXPECT_EQ(b.largest_photon_buffer, 4096u * 48);  // the paths and photons, above the cells
}

// The slots and steps themselves: tests/native/density_estimator_test.cpp.
TEST(MemoryEstimate, PppmStoresStepsSideBySide) {
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.photons_per_pass = 1000;
    settings.estimator = Estimator::Pppm;
    const PassStateShape shape = pass_state_shape(settings, nullptr, 3 * 1008 * 48);
    EXPECT_EQ(shape.photon_slot, 1008u);
    EXPECT_EQ(shape.steps_per_gather, 3u);
    EXPECT_EQ(pass_state_bytes(shape).photons, 3u * 1008 * 48);
    settings.estimator = Estimator::Sppm;
    const PassStateShape one_step = pass_state_shape(settings, nullptr, 3 * 1008 * 48);
    EXPECT_EQ(one_step.photon_slot, 1000u);
    EXPECT_EQ(one_step.steps_per_gather, 1u);
    EXPECT_EQ(pass_state_bytes(one_step).photons, 1000u * 48);
}

TEST(MemoryEstimate, VcmMergingStoresASlotPerLightVertex) {
    // One slot of photons_per_pass photons for each surface a light path may meet
    // (max_bounces + 1), as many as one storage buffer holds (docs/vcm.md): Blender's default
    // 12 bounces and 262,144 paths (12.6 MB a slot) take 13 slots where a buffer may hold
    // 1 GiB and 10 in llvmpipe's 128 MiB.
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.photons_per_pass = 262144;
    settings.max_bounces = 12;
    settings.estimator = Estimator::Vcm;
    settings.vcm_techniques = VcmTechniques::PathLightTracingAndMerging;
    const std::int64_t mib = 1 << 20;
    EXPECT_EQ(vcm_merge_slots(settings, 4096 * mib), 13u);
    EXPECT_EQ(vcm_merge_slots(settings, 128 * mib), 10u);
    EXPECT_EQ(vcm_merge_slots(settings, 0), 13u);  // unknown: 1 GiB
    const PassStateShape shape = pass_state_shape(settings, nullptr, 128 * mib);
    EXPECT_EQ(shape.photon_slot, 262144u);
    EXPECT_EQ(shape.steps_per_gather, 10u);
    EXPECT_EQ(pass_state_bytes(shape).photons, 10u * 262144 * 48);
    settings.photons_per_pass = 4 * 1024 * 1024;  // one slot over the buffer: still one slot
    EXPECT_EQ(vcm_merge_slots(settings, 128 * mib), 1u);
    settings.vcm_techniques = VcmTechniques::PathAndLightTracing;  // no merging: no slots
    EXPECT_EQ(vcm_merge_slots(settings, 128 * mib), 0u);
    settings.vcm_techniques = VcmTechniques::PathLightTracingAndMergingMergePart;
    settings.estimator = Estimator::Pppm;
    EXPECT_EQ(vcm_merge_slots(settings, 128 * mib), 0u);
}

TEST(MemoryEstimate, LightTracingAsSceneFeaturesDecidesIt) {
    const Scene box = make_cornell_box();  // a mirror and glass
    RenderSettings settings;
    EXPECT_TRUE(pass_state_shape(settings, &box, 0).light_tracing);
    settings.light_tracing = false;
    EXPECT_FALSE(pass_state_shape(settings, &box, 0).light_tracing);
    settings.light_tracing = true;
    settings.passes = {RenderPass::Direct, RenderPass::Indirect, RenderPass::Caustics};
    EXPECT_FALSE(pass_state_shape(settings, &box, 0).light_tracing);  // the light split
    EXPECT_FALSE(pass_state_shape(settings, nullptr, 0).light_tracing);
    settings.passes = {};
    Scene blurred = box;
    blurred.camera.aperture_radius = 0.1f;
    blurred.camera.focus_distance = 3.0f;
    EXPECT_TRUE(pass_state_shape(settings, &blurred, 0).light_tracing);  // through the lens
    // Light groups: each group's splats too, 48 bytes a group and pixel after the frame's.
    Scene grouped = box;
    grouped.light_groups = {"key", "fill"};
    const PassStateShape shape = pass_state_shape(settings, &grouped, 0);
    EXPECT_TRUE(shape.light_tracing);
    EXPECT_EQ(shape.light_splat_groups, 2u);
    EXPECT_EQ(pass_state_bytes(shape).light_splats, shape.pixels * 3 * 48);
    EXPECT_EQ(pass_state_shape(settings, &box, 0).light_splat_groups, 0u);
    EXPECT_TRUE(pass_state_shape(settings, nullptr, 0).light_tracing);    // no scene: at most
}

TEST(ForEachTile, VisitsThePlanInOrderWithEachTilesInputs) {
    const Scene box = make_cornell_box();
    RenderSettings settings;
    settings.width = 48;
    settings.height = 48;
    const TilePlan plan = plan_tiles(48, 48, 64, 144, 48 * 16 * 64);
    ASSERT_EQ(plan.tiles.size(), 3u);
    std::vector<int> rows;
    const std::size_t visited = for_each_tile(box, settings, plan, [&](const TileJob& job) {
        EXPECT_EQ(job.count, 3u);
        EXPECT_EQ(job.settings.height, job.tile.height);
        EXPECT_EQ(job.scene.camera.region_y, job.tile.y);
        EXPECT_EQ(job.scene.camera.full_height, 48);
        rows.push_back(job.tile.y);
        return job.index < 1;  // stop after the second
    });
    EXPECT_EQ(visited, 2u);
    EXPECT_EQ(rows, (std::vector<int>{0, 16}));
    // One tile: the frame's own scene and settings.
    const TilePlan one = plan_tiles(48, 48, 64, 144, 0);
    for_each_tile(box, settings, one, [&](const TileJob& job) {
        EXPECT_EQ(&job.scene, &box);
        EXPECT_EQ(&job.settings, &settings);
        return true;
    });
    TilePlan outside = one;
    outside.tiles[0].height = 49;
    EXPECT_THROW(for_each_tile(box, settings, outside, [](const TileJob&) { return true; }),
                 std::invalid_argument);
}
