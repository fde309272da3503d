#include "render/tiled_render.h"

#include <gtest/gtest.h>

using namespace glslppm;

TEST(PlanTiles, OneTileWhenTheVisiblePointsFit) {
    const TilePlan plan = plan_tiles(2560, 1080, 48, 128, 128u << 20);
    ASSERT_EQ(plan.tiles.size(), 1u);
    EXPECT_EQ(plan.tiles[0].width, 2560);
    EXPECT_EQ(plan.tiles[0].height, 1080);
    // No limit known: one tile too.
    EXPECT_EQ(plan_tiles(16384, 16384, 64, 144, 0).tiles.size(), 1u);
}

TEST(PlanTiles, FourKOnLlvmpipeIsThreeEqualBands) {
    // 128 MiB / (3840 x 48 bytes) = 728 rows: 2160 rows need 3 bands of 720.
    const TilePlan plan = plan_tiles(3840, 2160, 48, 128, 128u << 20);
    ASSERT_EQ(plan.tiles.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(plan.tiles[i].x, 0);
        EXPECT_EQ(plan.tiles[i].y, static_cast<int>(720 * i));
        EXPECT_EQ(plan.tiles[i].width, 3840);
        EXPECT_EQ(plan.tiles[i].height, 720);
        EXPECT_LE(std::size_t(3840) * 720 * 48, std::size_t(128) << 20);
    }
    // 8K with microfacet lobes: 128 MiB / (7680 x 64) = 273 rows; 4320 rows in 16 bands.
    const TilePlan eight = plan_tiles(7680, 4320, 64, 144, 128u << 20);
    ASSERT_EQ(eight.tiles.size(), 16u);
    int rows = 0;
    for (const Tile& t : eight.tiles) {
        EXPECT_EQ(t.y, rows);
        EXPECT_EQ(t.height, 270);
        rows += t.height;
    }
    EXPECT_EQ(rows, 4320);
}

TEST(PlanTiles, TileCameraComposesWithARenderRegion) {
    RenderSettings settings;
    settings.width = 100;
    settings.height = 60;
    Camera whole;
    Camera c = tile_camera(whole, settings, Tile{0, 20, 100, 20});
    EXPECT_EQ(c.full_width, 100);
    EXPECT_EQ(c.full_height, 60);
    EXPECT_EQ(c.region_x, 0);
    EXPECT_EQ(c.region_y, 20);
    Camera region;
    region.full_width = 400;
    region.full_height = 300;
    region.region_x = 50;
    region.region_y = 70;
    c = tile_camera(region, settings, Tile{0, 20, 100, 20});
    EXPECT_EQ(c.full_width, 400);
    EXPECT_EQ(c.region_x, 50);
    EXPECT_EQ(c.region_y, 90);
    EXPECT_EQ(tile_settings(settings, Tile{0, 20, 100, 20}).height, 20);
}
